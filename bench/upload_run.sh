#!/usr/bin/env bash
# The upload run behind docs/benchmarks.md, on whatever device this machine
# has: PROCESSES runs of bench/upload (default 3), each with its blocks, so
# that the intervals include run-to-run spread. Writes one CSV into OUT,
# headed by '# key: value' lines (device, driver, date, command, git
# revision, host) that scripts/gen_bench_docs.py reads, with a process
# column; copy it into docs/results/ and run the generator. No network.
#
#   bench/upload_run.sh BUILD_DIR OUT [NAME] [PROCESSES] [UPLOAD ARGS...]
#
# BUILD_DIR: a Release build with the bench (BUILD_DIR/bench/upload), e.g.
#   cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF -DVKRC_BUILD_EXAMPLES=OFF
#   cmake --build build-release -j --target upload
# NAME: the result's file prefix (default: the date and a device slug).
# UPLOAD ARGS: passed on (default --blocks 3 --reps 1000; lavapipe: --reps 250).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/upload_run.sh BUILD_DIR OUT [NAME] [PROCESSES] [UPLOAD ARGS...]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
processes=${4:-3}
shift $(($# < 4 ? $# : 4))
args=("$@")
[ ${#args[@]} -gt 0 ] || args=(--blocks 3 --reps 1000)
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"
bench_processes "$build" "$out" "$name" upload "$processes" "${args[@]}"
