#!/usr/bin/env bash
# A/B speed comparison of two commits of gpa, for every change to the time step.
#
#   bash benchmarks/compare.sh BASE [HEAD]        (HEAD defaults to HEAD; any git revision works)
#
# Builds both commits in Release (cached under build/compare/<commit>/, so a second comparison
# against the same base builds only what changed), then runs, in ROUNDS rounds, one after the
# other within each round (the order alternates from round to round, so that a machine that
# slows down or speeds up during the run weighs on both alike):
#   * gpa_bench_steps on the step cases (CASES, at NODES nodes, THREADS threads, STEPS steps after
#     WARMUP warm-up steps): whole step and every phase, ms per step;
#   * three whole scenes: the README main job (`gpa run`, the built-in Armco cylinder),
#     scenes/taylor-copper-190.toml and scenes/hypervelocity-spall.toml at 0.8 mm (both bodies'
#     spacing doubled: fracture, debris, switching, a search nearly every step), wall seconds of
#     the whole run.
# It prints medians over the rounds per case and per phase for both commits and their ratio
# (base / head: above 1 means HEAD is faster). Medians and ratios are only comparable within one
# run on one machine; quote them with the machine, the threads and the problem size.
#
# Settings (environment): ROUNDS (5), THREADS (2), NODES (1e5), CASES ("2d-variable 2d-fixed
# 3d-variable 3d-fixed"), STEPS (10), WARMUP (20), SCENES (1: run the two whole scenes; 0: skip),
# UNITY (0: the default build, as scripts/run.sh makes it; 1: the unity build of scripts/test.sh
# and CI, -DGPA_UNITY_BUILD=ON, in build-unity/ beside build/), COMPARE_DIR (build/compare). Raw
# output of every round goes to COMPARE_DIR/raw-<base>-<head>/ (raw-unity-<base>-<head>/ with UNITY=1).
set -euo pipefail
cd "$(dirname "$0")/.."
top=$(pwd)
if [[ $# -lt 1 || $# -gt 2 || "$1" == "-h" || "$1" == "--help" ]]; then
  sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'
  [[ $# -ge 1 && ( "$1" == "-h" || "$1" == "--help" ) ]] && exit 0
  exit 2
fi
base_rev=$1
head_rev=${2:-HEAD}
rounds=${ROUNDS:-5}
threads=${THREADS:-2}
nodes=${NODES:-1e5}
cases=${CASES:-"2d-variable 2d-fixed 3d-variable 3d-fixed"}
steps=${STEPS:-10}
warmup=${WARMUP:-20}
with_scenes=${SCENES:-1}
case ${UNITY:-0} in
  0) build_name=build unity_flag=OFF raw_prefix=raw ;;
  1) build_name=build-unity unity_flag=ON raw_prefix=raw-unity ;;
  *) echo "compare.sh: UNITY must be 0 or 1, not '${UNITY}'" >&2; exit 2 ;;
esac
dir=${COMPARE_DIR:-$top/build/compare}

resolve() {
  git -C "$top" rev-parse --verify --quiet "$1^{commit}" || { echo "compare.sh: '$1' is not a commit of this repository" >&2; exit 2; }
}
base=$(resolve "$base_rev")
head=$(resolve "$head_rev")
command -v python3 >/dev/null || { echo "compare.sh: needs python3 for the tables" >&2; exit 2; }

# Build one commit: its source from git (a detached worktree), its own Release build folder.
build_commit() {
  local sha=$1 src="$dir/$1/src" bld="$dir/$1/$build_name"
  mkdir -p "$dir/$sha"
  if [[ ! -d "$src" ]]; then
    git -C "$top" worktree add --detach --force "$src" "$sha" >/dev/null
  fi
  cmake -S "$src" -B "$bld" -DCMAKE_BUILD_TYPE=Release -DGPA_UNITY_BUILD=$unity_flag -DGPA_BUILD_TESTS=OFF -DGPA_BUILD_TOOLS=OFF >"$dir/$sha/cmake-$build_name.log" 2>&1 ||
    { echo "compare.sh: cmake failed for $sha (see $dir/$sha/cmake-$build_name.log)" >&2; exit 1; }
  cmake --build "$bld" --target gpa_bench_steps gpa_cli -j"$(nproc)" >"$dir/$sha/$build_name.log" 2>&1 ||
    { echo "compare.sh: the build of $sha failed (see $dir/$sha/$build_name.log)" >&2; exit 1; }
}
echo "compare.sh: building $(git -C "$top" rev-parse --short "$base") and $(git -C "$top" rev-parse --short "$head") in $dir"
build_commit "$base"
build_commit "$head"

raw="$dir/$raw_prefix-${base:0:7}-${head:0:7}"
rm -rf "$raw"
mkdir -p "$raw"
case_args=()
for c in $cases; do case_args+=(--case "$c"); done

# One round of one commit: the step benchmark, then the three scenes, each timed.
run_round() {
  local sha=$1 tag=$2 k=$3 bld="$dir/$1/$build_name" src="$dir/$1/src"
  (cd "$src" && "$bld/benchmarks/gpa_bench_steps" "${case_args[@]}" --nodes "$nodes" --threads "$threads" \
     --steps "$steps" --warmup "$warmup" --repeat 1) >"$raw/$tag-$k.steps.md"
  if [[ "$with_scenes" == 1 ]]; then
    local out t0 t1
    out=$(mktemp -d)
    for scene in main-job scenes/taylor-copper-190.toml hypervelocity-spall-0.8mm; do
      if [[ "$scene" == hypervelocity-spall-0.8mm ]]; then
        sed 's/^spacing = "0.4 mm"/spacing = "0.8 mm"/' "$src/scenes/hypervelocity-spall.toml" >"$out/hypervelocity.toml"
      fi
      t0=$(date +%s.%N)
      if [[ "$scene" == main-job ]]; then
        (cd "$src" && "$bld/apps/gpa" run -o "$out/run" --threads "$threads" -q --overwrite) >/dev/null
      elif [[ "$scene" == hypervelocity-spall-0.8mm ]]; then
        (cd "$src" && "$bld/apps/gpa" run "$out/hypervelocity.toml" -o "$out/run" --threads "$threads" -q --overwrite) >/dev/null
      else
        (cd "$src" && "$bld/apps/gpa" run "$scene" -o "$out/run" --threads "$threads" -q --overwrite) >/dev/null
      fi
      t1=$(date +%s.%N)
      echo "scene $scene $(python3 -c "print($t1 - $t0)")" >>"$raw/$tag-$k.scenes.txt"
      rm -rf "$out/run"
    done
    rm -rf "$out"
  fi
}

for ((k = 1; k <= rounds; ++k)); do
  echo "compare.sh: round $k of $rounds"
  if ((k % 2)); then
    run_round "$base" base "$k"
    run_round "$head" head "$k"
  else
    run_round "$head" head "$k"
    run_round "$base" base "$k"
  fi
done

python3 - "$raw" "$rounds" "$(git -C "$top" rev-parse --short "$base")" "$(git -C "$top" rev-parse --short "$head")" \
  "$threads" "$nodes" <<'PY'
import re, statistics, sys, pathlib
raw, rounds, base, head, threads, nodes = sys.argv[1], int(sys.argv[2]), *sys.argv[3:]
raw = pathlib.Path(raw)

def read_steps(path):
    """{case: {row: ms}} from one gpa_bench_steps output with one thread count."""
    out, case = {}, None
    for line in path.read_text().splitlines():
        m = re.match(r"## (\S+) with (\d+) nodes .*?([\d.]+) neighbours per node", line)
        if m:
            case = m.group(1)
            out[case] = {"neighbours per node": float(m.group(3))}
            continue
        m = re.match(r"\| (.+?) \| ([-\d.e+]+)( M)? \|$", line)
        if case and m and m.group(1) not in ("phase (ms/step)", "speed-up", "searches/round"):
            out[case][m.group(1)] = float(m.group(2))
    return out

def read_scenes(path):
    out = {}
    if path.exists():
        for line in path.read_text().splitlines():
            _, name, seconds = line.split()
            out[name] = float(seconds)
    return out

data = {"base": [], "head": []}
for tag in data:
    for k in range(1, rounds + 1):
        data[tag].append((read_steps(raw / f"{tag}-{k}.steps.md"), read_scenes(raw / f"{tag}-{k}.scenes.txt")))

def med(tag, getter):
    values = [v for v in (getter(r) for r in data[tag]) if v is not None]
    return statistics.median(values) if values else None

def fmt(x, unit=""):
    return "-" if x is None else f"{x:.4g}{unit}"

print(f"\n# compare.sh: base {base} against head {head}, {threads} thread(s), about {nodes} nodes, "
      f"medians of {rounds} interleaved rounds\n")
print("ratio = base / head for times (above 1: head faster), head / base for node-steps/s\n")
print("| case | base | head | ratio |\n|---|---|---|---|")
cases = list(data["base"][0][0].keys())
for case in cases:
    for row, unit, invert in (("whole step", " ms", False), ("node-steps/s", " M", True), ("pair-steps/s", " M", True),
                              ("neighbours per node", "", None)):
        b = med("base", lambda r: r[0].get(case, {}).get(row))
        h = med("head", lambda r: r[0].get(case, {}).get(row))
        ratio = None if b is None or h is None or invert is None else (h / b if invert else b / h)
        print(f"| {case} {row} | {fmt(b, unit)} | {fmt(h, unit)} | {fmt(ratio, 'x')} |")
scene_names = list(data["base"][0][1].keys())
for name in scene_names:
    b = med("base", lambda r: r[1].get(name))
    h = med("head", lambda r: r[1].get(name))
    print(f"| whole run {name} | {fmt(b, ' s')} | {fmt(h, ' s')} | {fmt(None if not (b and h) else b / h, 'x')} |")
for case in cases:
    print(f"\n## {case}: phases, ms per step\n\n| phase | base | head | ratio | share of head's step |\n|---|---|---|---|---|")
    rows = []
    for tag in ("base", "head"):
        for name in data[tag][0][0].get(case, {}):
            if name not in rows and name not in ("node-steps/s", "pair-steps/s", "neighbours per node"):
                rows.append(name)
    whole = med("head", lambda r: r[0].get(case, {}).get("whole step"))
    for name in rows:
        b = med("base", lambda r: r[0].get(case, {}).get(name))
        h = med("head", lambda r: r[0].get(case, {}).get(name))
        share = None if h is None or not whole else 100.0 * h / whole
        print(f"| {name} | {fmt(b)} | {fmt(h)} | {fmt(None if not (b and h) else b / h, 'x')} | {fmt(share, ' %')} |")
print(f"\nraw output: {raw}")
PY
