#!/usr/bin/env bash
# The gpa command on bad input: every malformed scene and bad command line ends with a one-line
# message and a non-zero exit (never a crash), and an existing output folder is never touched.
# Also `gpa study` on a small bar (tests/cli/study-bar.toml): its outputs, and its bad options.
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

# 4b. Snapshots at the scheduled times: each is the step nearest to k x interval, within half a
#     step of it (the steps of this bar are about 15 ns; the interval, 50 ns, is no multiple).
sed 's/^snapshots = 3/snapshot_interval = "50 ns"/' "$src/tests/cli/tiny.toml" > timed.toml
expect 0 "timed snapshots" -- "$gpa" run timed.toml -o timed -q
largest_dt=$(awk -F, 'NR > 1 && $2 > m { m = $2 } END { print m }' timed/history.csv)
grep -o 'timestep="[^"]*"' timed/particles.pvd | sed 's/timestep="\(.*\)"/\1/' |
  awk -v dt="$largest_dt" -v interval=50e-9 'NR > 1 {
      k = int($1 / interval + 0.5); off = $1 - k * interval; if (off < 0) off = -off
      if (off > 0.5 * dt * (1 + 1e-9)) { print "snapshot at " $1 " s is " off " s from " k * interval " s (half a step: " 0.5 * dt ")"; bad = 1 }
    } END { exit bad }' > timed.txt || fail "snapshots not at the nearest step: $(cat timed.txt)"

# 5. The library listing and a good check.
expect 0 "materials" -- "$gpa" materials
for m in "OFHC copper" "Armco iron" "4340 steel" "2024-T351"; do grep -q "$m" out.txt || fail "materials lacks $m"; done
# Every constant of a named material, as a [[material]] table that a scene can use as it is.
expect 0 "materials NAME" -- "$gpa" materials "4340 STEEL"
grep -q '^name = "4340 steel"$' out.txt || fail "materials NAME does not print the table: $(head -c 300 out.txt)"
for key in density shear_modulus specific_heat melt_temperature eos strength failure.johnson_cook source; do
  grep -q "^$key = " out.txt || fail "materials NAME lacks $key"
done
sed 's/^material = "elastic steel"$/material = "pasted steel"/' "$src/tests/cli/tiny.toml" > pasted.toml
sed 's/^name = "4340 steel"$/name = "pasted steel"/' out.txt >> pasted.toml
expect 0 "a scene with the printed table" -- "$gpa" check pasted.toml
expect 2 "materials of an unknown name" -- "$gpa" materials "4340 steel" "6061-T5"
grep -q '6061-T5' err.txt || fail "unknown material not named: $(cat err.txt)"
[[ -s out.txt ]] && fail "materials printed something before refusing an unknown name"
# An implausible value is a warning that names it (a unit slip), not a refusal.
sed 's/"-50 m\/s"/"-50 km\/s"/' "$src/tests/cli/tiny.toml" > fast.toml
expect 0 "check a scene at 50 km/s" -- "$gpa" check fast.toml
grep -q 'a speed of 50 km/s is beyond any impact experiment' out.txt || fail "no warning for 50 km/s: $(cat out.txt)"
expect 0 "check good scene" -- "$gpa" check "$src/scenes/hypervelocity-small.toml"
grep -qF 'material "Armco iron (shock)": base "Armco iron", with eos.model = "mie-gruneisen" (base: "polynomial")' out.txt ||
  fail "check does not show what a derived material changes: $(grep material out.txt)"
expect 0 "check good scene" -- "$gpa" check "$src/scenes/taylor-copper-190.toml"
# The first time step of the 0.254 mm copper bar is tens of nanoseconds (c about 4 km/s): a
# "0 ns" there would mean the check printed a step not yet computed.
grep -qE 'first time step [1-9][0-9.]* ns' out.txt || fail "check prints no positive first time step: $(grep 'time step' out.txt)"

# 6. gpa study: a small elastic bar over three resolutions, two variants and two thread counts.
bar="$src/tests/cli/study-bar.toml"
expect 0 "study" -- "$gpa" study "$bar" -o study --refine 1,1.5,2 --threads 1,2 --variant scene --variant sph:weight=sph-nsf -q
for f in study.csv study.md error_vs_time.svg discretisation_error_vs_time.svg; do
  [[ -s "study/$f" ]] || fail "study output lacks $f"
done
[[ -e study.partial ]] && fail "finished study left study.partial"
rows=$(( $(wc -l < study/study.csv) - 1 ))
[[ $rows -eq 12 ]] || fail "study.csv has $rows rows, expected 12 (3 resolutions x 2 variants x 2 thread counts)"
for series in scene-1t scene-2t sph-1t sph-2t; do
  n=$(cut -d, -f2 study/study.csv | grep -cx "$series")
  [[ $n -eq 3 ]] || fail "study.csv has $n rows of series $series, expected 3"
done
head -1 study/study.csv | grep -q "contact_time_s,contact_time_discretisation_error,contact_time_reference_error" \
  || fail "study.csv header lacks the contact-time columns: $(head -1 study/study.csv)"
[[ $(grep -c ",finished," study/study.csv) -eq 12 ]] || fail "not every study case finished"
grep -q "Observed orders" study/study.md || fail "study.md has no table of observed orders"
grep -q "<polyline" study/error_vs_time.svg || fail "error_vs_time.svg draws no line"
tail -1 study/error_vs_time.svg | grep -q "</svg>" || fail "error_vs_time.svg is not complete"
grep -q "^output: study " out.txt || fail "study does not say where its output went: $(cat out.txt)"

# Without --variant the scene as written is the one series; two resolutions give no order.
expect 0 "study, two resolutions" -- "$gpa" study "$bar" -o study2 --refine 1,2 --threads 1 -q
[[ $(( $(wc -l < study2/study.csv) - 1 )) -eq 2 ]] || fail "two-resolution study.csv rows"
grep -q "fewer than three resolutions" study2/study.md || fail "two-resolution study.md does not say why there is no order"

# 7. gpa study --reference: the element version of the bar at three resolutions is written as an
#    element reference; a scene that names it gets the ratio columns and section; a scene naming a
#    file that is not there is refused at once, naming the key.
expect 0 "study --reference" -- "$gpa" study "$bar" -o study-el --refine 1,1.5,2 --threads 1 \
  --variant elements:discretisation=elements --reference ref.toml -q
[[ -s ref.toml ]] || fail "study --reference wrote no file"
grep -q '^\[values.final_length\]' ref.toml || fail "the reference has no final length: $(head -c 600 ref.toml)"
grep -q '^kind = "' ref.toml || fail "the reference values have no kind"
grep -q '^\[outline\]' ref.toml || fail "the reference has no outline"
grep -q '^commit = "' ref.toml || fail "the reference has no commit"
sed "s#^source = \"one-dimensional elastic wave theory\"#&\nelements = \"$PWD/ref.toml\"#" "$bar" > bar-ref.toml
grep -q '^elements = ' bar-ref.toml || fail "could not make the scene with a reference"
expect 0 "study against a reference" -- "$gpa" study bar-ref.toml -o study-ref --refine 1,1.5,2 --threads 1 -q
head -1 study-ref/study.csv | grep -q "L_star,D_star,PW_star" || fail "study.csv lacks the ratio columns: $(head -1 study-ref/study.csv)"
grep -q "Against the element reference" study-ref/study.md || fail "study.md lacks the element reference section"
expect 0 "run against a reference" -- "$gpa" run bar-ref.toml -o run-ref -q
grep -q '"element_reference": {"file"' run-ref/summary.json || fail "summary.json lacks the element reference"
#    The same reference named by a scene without a rigid plane, where length and footprint are not
#    measured (issue 21, item 5: it reported L* 0.0000): no ratio of a metric the run does not have.
sed '/^\[\[plane\]\]/,/^lift_off/d' bar-ref.toml > bar-ref-free.toml
grep -q '^\[\[plane\]\]' bar-ref-free.toml && fail "could not make the scene without a plane"
expect 0 "run without a plane against a reference" -- "$gpa" run bar-ref-free.toml -o run-ref-free
grep -q 'L\* \|D\* ' out.txt && fail "a run without a rigid plane reports L* or D*: $(grep 'element reference' out.txt)"
grep -q 'against the element reference' out.txt || fail "no word on the reference: $(grep -i 'reference' out.txt)"
grep -q '"final_length": {"reference": [^}]*"computed": null' run-ref-free/summary.json ||
  fail "summary.json of a run without a plane: $(grep -o '"final_length": {[^}]*}' run-ref-free/summary.json)"
sed "s#^source = \"one-dimensional elastic wave theory\"#&\nelements = \"no-such-reference.toml\"#" "$bar" > bar-noref.toml
#    A reference that is not there (a shipped scene copied elsewhere) is no reason to refuse a scene
#    (issue 25): check and run warn, naming the key and the file, and the run is not compared.
expect 0 "scene naming a missing reference" -- "$gpa" check bar-noref.toml
grep -q "warning: .*reference.elements: .*no-such-reference.toml is not there: the run will not be compared" out.txt ||
  fail "check does not warn of the missing reference: $(cat out.txt)"
expect 0 "run of a scene naming a missing reference" -- "$gpa" run bar-noref.toml -o run-noref -q
grep -q "reference.elements: .*no-such-reference.toml is not there" out.txt err.txt ||
  fail "run: no warning of the missing reference: $(cat out.txt err.txt)"
grep -q '"element_reference": {"file": "[^"]*no-such-reference.toml", "error"' run-noref/summary.json ||
  fail "summary.json does not say the reference was missing: $(grep -o '"element_reference": {[^}]*}' run-noref/summary.json)"
#    The built-in default scene finds its reference beside the scene file it was made from, from any
#    working folder, and compares the headline run with it.
expect 0 "the built-in scene from another folder" -- bash -c "cd / && '$gpa' run -o '$PWD/run-builtin' --threads 2"
grep -q "against the element reference (.*armco-cylinder-nodal.elements.toml): L\\* " out.txt ||
  fail "the built-in scene is not compared with its element reference: $(grep -i reference out.txt)"
#    A folder or an empty file named as the reference: the message says which (issue 21, item 5).
mkdir -p ref-folder && : > ref-empty.toml
for ref in ref-folder ref-empty.toml; do
  sed "s#^source = \"one-dimensional elastic wave theory\"#&\nelements = \"$PWD/$ref\"#" "$bar" > bar-$ref.toml
done
expect 2 "a folder as the element reference" -- "$gpa" check bar-ref-folder.toml
grep -q "reference.elements: .*ref-folder: is a folder, not an element reference file" err.txt || fail "folder as reference: $(cat err.txt)"
expect 2 "an empty file as the element reference" -- "$gpa" check bar-ref-empty.toml.toml
grep -q "reference.elements: .*ref-empty.toml: the file is empty" err.txt || fail "empty reference: $(cat err.txt)"
#    A reference of bytes the TOML parser must not see (a non-ASCII character after a quote in a
#    bare value: undefined behaviour in toml++ 3.3.0) goes through the scene's guard (issue 21, item 6).
printf 'scene = "x"\nkind = 2"\317\273"\n' > ref-bytes.toml
sed "s#^source = \"one-dimensional elastic wave theory\"#&\nelements = \"$PWD/ref-bytes.toml\"#" "$bar" > bar-ref-bytes.toml
expect 2 "a reference the TOML parser must not see" -- "$gpa" check bar-ref-bytes.toml
grep -q "ref-bytes.toml:2: a non-ASCII character outside a quoted string" err.txt || fail "reference bytes: $(cat err.txt)"
#    A relative reference is found beside the scene file, whatever the working folder (as the
#    scenes in scenes/ name theirs), by run and study alike.
mkdir -p sub/references && cp ref.toml sub/references/bar.elements.toml
sed "s#^source = \"one-dimensional elastic wave theory\"#&\nelements = \"references/bar.elements.toml\"#" "$bar" > sub/bar-rel.toml
expect 0 "run against a relative reference" -- "$gpa" run sub/bar-rel.toml -o run-rel -q
grep -q '"element_reference": {"file"' run-rel/summary.json || fail "summary.json lacks the relative element reference"
grep -q '"element_reference": {[^}]*"error"' run-rel/summary.json && fail "the relative element reference was not found: $(grep -o '"element_reference": {[^}]*}' run-rel/summary.json)"

# Bad options: one line naming the option, exit 2, and no output folder.
study_refused() {
  local what=$1 fragment=$2; shift 2
  expect 2 "study $what" -- "$gpa" study "$bar" -o refused -q "$@"
  grep -qF -- "$fragment" err.txt || fail "study $what: message lacks '$fragment': $(cat err.txt)"
  [[ -e refused || -e refused.partial ]] && fail "study $what left an output folder"
}
study_refused "refine not a number" "--refine '1,x'" --refine 1,x
study_refused "refine twice" "listed twice" --refine 1,2,1
study_refused "refine zero" "positive refinement factor" --refine 0,1
study_refused "an unknown metric" "no metric 'length'" --metrics length
study_refused "threads" "--threads" --threads 1,-1
study_refused "reference from two series" "--reference" --refine 1,1.5,2 --variant a --variant b:weight=sph-nsf --reference r.toml
study_refused "reference from two resolutions" "--reference" --refine 1,2 --reference r.toml
study_refused "unknown variant key" "unknown key 'colour'" --variant x:colour=red
study_refused "bad variant value" 'solver.weight: "foo" is not one of "gpa" or "sph-nsf"' --variant x:weight=foo
study_refused "variant without a name" "name before its settings" --variant weight=sph-nsf
study_refused "variant name twice" "given twice" --variant a --variant a:weight=sph-nsf
study_refused "variant out of range" "--variant 'fast:cfl=2': solver.cfl = 2 is outside (0, 1]" --variant fast:cfl=2
study_refused "refinements on one lattice" "give the same lattice" --refine 1,1.01,2
expect 2 "study of a missing scene" -- "$gpa" study "$work/no-such-scene.toml" -o refused -q
[[ -e refused || -e refused.partial ]] && fail "study of a missing scene left an output folder"

# An existing study folder is refused and left as it was; --overwrite replaces it at the end.
mkdir -p keep2 && echo "precious" > keep2/result.txt
expect 2 "study into an existing folder" -- "$gpa" study "$bar" -o keep2 -q --refine 1
grep -q "overwrite" err.txt || fail "study refusal does not mention --overwrite: $(cat err.txt)"
[[ "$(cat keep2/result.txt)" == "precious" ]] || fail "study changed an existing folder"
expect 0 "study --overwrite" -- "$gpa" study "$bar" -o keep2 -q --refine 1 --overwrite
[[ -e keep2/result.txt ]] && fail "study --overwrite kept the old contents"
[[ -s keep2/study.csv ]] || fail "study --overwrite wrote no study.csv"

echo "$failures failure(s)"
exit $(( failures > 0 ))
