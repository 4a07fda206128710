#!/usr/bin/env bash
# The gpa command on bad input: every malformed scene and bad command line ends with a one-line
# message and a non-zero exit (never a crash), and an existing output folder is never touched.
# Usage: test_cli.sh GPA_BINARY SOURCE_DIR WORK_DIR
set -u
gpa=$1; src=$2; work=$3
rm -rf "$work"; mkdir -p "$work"; cd "$work" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect CODE DESCRIPTION -- COMMAND...: the exit code, and for codes != 0 a one-line stderr.
expect() {
  local want=$1 what=$2; shift 3
  "$@" > out.txt 2> err.txt
  local got=$?
  if [[ $got -ne $want ]]; then fail "$what: exit $got, expected $want ($(head -c 300 err.txt))"; return; fi
  if [[ $want -ne 0 ]]; then
    local lines; lines=$(wc -l < err.txt)
    if [[ $lines -ne 1 ]]; then fail "$what: $lines lines on stderr: $(head -c 400 err.txt)"; fi
  fi
}

# 1. Every corpus scene: check and run refuse it with exit 2, a single line naming the file, and
#    no output folder.
count=0
for scene in "$src"/tests/io/bad_scenes/*; do
  name=$(basename "$scene")
  expect 2 "check $name" -- "$gpa" check "$scene"
  grep -qF "$name" err.txt || fail "check $name: message does not name the file: $(head -c 300 err.txt)"
  expect 2 "run $name" -- "$gpa" run "$scene" -o "out-$name" -q
  [[ -e "out-$name" || -e "out-$name.partial" ]] && fail "run $name left an output folder"
  count=$((count + 1))
done
echo "corpus: $count malformed scenes refused"

# 2. Bad command lines.
expect 2 "missing scene file" -- "$gpa" check "$work/no-such-scene.toml"
grep -qF "no-such-scene.toml" err.txt || fail "missing file not named: $(cat err.txt)"
"$gpa" run --threads -1 "$src/tests/cli/tiny.toml" > /dev/null 2>&1 && fail "negative thread count accepted"
"$gpa" frobnicate > /dev/null 2>&1 && fail "unknown subcommand accepted"

# A scene that reads but cannot be set up: refused before any output folder is made.
expect 2 "fixed body apart from the plane" -- "$gpa" run "$src/tests/cli/gap.toml" -o gap -q
grep -q "does not start on plane" err.txt || fail "gap scene message: $(cat err.txt)"
[[ -e gap || -e gap.partial ]] && fail "a refused scene left an output folder"

# 3. An existing, non-empty output folder is refused and left as it was.
mkdir -p keep && echo "precious" > keep/result.txt
expect 2 "existing output" -- "$gpa" run "$src/tests/cli/tiny.toml" -o keep -q
grep -q "overwrite" err.txt || fail "refusal does not mention --overwrite: $(cat err.txt)"
[[ "$(ls keep)" == "result.txt" && "$(cat keep/result.txt)" == "precious" ]] || fail "existing folder was changed"
[[ -e keep.partial ]] && fail "a refused run left keep.partial"

# 4. A good run writes a complete folder; --overwrite replaces an old one only at the end.
expect 0 "tiny run" -- "$gpa" run "$src/tests/cli/tiny.toml" -o fresh -q
for f in particles.pvd particles_00000.vtp history.csv summary.json profile.csv; do
  [[ -s "fresh/$f" ]] || fail "run output lacks $f"
done
[[ -e fresh.partial ]] && fail "finished run left fresh.partial"
grep -q '"status": "finished"' fresh/summary.json || fail "summary status"
expect 0 "overwrite" -- "$gpa" run "$src/tests/cli/tiny.toml" -o keep --overwrite -q
[[ -e keep/result.txt ]] && fail "--overwrite kept the old contents"
[[ -s keep/summary.json ]] || fail "--overwrite run has no summary"

# 5. The library listing and a good check.
expect 0 "materials" -- "$gpa" materials
for m in "OFHC copper" "Armco iron" "4340 steel" "2024-T351"; do grep -q "$m" out.txt || fail "materials lacks $m"; done
expect 0 "check good scene" -- "$gpa" check "$src/scenes/taylor-copper-190.toml"

echo "$failures failure(s)"
exit $(( failures > 0 ))
