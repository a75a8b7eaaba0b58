#!/usr/bin/env bash
# The main job: installs what is missing, builds in Release and runs the
# teapot draw-loop benchmark headless (extra arguments go to it, e.g. --sweep,
# --csv teapot.csv, --variants raw,vkrc-st; see bench/teapot --help).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d /tmp/vkrc-xdg.XXXXXX)}"
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF >/dev/null
cmake --build build-release -j "$(nproc)" --target teapot
./build-release/bench/teapot "$@"
