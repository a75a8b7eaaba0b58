#!/usr/bin/env python3
"""Checks the guide's appendix of create-infos against the headers (issue 34:
each create-info the guide uses is shown whole once, in declaration order).

Every C++ block of the appendix (from its heading to the end of the file)
declares one struct, `vkrc::Name var{ .member = value, ... };`. For each:
  - its members are those of `struct Name` in include/vkrc/*.hpp, all of
    them, in declaration order (designated initializers must follow it);
  - a member whose comment does not begin with "required" shows the
    header's default, token for token (so no default is typed by hand);
  - the text between its heading and the block links its header;
  - no struct has two blocks.
And every create-info the guide or README uses has a block: each struct of
the headers whose name ends in "Info" and appears in them, and
`TCreateInfo` for each `T::create(` in their code.

usage: check_create_infos.py INCLUDE_DIR GUIDE.md [OTHER.md...]
"""
import glob
import os
import re
import sys

APPENDIX = "## Appendix: create-infos"


def strip_comment(line):
    """line without its // comment (outside string literals), and the comment."""
    quoted = False
    for i, c in enumerate(line):
        if c == '"' and (i == 0 or line[i - 1] != "\\"):
            quoted = not quoted
        elif not quoted and line.startswith("//", i):
            return line[:i], line[i + 2 :].strip()
    return line, ""


def norm(text):
    return re.sub(r"\s+", "", text)


def top_level(text):
    """(index, character, depth) of each character of text outside string
    literals, depth counting the (), {} and [] open before it (a closer
    already counted out)."""
    depth, quoted = 0, False
    for i, c in enumerate(text):
        if c == '"':
            quoted = not quoted
        elif quoted:
            continue
        elif c in "({[":
            depth += 1
        elif c in ")}]":
            depth -= 1
        yield i, c, depth


def split_top(text, separators):
    """Splits text at the separators that stand outside (), {}, [] and strings."""
    parts, start = [], 0
    for i, c, depth in top_level(text):
        if depth == 0 and c in separators:
            parts.append((text[start:i], c))
            start = i + 1
    parts.append((text[start:], ""))
    return parts


def head_of(decl):
    """What a declaration says before its initializer or body, template arguments left out."""
    head = re.split(r"[={]", decl, 1)[0]
    while re.search(r"<[^<>]*>", head):
        head = re.sub(r"<[^<>]*>", "", head)
    return head


def header_structs(include_dir):
    """{name: (file, [(member, default)])} of every top-level struct in the headers."""
    structs = {}
    for path in sorted(glob.glob(os.path.join(include_dir, "vkrc", "*.hpp"))):
        text = open(path, encoding="utf-8").read()
        for m in re.finditer(r"^struct (\w+) \{\n(.*?)^\};", text, re.M | re.S):
            body = "\n".join(strip_comment(l)[0] for l in m.group(2).split("\n") if not l.lstrip().startswith("#"))
            members = []
            rest = body
            while rest.strip():
                # One declaration: up to ';' at depth 0, or to the '}' that
                # ends a function's body (one not followed by ';').
                end = None
                for i, c, depth in top_level(rest):
                    closes_body = (depth == 0 and c == "}" and "(" in head_of(rest[:i])
                                   and not rest[i + 1 :].lstrip().startswith((";", ",")))
                    if closes_body or (c == ";" and depth == 0):
                        end = i
                        break
                if end is None:
                    break
                decl, rest = rest[:end].strip(), rest[end + 1 :]
                if "(" in head_of(decl) or re.match(r"(static|friend|using|template|explicit|struct|class)\b", decl):
                    continue
                if "=" in decl.split("{")[0]:
                    lhs, default = decl.split("=", 1)
                else:
                    brace = decl.find("{")
                    lhs, default = (decl, "{}") if brace < 0 else (decl[:brace], decl[brace:])
                members.append((lhs.split()[-1], default.strip()))
            structs[m.group(1)] = (os.path.relpath(path, include_dir), members)
    return structs


def appendix_blocks(path):
    """(line, struct name, [(member, value, comment)]) of each C++ block of the appendix."""
    lines = open(path, encoding="utf-8").read().split("\n")
    if APPENDIX not in lines:
        sys.exit(f"{path}: no '{APPENDIX}' heading")
    i = lines.index(APPENDIX)
    heading = i
    while i < len(lines):
        if lines[i].startswith("#"):
            heading = i
        if lines[i].strip() in ("```cpp", "```c++"):
            j = i + 1
            while not lines[j].strip().startswith("```"):
                j += 1
            code = lines[i + 1 : j]
            m = re.match(r"\s*vkrc::(?:\w+::)*(\w+) \w+\{\s*$", strip_comment(code[0])[0])
            if not m:
                sys.exit(f"{path}:{i + 2}: an appendix block must start with 'vkrc::Name variable{{'")
            text, comments = "", []
            for line in code[1:]:
                code_part, comment = strip_comment(line)
                # A comment alone on its line goes on with the one above it.
                at = len(text) if code_part.strip() else len(text.rstrip()) - 1
                comments.append((at, comment))
                text += code_part + "\n"
            body = text[: text.rstrip().rfind("}")]
            entries, offset = [], 0
            for part, _ in split_top(body, ","):
                field = re.match(r"\s*\.(\w+)\s*=(.*)", part, re.S)
                if field:
                    said = [c for at, c in comments if c and offset <= at < offset + len(part) + 1]
                    entries.append((field.group(1), field.group(2).strip(), said))
                elif part.strip():
                    sys.exit(f"{path}:{i + 2}: not a designated initializer: {part.strip()}")
                offset += len(part) + 1
            yield i + 2, m.group(1), entries, "\n".join(lines[heading:i])
            i = j
        i += 1


def main():
    include_dir, guide, others = sys.argv[1], sys.argv[2], sys.argv[3:]
    structs = header_structs(include_dir)
    errors, shown = [], {}
    for line, name, entries, before in appendix_blocks(guide):
        where = f"{guide}:{line}: {name}"
        if name not in structs:
            errors.append(f"{where}: no such struct in {include_dir}/vkrc/*.hpp")
            continue
        if name in shown:
            errors.append(f"{where}: shown twice (also at line {shown[name]})")
        shown[name] = line
        header, members = structs[name]
        if f"](../include/{header})" not in before:
            errors.append(f"{where}: the text above the block does not link ../include/{header}")
        declared = [m for m, _ in members]
        listed = [e[0] for e in entries]
        if listed != declared:
            errors.append(f"{where}: members {listed}\n  but {header} declares {declared}")
            continue
        for (member, default), (_, value, comment) in zip(members, entries):
            required = any(c.lower().startswith("required") for c in comment)
            if not required and norm(value).replace("vkrc::", "") != norm(default):
                errors.append(f"{where}: .{member} = {value} but its default in {header} is {default}"
                              " (or say 'required' in its comment)")
    # Every create-info used has a block.
    appendix_at = open(guide, encoding="utf-8").read().find(APPENDIX)
    used = {}
    for path in [guide] + others:
        text = open(path, encoding="utf-8").read()
        if path == guide:
            text = text[:appendix_at]
        for name in structs:
            if name.endswith("Info") and re.search(rf"\b{name}\b", text):
                used.setdefault(name, path)
        for owner in re.findall(r"\b(\w+)::create\(", text):
            if owner + "CreateInfo" in structs:
                used.setdefault(owner + "CreateInfo", path)
    for name, path in sorted(used.items()):
        if name not in shown:
            errors.append(f"{path}: uses {name}, which the appendix of {guide} does not show")
    for e in errors:
        print(e)
    if errors:
        sys.exit(1)
    print(f"{len(shown)} create-infos shown whole, in declaration order, with their defaults")


if __name__ == "__main__":
    main()
