#!/usr/bin/env bash
# The header-cost runs behind docs/benchmarks.md and README: bench/header_cost
# at -O3 and at -O0 with one build's compiler. Writes one CSV per flag set into
# OUT, headed by '# key: value' lines (compiler, Vulkan headers, date, command,
# git revision, host, load) that scripts/gen_bench_docs.py reads; copy them
# into docs/results/ and run the generator. Run it once per compiler:
#
#   bench/header_cost_run.sh BUILD_DIR OUT [REPETITIONS [--instructions]]
#
# BUILD_DIR: a Release build with the bench, e.g. for clang
#   CXX=clang++ cmake -S . -B build-clang -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_BENCH=ON -DVKRC_BUILD_EXAMPLES=OFF
#   cmake --build build-clang --target header_cost
# REPETITIONS: compiles of each probe per flag set (default 5; the median is kept).
# --instructions (or INSTRUCTIONS=1 in the environment): header_cost
#   --instructions, which also counts the compiler's instructions of each probe
#   once under valgrind (the instructions and instruction_ratio_to_raii
#   columns): a figure the machine's load does not move. Needs valgrind; adds
#   minutes per flag set (vk::raii under valgrind).
set -euo pipefail
if [ $# -lt 2 ] || [ $# -gt 4 ] || { [ $# -eq 4 ] && [ "$4" != --instructions ]; }; then
  echo "usage: bench/header_cost_run.sh BUILD_DIR OUT [REPETITIONS [--instructions]]" >&2
  exit 2
fi
build=$1
out=$2
repetitions=${3:-5}
options=()
if [ "${4:-}" = --instructions ] || [ "${INSTRUCTIONS:-0}" = 1 ]; then options=(--instructions); fi
bin="$build/bench/header_cost/header_cost"
[ -x "$bin" ] || { echo "header_cost_run.sh: no $bin (build the header_cost target first)" >&2; exit 1; }
mkdir -p "$out"
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
revision=$(git -C "$source_dir" rev-parse --short HEAD 2>/dev/null || echo unknown)
if git -C "$source_dir" status --porcelain 2>/dev/null | grep -q .; then revision="$revision (with local changes)"; fi
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
version=$("$compiler" --version | head -1)
case "$("$compiler" -dM -E -x c++ /dev/null)" in *__clang__*) slug=clang ;; *) slug=gcc ;; esac
vulkan_include=$(sed -n 's/^Vulkan_INCLUDE_DIR:[A-Z]*=//p' "$build/CMakeCache.txt")
headers=$(awk '/^#define VK_HEADER_VERSION_COMPLETE/ {s = $0; sub(/.*\(/, "", s); gsub(/[^0-9,A-Z_]/, "", s); split(s, v, ","); mm = v[2] "." v[3]}
               /^#define VK_HEADER_VERSION / {patch = $3} END {print mm "." patch}' \
  "${vulkan_include:-/usr/include}/vulkan/vulkan_core.h" 2>/dev/null || true)
cpu=$(awk -F': ' '/^model name/ {print $2; exit}' /proc/cpuinfo)
date_utc=$(date -u +%Y-%m-%dT%H:%MZ)

for level in -O3 -O0; do
  csv="$out/tmp-header-cost.csv"
  load_before=$(cut -d' ' -f1-3 /proc/loadavg)
  command="bench/header_cost --csv FILE ${options[*]:+${options[*]} }$repetitions $level"
  echo "== $command ($version)" >&2
  "$bin" --csv "$csv" "${options[@]}" "$repetitions" "$level"
  load_after=$(cut -d' ' -f1-3 /proc/loadavg)
  {
    echo "# compiler: $version"
    echo "# vulkan-headers: ${headers:-unknown}"
    echo "# date: $date_utc"
    echo "# command: $command (Release build)"
    echo "# git: $revision"
    echo "# host: $(nproc) CPUs, ${cpu:-unknown CPU}, $(uname -sr)"
    echo "# load: load average $load_before before, $load_after after"
    cat "$csv"
  } >"$out/$(date -u +%Y-%m-%d)-header-cost-$slug${level}.csv"
  rm -f "$csv"
  echo "wrote $out/$(date -u +%Y-%m-%d)-header-cost-$slug${level}.csv" >&2
done
