#!/usr/bin/env python3
"""Regenerates the benchmark results in docs/benchmarks.md and README.md from
the CSV files under docs/results/ (one file per run: '# key: value' header
lines, then the program's CSV): the teapot runs (bench/device_run.sh), the
allocation runs (bench/alloc_run.sh), the contention runs
(bench/contention_run.sh) and the header-cost runs
(bench/header_cost_run.sh).

The contention runs also get a figure each (docs/img/<results file>.svg),
written and checked like the tables.

Every generated block sits between '<!-- generated:NAME -->' and
'<!-- end generated:NAME -->', a generated table row ends with
'<!-- generated-row:NAME -->'; nothing else is touched.
A teapot run with a block file beside it (<run>-blocks.csv.gz: every
block's median, bench/teapot --blocks-csv) has its ratio intervals
recomputed from the blocks, with bench/teapot's own bootstrap
(process_bootstrap); runs without one keep the intervals of their summary.
  scripts/gen_bench_docs.py          rewrite the files
  scripts/gen_bench_docs.py --check  exit 1 if a file would change (ctest docs.bench_tables)
  scripts/gen_bench_docs.py --check-blocks [SUMMARY.csv...]
        exit 1 unless every interval of every teapot run in docs/results/ with
        a block file (and of each SUMMARY given, a run with its block file
        beside it) equals the one recomputed from its blocks (ctest docs.teapot_blocks)
Python 3 standard library only."""
import argparse
import csv
import glob
import gzip
import io
import math
import os
import re
import sys
from bisect import bisect_right
from itertools import accumulate
from operator import itemgetter

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
import run_summary  # noqa: E402 (bench/run_summary.py: the per-frame instruction sum)
STAGES = ["preinit", "acquire", "uniform", "command", "submit", "present", "wait", "update", "frame"]


def load(path):
    meta, lines = {}, []
    with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as f:
        for line in f:
            m = re.match(r"#\s*([^:]+):\s*(.*)", line)
            if m and not lines:
                meta[m.group(1).strip()] = m.group(2).strip()
            else:
                lines.append(line)
    rows = list(csv.DictReader(io.StringIO("".join(lines))))
    return {"path": os.path.relpath(path, ROOT), "meta": meta, "rows": rows}


def median(values):
    """The median; of an even count, the mean of the middle two. Every median the generator computes is this."""
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else (v[n // 2 - 1] + v[n // 2]) / 2


def variants_of(rows):
    seen = []
    for r in rows:
        if r["variant"] not in seen:
            seen.append(r["variant"])
    return seen


def fmt_ratio(r):
    return f"{float(r['ratio_to_ref']):.3f} [{float(r['ref_ci_low']):.3f}, {float(r['ref_ci_high']):.3f}]"


def describe(result):
    m, rows = result["meta"], result["rows"]
    first = rows[0]
    frames = {r["variant"]: r for r in rows if r["stage"] == "frame"}
    ref = frames.get("raw-direct", first)
    per_run = int(ref["frames"]) // max(1, int(ref["runs"]))
    return (f"{first['teapots']} teapots, {per_run} frames per variant in each of {ref['runs']} runs "
            f"(tessellation {first['tessellation']}, {first['frames_in_flight']} frames in flight, "
            f"{first['uniform_writes']} uniform write(s))")


def control_resolves(control):
    """The A/A control resolves a stage when its interval lies within 1 +- 0.01."""
    return float(control["ref_ci_low"]) >= 0.99 and float(control["ref_ci_high"]) <= 1.01


# The per-stage time goals (issue 32 item 2; bench/teapot's target_ratio prints
# the same): every run is judged by today's goal, whatever target its CSV
# recorded (runs before issue 32 wrote vkrc-mt's 1.03 of issue 12).
TEAPOT_TARGETS = {"vkrc-st": "1.01", "vkrc-mt": "1.02"}


def row_target(row):
    """The goal of a row whose stage has one (its CSV's target column says which), else ''."""
    return TEAPOT_TARGETS.get(row["variant"], row["target"]) if row["target"] else ""


def teapot_verdict(row, control):
    """A target is met when the whole interval is within it and not met when the
    whole interval is above it, each only where the control resolves the stage
    (bench/teapot prints the same rule); runs written before the 'not met' case
    existed are judged again from their numbers."""
    if not row_target(row):
        return ""
    if control is None or not control_resolves(control):
        return "not resolved"
    target = float(row_target(row))
    if float(row["ref_ci_high"]) <= target:
        return "met"
    return "not met" if float(row["ref_ci_low"]) > target else "not resolved"


GPU_TIME_STAGES = ("wait", "frame")  # the CPU waiting for the GPU: time a wrapper cannot move, so no verdict
TIMER_FLOOR_US = 1.0  # raw-direct's median of a stage below it: judged by instruction counts only, not by time


def stage_kind(stage, ref):
    """'GPU time', 'timer floor' (from raw-direct's median in the same run) or '' for a timed CPU stage."""
    if stage in GPU_TIME_STAGES:
        return "GPU time"
    return "timer floor" if ref and stage != "preinit" and float(ref["median_us"]) < TIMER_FLOOR_US else ""


def stage_cells(row, control, kind):
    """The target and verdict cells: none but a note on a GPU-time or timer-floor stage."""
    if kind:
        return ("", f"no verdict: {kind}") if row["target"] else ("", "")
    return (("<= " + row_target(row)) if row_target(row) else ""), teapot_verdict(row, control)


def table(result):
    rows = result["rows"]
    m = result["meta"]
    out = [f"#### {describe(result)}", "",
           f"Device: {m.get('device', '?')}; driver: {m.get('driver', '?')}; date: {m.get('date', '?')}; "
           f"git: {m.get('git', '?')}; host: {m.get('host', '?')}. Data: `{result['path']}`.", "",
           f"    {m.get('command', '?')}", ""]
    floor = next((r["floor_ns"] for r in rows if r["stage"] != "image" and r.get("floor_ns")), "")
    out += [block_data_note(result), ""]
    out.append(f"Floor (an empty timed region, measured in the same run): {floor} ns. "
               "*above floor* is the median minus it.")
    out.append(f"Stages marked *GPU time* ({', '.join(GPU_TIME_STAGES)}) are the CPU waiting for the GPU, which "
               "a wrapper cannot move: no verdict. Stages marked *timer floor* (raw-direct's median in this run "
               f"below {TIMER_FLOOR_US:g} µs) are too short for the timer to judge: they are judged by the "
               "instruction counts (section *Instruction counts*) only.")
    out.append("")
    out.append("| stage | variant | median (µs) | above floor (ns) | ratio to raw-direct [95 % CI] | target | verdict |")
    out.append("|---|---|---:|---:|---|---|---|")
    control = {r["stage"]: r for r in rows if r["variant"] == "raw-direct-control"}
    ref = {r["stage"]: r for r in rows if r["variant"] == "raw-direct"}
    for stage in STAGES:
        kind = stage_kind(stage, ref.get(stage))
        for r in rows:
            if r["stage"] != stage:
                continue
            target, verdict_text = stage_cells(r, control.get(stage), kind)
            out.append(f"| {stage}{f' ({kind})' if kind else ''} | {r['variant']} | {float(r['median_us']):.3f} | "
                       f"{r['above_floor_ns']} | {fmt_ratio(r)} | {target} | {verdict_text} |")
    notes = []
    for stage in ("command", "submit", "wait"):
        c = control.get(stage)
        if c:
            notes.append(f"{stage} {fmt_ratio(c)} ({'within' if control_resolves(c) else 'not within'} 1 ± 0.01)")
    out.append("")
    out.append("A/A control (raw-direct against itself): " + "; ".join(notes) + ".")
    images = [r for r in rows if r["stage"] == "image"]
    bad = [r["variant"] for r in images if float(r["median_us"]) != 0]
    checked = images[0]["frames"] if images else "0"
    out.append("")
    if bad:
        out.append(f"Image check: **{', '.join(bad)} differed** from raw-direct.")
    else:
        out.append(f"Image check: the last timed frame of every block and the reference frame ({checked} per "
                   "variant) are byte-identical to raw-direct's for every variant.")
    return out


def block_data_note(result):
    """Which intervals a teapot table shows: recomputed from the run's block data, or its summary's."""
    if result.get("blocks"):
        return (f"Block data: `{result['blocks']}` (every block's median): the ratios and "
                "intervals below are recomputed from it by the generator, with bench/teapot's bootstrap "
                "(ctest `docs.teapot_blocks` checks that they equal the run's own).")
    return ("Block data: none (the run predates `bench/teapot --blocks-csv`): the ratios and intervals below are "
            "bench/teapot's summary and cannot be recomputed.")


def threads(row):
    # Files from before issue 17 have no threads column: one recording thread.
    return int(row.get("threads") or 1)


def is_threaded(result):
    return any(threads(x) > 1 for x in result["rows"])


LOADED = {}  # path -> load(path), teapot runs with their intervals recomputed from their blocks


def load_result(path):
    if path not in LOADED:
        r = load(path)
        if r["rows"] and "median_us" in r["rows"][0] and os.path.exists(blocks_path(path)):
            recompute_intervals(r, blocks_path(path), STAGES)
        LOADED[path] = r
    return LOADED[path]


def results(pattern, kind="median_us", threaded=False):
    # kind: a column that tells the CSV's kind (median_us: a timed run;
    # instructions_per_call: bench/instructions.sh). Timed runs with several
    # recording threads (teapot --threads) have their own tables.
    files = sorted(glob.glob(os.path.join(ROOT, "docs", "results", "*.csv")))
    return [r for r in map(load_result, files)
            if r["rows"] and kind in r["rows"][0] and re.search(pattern, r["meta"].get("device", ""), re.I)
            and (kind != "median_us" or is_threaded(r) == threaded)]


def instructions(pattern, pending):
    found = results(pattern, "instructions_per_call")
    if not found:
        return [pending]
    out = []
    for r in found:
        m = r["meta"]
        variants = variants_of(r["rows"])
        get = {(x["variant"], x["stage"]): x for x in r["rows"]}
        stages = [s for s in STAGES if any((v, s) in get for v in variants)]
        out += [f"Device: {m.get('device', '?')}; driver: {m.get('driver', '?')}; date: {m.get('date', '?')}; "
                f"git: {m.get('git', '?')}; build: {m.get('build', '?')}. Data: `{r['path']}`.", "",
                f"    {m.get('command', '?')}", "",
                "Instructions per call (ratio to raw-direct); after the semicolon, those outside the driver "
                "(the calls into the ICD and its libraries subtracted):", "",
                "| stage | " + " | ".join(variants) + " |", "|---|" + "---:|" * len(variants)]
        for s in stages:
            cells = []
            for v in variants:
                x = get.get((v, s))
                if not x:
                    cells.append("")
                    continue
                ratio = f" ({float(x['ratio_to_ref']):.2f})" if x["ratio_to_ref"] and v != "raw-direct" else ""
                cell = f"{float(x['instructions_per_call']):.0f}{ratio}"
                if x.get("outside_driver_per_call"):
                    o = float(x["outside_driver_per_call"])
                    ratio = x["outside_driver_ratio_to_ref"]
                    cell += f"; {o:.0f}" + (f" ({float(ratio):.2f})" if ratio and v != "raw-direct" else "")
                cells.append(cell)
            out.append(f"| {s} | " + " | ".join(cells) + " |")
        out.append("")
    return out[:-1]


def section(pattern, pending):
    found = results(pattern)
    if not found:
        return [pending]
    out = []
    for r in sorted(found, key=lambda r: (int(r["rows"][0]["teapots"]), r["path"])):
        out += table(r) + [""]
    return out[:-1]


THREADS_THROUGHPUT_GOAL = 0.97  # vkrc-mt's recording throughput against raw-direct's, every thread count
THREADS_SPEEDUP_GOAL = (25000, 8, 6.0)  # teapots, threads, speed-up (or raw-direct's, if it falls short)


def fmt_speedup(r):
    if not r.get("speedup"):
        return "1 (the baseline)" if threads(r) == 1 else ""
    return f"{float(r['speedup']):.2f} [{float(r['speedup_ci_low']):.2f}, {float(r['speedup_ci_high']):.2f}]"


def verdict(low, high, goal):
    """A goal (at least goal) is met or not met only when the interval [low, high] lies on one side of it."""
    return "met" if low >= goal else "not met" if high < goal else "not resolved"


def overall_verdict(verdicts):
    """Several cells of one goal: not met if any is, met if all are, else not resolved."""
    return "not met" if "not met" in verdicts else "met" if set(verdicts) == {"met"} else "not resolved"


def threads_goals(rows, teapots):
    """The goals of issue 17 read off one configuration's command rows."""
    get = {(threads(x), x["variant"]): x for x in rows}
    counts = sorted({threads(x) for x in rows})
    out = []
    if any((n, "vkrc-mt") in get for n in counts):
        cells, verdicts = [], []
        for n in counts:
            x = get.get((n, "vkrc-mt"))
            if not x:
                continue
            # Throughput is the inverse of time: the time ratio's bounds swap.
            low, high = 1 / float(x["ref_ci_high"]), 1 / float(x["ref_ci_low"])
            verdicts.append(verdict(low, high, THREADS_THROUGHPUT_GOAL))
            cells.append(f"{n}: {1 / float(x['ratio_to_ref']):.3f} [{low:.3f}, {high:.3f}] {verdicts[-1]}")
        overall = overall_verdict(verdicts)
        out.append(f"Goal: vkrc-mt's recording throughput at least {THREADS_THROUGHPUT_GOAL}x raw-direct's at every "
                   f"thread count (throughput ratio [95 % CI], met or not met only when the interval clears the "
                   f"goal): {'; '.join(cells)}: **{overall}**.")
    goal_teapots, goal_threads, goal_speedup = THREADS_SPEEDUP_GOAL
    mt, raw = get.get((goal_threads, "vkrc-mt")), get.get((goal_threads, "raw-direct"))
    if teapots == goal_teapots and mt and raw and mt.get("speedup") and raw.get("speedup"):
        target = min(goal_speedup, float(raw["speedup"]))
        out.append(f"Goal: at {goal_threads} threads and {goal_teapots} draws, vkrc-mt's speed-up at least "
                   f"{target:.2f} ({goal_speedup} or raw-direct's {float(raw['speedup']):.2f}, whichever is lower): "
                   f"{fmt_speedup(mt)}: "
                   f"**{verdict(float(mt['speedup_ci_low']), float(mt['speedup_ci_high']), target)}**.")
    return out


def threads_table(result):
    rows, m = result["rows"], result["meta"]
    out = []
    key = lambda x: (x["teapots"], x["frames_in_flight"], x["uniform_writes"], x["tessellation"])
    for config in sorted({key(x) for x in rows}, key=lambda k: tuple(map(int, k))):
        mine = [x for x in rows if key(x) == config]
        if max(map(threads, mine)) == 1:
            continue  # a sweep's other settings: the single-thread tables' business
        command = sorted((x for x in mine if x["stage"] == "command"), key=threads)
        first = command[0] if command else mine[0]
        per_run = int(first["frames"]) // max(1, int(first["runs"]))
        out += [f"#### {config[0]} teapots on 1 to {max(map(threads, mine))} recording threads, {per_run} frames per "
                f"variant and thread count in each of {first['runs']} runs (tessellation {config[3]}, {config[1]} "
                f"frames in flight, {config[2]} uniform write(s))", "",
                f"Device: {m.get('device', '?')}; driver: {m.get('driver', '?')}; date: {m.get('date', '?')}; "
                f"git: {m.get('git', '?')}; host: {m.get('host', '?')}. Data: `{result['path']}`.", "",
                f"    {m.get('command', '?')}", "", block_data_note(result), "",
                "Command stage per frame. Speed-up: the 1-thread run's block medians over this thread count's "
                "(block b with block b of the same run; the thread counts run one after the other), ratio: "
                "block-wise to raw-direct at the same thread count; 95 % intervals over blocks and runs.", "",
                "| threads | variant | median (µs) | speed-up against 1 thread [95 % CI] | ratio to raw-direct [95 % CI] |",
                "|---:|---|---:|---|---|"]
        for x in command:
            out.append(f"| {threads(x)} | {x['variant']} | {float(x['median_us']):.3f} | {fmt_speedup(x)} | "
                       f"{fmt_ratio(x)} |")
        control = [f"{threads(x)}: {fmt_ratio(x)}" for x in command if x["variant"] == "raw-direct-control"]
        out += ["", "A/A control (raw-direct against itself, command): " + "; ".join(control) + "."]
        serial = amdahl_lines(command)
        if serial:
            out += ["", serial]
        goals = threads_goals(command, int(config[0]))
        if goals:
            out += [""] + goals
        lines = {v: [(threads(x), float(x["speedup"]) if x.get("speedup") else 1.0)
                     for x in command if x["variant"] == v]
                 for v in dict.fromkeys(x["variant"] for x in command)}
        lines = {v: pts for v, pts in lines.items() if len(pts) > 1}
        out += ["", f"![command-stage speed-up against recording threads, {m.get('device', '?')}]"
                f"({speedup_plot(result, sorted({threads(x) for x in command}), lines)})"]
        images = [x for x in mine if x["stage"] == "image"]
        bad = sorted({f"{x['variant']} at {threads(x)}" for x in images if float(x["median_us"]) != 0})
        out += ["", f"Image check: **{', '.join(bad)} differed**." if bad else
                "Image check: at every thread count, every variant's last timed frames and reference frame are "
                "byte-identical to raw-direct's at that count, and every threaded reference frame to the 1-thread "
                "raw-direct's.", ""]
    return out


AMDAHL_TOLERANCE = 0.10  # the largest miss of a measured median from the fit for "the fit holds"


def amdahl_serial(medians):
    """s of Amdahl's t(n) = s + (t(1) - s) / n fitted by least squares to {n: median} (n = 1 included):
    t(n) - t(1)/n = s (1 - 1/n), one unknown, so s = sum(a b) / sum(a a)."""
    one = medians[1]
    pairs = [(1 - 1 / n, t - one / n) for n, t in medians.items() if n > 1]
    return sum(a * b for a, b in pairs) / sum(a * a for a, _ in pairs)


def amdahl_lines(command):
    """The part of the command stage that more threads do not shrink, per variant, from the medians: what
    caps the speed-up (a fixed or serial share) where the fit holds at every count."""
    parts = []
    for v in ("raw-direct", "vkrc-mt"):
        medians = {threads(x): float(x["median_us"]) for x in command if x["variant"] == v}
        if 1 not in medians or len([n for n in medians if n > 1]) < 2:
            continue
        s = amdahl_serial(medians)
        fitted = {n: s + (medians[1] - s) / n for n in medians if n > 1}
        fit = ", ".join(f"{n}: {medians[n]:.0f} against {fitted[n]:.0f}" for n in sorted(fitted))
        miss = max(abs(medians[n] / fitted[n] - 1) for n in fitted)
        holds = (f"the fit holds within {100 * miss:.0f} %" if miss <= AMDAHL_TOLERANCE else
                 f"**the fit does not hold** (a miss of {100 * miss:.0f} %): a serial part alone does not explain "
                 "this curve")
        parts.append(f"{v} s = {s:.0f} µs of t(1) = {medians[1]:.0f} µs (measured against fitted µs at {fit}; "
                     f"{holds})")
    if not parts:
        return ""
    return ("Serial part (Amdahl's t(n) = s + (t(1) - s) / n fitted to the medians by least squares): "
            + "; ".join(parts) + ".")


def threads_section(pattern, pending):
    found = results(pattern, threaded=True)
    if not found:
        return [pending]
    out = []
    for r in sorted(found, key=lambda r: r["path"]):
        out += threads_table(r)
    return out[:-1]


def thousands(n):
    return f"{int(round(float(n))):,}".replace(",", " ")


def run_line(r, keys=("device", "driver", "date", "git", "host")):
    m = r["meta"]
    parts = "; ".join(f"{k}: {m.get(k, '?')}" for k in keys)
    return f"{parts[0].upper()}{parts[1:]}. Data: `{r['path']}`."


ALLOC_SPEED_GOAL = 100  # pool vs dedicated allocate+free rate (issue 32; issue 7 asked 50)
ALLOC_WASTE_GOAL = 15.0  # % of the reserved bytes unused at the peak (issue 32; issue 7 asked 25)


def alloc_waste(x):
    reserved = int(x["peak_reserved_bytes"])
    return 100.0 * (1 - int(x["peak_requested_bytes"]) / reserved) if reserved else 0.0


def alloc_speedup(r):
    get = {x["allocator"]: x for x in r["rows"]}
    return float(get["pool"]["ops_per_s"]) / float(get["dedicated"]["ops_per_s"])


def alloc_runs(pattern):
    return sorted(results(pattern, "ops_per_s"), key=lambda r: r["path"])


def alloc_section(pattern, pending):
    found = alloc_runs(pattern)
    if not found:
        return [pending]
    out = []
    for r in found:
        out += [run_line(r), ""]
    out += [f"    {found[0]['meta'].get('command', '?')}", "",
            "| run | allocator | operations | alloc+free/s | ns per alloc+free | vkAllocateMemory calls | "
            "peak reserved (bytes) | peak requested (bytes) | waste |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for i, r in enumerate(found, 1):
        for x in r["rows"]:
            out.append(f"| {i} | {x['allocator']} | {thousands(x['operations'])} | {thousands(x['ops_per_s'])} | "
                       f"{thousands(1e9 / float(x['ops_per_s']))} | {thousands(x['vk_allocate_calls'])} | "
                       f"{thousands(x['peak_reserved_bytes'])} | {thousands(x['peak_requested_bytes'])} | "
                       f"{alloc_waste(x):.1f} % |")
    speedups = [alloc_speedup(r) for r in found]
    middle = median(speedups)
    waste = max(alloc_waste(x) for r in found for x in r["rows"] if x["allocator"] == "pool")
    out += ["", f"Pool vs dedicated allocate+free rate: {', '.join(f'{v:.1f}x' for v in speedups)} "
            f"(run {', '.join(str(i) for i in range(1, len(found) + 1))}; median {middle:.1f}x): the speed goal "
            f"(at least {ALLOC_SPEED_GOAL}x) is **{'met' if middle >= ALLOC_SPEED_GOAL else 'not met'}** here. "
            f"The pool's waste at the peak: at most {waste:.1f} %: the memory goal (under {ALLOC_WASTE_GOAL:.0f} %) "
            f"is **{'met' if waste < ALLOC_WASTE_GOAL else 'not met'}**."]
    return out


def header_cost_runs():
    order = {"gcc": 0, "clang": 1}

    def key(r):
        m = re.search(r"header-cost-(\w+)-O(\d)", r["path"])
        return (order.get(m.group(1), 2) if m else 2, -int(m.group(2)) if m else 0, r["path"])

    return sorted(results("", "cpu_ratio_to_raii"), key=key)


def compiler_name(r):
    # '--version' lines: 'c++ (Debian 12.2.0-14+deb12u1) 12.2.0', 'Debian clang version 14.0.6'.
    text = r["meta"].get("compiler", "?")
    version = text.split()[-1]
    return f"clang++ {version}" if "clang" in text else f"g++ {version}"


HEADER_COST_GOAL = 0.08  # vkrc / vk::raii compiler instructions (issue 18's goal; issue 32: judged by instructions)


def instruction_ratio(r, probe):
    """probe's compiler instructions over vk::raii's (header_cost --instructions), from the counts rather than
    the rounded ratio column; None where the run did not count them (files from before the column, or runs
    without --instructions, leave it out or empty)."""
    get = {x["probe"]: x for x in r["rows"]}
    count, raii = get[probe].get("instructions"), get["vk::raii"].get("instructions")
    return int(count) / int(raii) if count and raii else None


def header_cost_goal(r):
    """The goal is judged by compiler instructions, which the machine's load does not move (CPU time swings
    by tens of percent between runs of the same day); a run without them is not judged."""
    ratio = instruction_ratio(r, "vkrc")
    if ratio is None:
        return "not judged (no instruction count)"
    return "met" if ratio <= HEADER_COST_GOAL else "not met"


def instruction_cells(r):
    """A header-cost row's instruction columns and the verdict."""
    ratio = instruction_ratio(r, "vkrc")
    if ratio is None:
        return " not counted | | " + header_cost_goal(r) + " |"
    return f" {ratio:.3f} | {instruction_ratio(r, 'floor'):.3f} | {header_cost_goal(r)} |"


def header_cost_section():
    found = header_cost_runs()
    if not found:
        return ["No header-cost results in docs/results/ yet."]
    out = []
    for r in found:
        out += [run_line(r, ("compiler", "vulkan-headers", "date", "command", "git", "host", "load")), ""]
    out += ["Judged by the compiler's instructions (the driver and the processes it spawns) in one compile under "
            "valgrind (`header_cost --instructions`), which the machine's load does not move; beside them, the "
            f"medians of {found[0]['rows'][0]['repetitions']} compiles' CPU time (user + system), which it does:", "",
            "| compiler | flags | instructions vkrc / vk::raii | instructions floor / vk::raii | "
            f"goal by instructions (<= {HEADER_COST_GOAL}) | vkrc ms | vk::raii ms | floor ms | "
            "CPU time vkrc / vk::raii | CPU time floor / vk::raii |",
            "|---|---|---:|---:|---|---:|---:|---:|---:|---:|"]
    for r in found:
        get = {x["probe"]: x for x in r["rows"]}
        v, raii, floor = get["vkrc"], get["vk::raii"], get["floor"]
        out.append(f"| {compiler_name(r)} | `{v['flags']}` |{instruction_cells(r)} {thousands(v['cpu_ms'])} | "
                   f"{thousands(raii['cpu_ms'])} | {thousands(floor['cpu_ms'])} | "
                   f"{float(v['cpu_ratio_to_raii']):.3f} | {float(floor['cpu_ratio_to_raii']):.3f} |")
    return out


def newest_header_cost_runs():
    """The newest run of each compiler and -O level (README's row; docs/benchmarks.md keeps them all)."""
    runs = header_cost_runs()
    newest = {}
    for r in runs:
        key = (compiler_name(r), r["rows"][0]["flags"])
        if key not in newest or r["meta"].get("date", "") > newest[key]["meta"].get("date", ""):
            newest[key] = r
    return [r for r in runs if r in newest.values()]


def readme_compile_row():
    found = newest_header_cost_runs()
    if not found:
        return ["| compile cost: instance + device TU | pending re-measurement | | | |"]

    def cell(r, probe):
        get = {x["probe"]: x for x in r["rows"]}
        return get[probe]

    compilers = []
    for r in found:
        if compiler_name(r) not in compilers:
            compilers.append(compiler_name(r))

    def by_compiler(text):  # 'g++ 12.2.0: -O3 X, -O0 Y; clang++ ...'
        return "; ".join(c + ": " + ", ".join(f"{cell(r, 'vkrc')['flags'].split()[-2]} {text(r)}"
                                              for r in found if compiler_name(r) == c) for c in compilers)

    raw = by_compiler(lambda r: f"{thousands(cell(r, 'floor')['cpu_ms'])} ms")
    raii = by_compiler(lambda r: f"{thousands(cell(r, 'vk::raii')['cpu_ms'])} ms")

    def by_instructions(r):
        ratio = instruction_ratio(r, "vkrc")
        return "not counted" if ratio is None else f"**{ratio:.3f}**"

    vkrc = by_compiler(lambda r: f"{thousands(cell(r, 'vkrc')['cpu_ms'])} ms "
                       f"({by_instructions(r)}; CPU time {float(cell(r, 'vkrc')['cpu_ratio_to_raii']):.3f})")
    return [f"| compile cost: instance + device TU, compiler CPU time and instructions (bench/header_cost, data "
            f"`docs/results/*header-cost*.csv`) | floor (the standard and Vulkan headers of vkrc's API, no vkrc): "
            f"{raw} | {raii} | not comparable (Rust) | {vkrc}; in bold, the ratio of compiler instructions to "
            f"`vk::raii`, by which the goal (<= {HEADER_COST_GOAL}) is judged, after it the ratio of CPU time |"]


def readme_alloc_row():
    lavapipe = alloc_runs("llvmpipe")
    h200 = alloc_runs("H200")

    def median_of(runs, allocator):
        return median(float(x["ops_per_s"]) for r in runs for x in r["rows"] if x["allocator"] == allocator)

    def part(runs, where):
        if not runs:
            return None, None
        speed = median(alloc_speedup(r) for r in runs)
        calls = {x["vk_allocate_calls"] for r in runs for x in r["rows"] if x["allocator"] == "pool"}
        return (f"{thousands(median_of(runs, 'dedicated'))}/s on {where}",
                f"{thousands(median_of(runs, 'pool'))}/s on {where} ({speed:.0f}x, "
                f"{'/'.join(sorted(calls))} `vkAllocateMemory` calls)")

    raw, pool = [], []
    for runs, where in ((lavapipe, "lavapipe"), (h200, "an H200")):
        r, p = part(runs, where)
        raw.append(r or f"pending re-measurement on {where}")
        pool.append(p or f"pending re-measurement on {where}")
    return [f"| allocation: 100 000 mixed alloc+free (median of the runs in docs/benchmarks.md) "
            f"| one `vkAllocateMemory` per resource: {', '.join(raw)} | same as raw | not compared here "
            f"| pool: {', '.join(pool)} |"]


def readme_row():
    # The newest 25-teapot run of every variant the row names (targeted runs of
    # a few variants are in docs/benchmarks.md only): H200 if there is one, else lavapipe.
    for pattern in ("H200", "llvmpipe"):
        found = [r for r in results(pattern) if r["rows"][0]["teapots"] == "25"
                 and {"raw", "raw-direct-control", "vkhpp"} <= set(variants_of(r["rows"]))]
        if found:
            break
    else:
        return ["| teapot loop | pending re-measurement | | | |"]
    r = sorted(found, key=lambda r: r["meta"].get("date", ""))[-1]
    get = {(x["variant"], x["stage"]): x for x in r["rows"]}

    def three(variant):
        return " / ".join(f"{float(get[(variant, s)]['ratio_to_ref']):.3f}" for s in ("command", "submit", "frame"))

    have = variants_of(r["rows"])
    vkrc = "; ".join(f"{v} {three(v)}" for v in ("vkrc-st", "vkrc-mt", "vkrc-st-checked") if v in have)
    images = all(float(x["median_us"]) == 0 for x in r["rows"] if x["stage"] == "image")
    return [f"| teapot loop on {r['meta'].get('device', '?')}, 25 teapots, block-wise ratio to raw-direct "
            f"(command / submit / frame, the frame GPU time; intervals and the A/A control in docs/benchmarks.md, "
            f"data `{r['path']}`) "
            f"| raw (loader trampolines) {three('raw')}; A/A control {three('raw-direct-control')} "
            f"| {three('vkhpp')} | not run here | {vkrc}; "
            f"{'all images byte-identical to raw-direct' if images else 'IMAGES DIFFER'} |"]


HEADLINE_VARIANTS = (("vkrc-st", "vkrc-st"), ("vkrc-mt", "vkrc-mt"), ("vkhpp", "vk::raii"))
HEADLINE_TEAPOTS = "25"


def newest_teapot_run(pattern, variant):
    """The newest single-thread run at HEADLINE_TEAPOTS on the device that timed variant beside raw-direct;
    '-base-' files time an older commit beside a newer one, for comparison, and are left out."""
    found = [r for r in results(pattern) if r["rows"][0]["teapots"] == HEADLINE_TEAPOTS and "-base-" not in r["path"]
             and {variant, "raw-direct"} <= set(variants_of(r["rows"]))]
    return max(found, key=lambda r: (r["meta"].get("date", ""), r["path"]), default=None)


def ns_above(r, variant, stage):
    """'+ns [low, high]': the block-wise ratio to raw-direct and its bootstrap interval (bench/teapot's, over
    processes and blocks) less 1, times raw-direct's median of the stage in the same run."""
    get = {(x["variant"], x["stage"]): x for x in r["rows"] if x["teapots"] == HEADLINE_TEAPOTS}
    x, ref = get.get((variant, stage)), get.get(("raw-direct", stage))
    if not x or not ref:
        return ""
    a, low, high = ((float(x[k]) - 1) * 1000 * float(ref["median_us"]) + 0.0
                    for k in ("ratio_to_ref", "ref_ci_low", "ref_ci_high"))
    return f"{a:+.0f} [{low:+.0f}, {high:+.0f}]"


def newest_instructions():
    found = sorted(glob.glob(os.path.join(ROOT, "docs", "results", "*lavapipe-instructions.csv")))
    return os.path.relpath(found[-1], ROOT) if found else None


def headline_instruction_rows(path):
    counts = run_summary.instructions_per_frame(os.path.join(ROOT, path))
    ref, data = counts["raw-direct"][1], data_cell(load(os.path.join(ROOT, path)))
    return [f"| lavapipe | {name} | {counts[v][1] - ref:+.0f} ({thousands(counts[v][1])} against {thousands(ref)}) "
            f"| | | | {data} |" for v, name in HEADLINE_VARIANTS if v in counts]


def data_cell(r):
    blocks = f", block data `{os.path.basename(r['blocks'])}`" if r.get("blocks") else ""
    return f"`{os.path.basename(r['path'])}` (git {r['meta'].get('git', '?').split()[0]}{blocks})"


def headline_time_rows(device, pattern):
    out, used = [], []
    for v, name in HEADLINE_VARIANTS:
        r = newest_teapot_run(pattern, v)
        if r:
            used += [r] if r not in used else []
            out.append(headline_time_row(device, name, r, v))
    return out + [headline_time_row(device, "A/A control", r, "raw-direct-control") for r in used]


def headline_time_row(device, name, r, variant):
    cells = " | ".join(ns_above(r, variant, s) for s in ("command", "submit", "frame"))
    return f"| {device} | {name} | | {cells} | {data_cell(r)} |"


def headline():
    """What a user pays per frame over raw-direct (issue 32 item 4): instructions on lavapipe, time on NVIDIA."""
    path = newest_instructions()
    rows = (headline_instruction_rows(path) if path else []) + headline_time_rows("H100", "H100") + \
        headline_time_rows("H200", "H200")
    return [f"What each variant costs per frame above raw-direct (raw C through `vkGetDeviceProcAddr` pointers), "
            f"{HEADLINE_TEAPOTS} teapots; the data file of each row is in its last column "
            "(under `docs/results/`). Instructions: callgrind's count outside the driver (`bench/instructions.sh`), "
            f"summed over the six per-frame stages ({', '.join(run_summary.STAGES)}); deterministic, so no "
            "interval; every stage, those too short to time included, counts in it. Time: per stage, the median "
            "of the block-wise ratios to raw-direct and its 95 % interval (bench/teapot's bootstrap over processes "
            "and blocks) less 1, times raw-direct's median of the stage in the same run. Command and submit are "
            "the CPU stages above the timer floor; the frame is GPU time (it includes the wait for the GPU, which "
            "hides CPU work), shown for what a frame takes, not as a verdict. The A/A control is raw-direct "
            "against itself in the same run: what the timer resolves.", "",
            "| device | variant | instructions per frame above raw-direct | command: ns above raw-direct [95 % CI] "
            "| submit: ns [95 % CI] | frame (GPU time): ns [95 % CI] | data |",
            "|---|---|---:|---:|---:|---:|---|"] + rows


UPLOAD_RAW_GOAL = 0.95  # vkrc-stream vs raw-stream throughput (issue 15)
UPLOAD_BLOCKING_GOAL = 5.0  # vkrc-stream vs vkrc-blocking throughput, 4 KiB uploads
# raw-stream-aa (runs from 2026-11-23 r3 on) is raw-stream again: the A/A control.
UPLOAD_VARIANTS = ("vkrc-stream", "raw-stream", "vkrc-blocking", "raw-stream-aa")


def upload_stats(rows, upload, variant, column):
    """Median and range over every block of every process."""
    values = sorted(float(x[column]) for x in rows if x["upload"] == upload and x["variant"] == variant)
    return median(values), values[0], values[-1], len(values)


def upload_ratios(rows, upload, a, b):
    """Per (process, block) ratios of throughputs, sorted: the variants of a block run back to back."""
    get = {(x["process"], x["block"], x["variant"]): float(x["gb_per_s"]) for x in rows if x["upload"] == upload}
    return sorted(get[(p, k, a)] / get[(p, k, b)] for (p, k, v) in get if v == a and (p, k, b) in get)


def upload_ratio(rows, upload, a, b):
    ratios = upload_ratios(rows, upload, a, b)
    return median(ratios), ratios[0], ratios[-1]


def upload_ratios_by_process(rows, upload, a, b):
    """{process: [ratio of each of its blocks]}, as upload_ratios pairs them."""
    get = {(x["process"], x["block"], x["variant"]): float(x["gb_per_s"]) for x in rows if x["upload"] == upload}
    by_process = {}
    for (p, k, v) in get:
        if v == a and (p, k, b) in get:
            by_process.setdefault(p, []).append(get[(p, k, a)] / get[(p, k, b)])
    return by_process


def upload_goal(rows, upload, a, b, goal):
    """'median [95 % CI]: verdict' of a ratio goal, the interval bootstrapped over processes."""
    m, low, high = process_bootstrap(upload_ratios_by_process(rows, upload, a, b))
    return f"{m:.3f} [{low:.3f}, {high:.3f}]", verdict(low, high, goal)


def upload_section(pattern, pending):
    found = sorted(results(pattern, "gb_per_s"), key=lambda r: r["path"])
    if not found:
        return [pending]
    out = []
    for r in found:
        rows = r["rows"]
        uploads = []
        for x in rows:
            if x["upload"] not in uploads:
                uploads.append(x["upload"])
        out += [run_line(r), "", f"    {r['meta'].get('command', '?')}", "",
                "| upload | variant | uploads per block | GB/s median [min, max] | CPU us per upload median [min, max] "
                "| blocks |",
                "|---|---|---:|---:|---:|---:|"]
        for u in uploads:
            for v in [v for v in UPLOAD_VARIANTS if any(x["variant"] == v for x in rows)]:
                g = upload_stats(rows, u, v, "gb_per_s")
                c = upload_stats(rows, u, v, "cpu_us_per_upload")
                per_block = next(x["uploads"] for x in rows if x["upload"] == u and x["variant"] == v)
                out.append(f"| {u} | {v} | {per_block} | {g[0]:.3f} [{g[1]:.3f}, {g[2]:.3f}] | "
                           f"{c[0]:.1f} [{c[1]:.1f}, {c[2]:.1f}] | {g[3]} |")
        control = any(x["variant"] == "raw-stream-aa" for x in rows)
        out += ["", "| upload | vkrc-stream / raw-stream GB/s, median [min, max] of the blocks | "
                "vkrc-stream / vkrc-blocking |" + (" A/A: raw-stream / raw-stream-aa |" if control else ""),
                "|---|---:|---:|" + ("---:|" if control else "")]
        for u in uploads:
            raw = upload_ratio(rows, u, "vkrc-stream", "raw-stream")
            blocking = upload_ratio(rows, u, "vkrc-stream", "vkrc-blocking")
            aa = upload_ratio(rows, u, "raw-stream", "raw-stream-aa") if control else None
            out.append(f"| {u} | {raw[0]:.3f} [{raw[1]:.3f}, {raw[2]:.3f}] | "
                       f"{blocking[0]:.2f} [{blocking[1]:.2f}, {blocking[2]:.2f}] |" +
                       (f" {aa[0]:.3f} [{aa[1]:.3f}, {aa[2]:.3f}] |" if control else ""))
        raw = [upload_goal(rows, u, "vkrc-stream", "raw-stream", UPLOAD_RAW_GOAL) for u in uploads]
        small = upload_goal(rows, uploads[0], "vkrc-stream", "vkrc-blocking", UPLOAD_BLOCKING_GOAL)
        out += ["", "Goals (the median ratio of the blocks with its 95 % interval, bootstrapped over the processes "
                "and their blocks; met or not met only when the interval clears the goal): vkrc-stream "
                f"at least {UPLOAD_RAW_GOAL}x raw-stream's throughput ("
                f"{'; '.join(f'{u}: {text} {v}' for u, (text, v) in zip(uploads, raw))}: "
                f"**{overall_verdict([v for _, v in raw])}**); at least {UPLOAD_BLOCKING_GOAL:.0f}x vkrc-blocking "
                f"for {uploads[0]} ({small[0]}: **{small[1]}**).", ""]
    return out[:-1]


# (case, thread count, least speed-up over 1 thread, what it is, the driver's own share of that work or None):
# issue 17's shared PoolAllocator at 8 threads, then issue 32's creation and destruction at 16.
CONTENTION_GOALS = [
    ("alloc-pool", 8, 4.0, "PoolAllocator alloc+free, one pool shared (issue 17)", None),
    ("alloc-pool", 16, 6.0, "the same at 16 threads (issue 32)", None),
    ("buffer-pool", 16, 6.0, "Buffer::create + drop, one PoolAllocator shared (issue 32)", "buffer-bound"),
    ("buffer-pool-own", 16, 10.0, "Buffer::create + drop, a PoolAllocator per thread (issue 32)", "buffer-bound"),
    ("sets-free", 16, 10.0, "descriptor set allocate + drop, a pool per thread (issue 32)", "sets-raw"),
]


def splitmix64(state):
    """One step of SplitMix64: (next state, output). The bootstrap's generator, so that the intervals do
    not depend on the Python version's random module."""
    state = (state + 0x9E3779B97F4A7C15) & 0xFFFFFFFFFFFFFFFF
    z = state
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & 0xFFFFFFFFFFFFFFFF
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & 0xFFFFFFFFFFFFFFFF
    return state, z ^ (z >> 31)


def quantile(sorted_values, q):
    """Linear interpolation between the order statistics (as bench/teapot's harness/stats.cpp)."""
    position = q * (len(sorted_values) - 1)
    below = math.floor(position)
    above = min(below + 1, len(sorted_values) - 1)
    return sorted_values[below] + (sorted_values[above] - sorted_values[below]) * (position - below)


BOOTSTRAP_PICKS = {}  # (block counts of the processes, resamples, seed) -> bootstrap_picks's table


def bootstrap_picks(shape, resamples, seed):
    """process_bootstrap's draws for processes of shape[p] blocks: per resample, how often each block (the
    processes' blocks laid end to end) was drawn, and the sample's size. SplitMix64, one output a pick
    (modulo the count): a process, then as many of its blocks as it has, as many processes as there are.
    The draws depend on the shape only, so they are made once for every set of values of that shape."""
    key = (shape, resamples, seed)
    if key in BOOTSTRAP_PICKS:
        return BOOTSTRAP_PICKS[key]
    offsets = [0] + list(accumulate(shape))[:-1]
    state, table = seed, []
    for _ in range(resamples):
        counts, size = [0] * sum(shape), 0
        for _ in shape:
            state, z = splitmix64(state)
            run = z % len(shape)
            size += shape[run]
            for _ in range(shape[run]):
                state, z = splitmix64(state)
                counts[offsets[run] + z % shape[run]] += 1
        table.append((counts, size))
    BOOTSTRAP_PICKS[key] = table
    return table


def process_bootstrap(by_process, resamples=2000, seed=0x7EA907):
    """The median of every block's value and its 95 % interval from the two-level percentile bootstrap of
    bench/teapot (harness/stats.cpp, block_bootstrap_ratio): processes resampled with replacement, then
    blocks within each chosen process, so that the spread between processes widens the interval (pooling
    the blocks as if independent would not). by_process: {process: [value of each block]}, processes in
    key order, each one's values sorted: bench/teapot draws the same picks from the same generator
    (bootstrap_picks), so the two agree to the last bit. Each resample's median is read off the pooled
    values in order, weighted by how often each was drawn: the same number as sorting the sample."""
    runs = [sorted(v) for _, v in sorted(by_process.items()) if v]
    flat = [x for run in runs for x in run]
    if not flat:
        return 0.0, 0.0, 0.0
    order = sorted(range(len(flat)), key=flat.__getitem__)
    pooled = [flat[i] for i in order]
    in_order = itemgetter(*order) if len(order) > 1 else (lambda counts: (counts[order[0]],))
    medians = []
    for counts, size in bootstrap_picks(tuple(map(len, runs)), resamples, seed):
        below_count = list(accumulate(in_order(counts)))  # how many drawn values are pooled[0..i]
        position = 0.5 * (size - 1)  # quantile()'s arithmetic on the sorted sample
        below = math.floor(position)
        low = pooled[bisect_right(below_count, below)]
        high = pooled[bisect_right(below_count, min(below + 1, size - 1))]
        medians.append(low + (high - low) * (position - below))
    medians.sort()
    return quantile(pooled, 0.5), quantile(medians, 0.025), quantile(medians, 0.975)


# ---- teapot block data: the intervals recomputed -------------------------

def blocks_path(path):
    """A teapot results file's block data: docs/results/NAME.csv -> docs/results/NAME-blocks.csv.gz."""
    return re.sub(r"\.csv$", "-blocks.csv.gz", path)


def load_blocks(path):
    """{(configuration, variant, stage): {process: [each block's median in block order]}} of a
    bench/teapot --blocks-csv file (gzip, '# key: value' header lines)."""
    blocks = {}
    for x in load(path)["rows"]:
        values = blocks.setdefault((x["config"], x["variant"], x["stage"]), {}).setdefault(int(x["process"]), [])
        if int(x["block"]) != len(values):
            sys.exit(f"{path}: block {x['block']} of process {x['process']}, {x['config']} {x['variant']} "
                     f"{x['stage']} out of order")
        values.append(float(x["median_us"]))
    return blocks


def config_tag(row):
    """bench/teapot's config_tag of a summary row's configuration: how its block file names it."""
    tag = f"t{row['teapots']}_f{row['frames_in_flight']}_u{row['uniform_writes']}_s{row['tessellation']}"
    return tag + (f"_n{threads(row)}" if threads(row) != 1 else "")


def block_ratios(blocks, numerator, denominator):
    """{process: [numerator's block b over denominator's block b]}, paired as bench/teapot's block_pairs
    pairs them (the same process, block b with block b; blocks over a zero left out)."""
    theirs = blocks.get(denominator, {})
    return {p: [a / b for a, b in zip(mine, theirs.get(p, [])) if b > 0]
            for p, mine in blocks.get(numerator, {}).items()}


def teapot_intervals(row, blocks, to_raw=True):
    """{column: value as bench/teapot writes it} of every interval a summary row has, recomputed from the
    blocks: the ratio to the reference (and the block count behind it), to raw where raw ran (unless
    to_raw is false: no table shows it) and the speed-up over the 1-thread configuration where it ran."""
    tag, v, s = config_tag(row), row["variant"], row["stage"]
    out = {}

    def put(columns, by_process):
        out.update(zip(columns, (f"{x:.4f}" for x in process_bootstrap(by_process))))

    to_ref = block_ratios(blocks, (tag, v, s), (tag, row["reference"], s))
    put(("ratio_to_ref", "ref_ci_low", "ref_ci_high"), to_ref)
    out["blocks"] = str(sum(map(len, to_ref.values())))
    if to_raw and (tag, "raw", s) in blocks:
        put(("ratio_to_raw", "ratio_ci_low", "ratio_ci_high"), block_ratios(blocks, (tag, v, s), (tag, "raw", s)))
    base = re.sub(r"_n\d+$", "", tag)
    if base != tag and (base, v, s) in blocks:
        put(("speedup", "speedup_ci_low", "speedup_ci_high"), block_ratios(blocks, (base, v, s), (tag, v, s)))
    return out


def recompute_intervals(result, blocks_file, stages):
    """A teapot run's rows of the given stages take the intervals the tables show recomputed from its
    block data, blocks_file (result['blocks'] names it); the other rows and columns keep their summary's (the
    bootstrap takes a tenth of a second for 16 processes of 100 blocks: what no table shows is left)."""
    result["blocks"] = os.path.relpath(blocks_file, ROOT)
    blocks = load_blocks(blocks_file)
    for row in result["rows"]:
        if row["stage"] in stages:
            row.update(teapot_intervals(row, blocks, to_raw=False))


def check_blocks(extra):
    """--check-blocks: every interval of every teapot run with block data (docs/results/ and extra) against
    the one recomputed from its blocks; the differences, or none."""
    extra = [os.path.abspath(p) for p in extra]
    files = sorted(glob.glob(os.path.join(ROOT, "docs", "results", "*.csv"))) + extra
    problems, checked = [], []
    for path in files:
        r = load(path)
        if not (r["rows"] and "median_us" in r["rows"][0]):
            continue
        if not os.path.exists(blocks_path(path)):
            if path in extra:
                problems.append(f"{r['path']}: no block file {os.path.basename(blocks_path(path))}")
            continue
        blocks, count = load_blocks(blocks_path(path)), 0
        for row in r["rows"]:
            if row["stage"] == "image":
                continue
            for column, value in teapot_intervals(row, blocks).items():
                count += 1
                if row[column] != value:
                    problems.append(f"{r['path']}: {config_tag(row)} {row['variant']} {row['stage']} {column}: "
                                    f"summary {row[column] or '(empty)'}, from the blocks {value}")
        checked.append(f"{r['path']} ({count} values)")
    if not checked:
        problems.append("no teapot run with block data to check")
    return checked, problems


def contention_runs(pattern):
    return sorted(results(pattern, "ops_per_second"), key=lambda r: r["path"])


def contention_ratios_by_process(rows, case, threads, repeat="1"):
    """{process: [per block: the rate at threads (repeat) over the first thread count's (repeat 1) of the
    same block]}; the counts of a block run back to back."""
    first = rows[0]["threads"]
    get = {(x["process"], x["block"], x["threads"], x["repeat"]): float(x["ops_per_second"])
           for x in rows if x["case"] == case}
    by_process = {}
    for (p, b, t, rep) in get:
        if t == threads and rep == repeat and get.get((p, b, first, "1")):
            by_process.setdefault(p, []).append(get[(p, b, t, rep)] / get[(p, b, first, "1")])
    return by_process


def contention_ratios(rows, case, threads, repeat="1"):
    """Every block's ratio (contention_ratios_by_process), sorted."""
    return sorted(x for v in contention_ratios_by_process(rows, case, threads, repeat).values() for x in v)


def host_cpus(r):
    m = re.match(r"(\d+) CPUs", r["meta"].get("host", ""))
    return int(m.group(1)) if m else 0


def interval(values, digits=2):
    return f"{median(values):.{digits}f} [{values[0]:.{digits}f}, {values[-1]:.{digits}f}]"


def contention_goal(r, case, threads, goal, driver_case):
    """One goal's line: the speed-up with its interval over processes and the verdict; beside it, the
    driver's own share of the work (driver_case) at the same count, which bounds what vkrc can reach."""
    rows = r["rows"]
    by_process = contention_ratios_by_process(rows, case, str(threads))
    ratios = sorted(x for v in by_process.values() for x in v)
    if not ratios:
        return f"not measured ({threads} threads or {case} missing)"
    m, low, high = process_bootstrap(by_process)
    text = (f"{case} at {threads} threads: {m:.2f}x the 1-thread rate (95 % interval bootstrapped over the "
            f"{len(by_process)} processes [{low:.2f}, {high:.2f}]; blocks range {ratios[0]:.2f} to {ratios[-1]:.2f})")
    cpus = host_cpus(r)
    v = verdict(low, high, goal)
    verdict_text = v + (" (the interval straddles the goal)" if v == "not resolved" else "")
    note = (f" This host has {cpus} CPUs: {threads} threads cannot all run at once, so it cannot show the goal "
            "whatever vkrc does." if 0 < cpus < threads else "")
    driver = contention_ratios_by_process(rows, driver_case, str(threads)) if driver_case else {}
    if driver:
        dm, dlow, dhigh = process_bootstrap(driver)
        note += (f" The driver's own share of the work ({driver_case}) scales {dm:.2f}x [{dlow:.2f}, {dhigh:.2f}] "
                 "at the same count.")
    return f"{text}: **{verdict_text}** here.{note}"


def contention_lock(r):
    """Whether the shared PoolAllocator's lock limits alloc-pool's scaling: its speed-up against a pool
    per thread (alloc-pool-own) and the uncontended handle-own at the most threads this host runs at once."""
    rows = r["rows"]
    cpus = host_cpus(r) or 1
    counts = sorted({int(x["threads"]) for x in rows if int(x["threads"]) <= max(cpus, 2)})
    if len(counts) < 2:
        return ""
    n = str(counts[-1])
    get = {c: contention_ratios(rows, c, n) for c in ("handle-own", "alloc-pool", "alloc-pool-own")}
    if not all(get.values()):
        return ""
    pool, own = get["alloc-pool"], get["alloc-pool-own"]
    if median(get["handle-own"]) < 0.75 * int(n):
        verdict = ("handle-own, which shares nothing, does not scale either: the host gave the process no spare "
                   "CPU (other work ran), so this run decides nothing about contention")
    elif pool[-1] < own[0]:
        verdict = "the shared pool scales less than a pool per thread: its lock limits it"
    elif pool[0] > own[-1]:
        verdict = "the shared pool scales more than a pool per thread"
    else:
        verdict = "the two intervals overlap: this run does not show the shared lock limiting"
    return (f"At {n} threads (this host has {cpus} CPUs): handle-own (nothing shared) {interval(get['handle-own'])}x, "
            f"alloc-pool {interval(pool)}x, alloc-pool-own (a PoolAllocator per thread) {interval(own)}x: "
            f"{verdict}.")


# Generated figures: path (relative to ROOT) -> SVG text, written (or checked) with the Markdown.
FIGURES = {}
PLOT_CASES = ["handle-shared", "handle-own", "alloc-pool", "alloc-pool-own", "alloc-dedicated", "buffer-pool",
              "buffer-dedicated", "buffer-raw", "buffer-bound", "sets-free"]
PLOT_COLOURS = ["#1f77b4", "#aec7e8", "#d62728", "#ff9896", "#9467bd", "#2ca02c", "#98df8a", "#8c564b",
                "#c49c94", "#7f7f7f"]


def contention_plot(r):
    """The speed-up figure of a contention run: one line per case of PLOT_CASES (median over the blocks)."""
    rows = r["rows"]
    counts = sorted({int(x["threads"]) for x in rows})
    lines = {}
    for c in PLOT_CASES:
        points = [(1, 1.0)] + [(n, median(contention_ratios(rows, c, str(n)))) for n in counts[1:]
                               if contention_ratios(rows, c, str(n))]
        if len(points) > 1:
            lines[c] = points
    return speedup_plot(r, counts, lines)


def speedup_plot(r, counts, lines):
    """An SVG of speed-up against the thread count (both axes log2) for the run r, one line per entry of
    lines (label: [(threads, speed-up)]), with the ideal (speed-up = threads) dashed; returns its path
    relative to docs/."""
    import math
    top = max([counts[-1]] + [y for pts in lines.values() for _, y in pts])
    bottom = min([1.0] + [y for pts in lines.values() for _, y in pts])
    lo, hi = math.floor(math.log2(bottom)), math.ceil(math.log2(top))
    w, h, left, right, pad = 640, 360, 60, 170, 30

    def x(n):
        return left + (w - left - right) * math.log2(n) / max(1, math.log2(counts[-1]))

    def y(v):
        return h - pad - (h - 2 * pad) * (math.log2(v) - lo) / max(1, hi - lo)

    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" '
           'font-size="11">', f'<rect width="{w}" height="{h}" fill="white"/>']
    for e in range(lo, hi + 1):
        v = 2.0 ** e
        svg.append(f'<line x1="{left}" x2="{w - right}" y1="{y(v):.1f}" y2="{y(v):.1f}" stroke="#ddd"/>')
        svg.append(f'<text x="{left - 6}" y="{y(v) + 4:.1f}" text-anchor="end">{v:g}x</text>')
    for n in counts:
        svg.append(f'<text x="{x(n):.1f}" y="{h - pad + 16}" text-anchor="middle">{n}</text>')
    svg.append(f'<text x="{(left + w - right) / 2:.0f}" y="{h - 2}" text-anchor="middle">threads</text>')
    svg.append(f'<text x="{left}" y="14">median speed-up vs 1 thread ({r["meta"].get("device", "?")})</text>')
    ideal = " ".join(f"{x(n):.1f},{y(n):.1f}" for n in counts if lo <= math.log2(n) <= hi)
    svg.append(f'<polyline points="{ideal}" fill="none" stroke="black" stroke-dasharray="4 3"/>')
    for i, (c, pts) in enumerate(lines.items()):
        colour = PLOT_COLOURS[i % len(PLOT_COLOURS)]
        svg.append(f'<polyline points="{" ".join(f"{x(n):.1f},{y(v):.1f}" for n, v in pts)}" fill="none" '
                   f'stroke="{colour}" stroke-width="2"/>')
        ly = pad + 16 * i
        svg.append(f'<line x1="{w - right + 10}" x2="{w - right + 30}" y1="{ly}" y2="{ly}" stroke="{colour}" '
                   'stroke-width="2"/>')
        svg.append(f'<text x="{w - right + 35}" y="{ly + 4}">{c}</text>')
    ly = pad + 16 * len(lines)
    svg.append(f'<line x1="{w - right + 10}" x2="{w - right + 30}" y1="{ly}" y2="{ly}" stroke="black" '
               'stroke-dasharray="4 3"/>')
    svg.append(f'<text x="{w - right + 35}" y="{ly + 4}">ideal</text>')
    svg.append("</svg>")
    name = "img/" + os.path.splitext(os.path.basename(r["path"]))[0] + ".svg"
    FIGURES[os.path.join("docs", name)] = "\n".join(svg) + "\n"
    return name


def contention_section(pattern, pending):
    found = contention_runs(pattern)
    if not found:
        return [pending]
    out = []
    for r in found:
        rows = r["rows"]
        processes = len({x["process"] for x in rows})
        blocks = len({x["block"] for x in rows})
        cases = []
        for x in rows:
            if x["case"] not in cases:
                cases.append(x["case"])
        counts = []
        for x in rows:
            if x["threads"] not in counts:
                counts.append(x["threads"])
        out += [run_line(r), "", f"    {r['meta'].get('command', '?')}", "",
                f"{processes} processes x {blocks} blocks per case and thread count. Speed-up: the rate over the "
                f"same block's {counts[0]}-thread rate; on the {counts[0]}-thread rows, the A/A control instead "
                "(the block's second 1-thread measurement over its first). Median [min, max] over every block "
                "of every process.", "",
                "| case | threads | ops/s median [min, max] | speed-up vs 1 thread (1 thread: A/A) |",
                "|---|---:|---:|---:|"]
        for c in cases:
            for n in counts:
                rates = sorted(float(x["ops_per_second"]) for x in rows
                               if x["case"] == c and x["threads"] == n and x["repeat"] == "1")
                if n == counts[0]:
                    ratio = "A/A " + interval(contention_ratios(rows, c, n, "2"))
                else:
                    ratio = interval(contention_ratios(rows, c, n)) + "x"
                out.append(f"| {c} | {n} | {thousands(median(rates))} [{thousands(rates[0])}, "
                           f"{thousands(rates[-1])}] | {ratio} |")
        out += ["", f"![speed-up against threads, {r['meta'].get('device', '?')}]({contention_plot(r)})",
                "", "Goals (the speed-up over 1 thread at least the stated factor, the whole interval above it):", ""]
        out += [f"- {what}, at least {goal:.0f}x: {contention_goal(r, case, threads, goal, driver)}"
                for case, threads, goal, what, driver in CONTENTION_GOALS]
        lock = contention_lock(r)
        out += (["", lock] if lock else []) + [""]
    return out[:-1]


DESCRIPTOR_PAIRS = [("vkrc-write1", "raw-write1"), ("vkrc-update1000", "raw-update1000"),
                    ("vkrc-table1000", "raw-update1000")]


def descriptors_section(pending):
    """bench/descriptors_run.sh runs: ns and instructions per operation, vkrc against raw."""
    found = sorted((load(p) for p in glob.glob(os.path.join(ROOT, "docs/results/*-descriptors.csv"))),
                   key=lambda r: r["path"])
    if not found:
        return [pending]
    out = []
    for r in found:
        get = {x["case"]: x for x in r["rows"]}
        out += [run_line(r), "", f"    {r['meta'].get('command', '?')}", "",
                "| case | ns per operation (median) | instructions per operation | vs raw: time | vs raw: instructions |",
                "|---|---:|---:|---:|---:|"]
        ref = dict(DESCRIPTOR_PAIRS)
        for x in r["rows"]:
            raw = get.get(ref.get(x["case"], ""))
            ratio = (lambda k: f"{float(x[k]) / float(raw[k]):.2f}x") if raw else (lambda k: "")
            out.append(f"| {x['case']} | {thousands(x['ns_per_op_median'])} | {thousands(x['instructions_per_op'])} | "
                       f"{ratio('ns_per_op_median')} | {ratio('instructions_per_op')} |")
        out.append("")
    return out[:-1]


def objects_section(pending):
    """bench/contention_instructions.sh runs: instructions per create + drop on one thread, per policy, the
    runs side by side in path order (the first: the baseline they are compared with), outside the driver
    (what vkrc and the allocator execute) with the total beside it."""
    found = results("", "outside_driver_per_op")
    if not found:
        return [pending]
    out = []
    for i, r in enumerate(found):
        out += [f"Run {i + 1}: {run_line(r)}", ""]
    out += ["Instructions per operation outside the driver (total with the driver in parentheses); the "
            "last column: the last run against run 1.", "",
            "| case | policy | " + " | ".join(f"run {i + 1} ({r['meta'].get('git', '?')})"
                                             for i, r in enumerate(found)) + " | last - run 1 |",
            "|---|---|" + "---:|" * (len(found) + 1)]
    keys = []
    for r in found:
        for x in r["rows"]:
            if (x["case"], x["policy"]) not in keys:
                keys.append((x["case"], x["policy"]))
    def count(v):  # a handle copy costs about ten: keep its decimal
        return f"{float(v):.1f}" if float(v) < 100 else thousands(v)
    for case, policy in sorted(keys, key=lambda k: (k[1] != "st", k[0])):
        cells = [next((x for x in r["rows"] if x["case"] == case and x["policy"] == policy), None) for r in found]
        text = [f"{count(c['outside_driver_per_op'])} ({count(c['instructions_per_op'])})" if c else "" for c in cells]
        delta = (f"{float(cells[-1]['outside_driver_per_op']) - float(cells[0]['outside_driver_per_op']):+.1f}"
                 if cells[0] and cells[-1] else "")
        out.append(f"| {case} | {policy} | " + " | ".join(text) + f" | {delta} |")
    return out


def raytrace_rows(rows, path):
    return [x for x in rows if x["path"] == path]


def raytrace_section(pending):
    """examples/raytrace --compare runs (bench/raytrace_run.sh): per device and path, the GPU time per frame
    of the path and of the rasterised reference drawn beside it in the same frames (median over the
    processes of each process's median over its frames, [min, max] of the processes), their ratio, and the
    path's difference from the reference image (the worst process's)."""
    found = sorted(results("", "psnr_db"), key=lambda r: r["path"])
    if not found:
        return [pending]
    out = ["| device | path | size | processes x frames | path ms per frame | raster ms per frame | "
           "path / raster | differing pixels | max channel difference | PSNR dB | data |",
           "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in found:
        rows = r["rows"]
        for path in [p for p in variants_of([{"variant": x["path"]} for x in rows]) if p != "raster"]:
            mine, ref = raytrace_rows(rows, path), raytrace_rows(rows, "raster")
            times = sorted(float(x["median_ms"]) for x in mine)
            ref_times = sorted(float(x["median_ms"]) for x in ref)
            worst = max(mine, key=lambda x: int(x["differing_pixels"]))
            pixels = int(worst["width"]) * int(worst["height"])
            differing = int(worst["differing_pixels"])
            psnr = float(worst["psnr_db"])
            out.append(f"| {r['meta'].get('device', '?')} | {path} | {worst['width']}x{worst['height']} | "
                       f"{len(mine)} x {worst['frames']} | {median(times):.3f} [{times[0]:.3f}, {times[-1]:.3f}] | "
                       f"{median(ref_times):.3f} [{ref_times[0]:.3f}, {ref_times[-1]:.3f}] | "
                       f"{median(times) / median(ref_times):.2f} | {differing} of {pixels} "
                       f"({100 * differing / pixels:.3f} %) | {worst['max_channel_difference']} | "
                       f"{'identical' if math.isinf(psnr) else f'{psnr:.2f}'} | `{os.path.basename(r['path'])}` "
                       f"(git {r['meta'].get('git', '?')}) |")
    return out


BLOCKS = {
    "raytrace": lambda: raytrace_section("No examples/raytrace results in docs/results/ yet."),
    "descriptors": lambda: descriptors_section("No descriptor-write results in docs/results/ yet."),
    "objects": lambda: objects_section("No per-object instruction counts in docs/results/ yet."),
    "upload-lavapipe": lambda: upload_section("llvmpipe", "No lavapipe upload results in docs/results/ yet."),
    "upload-h200": lambda: upload_section(
        "H200", "**Pending:** no H200 upload run is committed yet. `bench/upload_run.sh BUILD_DIR OUT NAME` on the "
        "H200 machine writes the CSV; committed under docs/results/, it appears here."),
    "teapot-lavapipe": lambda: section("llvmpipe", "No lavapipe results in docs/results/ yet."),
    "teapot-h200": lambda: section(
        "H200", "**The H200 figures are pending re-measurement.** The earlier tables were measured with the "
        "old method (frame-wise intervals, `raw` as the reference, unequal setup) and cannot be re-derived from "
        "committed data, so they are removed. `bench/device_run.sh` produces the CSVs; committed under "
        "docs/results/, they appear here."),
    "teapot-h100": lambda: section("H100", "No H100 results in docs/results/ yet."),
    "teapot-threads-lavapipe": lambda: threads_section(
        "llvmpipe", "No lavapipe `--threads` results in docs/results/ yet."),
    "teapot-threads-h200": lambda: threads_section(
        "H200", "**Pending:** no H200 `--threads` run is committed yet (the commands are above); committed under "
        "docs/results/, it appears here."),
    "teapot-threads-h100": lambda: threads_section(
        "H100", "No H100 `--threads` run is committed yet."),
    "readme-teapot": readme_row,
    "teapot-headline": headline,
    "teapot-instructions": lambda: instructions("", "No instruction counts in docs/results/ yet."),
    "alloc-lavapipe": lambda: alloc_section("llvmpipe", "No lavapipe allocation results in docs/results/ yet."),
    "alloc-h200": lambda: alloc_section(
        "H200", "**The H200 allocation figures are pending re-measurement.** The earlier table was typed by hand "
        "(its run's output was not committed; it is in docs/benchmarks.md at 8c4a8a5), so it is removed. "
        "`bench/device_run.sh` (or `bench/alloc_run.sh`) produces the CSV; committed under docs/results/, it "
        "appears here."),
    "contention-lavapipe": lambda: contention_section(
        "llvmpipe", "No lavapipe contention results in docs/results/ yet."),
    "contention-h200": lambda: contention_section(
        "H200", "**Pending:** no H200 contention run is committed yet. `bench/contention_run.sh BUILD_DIR OUT NAME` "
        "on the H200 machine writes the CSV; committed under docs/results/, it appears here."),
    "contention-h100": lambda: contention_section(
        "H100", "**Pending:** no H100 contention run is committed yet (bench/contention_run.sh on the H100 machine)."),
    "header-cost": header_cost_section,
    "readme-compile-cost": readme_compile_row,
    "readme-alloc": readme_alloc_row,
}


def regenerate(text, path):
    def fill(m):
        name = m.group(1)
        if name not in BLOCKS:
            sys.exit(f"{path}: unknown generated block {name}")
        body = "\n".join(BLOCKS[name]())
        return f"<!-- generated:{name} -->\n{body}\n<!-- end generated:{name} -->"

    text = re.sub(r"<!-- generated:([\w-]+) -->\n.*?<!-- end generated:\1 -->", fill, text, flags=re.S)

    # A table row cannot hold marker lines: a generated row ends with its marker.
    def fill_row(m):
        name = m.group(1)
        if name not in BLOCKS:
            sys.exit(f"{path}: unknown generated row {name}")
        return BLOCKS[name]()[0] + f" <!-- generated-row:{name} -->"

    return re.sub(r"^\|.*<!-- generated-row:([\w-]+) -->$", fill_row, text, flags=re.M)


def check_tables(text, path):
    # No two tables may share their body rows (issue 12's copied tables).
    bodies, current = [], []
    for line in text.splitlines() + [""]:
        if line.startswith("|"):
            current.append(line)
        elif current:
            body = tuple(current[2:])
            if body and body in bodies:
                sys.exit(f"{path}: two tables share their body rows, starting '{body[0]}'")
            bodies.append(body)
            current = []


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--check-blocks", nargs="*", metavar="SUMMARY")
    args = parser.parse_args()
    if args.check_blocks is not None:
        checked, problems = check_blocks(args.check_blocks)
        print("checked against their block data: " + ", ".join(checked))
        sys.exit("\n".join(["gen_bench_docs.py --check-blocks: intervals differ from their blocks':"] + problems)
                 if problems else 0)
    changed = []
    for name in ("docs/benchmarks.md", "README.md"):
        path = os.path.join(ROOT, name)
        text = open(path).read()
        new = regenerate(text, name)
        check_tables(new, name)
        if new != text:
            changed.append(name)
            if not args.check:
                open(path, "w").write(new)
    for name, svg in FIGURES.items():
        path = os.path.join(ROOT, name)
        if not os.path.exists(path) or open(path).read() != svg:
            changed.append(name)
            if not args.check:
                open(path, "w").write(svg)
    if args.check and changed:
        sys.exit("gen_bench_docs.py --check: out of date (run scripts/gen_bench_docs.py): " + ", ".join(changed))
    print(("would change: " if args.check else "regenerated: ") + (", ".join(changed) or "nothing"))


if __name__ == "__main__":
    main()
