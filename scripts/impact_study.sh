#!/usr/bin/env bash
# The projectile-and-target studies of docs/validation.md (issue 10): each case is one run of
# build/tools/gpa_impact_study, its report written to docs/study/impact/CASE.txt.
#   bash scripts/impact_study.sh [CASE ...]     (no case: all of them; THREADS=N, default 2)
# Cases: spall-0.8-automatic ... spall-0.2-variable (scenes/hypervelocity-spall.toml at 0.8, 0.4 and
# 0.2 mm), small-0.4-automatic ... (scenes/hypervelocity-small.toml: plate spacing 0.8 / 0.4 / 0.2 mm,
# projectile 0.3 / 0.16 / 0.08 mm), perforation-0.5-variable-250 ... (the Weldox 460 E plate and
# its projectile at 0.7 / 0.5 / 0.35 mm, 250 and 300 m/s, variable or automatic connectivity: the
# Recht-Ipson ballistic limit of docs/validation.md comes from each pair of speeds).
set -euo pipefail
cd "$(dirname "$0")/.."
[[ -x build/tools/gpa_impact_study ]] || cmake --build build -j"$(nproc)" --target gpa_impact_study
out=docs/study/impact
mkdir -p "$out"
threads=${THREADS:-2}
all=()
for s in 0.8 0.4 0.2; do for c in automatic variable; do all+=("spall-$s-$c"); done; done
for s in 0.8 0.4 0.2; do for c in automatic variable; do all+=("small-$s-$c"); done; done
for s in 0.7 0.5 0.35; do for c in variable automatic; do for v in 250 300; do all+=("perforation-$s-$c-$v"); done; done; done
cases=("$@")
[[ ${#cases[@]} -gt 0 ]] || cases=("${all[@]}")
for case in "${cases[@]}"; do
  IFS=- read -r kind spacing connectivity speed <<< "$case"
  args=(--spacing "$spacing" --connectivity "$connectivity" --threads "$threads")
  case $kind in
    spall) scene=scenes/hypervelocity-spall.toml ;;
    small)
      scene=scenes/hypervelocity-small.toml
      # the projectile at 2.5 times finer than the plate, but at most 0.3 mm (2 nodes across its
      # radius: the plate at 0.8 mm would give 0.32 mm, which the scene check refuses)
      projectile=$(awk -v s="$spacing" 'BEGIN { p = s / 2.5; if (p > 0.3) p = 0.3; printf "%.3g", p }')
      args+=(--projectile-spacing "$projectile") ;;
    perforation) scene=scenes/perforation-weldox-460e.toml; args+=(--speed "$speed") ;;
    *) echo "impact_study: unknown case '$case'" >&2; exit 2 ;;
  esac
  echo "== $case"
  build/tools/gpa_impact_study "$scene" "${args[@]}" | tee "$out/$case.txt"
done
