#!/usr/bin/env python3
"""Counts the Vulkan valid-usage rules (VUIDs) of what vkrc wraps and splits
them into: guaranteed statically by vkrc's types and RAII, checked at run time
by vkrc, and left to the user. Like Table 5.5 of the Vulkayes thesis.

What vkrc wraps is derived from the code: every Vulkan command called through
the function tables (fn.vkX, fn().vkX, fn->vkX, Functions::vkX) in src/ and
include/, and every structure whose sType vkrc writes (VK_STRUCTURE_TYPE_X),
plus the sType-less structures those reach through their members (vk.xml).
Each command or structure maps to its VUIDs in validusage.json (grouped by
name there), keeping only those whose condition holds for a Vulkan 1.3
device with the extensions vkrc uses.

Runtime: docs/validation_runtime_checks.txt (explicit, reviewed list).
Static: the regex rules in STATIC_RULES below, over the rule's text.
User: everything else. The regex classification is approximate (see
docs/validation.md).

Usage: scripts/validation_coverage.py [--markdown] [--list-static]
"""
import json
import pathlib
import re
import sys
import xml.etree.ElementTree as ET

ROOT = pathlib.Path(__file__).resolve().parent.parent
REGISTRY = pathlib.Path("/usr/share/vulkan/registry")
VALIDUSAGE = REGISTRY / "validusage.json"
VK_XML = REGISTRY / "vk.xml"
RUNTIME_TABLE = ROOT / "docs" / "validation_runtime_checks.txt"

# What a vkrc device has: Vulkan 1.3 core (promoted extensions included) and
# the instance/device extensions vkrc loads.
AVAILABLE = {"VK_VERSION_1_0", "VK_VERSION_1_1", "VK_VERSION_1_2", "VK_VERSION_1_3",
             "VK_KHR_surface", "VK_KHR_swapchain", "VK_EXT_debug_utils", "VK_EXT_memory_budget",
             "VK_KHR_push_descriptor", "VK_KHR_acceleration_structure"}

# (name, regex over the rule's text or VUID): guaranteed by vkrc's types/RAII.
STATIC_RULES = [
    ("valid handle: handles come from live RAII objects",
     r"must be a valid (\w+ )?Vk\w+ handle|must be a valid pointer to a (valid )?Vk\w+ handle"),
    ("valid pointers and arrays: vkrc builds them from spans and its own structs",
     r"must be a valid pointer to|must be a valid pointer to an array|must be NULL or a pointer to"),
    ("sType: vkrc fills it", r"-sType-sType$"),
    ("parentage: a child is made from its parent's state and keeps it alive",
     r"must have been created, allocated, or retrieved from|must have been (created|allocated) from"),
    ("destruction after the GPU is done: deferred destruction on the queue timelines",
     r"must have completed execution|must not be destroyed|in use|pending execution.*(destroy|free)|"
     r"All submitted commands that refer to"),
    ("allocation callbacks: vkrc never passes any",
     r"VkAllocationCallbacks were provided|no VkAllocationCallbacks were provided|pAllocator"),
    ("object lifetime of children before the parent: children keep their parents",
     r"All child objects created (on|using) \w+ must have been destroyed"),
]

TAG = re.compile(r"<[^>]+>")


def plain(text):
    return re.sub(r"\s+", " ", TAG.sub("", text).replace("&#43;", "+")).strip()


def condition_holds(condition):
    if condition == "core":
        return True
    for term in condition.split("+"):
        negated = term.startswith("!")
        names = set(term.lstrip("!").strip("()").split(","))
        present = bool(names & AVAILABLE)
        if present == negated:
            return False
    return True


def wrapped_names():
    calls, stypes = set(), set()
    call = re.compile(r"(?:fn\(\)|fn_?)\s*(?:\.|->)\s*(vk[A-Z]\w+)|Functions::(vk[A-Z]\w+)")
    stype = re.compile(r"\bVK_STRUCTURE_TYPE_([A-Z0-9_]+)\b")
    for path in list((ROOT / "src").rglob("*.[ch]pp")) + list((ROOT / "include").rglob("*.hpp")):
        text = path.read_text()
        for m in call.finditer(text):
            calls.add(m.group(1) or m.group(2))
        stypes.update(stype.findall(text))
    return calls, {"VK_STRUCTURE_TYPE_" + s for s in stypes}


def structures(stype_values):
    """Struct names for sType values, plus the structs they reach through members."""
    registry = ET.parse(VK_XML).getroot()
    by_name, by_stype = {}, {}
    for t in registry.iter("type"):
        if t.get("category") != "struct":
            continue
        by_name[t.get("name")] = t
        for member in t.findall("member"):
            if member.findtext("name") == "sType" and member.get("values"):
                by_stype[member.get("values")] = t.get("name")
    found = {by_stype[v] for v in stype_values if v in by_stype}
    todo = list(found)
    while todo:
        for member in by_name[todo.pop()].findall("member"):
            ty = member.findtext("type")
            if ty in by_name and ty not in found:
                # Only structures without sType: those with one are counted
                # when vkrc writes their sType (pNext chains are the user's).
                has_stype = any(m.findtext("name") == "sType" for m in by_name[ty].findall("member"))
                if not has_stype:
                    found.add(ty)
                    todo.append(ty)
    return found


def main():
    markdown = "--markdown" in sys.argv
    validation = json.loads(VALIDUSAGE.read_text())["validation"]
    calls, stypes = wrapped_names()
    commands = sorted(c for c in calls if c in validation)
    structs = sorted(s for s in structures(stypes) if s in validation)

    runtime = {}
    for line in RUNTIME_TABLE.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            vuid, _, where = line.partition(" ")
            runtime[vuid] = where.strip()

    rules = [(name, re.compile(rx)) for name, rx in STATIC_RULES]
    rows = []  # (name, total, static, runtime, user)
    seen_runtime = set()
    rule_counts = {name: 0 for name, _ in rules}
    for name in commands + structs:
        counts = [0, 0, 0]
        for condition, entries in validation[name].items():
            if not condition_holds(condition):
                continue
            for e in entries:
                vuid, text = e["vuid"], plain(e["text"])
                if vuid in runtime:
                    counts[1] += 1
                    seen_runtime.add(vuid)
                    continue
                for rule_name, rx in rules:
                    if rx.search(text) or rx.search(vuid):
                        counts[0] += 1
                        rule_counts[rule_name] += 1
                        break
                else:
                    counts[2] += 1
        rows.append((name, sum(counts), *counts))

    unknown = sorted(set(runtime) - seen_runtime)
    if unknown:
        sys.exit("validation_coverage.py: runtime-checked VUIDs not among the wrapped rules: " + ", ".join(unknown))

    total = [sum(r[i] for r in rows) for i in range(1, 5)]
    pct = lambda n: f"{100.0 * n / total[0]:.1f}%"
    if markdown:
        print("| | commands | structures | VUIDs | static (types/RAII) | runtime (vkrc) | user |")
        print("|---|---|---|---|---|---|---|")
        print(f"| vkrc | {len(commands)} | {len(structs)} | {total[0]} | {total[1]} ({pct(total[1])}) | "
              f"{total[2]} ({pct(total[2])}) | {total[3]} ({pct(total[3])}) |")
        print()
        print("| static rule | VUIDs |")
        print("|---|---|")
        for name, _ in rules:
            print(f"| {name} | {rule_counts[name]} |")
    else:
        print(f"{'command or structure':44} {'VUIDs':>6} {'static':>7} {'runtime':>8} {'user':>6}")
        for r in rows:
            print(f"{r[0]:44} {r[1]:6} {r[2]:7} {r[3]:8} {r[4]:6}")
        print(f"{'total (' + str(len(commands)) + ' commands, ' + str(len(structs)) + ' structures)':44} "
              f"{total[0]:6} {total[1]:7} {total[2]:8} {total[3]:6}")
        print(f"static {pct(total[1])}, runtime {pct(total[2])}, user {pct(total[3])}")
        for name, _ in rules:
            print(f"  static rule: {name}: {rule_counts[name]}")


if __name__ == "__main__":
    main()
