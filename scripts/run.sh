#!/usr/bin/env bash
# Sets up a fresh Debian machine, builds gpa and runs the main job.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build --target gpa_cli -j"$(nproc)"
./build/apps/gpa run "$@"
