#!/usr/bin/env bash
# The element solver on the Taylor scenes of scenes/ and on the published finite-element copper
# bar (scenes/copper-bar-227-elements.toml): `gpa study` of each at three resolutions, the scene's
# spacing halved, as written and doubled (refinement 0.5, 1, 2: 7-8, 15 and 30 elements across
# the radius of the 7.62 mm bars), with every body discretised by elements. Results in
# docs/study/elements/<scene>/ (study.md, study.csv and the error plots); docs/validation.md
# holds the tables. Builds gpa like scripts/study.sh; some two hours on 2 busy cores.
#
# Usage: bash scripts/element_study.sh [SCENE...]   (scene names of scenes/; default: all below)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build --target gpa_cli -j"$(nproc)"
gpa=./build/apps/gpa

scenes=("$@")
if ((${#scenes[@]} == 0)); then
  scenes=(copper-bar-227-elements armco-cylinder-nodal taylor-steel-343 taylor-steel-282 taylor-steel-208
          taylor-copper-130 taylor-copper-146 taylor-copper-190)
fi
status=0
start=$SECONDS
for scene in "${scenes[@]}"; do
  echo "== $scene"
  "$gpa" study "scenes/$scene.toml" -o "docs/study/elements/$scene" --overwrite --threads 2 --refine 0.5,1,2 \
    --variant elements:discretisation=elements || status=$?
done
echo "element_study.sh: $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s; results in docs/study/elements/"
exit $status
