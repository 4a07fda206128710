#!/usr/bin/env bash
# Side by side with a peer: PySPH's taylor_bar example and gpa's statement of the same problem
# (benchmarks/peers/taylor_bar.toml), both to 25 us on 2 threads, one after the other.
#
#   bash benchmarks/peers/run_pysph_taylor.sh [BUILD_DIR]     (from the repository root)
#
# BUILD_DIR (default: build) holds the gpa program, BUILD_DIR/apps/gpa. PEERS_OUT=DIR puts the
# outputs in DIR instead of a new temporary directory. PySPH comes from the Debian package
# python3-pysph and runs with /usr/bin/python3; without it this prints one line and exits 0.
# The example is copied from the installed package into the output directory and patched
# there (S = 1800.0 -> S = 1.8); nothing of PySPH is kept in the repository.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
py=/usr/bin/python3
threads=2

if ! [ -x "$py" ] || ! "$py" -c 'import pysph, pysph.solver.utils, compyle' 2>/dev/null; then
    echo "run_pysph_taylor: skipped: PySPH is not importable by $py (install it with: apt-get install python3-pysph)"
    exit 0
fi

build="${1:-build}"
case "$build" in /*) ;; *) build="$root/$build" ;; esac
gpa="$build/apps/gpa"
if ! [ -x "$gpa" ]; then
    echo "run_pysph_taylor: $gpa not found; build it first: cmake --build ${1:-build} --target gpa_cli" >&2
    exit 1
fi

example="$("$py" -c 'import os, pysph; print(os.path.join(os.path.dirname(pysph.__file__), "examples", "solid_mech", "taylor_bar.py"))')"
if ! [ -f "$example" ]; then
    echo "run_pysph_taylor: the installed PySPH has no $example" >&2
    exit 1
fi

out="${PEERS_OUT:-$(mktemp -d "${TMPDIR:-/tmp}/gpa-peers-taylor.XXXXXX")}"
mkdir -p "$out"
echo "run_pysph_taylor: outputs in $out"

# The patched copy: the example writes the Hugoniot slope s as 1800; the problem has s = 1.8.
cp "$example" "$out/taylor_bar.py"
if [ "$(grep -c '^S = 1800\.0$' "$out/taylor_bar.py")" != 1 ]; then
    echo "run_pysph_taylor: $example has no single line 'S = 1800.0' to patch; the example changed, check it" >&2
    exit 1
fi
sed -i 's/^S = 1800\.0$/S = 1.8/' "$out/taylor_bar.py"
grep -q '^S = 1\.8$' "$out/taylor_bar.py" || { echo "run_pysph_taylor: patching S failed" >&2; exit 1; }

now() { date +%s.%N; }

# PySPH: tf = 25 us and dt = 1 ns as in the example (given again so that a changed default
# shows); output only at the start and the end (--pfreq beyond the step count), so that I/O
# does not enter the time. OpenMP is switched on by pysph_openmp_run.py (this PySPH has no
# --openmp option), with OMP_NUM_THREADS threads.
echo "run_pysph_taylor: PySPH taylor_bar, 25 us at dt = 1 ns on $threads threads (minutes) ..."
t0=$(now)
( cd "$out" && OMP_NUM_THREADS=$threads "$py" "$here/pysph_openmp_run.py" taylor_bar.py \
      --tf 2.5e-5 --timestep 1e-9 --pfreq 100000000 -q -d "$out/pysph" ) > "$out/pysph.stdout" 2>&1 || {
    echo "run_pysph_taylor: PySPH failed; see $out/pysph.stdout" >&2; tail -n 20 "$out/pysph.stdout" >&2; exit 1; }
t1=$(now)

echo "run_pysph_taylor: gpa $(basename "$here")/taylor_bar.toml on $threads threads ..."
"$gpa" run "$here/taylor_bar.toml" -o "$out/gpa" --threads "$threads" -q > "$out/gpa.stdout" 2>&1 || {
    echo "run_pysph_taylor: gpa failed; see $out/gpa.stdout" >&2; tail -n 20 "$out/gpa.stdout" >&2; exit 1; }
t2=$(now)

echo
"$py" "$here/taylor_compare.py" \
    --pysph-dir "$out/pysph" --pysph-process-seconds "$(awk "BEGIN{print $t1 - $t0}")" \
    --gpa-dir "$out/gpa" --gpa-process-seconds "$(awk "BEGIN{print $t2 - $t1}")" \
    --dx 0.384848e-3 --out "$out/results.md"
echo
echo "run_pysph_taylor: table written to $out/results.md"
