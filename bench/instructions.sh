#!/usr/bin/env bash
# Instructions per call of every per-frame stage of every teapot variant,
# counted by valgrind's callgrind: deterministic where timers are noise.
#
#   bench/instructions.sh TEAPOT CSV [teapot options...]
#
# TEAPOT is a built bench/teapot (Release for figures worth quoting), CSV the
# file to write (variant,stage,calls,instructions,instructions_per_call,
# ratio_to_ref; the reference is raw-direct); the options go to
# `teapot --instructions` (e.g. --variants vkrc-st,vkrc-mt --frames 50
# --teapots 25; --frames is the number of calls counted per stage). Each
# stage of each variant is collected on its own (callgrind client requests
# around that stage's call, main thread only) and dumped; the dumps are
# parsed here. Prints the table too.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: bench/instructions.sh TEAPOT CSV [teapot options...]" >&2
  exit 2
fi
teapot=$1
csv=$2
shift 2
valgrind=${VALGRIND:-valgrind}
if ! command -v "$valgrind" >/dev/null 2>&1; then
  echo "instructions.sh: FAILED: valgrind not found (install the Debian package valgrind," \
       "scripts/install-deps.sh does)" >&2
  exit 1
fi
dumps=$(mktemp -d /tmp/teapot-callgrind.XXXXXX)
trap 'rm -rf "$dumps"' EXIT
"$valgrind" --tool=callgrind --collect-atstart=no --callgrind-out-file="$dumps/callgrind.out" \
  "$teapot" --instructions "$@" >"$dumps/log" 2>&1 || {
  cat "$dumps/log" >&2
  echo "instructions.sh: FAILED: teapot --instructions under callgrind" >&2
  exit 1
}
source_dir="$(cd "$(dirname "$0")/.." && pwd)"
# shellcheck source=bench/run_header.sh
source "$source_dir/bench/run_header.sh"
device=$(awk -F': ' '/^device: / {print $2; exit}' "$dumps/log")
{
  echo "# device: ${device:-${DEVICE:-unknown}}"
  # The NVIDIA driver where one is installed (a run on the device machine), else lavapipe's package.
  if command -v nvidia-smi >/dev/null 2>&1; then
    echo "# driver: $(bench_driver)"
  else
    echo "# driver: $(dpkg-query -W -f='mesa-vulkan-drivers ${Version}' mesa-vulkan-drivers 2>/dev/null || echo unknown)"
  fi
  echo "# date: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "# command: bench/instructions.sh TEAPOT CSV $*"
  echo "# git: $(bench_revision "$(dirname "$teapot")/..")"
  cache="$(dirname "$teapot")/../CMakeCache.txt"
  compiler=$(grep -s '^CMAKE_CXX_COMPILER:' "$cache" | cut -d= -f2 || true)
  echo "# build: $(grep -s '^CMAKE_BUILD_TYPE:' "$cache" | cut -d= -f2 || true)${compiler:+, $("$compiler" --version | head -1)}"
} >"$dumps/header"
python3 - "$dumps" "$csv" "$source_dir/bench" <<'PY'
import glob, os, sys
dumps, csv = sys.argv[1], sys.argv[2]
sys.path.insert(0, sys.argv[3])
from callgrind_dump import read_dump
rows = {}
for path in glob.glob(os.path.join(dumps, "callgrind.out*")):
    desc, total, outside = read_dump(path, "teapot ")
    if desc and total is not None:
        rows[(desc["variant"], desc["stage"])] = (int(desc["calls"]), total, outside)
if not rows:
    sys.exit("instructions.sh: FAILED: no per-stage dumps (teapot built without valgrind/callgrind.h?)")
order = ["acquire", "uniform", "command", "submit", "present", "wait", "update"]
variants = []
for v, _ in sorted(rows, key=lambda k: k[0]):
    if v not in variants:
        variants.append(v)
if "raw-direct" in variants:
    variants.remove("raw-direct")
    variants.insert(0, "raw-direct")
os.makedirs(os.path.dirname(os.path.abspath(csv)), exist_ok=True)
with open(csv, "w") as out:
    out.write(open(os.path.join(dumps, "header")).read())
    out.write("variant,stage,calls,instructions,instructions_per_call,ratio_to_ref,"
              "outside_driver_per_call,outside_driver_ratio_to_ref\n")
    print(f"{'stage':8} {'variant':16} {'calls':>6} {'instructions':>14} {'per_call':>12} {'ratio':>8}"
          f" {'outside_driver':>15} {'ratio':>8}")
    for stage in order:
        ref = rows.get(("raw-direct", stage))
        for v in variants:
            if (v, stage) not in rows:
                continue
            calls, total, outside = rows[(v, stage)]
            per, per_out = total / calls, outside / calls
            ratio = "" if not ref or ref[1] == 0 else f"{per / (ref[1] / ref[0]):.4f}"
            ratio_out = "" if not ref or ref[2] == 0 else f"{per_out / (ref[2] / ref[0]):.4f}"
            out.write(f"{v},{stage},{calls},{total},{per:.1f},{ratio},{per_out:.1f},{ratio_out}\n")
            print(f"{stage:8} {v:16} {calls:6} {total:14} {per:12.1f} {ratio:>8} {per_out:15.1f} {ratio_out:>8}")
print(f"CSV in {csv}")
PY
