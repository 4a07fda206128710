#!/usr/bin/env bash
# gpa render on a tiny run (tests/cli/tiny.toml, 20 steps): a picture of the last snapshot and of
# a chosen one, the listing of snapshots and fields, and bad input: a missing, running or empty
# folder, a garbled .pvd or .vtp, a snapshot file gone, an unknown field, bad sizes, ranges,
# snapshots and options. Every refusal is one line on stderr, exit 2, and leaves no picture.
# Usage: test_render.sh GPA_BINARY SOURCE_DIR WORK_DIR
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
# A PNG file: its 8-byte signature, and its width and height from the IHDR chunk.
is_png() { [[ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" == "89504e470d0a1a0a" ]]; }
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{printf "%dx%d", $1*16777216+$2*65536+$3*256+$4, $5*16777216+$6*65536+$7*256+$8}'; }

expect 0 "tiny run" -- "$gpa" run "$src/tests/cli/tiny.toml" -o run -q

# 1. Pictures.
expect 0 "render, all defaults" -- "$gpa" render run
[[ -s run/velocity-00001.png ]] || fail "no run/velocity-00001.png: $(ls run)"
is_png run/velocity-00001.png || fail "velocity-00001.png is not a PNG"
grep -q "^wrote run/velocity-00001.png" out.txt || fail "render does not say what it wrote: $(cat out.txt)"
grep -q "mirrored" out.txt || fail "an axisymmetric run is not mirrored by default: $(cat out.txt)"
expect 0 "render a component at a size" -- "$gpa" render run --field velocity:z --snapshot 0 --size 640x480 -o first.png
is_png first.png || fail "first.png is not a PNG"
[[ "$(png_size first.png)" == "640x480" ]] || fail "first.png is $(png_size first.png), expected 640x480"
expect 0 "render by time, width, range with units, into a folder" -- \
  "$gpa" render run --field pressure --time 300ns --width 400 --range=-1GPa:1GPa --no-mirror -o . -q
[[ -s pressure-00001.png ]] || fail "no pressure-00001.png in the folder given"
[[ $(png_size pressure-00001.png) == 400x* ]] || fail "pressure-00001.png is $(png_size pressure-00001.png), expected 400 wide"
[[ -s out.txt ]] && fail "-q printed: $(cat out.txt)"
expect 0 "render a region with units" -- "$gpa" render run --field pressure --region=-1mm:1mm,0:2mm -o region.png
is_png region.png || fail "region.png is not a PNG"
expect 0 "render the .pvd itself" -- "$gpa" render run/particles.pvd --field plastic_strain -o strain.png
is_png strain.png || fail "strain.png is not a PNG"
expect 0 "render with one frame for the run, a tensor component, no failure marks" -- \
  "$gpa" render run --field stress:hoop --frame run --snapshot 0 --no-failed-marks -o framed.png
is_png framed.png || fail "framed.png is not a PNG"
expect 0 "render the bodies by name" -- "$gpa" render run --field body -o bodies.png
is_png bodies.png || fail "bodies.png is not a PNG"
expect 0 "list" -- "$gpa" render run --list
for word in particles_00000.vtp particles_00001.vtp pressure von_mises_stress "axisymmetric (from scene.toml)"; do
  grep -qF "$word" out.txt || fail "--list lacks '$word': $(head -c 600 out.txt)"
done

# 2. Bad input: one line naming what is wrong, exit 2, no picture.
refused() {
  local what=$1 fragment=$2; shift 2
  rm -f refused.png
  expect 2 "$what" -- "$gpa" render "$@" -o refused.png
  grep -qF -- "$fragment" err.txt || fail "$what: message lacks '$fragment': $(cat err.txt)"
  [[ -e refused.png || -e refused.png.tmp ]] && fail "$what left a picture"
}
refused "missing folder" "nothing: no such folder" nothing
mkdir -p going.partial
refused "a run still going" "going.partial is there" going
mkdir -p empty
refused "folder without snapshots" "no particles.pvd" empty
refused "unknown field" "the fields are: alpha, body, connectivity" run --field presure
refused "component of a scalar" "scalar field" run --field pressure:z
refused "component 2D runs lack" "x and z" run --field velocity:y
refused "size not WxH" "--size 'big'" run --size big
refused "size too small" "the width must be 200 to 8192" run --size 0x0
refused "width too large" "--width 100000" run --width 100000
refused "width zero" "--width 0: it must be 200 to 8192" run --width 0
refused "size and width" "excludes" run --size 800x600 --width 800
refused "snapshot out of range" "--snapshot 9" run --snapshot 9
refused "snapshot not a number" "--snapshot 'first'" run --snapshot first
refused "snapshot and time" "excludes" run --snapshot 0 --time 1us
refused "time not a time" "--time '3 mm'" run --time "3 mm"
refused "range the wrong way" "must end above" run --field pressure --range 5:1
refused "range without a colon" "--range '5'" run --field pressure --range 5
refused "range of the wrong unit" "--range" run --field pressure --range "1 mm:2 mm"
refused "frame not a word it knows" "--frame 'all'" run --frame all
refused "frame and region" "excludes" run --frame run --region=-1mm:1mm,0:2mm
refused "a whole tensor" "von_mises_stress" run --field stress
refused "region without a comma" "--region '0:1'" run --region 0:1
refused "region the wrong way" "must end above" run --region=1mm:0mm,0:1mm
refused "region of the wrong unit" "--region" run --region "0:1 s,0:1"
refused "region missing the run" "nothing to draw in the region" run --region 1:2,1:2
refused "view of a 2D run" "3D runs only" run --view +x
refused "unknown view" "--view 'up'" run --view up
refused "unknown geometry" "--geometry 'round'" run --geometry round
refused "mirror and no-mirror" "excludes" run --mirror --no-mirror
expect 2 "output folder missing" -- "$gpa" render run -o nowhere/picture.png
grep -qF "the folder nowhere does not exist" err.txt || fail "output folder missing: $(cat err.txt)"
[[ -e nowhere ]] && fail "a missing output folder was made"

cp -r run broken
printf 'not a collection' > broken/particles.pvd
refused "garbled pvd" "broken/particles.pvd: not a VTK time-series collection" broken
cp run/particles.pvd broken/particles.pvd
head -c 2000 run/particles_00001.vtp > broken/particles_00001.vtp
refused "truncated vtp" "broken/particles_00001.vtp" broken
grep -q "cut short" err.txt || fail "truncated vtp: message does not say it is cut short: $(cat err.txt)"
rm broken/particles_00001.vtp
refused "snapshot file gone" "particles_00001.vtp: no such file (listed in" broken
# A snapshot of random bytes, and one of XML with raw bytes in its names: the message says what is
# wrong and shows no raw byte (only printable ASCII on stderr).
LC_ALL=C awk 'BEGIN { srand(21); for (i = 0; i < 3000; i++) printf "%c", int(rand() * 256) }' > broken/particles_00001.vtp
refused "vtp of random bytes" "broken/particles_00001.vtp: not a VTK XML file" broken
LC_ALL=C grep -q '[^[:print:]]' err.txt && fail "vtp of random bytes: the message shows raw bytes: $(od -c err.txt | head -5)"
printf '<?xml version="1.0"?>\n<VTKFile type="PolyData"><Pi\317\273\001 /a\002=x>' > broken/particles_00001.vtp
refused "vtp with raw bytes in its XML" "broken/particles_00001.vtp: malformed XML" broken
LC_ALL=C grep -q '[^[:print:]]' err.txt && fail "vtp with raw bytes in its XML: the message shows raw bytes: $(od -c err.txt | head -5)"
# The run's scene.toml, read for its geometry, goes through the scene's guard (issue 21, item 6).
cp -r run bytes-run
printf 'geometry = 2"\317\273"\n' > bytes-run/scene.toml
refused "scene.toml the TOML parser must not see" "bytes-run/scene.toml:1: a non-ASCII character outside a quoted string" bytes-run
expect 0 "another snapshot of the broken folder still renders" -- "$gpa" render broken --snapshot 0 -o zero.png -q

echo "$failures failure(s)"
exit $(( failures > 0 ))
