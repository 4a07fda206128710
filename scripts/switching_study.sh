#!/usr/bin/env bash
# Automatic fixed-to-variable switching against all-variable connectivity (docs/connectivity.md):
# every Taylor scene of scenes/ and the paper's Armco cylinder at 10, 15 and 20 nodes across the
# radius, both connectivities on 1 and 2 threads (wall time; results are bit-identical), and the
# switching threshold at 0.05 and 0.2 beside the default 0.1 on 1 thread. Writes
# docs/study/switching/<scene>/ (study.md, study.csv, plots) with `gpa study`. About an hour on 2
# idle cores; the wall times are part of the record, so run it on an otherwise quiet machine.
#
# Usage: bash scripts/switching_study.sh [SCENE...]   (scene names of scenes/; default: all seven)
#
# The threshold also ends the hourglass control of variable nodes (the lattice regime), so each
# threshold is run with both connectivities: the switched run is compared with the all-variable
# run at the same threshold.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build --target gpa_cli -j"$(nproc)"
gpa=./build/apps/gpa

variants=(
  --variant variable:connectivity=variable
  --variant variable-2t:connectivity=variable,threads=2
  --variant automatic:connectivity=automatic
  --variant automatic-2t:connectivity=automatic,threads=2
  --variant variable-t0.05:connectivity=variable,switch_plastic_strain=0.05
  --variant automatic-t0.05:connectivity=automatic,switch_plastic_strain=0.05
  --variant variable-t0.2:connectivity=variable,switch_plastic_strain=0.2
  --variant automatic-t0.2:connectivity=automatic,switch_plastic_strain=0.2
)

scenes=("$@")
if ((${#scenes[@]} == 0)); then
  scenes=(taylor-copper-130 taylor-copper-146 taylor-copper-190 taylor-steel-208 taylor-steel-282 taylor-steel-343
          armco-cylinder-nodal)
fi
for scene in "${scenes[@]}"; do
  case "$scene" in
    armco-cylinder-*) refine=0.5,0.75,1 ;;          # 0.255 mm = 20 across: 10, 15, 20
    *) refine=0.6666667,1,1.3333333 ;;               # 0.254 mm = 15 across: 10, 15, 20
  esac
  out=docs/study/switching/$scene
  echo "== $scene (refine $refine) =="
  "$gpa" study "scenes/$scene.toml" --refine "$refine" --threads 1 "${variants[@]}" -o "$out" --overwrite -q
done
