#!/usr/bin/env python3
"""The summary scripts/run.sh ends with: what vk::raii, vkrc-st and vkrc-mt
cost per frame over raw-direct, in time (from bench/teapot's 'cost' lines:
median and 95% interval bootstrapped over processes and blocks) and in
instructions (from bench/instructions.sh's CSV: the per-call counts of the
six per-frame stages summed; update, the same scene update in every variant,
left out), the image check, and where the rest is. scripts/gen_bench_docs.py
sums the committed counts with instructions_per_frame too.

    bench/run_summary.py OUT SECONDS
"""
import csv
import re
import sys

NAMES = {"vkhpp": "vk::raii", "vkrc-st": "vkrc-st", "vkrc-mt": "vkrc-mt",
         "raw-direct-control": "A/A control"}
STAGES = ("acquire", "uniform", "command", "submit", "present", "wait")


def instructions_per_frame(path):
    """{variant: (all, outside the driver)}: the six stages' per-call counts summed."""
    totals = {}
    with open(path) as f:
        for row in csv.DictReader(line for line in f if not line.startswith("#")):
            if row["stage"] in STAGES:
                total, outside = totals.get(row["variant"], (0.0, 0.0))
                totals[row["variant"]] = (total + float(row["instructions_per_call"]),
                                          outside + float(row["outside_driver_per_call"]))
    return totals


def main(out, seconds):
    text = open(f"{out}/teapot.txt").read()
    device = re.search(r"^device: (.*)$", text, re.M).group(1)
    config = re.search(r"^teapots \d+.*$", text, re.M).group(0)
    costs = re.findall(r"^cost +(\S+) +([+-]\d+) ns \[([+-]\d+), ([+-]\d+)\] +ratio +(\S+) \[ *(\S+), *(\S+)\]$",
                       text, re.M)
    images = re.findall(r"^image +(\S+) +(\S+) \((\d+) of (\d+) ", text, re.M)
    counts = instructions_per_frame(f"{out}/instructions.csv")
    ref_total, ref_outside = counts["raw-direct"]
    print(f"\nwhat each variant costs per frame over raw-direct (raw C, device functions called directly)\n"
          f"{device}; {config}\n")
    print(f"{'variant':12} {'time per frame [95% CI]':>40} {'ratio [95% CI]':>24} {'instructions per frame':>24}"
          f" {'incl. the driver':>17}")
    for variant, ns, low, high, ratio, rlow, rhigh in costs:
        total, outside = counts.get(variant, (None, None))
        extra = f"{total - ref_total:+,.0f}" if total is not None else "-"
        extra_out = f"{outside - ref_outside:+,.0f}" if outside is not None else "-"
        time = f"{int(ns):+,} ns [{int(low):+,}, {int(high):+,}]"
        print(f"{NAMES.get(variant, variant):12} {time:>40} {f'{ratio} [{rlow}, {rhigh}]':>24} {extra_out:>24}"
              f" {extra:>17}")
    print(f"(instructions by callgrind at 64x64, outside the driver (lavapipe's own count varies a little from run"
          f" to run);\n raw-direct itself: {ref_outside:,.0f} per frame outside the driver, {ref_total:,.0f} with it;"
          " the A/A control is raw-direct again: what the timer resolves)")
    differing = [name for name, verdict, _, _ in images if verdict != "identical"]
    compared = sum(int(n) for _, _, _, n in images)
    print("image check: " + ("every variant's frames identical to raw-direct's" if not differing else
                             "DIFFERS: " + ", ".join(differing)) + f" ({compared} frames compared)")
    print(f"\nfull tables {out}/teapot.txt, CSV {out}/teapot.csv, plots and frames {out}/teapot/,\n"
          f"instructions per stage {out}/instructions.txt and .csv; {seconds} s after the build.\n"
          "The full statistical protocol (every variant, 2500 frames, the targets' verdicts): "
          "bash scripts/run.sh --full")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
