#!/usr/bin/env bash
# Regenerates the thread-scaling, memory and bandwidth figures of docs/performance.md: builds
# gpa like scripts/test.sh, then runs gpa_bench_steps (whole steps of a Taylor bar in plastic
# flow, per phase, 1 and 2 threads, at 10^4, 10^5 and 10^6 nodes, 2D and 3D, variable and fixed
# connectivity), the triad bandwidth and the peak memory per node. About 35 minutes on 2 idle
# cores; run it on an otherwise quiet machine. The raw output goes to docs/performance/.
#
# Usage: bash scripts/performance.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build --target gpa_bench_steps -j"$(nproc)"
mkdir -p docs/performance
out=docs/performance/bench_steps.md
{
  echo "# gpa_bench_steps, $(date -u +%Y-%m-%d) on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) CPUs"
  echo
  ./build/benchmarks/gpa_bench_steps --bandwidth --nodes 1e4,1e5,1e6 --threads 1,2 --steps 10 --repeat 5 --warmup 20
  ./build/benchmarks/gpa_bench_steps --case 2d-variable --case 3d-variable --case 2d-fixed --case 3d-fixed \
    --nodes 1e6 --threads 2 --memory --steps 1 --repeat 1 --warmup 0 | grep '^memory'
} | tee "$out"
echo "performance.sh: written $out"
