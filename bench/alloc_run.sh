#!/usr/bin/env bash
# The allocation run behind docs/benchmarks.md and README, on whatever device
# this machine has: bench/alloc with its defaults (100 000 allocations, seed 1).
# Writes one CSV into OUT, headed by '# key: value' lines (device, driver,
# date, command, git revision, host) that scripts/gen_bench_docs.py reads;
# copy it into docs/results/ and run the generator. bench/device_run.sh calls
# it too when the alloc target is built.
#
#   bench/alloc_run.sh BUILD_DIR OUT [NAME]
#
# BUILD_DIR: a Release build with the bench (BUILD_DIR/bench/alloc), e.g.
#   cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF -DVKRC_BUILD_EXAMPLES=OFF
#   cmake --build build-release -j --target alloc
# NAME: the result's file prefix (default: the date and a device slug).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/alloc_run.sh BUILD_DIR OUT [NAME]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
alloc="$build/bench/alloc"
[ -x "$alloc" ] || { echo "alloc_run.sh: no $alloc (build the alloc target first)" >&2; exit 1; }
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"

csv="$out/tmp-alloc.csv"
log="$out/tmp-alloc.log"
echo "== bench/alloc --csv FILE" >&2
"$alloc" --csv "$csv" | tee "$log"
device=$(sed -n 's/^device: \([^;]*\);.*/\1/p' "$log" | head -1)
prefix=$(bench_prefix "$name" "$device")
{
  bench_csv_header "$device" "bench/alloc --csv FILE (Release build)"
  cat "$csv"
} >"$out/$prefix-alloc.csv"
rm -f "$csv" "$log"
echo "wrote $out/$prefix-alloc.csv" >&2
