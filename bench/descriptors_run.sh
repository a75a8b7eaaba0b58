#!/usr/bin/env bash
# The descriptor-write run behind docs/benchmarks.md ("Descriptor writes"):
# bench/descriptors timed natively (--blocks 21 --reps 200), then under
# valgrind's callgrind for instructions per operation (each case's --reps 20
# operations collected alone, the driver included: the same driver work on
# both sides, so the difference is vkrc's). Writes one CSV into OUT headed by
# '# key: value' lines; copy it into docs/results/ and run
# scripts/gen_bench_docs.py.
#
#   bench/descriptors_run.sh BUILD_DIR OUT [NAME]
#
# BUILD_DIR: a Release build with the bench (BUILD_DIR/bench/descriptors).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/descriptors_run.sh BUILD_DIR OUT [NAME]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
program="$build/bench/descriptors"
[ -x "$program" ] || { echo "descriptors_run.sh: no $program (build the descriptors target first)" >&2; exit 1; }
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"
dumps=$(mktemp -d /tmp/descriptors-callgrind.XXXXXX)
trap 'rm -rf "$dumps"' EXIT

echo "== bench/descriptors --csv FILE" >&2
"$program" --csv "$dumps/time.csv" | tee "$dumps/log"
echo "== callgrind: bench/descriptors --reps 20 --blocks 1" >&2
valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$dumps/callgrind.out" \
  "$program" --reps 20 --blocks 1 >"$dumps/callgrind.log" 2>&1 || {
  cat "$dumps/callgrind.log" >&2
  echo "descriptors_run.sh: FAILED under callgrind" >&2
  exit 1
}
device=$(sed -n 's/^device: \([^;]*\);.*/\1/p' "$dumps/log" | head -1)
prefix=$(bench_prefix "$name" "$device")
{
  bench_csv_header "$device" "bench/descriptors_run.sh (Release build): descriptors --csv FILE; callgrind descriptors --reps 20 --blocks 1"
  python3 - "$dumps" <<'PY'
import csv, glob, os, re, sys
dumps = sys.argv[1]
instructions = {}
for path in glob.glob(os.path.join(dumps, "callgrind.out*")):
    case, total = None, None
    with open(path, errors="replace") as f:
        for line in f:
            m = re.match(r"desc: Trigger: Client Request: (\S+)", line)
            if m:
                case = m.group(1)
            m = re.match(r"(?:summary|totals): (\d+)", line)
            if m:
                total = int(m.group(1))
    if case and total is not None:
        instructions[case] = total / 20
if not instructions:
    sys.exit("descriptors_run.sh: FAILED: no per-case dumps")
rows = list(csv.DictReader(open(os.path.join(dumps, "time.csv"))))
print(",".join(list(rows[0].keys()) + ["instructions_per_op"]))
for r in rows:
    print(",".join(list(r.values()) + [f"{instructions[r['case']]:.0f}"]))
PY
} >"$out/$prefix-descriptors.csv"
echo "wrote $out/$prefix-descriptors.csv"
