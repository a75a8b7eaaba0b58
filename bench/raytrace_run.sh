#!/usr/bin/env bash
# The render paths of examples/raytrace against the rasterised image, on
# whatever device this machine has: for each path but raster, PROCESSES runs
# (default 3) of `raytrace --headless --path PATH --compare --frames FRAMES`,
# each drawing the rasterised reference and the path every frame and writing
# both rows (GPU time per frame, median over the frames; differing pixels,
# max channel difference and PSNR against the reference). Writes one CSV per
# path into OUT, headed by '# key: value' lines (device, driver, date,
# command, git revision, host) as the other bench/*_run.sh do, with a
# process column. No network.
#
#   bench/raytrace_run.sh BUILD_DIR OUT [NAME] [PROCESSES] [PATHS]
#
# BUILD_DIR: a Release build with the examples (BUILD_DIR/examples/raytrace), e.g.
#   cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF
#   cmake --build build-release -j --target raytrace
# NAME: the results' file prefix (default: the date and a device slug); each
# path's file is NAME-raytrace-PATH.csv.
# PATHS: comma-separated (default mesh,raytrace; raytrace is compared, and so
# timed, without shadows). FRAMES (environment): frames per run (default 200).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/raytrace_run.sh BUILD_DIR OUT [NAME] [PROCESSES] [PATHS]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
processes=${4:-3}
paths=${5:-mesh,raytrace}
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"
for path in ${paths//,/ }; do
  BENCH_DIR=examples BENCH_LABEL="raytrace-$path" bench_processes "$build" "$out" "$name" raytrace "$processes" \
    --headless --path "$path" --compare --frames "${FRAMES:-200}" --out "$out/tmp-raytrace.png"
done
rm -f "$out/tmp-raytrace.png"
