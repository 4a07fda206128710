#!/usr/bin/env bash
# The test suite under the address and undefined-behaviour sanitizers, then the libFuzzer targets
# on the scene reader and on the shape-file readers (STL and CSV node files) for a bounded time. One clang build (build-asan) serves all.
# Usage: scripts/sanitize.sh [FUZZ_SECONDS]   (default 60; 0 skips the fuzzing)
# FUZZ_SECONDS is processor time, shared by the two targets: one fuzzing process per core, each
# FUZZ_SECONDS / cores long in all.
# The tests labelled `slow` (long physics runs: not even built here) and `install` (a consumer built
# with the system compiler against these libraries) are left out, and so are the long accuracy runs
# of gpa_tests and the study programs of tools/. Needs clang and libFuzzer (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${1:-60}
build=build-asan
jobs=$(nproc)

# -O1 and line tables only: the quickest build that still gives stack traces with lines. The engine
# and the materials, where the tests' physics runs spend their time, at -O2 (GPA_ENGINE_COMPILE_OPTIONS,
# CMakeLists.txt): four of the longest sanitized tests took 51 s instead of 105 s, for 28 s more
# compiler time. (-O2 everywhere was measured while Eigen still had UBSan checks: the whole test run
# 519 s against 577 s at -O1, for a longer build.)
# Eigen's headers get no UBSan checks (tests/fuzz/ubsan-ignorelist.txt says why: they stopped its
# inlining and made the tests 5 times slower); gpa's own code keeps them all.
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -fsanitize=fuzzer-no-link"
flags+=" -fsanitize-ignorelist=$PWD/tests/fuzz/ubsan-ignorelist.txt"
mkdir -p "$build"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -gline-tables-only" \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DGPA_BUILD_BENCHMARKS=OFF -DGPA_BUILD_SLOW_TESTS=OFF -DGPA_BUILD_TOOLS=OFF -DGPA_BUILD_FUZZERS=ON -DGPA_UNITY_BUILD=ON -DGPA_ENGINE_COMPILE_OPTIONS=-O2 \
  > "$build/configure.log" || { cat "$build/configure.log"; exit 1; }
sanitize_build_start=$(date +%s)
cmake --build "$build" -j"$jobs"
echo "the sanitizer build took $(( $(date +%s) - sanitize_build_start )) s"

# Reports inside third-party headers only, each explained in the file.
export UBSAN_OPTIONS="suppressions=$PWD/tests/fuzz/ubsan.supp:print_stacktrace=1:halt_on_error=1"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1"
# Left out besides, to keep CI within its time: the longest accuracy runs of gpa_tests, whose
# kernels and phases the shorter tests of the same suites run too: the Taylor bar (68 s under the
# sanitizers), the elastic bar's contact time (36 s), the element bar's contact time and rebound
# (20 s; ElementContact.HeldWithoutLiftOffAndFreeWithIt holds and frees element nodes on a plane),
# the pulled bar's front (18 s; the other PrescribedVelocity tests hold, pull and book regions), and
# the bounced bar's measurement (9 s; MeasureBase.ABodyOffThePlane measures from the underside);
# and cli_bad_input (92 s), whose malformed scenes the Corpus tests and the fuzz target read under
# the sanitizers already (its gpa study runs are the time it would take).
ctest --test-dir "$build" --output-on-failure -j"$jobs" -LE "slow|install" \
  -E "^(Taylor\.|ElasticBar\.|ElementBar\.ContactTime|PrescribedVelocity\.PulledBar|MeasureBase\.AnElasticBarThatBouncedOff|cli_bad_input$)"

# fuzz NAME TARGET CORPUS SECONDS DICTIONARY SEEDS...: the libFuzzer target TARGET in one process
# per core for SECONDS each (none when 0: libFuzzer takes -max_total_time=0 as no limit), each with
# its own random seed, sharing the folder CORPUS, where the new inputs go (each reads the seeds
# first, so an input that fails as it is fails in every one). DICTIONARY may be "" for none. Prints
# each process's summary lines; returns 1 when one failed, after the end of its log.
fuzz() {
  local name=$1 target=$2 corpus=$3 seconds=$4 dictionary=$5
  shift 5
  local seeds=("$@") options=() pids=() failed=() w status f
  [[ $seconds -gt 0 ]] || return 0
  [[ -z $dictionary ]] || options+=(-dict="$dictionary")
  mkdir -p "$corpus"
  echo "== fuzzing the $name reader: $workers processes for $seconds s each (seeds: ${seeds[*]}) =="
  # -rss_limit_mb: a scene may make the set-up allocate up to the target's 16 MiB limit, an STL
  # file a surface and its inside test of a few times its length.
  for ((w = 0; w < workers; ++w)); do
    "$build/tests/fuzz/$target" "$corpus" "${seeds[@]}" "${options[@]}" \
      -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=16384 -print_final_stats=1 \
      -artifact_prefix="$build/$name-" > "$build/fuzz-$name-$w.log" 2>&1 &
    pids+=($!)
  done
  for ((w = 0; w < workers; ++w)); do
    status=0
    wait "${pids[$w]}" || status=$?
    echo "-- fuzzing the $name reader, process $w (exit $status):"
    grep -E "INFO: seed corpus|^Done |stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)|ERROR|SUMMARY|runtime error|Test unit written" \
      "$build/fuzz-$name-$w.log" || true
    [[ $status -eq 0 ]] || failed+=("$w:$status")
  done
  for f in "${failed[@]}"; do
    tail -60 "$build/fuzz-$name-${f%%:*}.log"
    echo "fuzzing the $name reader: process ${f%%:*} failed (exit ${f##*:}); the input that did it is in $build/ ($name-crash-*, $name-leak-*, $name-timeout-*)"
  done
  [[ ${#failed[@]} -eq 0 ]]
}

if [[ $fuzz_seconds -gt 0 ]]; then
  # The 3D copies of the 2D scenes (scenes/*-3d.toml) are left out of the seeds: they read like
  # their 2D originals, but the fuzz target sets up those within its memory limit (3500-5600 3D
  # nodes each), and their mutants with them: measured over 20 s on one build, 219 inputs per
  # second with them and 1287 without.
  scene_seeds="$build/fuzz-seeds-scenes"
  rm -rf "$scene_seeds" && mkdir -p "$scene_seeds"
  find scenes -maxdepth 1 -name '*.toml' ! -name '*-3d.toml' -exec cp {} "$scene_seeds/" \;
  # One process per core; together they run about as many inputs as one process would in the
  # same processor time (measured: 128 100 inputs in 60 s on one core). The two readers share
  # FUZZ_SECONDS, a quarter (rounded down) to the STL reader and the rest to the scene reader:
  # the STL reader is one small file whose inputs take about 40 us each under the sanitizers
  # (27 000 a second per process, against 800-900 for scenes, each also set up as a simulation),
  # and its coverage stopped growing after about 250 000 inputs in a 300 s run, which a quarter
  # of 60 s on two cores (7 s a process) nearly reaches. Each libFuzzer run ends up to a second
  # past its -max_total_time and takes a moment to start: the scene reader gives 2 s a process
  # to the second run, so that the stage takes the time it took alone (measured with 60 s on two
  # cores: 31.8-32.3 s for one run of 30 s a process, 31.7 s for 21 s and 7 s).
  workers=$jobs
  per_worker=$(( (fuzz_seconds + workers - 1) / workers ))
  stl_seconds=$(( per_worker / 4 ))
  scene_seconds=$(( per_worker - stl_seconds - (stl_seconds > 0 ? 2 : 0) ))
  failed=0
  fuzz scene gpa_fuzz_scene "$build/fuzz-corpus" "$scene_seconds" tests/fuzz/scene.dict \
    "$scene_seeds" tests/io/bad_scenes tests/io/good_scenes tests/cli || failed=1
  # No dictionary: the seeds hold every word of the format, and libFuzzer takes the words the
  # reader compares against from its comparisons as it runs.
  fuzz shape-file gpa_fuzz_shape_files "$build/fuzz-corpus-shape-files" "$stl_seconds" "" tests/fuzz/stl_seeds \
    tests/io/bad_scenes/nodes || failed=1
  [[ $failed -eq 0 ]] || exit 1
fi
