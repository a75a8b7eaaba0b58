#!/usr/bin/env bash
# The teapot runs behind docs/benchmarks.md, on whatever device this machine
# has: 25 and 2 500 teapots, headless, --runs 3 fresh processes each (RUNS
# overrides: more processes narrow the intervals, which include their spread). Writes
# one CSV per configuration into OUT, each headed by '# key: value' lines
# (device, driver, date, command, git revision) that scripts/gen_bench_docs.py
# reads, and beside it NAME-blocks.csv.gz (bench/teapot --blocks-csv, the same
# header, gzip -n so that the bytes depend on the data only): every block's
# median, from which the generator recomputes every interval. Copy both into
# docs/results/ and run the generator.
#
#   bench/device_run.sh BUILD_DIR OUT [NAME]
#
# BUILD_DIR: a Release build with the bench (BUILD_DIR/bench/teapot), e.g.
#   cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_TESTS=OFF
#   cmake --build build-release -j --target teapot alloc
# (with alloc built, bench/alloc_run.sh runs too: the allocation results).
# NAME: the results' file prefix (default: the date and a device slug).
# FRAMES_25 / FRAMES_2500 (environment) override the frames per run (2500 / 400).
# CONFIGS (below) picks which runs; VARIANTS (a,b,...) runs only those variants;
# EXTRA adds teapot arguments to every run (e.g. --size 64x64).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/device_run.sh BUILD_DIR OUT [NAME]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
teapot="$build/bench/teapot"
[ -x "$teapot" ] || { echo "device_run.sh: no $teapot (build the teapot target first)" >&2; exit 1; }
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"

run() {  # run FILE-SUFFIX teapot-args...
  local suffix=$1
  shift
  local csv="$out/tmp-$suffix.csv" blocks="$out/tmp-$suffix-blocks.csv" log="$out/tmp-$suffix.log"
  set -- "$@" ${EXTRA:-}
  local command="bench/teapot --runs ${RUNS:-3}${VARIANTS:+ --variants $VARIANTS} $*"
  echo "== $command" >&2
  "$teapot" --runs "${RUNS:-3}" ${VARIANTS:+--variants "$VARIANTS"} "$@" --csv "$csv" --blocks-csv "$blocks" --out-dir "$out/teapot_out-$suffix" | tee "$log"
  local device
  device=$(awk -F': ' '/^device: / {print $2; exit}' "$log")
  local prefix
  prefix=$(bench_prefix "$name" "$device")
  local header
  header=$(bench_csv_header "$device" "$command")
  {
    echo "$header"
    cat "$csv"
  } >"$out/$prefix-$suffix.csv"
  {
    echo "$header"
    cat "$blocks"
  } | gzip -n -9 >"$out/$prefix-$suffix-blocks.csv.gz"
  rm -f "$csv" "$blocks"
  echo "wrote $out/$prefix-$suffix.csv and $out/$prefix-$suffix-blocks.csv.gz" >&2
}

# CONFIGS (environment) picks the runs: t25, t2500, threads (the
# recording-thread scaling of issue 17: 25 000 draws on 1, 2, 4, 8 and 16
# threads; TEAPOTS_THREADS / FRAMES_THREADS / THREADS override), alloc. Default: all.
configs=" ${CONFIGS:-t25 t2500 threads alloc} "
[[ $configs == *" t25 "* ]] && run t25 --teapots 25 --frames "${FRAMES_25:-2500}"
[[ $configs == *" t2500 "* ]] && run t2500 --teapots 2500 --frames "${FRAMES_2500:-400}"
if [[ $configs == *" threads "* ]]; then
  run "threads-t${TEAPOTS_THREADS:-25000}" --teapots "${TEAPOTS_THREADS:-25000}" --threads "${THREADS:-1,2,4,8,16}" \
    --frames "${FRAMES_THREADS:-400}"
fi
if [[ $configs == *" alloc "* ]]; then
  if [ -x "$build/bench/alloc" ]; then
    "$source_dir/bench/alloc_run.sh" "$build" "$out" ${name:+"$name"}
  else
    echo "device_run.sh: no $build/bench/alloc: the allocation run is skipped" >&2
  fi
fi
