#!/usr/bin/env bash
# Sets up a fresh Debian machine, builds gpa with its tests and benchmarks, and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# The test programs' own sources at -O1 (CMakeLists.txt, GPA_TEST_COMPILE_OPTIONS): a shorter build,
# the same test times; the engine and everything else at -O3.
build_start=$(date +%s)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DGPA_UNITY_BUILD=ON -DGPA_TEST_COMPILE_OPTIONS=-O1
cmake --build build -j"$(nproc)"
test_start=$(date +%s)
echo "configure and build took $(( test_start - build_start )) s"
ctest --test-dir build --output-on-failure -j"$(nproc)"
echo "the tests took $(( $(date +%s) - test_start )) s"
