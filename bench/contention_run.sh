#!/usr/bin/env bash
# The contention run behind docs/benchmarks.md, on whatever device this
# machine has: PROCESSES runs of bench/contention (default 3), each with its
# blocks, so that the intervals include run-to-run spread. Writes one CSV
# into OUT, headed by '# key: value' lines (device, driver, date, command,
# git revision, host) that scripts/gen_bench_docs.py reads, with a process
# column; copy it into docs/results/ and run the generator. No network.
#
#   bench/contention_run.sh BUILD_DIR OUT [NAME] [PROCESSES] [CONTENTION ARGS...]
#
# BUILD_DIR: a Release build with the bench (BUILD_DIR/bench/contention), e.g.
#   cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF -DVKRC_BUILD_EXAMPLES=OFF
#   cmake --build build-release -j --target contention
# NAME: the result's file prefix (default: the date and a device slug).
# CONTENTION ARGS: passed on (default: bench/contention's, threads 1,2,4,8,16,
# 5 blocks of 50 ms: about 25 s per process).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/contention_run.sh BUILD_DIR OUT [NAME] [PROCESSES] [CONTENTION ARGS...]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
processes=${4:-3}
shift $(($# < 4 ? $# : 4))
args=("$@")
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"
bench_processes "$build" "$out" "$name" contention "$processes" "${args[@]}"
