#!/usr/bin/env bash
# The main job: installs what is missing, builds bench/teapot in Release,
# runs the teapot draw-loop benchmark headless and ends with a short summary.
#
#   bash scripts/run.sh [--full] [teapot options...]
#
# Default, a quick run (about 2 minutes after the build on 2 lavapipe cores):
# raw-direct (the reference), its A/A control, vk::raii, vkrc-st and vkrc-mt,
# 3 fresh processes of FRAMES (environment, default 250) frames per variant;
# then callgrind counts their instructions per frame (bench/instructions.sh,
# deterministic, so INSTRUCTION_FRAMES=5 calls per stage suffice, at 64x64:
# lavapipe renders on the CPU, under valgrind too); then the
# summary: each variant's per-frame cost over raw-direct in nanoseconds (95%
# interval bootstrapped over the processes and their blocks) and in
# instructions, the image check, and where the full tables, CSV and plots are.
# --full: the full statistical protocol instead (bench/teapot's defaults:
# every variant, 2500 frames, 3 processes, the overhead targets' verdicts),
# the one bench/device_run.sh runs; it prints the full tables.
# Options after go to bench/teapot (bench/teapot --help), e.g. --sweep or
# --variants raw,vkrc-st. Everything is written under build-release/.
set -euo pipefail
cd "$(dirname "$0")/.."
full=0
if [ "${1:-}" = "--full" ]; then
  full=1
  shift
fi
bash scripts/install-deps.sh
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d /tmp/vkrc-xdg.XXXXXX)}"
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF >/dev/null
cmake --build build-release -j "$(nproc)" --target teapot
teapot=build-release/bench/teapot
if [ $full -eq 1 ]; then
  exec "$teapot" "$@"
fi

out=build-release/run
rm -rf "$out"
mkdir -p "$out"
variants=vkhpp,vkrc-st,vkrc-mt
start=$(date +%s)
echo "run.sh: timing raw-direct, its A/A control, $variants: 3 processes of ${FRAMES:-250} frames each" >&2
"$teapot" --runs 3 --frames "${FRAMES:-250}" --variants "$variants" --out-dir "$out/teapot" \
  --csv "$out/teapot.csv" "$@" >"$out/teapot.txt" || {
  cat "$out/teapot.txt"
  echo "run.sh: FAILED: bench/teapot (its full output is above)" >&2
  exit 1
}
echo "run.sh: counting instructions per frame under callgrind (${INSTRUCTION_FRAMES:-5} frames per stage, 64x64)" >&2
bash bench/instructions.sh "$teapot" "$out/instructions.csv" --variants "$variants" \
  --frames "${INSTRUCTION_FRAMES:-5}" --size 64x64 >"$out/instructions.txt"
python3 bench/run_summary.py "$out" "$(($(date +%s) - start))"
