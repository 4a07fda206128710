#!/usr/bin/env bash
# Installs the Debian packages gpa needs to build, test, sanitize, fuzz and benchmark, and only those that are
# missing. Runs `apt-get update` once, and only when something has to be installed.
# Usage: scripts/install-deps.sh [--with-peers]   (--with-peers adds python3-pysph for the peer run)
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libtbb-dev libeigen3-dev libfmt-dev libspdlog-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libpng-dev   # gpa render: PNG pictures of snapshots
  libudunits2-dev   # tests only: the unit reader checked against UDUNITS-2's database
  python3-vtk9   # tests only: snapshots read by VTK's own readers (tests/io/vtk_round_trip.py)
  clang libclang-rt-14-dev llvm   # scripts/sanitize.sh: sanitizers, libFuzzer, llvm-symbolizer
)
if [[ "${1:-}" == "--with-peers" ]]; then
  packages+=(python3-pysph)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null; then sudo="sudo"; else
    echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2
    exit 1
  fi
fi
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
