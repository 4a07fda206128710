#!/usr/bin/env bash
# Fixed connectivity on the copper Taylor bar (scenes/taylor-copper-190.toml) at 10, 15 and 20
# nodes across the radius: the run never crashes. It finishes (exit 0), or it stops where a
# lattice cell collapses with exit code 3, the output kept, and a message that names the node (by its id)
# and what to change.
# Usage: test_fixed_connectivity.sh GPA_BINARY SOURCE_DIR WORK_DIR
set -u
gpa=$1; src=$2; work=$3
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
for spacing in 0.381 0.254 0.1905; do
  sed -e "/^elements = /d" -e 's/^connectivity = "variable"/connectivity = "fixed"/' -e "s/^spacing = \"0.254 mm\"/spacing = \"$spacing mm\"/" \
    "$src/scenes/taylor-copper-190.toml" > "fixed-$spacing.toml"
  grep -q '^connectivity = "fixed"' "fixed-$spacing.toml" || fail "could not make the fixed scene"
  "$gpa" run "fixed-$spacing.toml" -o "run-$spacing" -q > out.txt 2> err.txt
  code=$?
  if [[ $code -eq 0 ]]; then
    echo "spacing $spacing mm: finished"
    continue
  fi
  [[ $code -eq 3 ]] || fail "spacing $spacing mm: exit $code, expected 0 or 3: $(head -c 400 err.txt)"
  grep -q 'node id [0-9]* (index [0-9]*) of body "bar" at (' err.txt || fail "spacing $spacing mm: the message does not name the node: $(head -c 400 err.txt)"
  grep -q 'connectivity = \\"automatic\\"\|connectivity = "automatic"' err.txt || fail "spacing $spacing mm: no remedy in: $(head -c 400 err.txt)"
  grep -q 'step [0-9]* at t = ' err.txt || fail "spacing $spacing mm: no step and time in: $(head -c 400 err.txt)"
  [[ -s "run-$spacing.partial/history.csv" && -s "run-$spacing.partial/summary.json" ]] || fail "spacing $spacing mm: output not kept"
  grep -q '"status": "failed"' "run-$spacing.partial/summary.json" || fail "spacing $spacing mm: summary does not say failed"
  echo "spacing $spacing mm: stopped cleanly: $(head -n 1 err.txt | cut -c 1-160)"
done
if [[ $failures -ne 0 ]]; then echo "$failures failure(s)"; exit 1; fi
echo "fixed connectivity: no crash at three resolutions"
