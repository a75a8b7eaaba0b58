#!/usr/bin/env bash
# The per-object cost of each policy (issue 32: "the single-thread policy's
# per-object cost unchanged or lower"): instructions per create + drop of the
# contention cases on one thread, counted by valgrind's callgrind
# (deterministic where timers are noise), for bench/contention_st (vkrc::st)
# and bench/contention (vkrc::mt). Writes OUT/NAME-objects.csv headed by
# '# key: value' lines; copy it into docs/results/ and run
# scripts/gen_bench_docs.py, which puts the runs side by side.
#
#   bench/contention_instructions.sh BUILD_DIR OUT [NAME] [OPERATIONS]
#
# BUILD_DIR: a Release build of the contention and contention_st targets.
# OPERATIONS: counted per case (default 200), after one warm-up operation.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/contention_instructions.sh BUILD_DIR OUT [NAME] [OPERATIONS]" >&2
  exit 2
fi
build=$1
out=$2
name=${3:-}
operations=${4:-200}
cases=handle-own,alloc-pool,buffer-pool,image-pool,sets-free
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
bench_start "$build" "$out"
dumps=$(mktemp -d /tmp/objects-callgrind.XXXXXX)
trap 'rm -rf "$dumps"' EXIT
for policy in st mt; do
  program="$build/bench/contention$([ $policy = st ] && echo _st || true)"
  [ -x "$program" ] || { echo "contention_instructions.sh: no $program (build it first)" >&2; exit 1; }
  echo "== callgrind: $program --instructions $operations --cases $cases" >&2
  valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$dumps/$policy.out" \
    "$program" --instructions "$operations" --cases "$cases" >"$dumps/$policy.log" 2>&1 || {
    cat "$dumps/$policy.log" >&2
    echo "contention_instructions.sh: FAILED under callgrind" >&2
    exit 1
  }
done
device=$(sed -n 's/^device: \([^;]*\);.*/\1/p' "$dumps/st.log" | head -1)
prefix=$(bench_prefix "$name" "$device")
{
  bench_csv_header "$device" "bench/contention_instructions.sh BUILD OUT NAME $operations (Release build)"
  python3 - "$dumps" "$source_dir/bench" <<'PY'
import glob, os, sys
dumps = sys.argv[1]
sys.path.insert(0, sys.argv[2])
from callgrind_dump import read_dump
print("policy,case,operations,instructions_per_op,outside_driver_per_op")
rows = []
for policy in ("st", "mt"):
    for path in glob.glob(os.path.join(dumps, policy + ".out*")):
        desc, total, outside = read_dump(path)
        if desc and total is not None:
            n = int(desc["operations"])
            rows.append(f"{policy},{desc['case']},{n},{total / n:.1f},{outside / n:.1f}")
if not rows:
    sys.exit("contention_instructions.sh: FAILED: no per-case dumps")
print("\n".join(sorted(rows)))
PY
} >"$out/$prefix-objects.csv"
cat "$out/$prefix-objects.csv"
echo "wrote $out/$prefix-objects.csv"
