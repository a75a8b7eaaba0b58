#!/usr/bin/env python3
"""Checks docs/design.md's layer map against the tree.

The table between <!-- layer-map --> and <!-- /layer-map --> names, for each
layer, its public headers (include/vkrc/, without .hpp), its sources (src/,
without .cpp) and its private headers (src/, without .hpp). It must list:
  - exactly the sources of CMakeLists.txt's VKRC_SOURCES, each in the layer
    whose comment ("# device", ...) precedes it there, in the same order;
  - every file under include/vkrc/ and every private header in src/, once.
Exits 1 and says what differs otherwise. Usage: check_layer_map.py [ROOT]
"""
import pathlib
import re
import sys

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)


def cmake_layers():
    text = (ROOT / "CMakeLists.txt").read_text()
    block = re.search(r"set\(VKRC_SOURCES\n(.*?)\n\)", text, re.S).group(1)
    layers, layer = [], None
    for line in block.splitlines():
        line = line.strip()
        if line.startswith("#"):
            layer = line.lstrip("# ").strip()
            layers.append((layer, []))
        elif line:
            layers[-1][1].append(re.sub(r"^src/|\.cpp$", "", line))
    return layers


def names(cell):
    return re.findall(r"`([^`]+)`", cell)


def table_rows():
    text = (ROOT / "docs/design.md").read_text()
    block = re.search(r"<!-- layer-map -->\n(.*?)<!-- /layer-map -->", text, re.S)
    if not block:
        sys.exit("docs/design.md: no <!-- layer-map --> table")
    rows = []
    for line in block.group(1).splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 4 or cells[0] in ("Layer", "") or set(cells[0]) <= set("-: "):
            continue
        layer = re.sub(r"^\d+\.?\s*", "", cells[0])
        rows.append((layer, names(cells[1]), names(cells[2]), names(cells[3])))
    return rows


def main():
    errors = []
    rows = table_rows()
    cmake = cmake_layers()
    if [l for l, _ in cmake] != [r[0] for r in rows]:
        errors.append(f"layers: CMakeLists.txt has {[l for l, _ in cmake]}, design.md {[r[0] for r in rows]}")
    for (layer, sources), row in zip(cmake, rows):
        if sources != row[2]:
            errors.append(f"layer {layer}: VKRC_SOURCES has {sources}, design.md {row[2]}")
    headers = sorted(str(p.relative_to(ROOT / "include/vkrc")).removesuffix(".hpp")
                     for p in (ROOT / "include/vkrc").rglob("*") if p.is_file())
    private = sorted(p.name.removesuffix(".hpp") for p in (ROOT / "src").iterdir()
                     if p.suffix in (".hpp", ".inl"))
    for what, actual, listed in (("include/vkrc/", headers, [h for r in rows for h in r[1]]),
                                 ("src/ private headers", private, [h for r in rows for h in r[3]])):
        missing = sorted(set(actual) - set(listed))
        extra = sorted(set(listed) - set(actual))
        twice = sorted({n for n in listed if listed.count(n) > 1})
        if missing:
            errors.append(f"{what}: not in design.md's layer map: {missing}")
        if extra:
            errors.append(f"{what}: in design.md's layer map but not in the tree: {extra}")
        if twice:
            errors.append(f"{what}: listed more than once: {twice}")
    for e in errors:
        print("layer map:", e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
