#!/usr/bin/env python3
"""Checks that every vkrc call the guide's prose names has its declaration
linked in its section (issue 34: every call named has its signature or a
link to it), and that every link to a header or to a heading resolves.

A call is a name before "(" or after "Type::" inside backquotes, outside
code blocks. A name that some header of include/vkrc declares or calls
(an identifier before "(") must be declared or called in one of the headers
that the section (from one "## " heading to the next) links as
../include/vkrc/NAME.hpp. Names no header has (GLSL, CMake, Vulkan) are not
vkrc's and pass. The appendix is exempt: each of its blocks names its
header. Headers that declare a name many others also declare (`create`,
`vk`) satisfy it alike: the check asks for a link, not the right overload.

usage: check_call_links.py INCLUDE_DIR GUIDE.md
"""
import collections
import glob
import os
import re
import sys

# Words of C++, CMake or GLSL that a header also has before "(".
NOT_VKRC = {"catch", "decltype", "for", "if", "return", "set", "sizeof", "static_cast", "void", "while"}


def declared(include_dir):
    """{name: {header paths relative to include_dir}} of identifiers before '(' or declared as types."""
    names = collections.defaultdict(set)
    for path in glob.glob(os.path.join(include_dir, "vkrc", "**", "*.hpp"), recursive=True):
        rel = os.path.relpath(path, include_dir)
        text = "\n".join(line.split("//")[0] for line in open(path, encoding="utf-8").read().split("\n"))
        for m in re.finditer(r"\b([A-Za-z_]\w*)\s*\(", text):
            names[m.group(1)].add(rel)
        for m in re.finditer(r"^\s*(?:class|struct)\s+(\w+)", text, re.M):
            names[m.group(1)].add(rel)
    return names


def main():
    include_dir, guide = sys.argv[1], sys.argv[2]
    names = declared(include_dir)
    text = open(guide, encoding="utf-8").read()
    text = text[: text.find("## Appendix")] if "## Appendix" in text else text
    errors = []
    # Every link to a header or to a heading of the guide resolves.
    whole = open(guide, encoding="utf-8").read()
    slugs = {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
             for h in re.findall(r"^#+ (.*)$", whole, re.M)}
    for m in re.finditer(r"\]\((#[^)]+|\.\./include/[^)]+)\)", whole):
        target = m.group(1)
        if target.startswith("#") and target[1:] not in slugs or (
                not target.startswith("#") and not os.path.exists(os.path.join(include_dir, target[len("../include/"):]))):
            errors.append(f"{guide}:{whole.count(chr(10), 0, m.start()) + 1}: the link {target} leads nowhere")
    line_of = lambda at: text.count("\n", 0, at) + 1
    sections = [m.start() for m in re.finditer(r"^## ", text, re.M)] + [len(text)]
    for start, end in zip(sections, sections[1:]):
        body = text[start:end]
        title = body.split("\n", 1)[0]
        linked = {"vkrc/" + h for h in re.findall(r"\]\(\.\./include/vkrc/([\w/]+\.hpp)\)", body)}
        prose = re.sub(r"```.*?```", lambda m: "\n" * m.group(0).count("\n"), body, flags=re.S)
        for span in re.finditer(r"`([^`]+)`", prose):
            called = [(None, m.group(1)) for m in re.finditer(r"(\w+)\s*\(", span.group(1))]
            # Type::member: the header that declares Type will do.
            called += [m.groups() for m in re.finditer(r"\b([A-Z]\w*)::(\w+)", span.group(1))]
            for owner, name in called:
                if owner in names and names[owner] & linked:
                    continue
                if name in names and name not in NOT_VKRC and not names[name] & linked:
                    errors.append(f"{guide}:{line_of(start + span.start())}: `{span.group(1)}` names {name},"
                                  f" declared in {', '.join(sorted(names[name]))}, none linked in '{title}'")
    for e in errors:
        print(e)
    if errors:
        sys.exit(1)
    print(f"every call named in {len(sections) - 1} sections has its header linked there")


if __name__ == "__main__":
    main()
