#!/usr/bin/env python3
"""Regenerates the teapot results in docs/benchmarks.md and README.md from
the CSV files under docs/results/ (one file per run, written by
bench/device_run.sh: '# key: value' header lines, then bench/teapot's CSV).

Every generated block sits between '<!-- generated:NAME -->' and
'<!-- end generated:NAME -->', a generated table row ends with
'<!-- generated-row:NAME -->'; nothing else is touched.
  scripts/gen_bench_docs.py          rewrite the files
  scripts/gen_bench_docs.py --check  exit 1 if a file would change (ctest docs.bench_tables)
Python 3 standard library only."""
import argparse
import csv
import glob
import io
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STAGES = ["preinit", "acquire", "uniform", "command", "submit", "present", "wait", "update", "frame"]


def load(path):
    meta, lines = {}, []
    with open(path) as f:
        for line in f:
            m = re.match(r"#\s*([^:]+):\s*(.*)", line)
            if m and not lines:
                meta[m.group(1).strip()] = m.group(2).strip()
            else:
                lines.append(line)
    rows = list(csv.DictReader(io.StringIO("".join(lines))))
    return {"path": os.path.relpath(path, ROOT), "meta": meta, "rows": rows}


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


def table(result):
    rows = result["rows"]
    m = result["meta"]
    out = [f"#### {describe(result)}", "",
           f"Device: {m.get('device', '?')}; driver: {m.get('driver', '?')}; date: {m.get('date', '?')}; "
           f"git: {m.get('git', '?')}; host: {m.get('host', '?')}. Data: `{result['path']}`.", "",
           f"    {m.get('command', '?')}", ""]
    floor = next((r["floor_ns"] for r in rows if r["stage"] != "image" and r.get("floor_ns")), "")
    out.append(f"Floor (an empty timed region, measured in the same run): {floor} ns. "
               "*above floor* is the median minus it.")
    out.append("")
    out.append("| stage | variant | median (µs) | above floor (ns) | ratio to raw-direct [95 % CI] | target | verdict |")
    out.append("|---|---|---:|---:|---|---|---|")
    for stage in STAGES:
        for r in rows:
            if r["stage"] != stage:
                continue
            out.append(f"| {stage} | {r['variant']} | {float(r['median_us']):.3f} | {r['above_floor_ns']} | "
                       f"{fmt_ratio(r)} | {('<= ' + r['target']) if r['target'] else ''} | {r['verdict']} |")
    control = {r["stage"]: r for r in rows if r["variant"] == "raw-direct-control"}
    notes = []
    for stage in ("command", "submit", "wait"):
        c = control.get(stage)
        if c:
            ok = float(c["ref_ci_low"]) >= 0.99 and float(c["ref_ci_high"]) <= 1.01
            notes.append(f"{stage} {fmt_ratio(c)} ({'within' if ok else 'not within'} 1 ± 0.01)")
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


def results(pattern, kind="median_us"):
    # kind: a column that tells the CSV's kind (median_us: a timed run;
    # instructions_per_call: bench/instructions.sh).
    files = sorted(glob.glob(os.path.join(ROOT, "docs", "results", "*.csv")))
    return [r for r in map(load, files)
            if r["rows"] and kind in r["rows"][0] and re.search(pattern, r["meta"].get("device", ""), re.I)]


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


def readme_row():
    # The newest 25-teapot run: H200 if there is one, else lavapipe.
    for pattern in ("H200", "llvmpipe"):
        found = [r for r in results(pattern) if r["rows"][0]["teapots"] == "25"]
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
            f"(command / submit / frame; intervals and the A/A control in docs/benchmarks.md, data `{r['path']}`) "
            f"| raw (loader trampolines) {three('raw')}; A/A control {three('raw-direct-control')} "
            f"| {three('vkhpp')} | not run here | {vkrc}; "
            f"{'all images byte-identical to raw-direct' if images else 'IMAGES DIFFER'} |"]


BLOCKS = {
    "teapot-lavapipe": lambda: section("llvmpipe", "No lavapipe results in docs/results/ yet."),
    "teapot-h200": lambda: section(
        "H200", "**The H200 figures are pending re-measurement.** The earlier tables were measured with the "
        "old method (frame-wise intervals, `raw` as the reference, unequal setup) and cannot be re-derived from "
        "committed data, so they are removed. `bench/device_run.sh` produces the CSVs; committed under "
        "docs/results/, they appear here."),
    "readme-teapot": readme_row,
    "teapot-instructions": lambda: instructions("", "No instruction counts in docs/results/ yet."),
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
    args = parser.parse_args()
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
    if args.check and changed:
        sys.exit("gen_bench_docs.py --check: out of date (run scripts/gen_bench_docs.py): " + ", ".join(changed))
    print(("would change: " if args.check else "regenerated: ") + (", ".join(changed) or "nothing"))


if __name__ == "__main__":
    main()
