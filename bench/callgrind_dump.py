"""Reads one callgrind dump of a client-requested collection (the bench
scripts' CALLGRIND_DUMP_STATS_AT): its label's key=value pairs, its total
instructions and those outside the driver.

The driver: the ICD and what it links (lavapipe's LLVM and gallium, GPU
vendors' user-mode drivers). Calls from any other object into one of them
are the driver's work; their inclusive cost is subtracted to give the
instructions outside the driver (application, wrapper, loader, libc)."""
import re

DRIVER = re.compile(r"libvulkan_|libLLVM|libgallium|libnvidia|libdrm|libamdgpu|libGLX_nvidia|lvp|radv|anv")


def read_dump(path, label_prefix=""):
    """(label as a dict, total, outside the driver); label None when the dump has none after label_prefix."""
    desc, total, driver = None, None, 0
    names, ob, cob, call_target = {}, None, None, None
    with open(path, errors="replace") as f:
        for line in f:
            m = re.match(r"desc: Trigger: Client Request: " + re.escape(label_prefix) + r"(.*)", line)
            if m:
                desc = dict(kv.split("=", 1) for kv in m.group(1).split())
            m = re.match(r"(?:summary|totals): (\d+)", line)
            if m:
                total = int(m.group(1))
            m = re.match(r"(c?ob)=(?:\((\d+)\))?\s*(.*)", line)
            if m:
                key, ident, name = m.group(1), m.group(2), m.group(3).strip()
                if ident and name:
                    names[ident] = name
                obj = names.get(ident, name) if ident else name
                if key == "ob":
                    ob, cob = obj, None
                else:
                    cob = obj
                continue
            if line.startswith("calls="):
                call_target = cob if cob is not None else ob
                cob = None
                continue
            if call_target is not None and re.match(r"[+\-*\d]", line):
                cost = int(line.split()[1]) if len(line.split()) > 1 else 0
                if DRIVER.search(call_target or "") and not DRIVER.search(ob or ""):
                    driver += cost
                call_target = None
            elif line.startswith("fn="):
                cob = None
    return desc, total, None if total is None else total - driver
