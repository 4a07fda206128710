#!/usr/bin/env bash
# Issue 13: GPA against converged element references (docs/validation.md, "GPA against element
# references"). Two parts, each scene on 1 thread, one run at a time:
#
#   elements  the element reference of every Taylor scene and the Armco cylinder: `gpa study` of its
#             element version at the scene's spacing doubled, as written and halved (8, 15, 30
#             elements across the 7.62 mm bars), or divided by 1.5 at the finest for the Armco
#             cylinder and copper at 130 and 146 m/s (10, 20, 30 and 8, 15, 22 across: the session
#             that made them had not the hours for the finer runs), written to
#             scenes/references/<scene>.elements.toml by --reference (the rule: io/reference.hpp).
#             About an hour and a half on one core; copper 190 at 30 across takes 37 minutes of it.
#   gpa       the study of record: every scene at 2/3, 1 and 4/3 of its spacing (10, 15, 20 nodes
#             across the bars; 13, 20, 27 across the Armco cylinder), with the paper's Eq. 3 beside
#             the default diameter rule on copper 190, steel 208 and the Armco cylinder; reports in
#             docs/study/references/<scene>/ (study.md with L*, D*, PW*, the peaks and the outline
#             distance against the reference). About 15 minutes on one core.
#
# Usage: bash scripts/reference_study.sh [elements|gpa|all] [SCENE...]
set -euo pipefail
cd "$(dirname "$0")/.."
part=${1:-all}; shift || true
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build --target gpa_cli -j"$(nproc)" > /dev/null
gpa=./build/apps/gpa
scenes=("$@")
if ((${#scenes[@]} == 0)); then
  scenes=(taylor-steel-208 taylor-steel-282 taylor-steel-343 taylor-copper-130 taylor-copper-146 taylor-copper-190
          armco-cylinder-nodal)
fi
if [[ $part == elements || $part == all ]]; then
  for s in "${scenes[@]}"; do
    echo "== elements: $s"
    refine=0.5,1,2
    case $s in armco-cylinder-nodal|taylor-copper-130|taylor-copper-146) refine=0.5,1,1.5;; esac
    "$gpa" study "scenes/$s.toml" -o "studies/references/$s-elements" --overwrite --threads 1 --refine "$refine" \
      --variant elements:discretisation=elements --reference "scenes/references/$s.elements.toml"
  done
fi
if [[ $part == gpa || $part == all ]]; then
  for s in "${scenes[@]}" armco-cylinder-smoothing-tension armco-cylinder-bond armco-cylinder-smoothing-everywhere; do
    [[ " ${scenes[*]} " == *" $s "* || $s == armco-cylinder-* ]] || continue
    extra=()
    case $s in taylor-copper-190|taylor-steel-208|armco-cylinder-nodal) extra=(--variant hoop --variant eq3:node_diameter=section);; esac
    echo "== gpa: $s"
    "$gpa" study "scenes/$s.toml" -o "docs/study/references/$s" --overwrite --threads 1 --refine 0.6666667,1,1.3333333 "${extra[@]}"
  done
fi
