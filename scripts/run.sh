#!/usr/bin/env bash
# The main job: installs what is missing, builds vkrc in Release and runs the
# headless demo. Extra arguments go to the program.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d /tmp/vkrc-xdg.XXXXXX)}"
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF >/dev/null
cmake --build build-release -j "$(nproc)" --target device_info
./build-release/examples/device_info "$@"
