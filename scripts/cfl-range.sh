#!/usr/bin/env bash
# The stable range of solver.cfl on the scenes of scenes/: each scene as written, at C_cfl = 0.4 to
# 1.0 in steps of 0.1, with the energy guard at its default (stop.energy_error = 3 %). A run is
# stable when it finishes; the table gives, per scene and C_cfl, the energy error at the end or
# the step at which the run failed. Writes docs/cfl-range.md (the table) from gpa study runs
# kept in runs/cfl-range/.
# Usage: scripts/cfl-range.sh [THREADS]   (default 2)
set -euo pipefail
cd "$(dirname "$0")/.."
threads=${1:-2}
gpa=build/apps/gpa
[[ -x $gpa ]] || { echo "build gpa first (scripts/test.sh)"; exit 1; }
values=(0.4 0.5 0.6 0.7 0.8 0.9 1.0)
variants=()
for c in "${values[@]}"; do variants+=(--variant "cfl$c:cfl=$c"); done
out=runs/cfl-range
mkdir -p "$out"
start=$(date +%s)
table="| scene |"
rule="|---|"
for c in "${values[@]}"; do table+=" $c |"; rule+="---|"; done
table+=$'\n'"$rule"
for scene in scenes/*.toml; do
  name=$(basename "$scene" .toml)
  echo "== $name ==" >&2
  "$gpa" study "$scene" --refine 1 --threads "$threads" "${variants[@]}" -o "$out/$name" --overwrite -q > /dev/null || true
  row="| $name |"
  for c in "${values[@]}"; do
    # study.csv: ...,steps (7),...,status (15),...,energy_error,message (last two)
    line=$(grep "^cfl$c," "$out/$name/study.csv" || true)
    status=$(echo "$line" | awk -F, '{print $15}')
    if [[ $status == finished ]]; then
      energy=$(echo "$line" | awk -F, '{print $(NF-1)}')
      row+=" $(awk -v e="$energy" 'BEGIN { printf "%.2f %%", 100 * e }') |"
    else
      step=$(echo "$line" | grep -o 'step [0-9]*' | head -1)
      why=$(echo "$line" | grep -q 'energy error' && echo "energy" || echo "numerical")
      row+=" failed ($why, ${step:-?}) |"
    fi
  done
  table+=$'\n'"$row"
done
{
  echo "# Stable range of solver.cfl"
  echo
  echo "Each scene of \`scenes/\` as written, at C_cfl from 0.4 to 1.0, with the energy guard at its"
  echo "default (\`stop.energy_error = 3 %\`): the energy error at the end of a finished run, or the"
  echo "step at which a run failed (energy: the guard stopped it; numerical: a node collapsed or a"
  echo "value stopped being a number). Written by \`bash scripts/cfl-range.sh\` on $(nproc) cores,"
  echo "$threads threads, in $(( $(date +%s) - start )) s; gpa $(git describe --always --dirty 2> /dev/null || echo '?')."
  echo
  echo "$table"
} > docs/cfl-range.md
cat docs/cfl-range.md
