#!/usr/bin/env python3
"""Checks an instructions CSV (bench/instructions.sh) against the budget of
issue 12: a vkrc variant may exceed raw-direct by at most PCT percent on the
stages given by --relative and by at most ABS instructions per call on the
stages given by --absolute. One --budget VARIANT:PCT:ABS per variant checked.
Exits 1 listing every stage over budget, 0 when all are within."""
import argparse
import csv
import sys

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("csv")
parser.add_argument("--budget", action="append", required=True, help="VARIANT:PCT:ABS, e.g. vkrc-st:1:8")
parser.add_argument("--relative", default="command,submit,wait")
parser.add_argument("--absolute", default="acquire,uniform,present")
parser.add_argument("--reference", default="raw-direct")
parser.add_argument("--column", default="instructions_per_call",
                    help="instructions_per_call (all, on the calling thread) or outside_driver_per_call")
args = parser.parse_args()

per_call = {}
with open(args.csv) as f:
    for row in csv.DictReader(line for line in f if not line.startswith("#")):
        per_call[(row["variant"], row["stage"])] = float(row[args.column])

failures, lines = [], []
for budget in args.budget:
    variant, pct, absolute = budget.split(":")
    pct, absolute = float(pct), float(absolute)
    for kind, stages in (("relative", args.relative), ("absolute", args.absolute)):
        for stage in filter(None, stages.split(",")):
            ref = per_call.get((args.reference, stage))
            mine = per_call.get((variant, stage))
            if ref is None or mine is None:
                failures.append(f"{variant} {stage}: missing from {args.csv}")
                continue
            limit = ref * (1 + pct / 100) if kind == "relative" else ref + absolute
            rule = f"+{pct:g}%" if kind == "relative" else f"+{absolute:g}/call"
            ok = mine <= limit
            lines.append(f"{variant:10} {stage:8} {mine:12.1f} vs {args.reference} {ref:12.1f} "
                         f"(budget {rule}: <= {limit:.1f}) {'ok' if ok else 'OVER'}")
            if not ok:
                failures.append(f"{variant} {stage}: {mine:.1f} > {limit:.1f} instructions per call")
print("\n".join(lines))
if failures:
    print("instruction budget FAILED:\n  " + "\n  ".join(failures), file=sys.stderr)
    sys.exit(1)
print("instruction budget met")
