#!/usr/bin/env python3
"""Writes every C++ block of the given Markdown files into one translation
unit, each where its wrapper says, with #line directives so that a compiler
error names the Markdown file and line (issue 34: a renamed API breaks CI).

The wrapper of a block is stated by an HTML comment (not rendered) on the
line before its fence; without one, a block is a function body:
  (none)                          the body of a function of its own, int
                                  vkrc_snippets::snippet_N(); the names it uses without
                                  declaring them are prelude.hpp's (a block
                                  may declare its own)
  <!-- snippet: continues -->     more of the previous block's function (a
                                  walk-through shown in steps)
  <!-- snippet: file -->          namespace scope (a whole program, a class)

A line of "..." alone stands for code left out.

usage: extract.py OUT.cpp FILE.md...
"""
import re
import sys

ELIDED = re.compile(r"\s*\.\.\.\s*")  # a line of "..." alone stands for code left out
MARKER = re.compile(r"<!--\s*snippet:\s*(\w+)\s*-->")


def blocks(path):
    """(first line number, wrapper, code) of each cpp block of path."""
    lines = open(path, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        fence = lines[i].strip()
        if fence.startswith("```"):
            j = i + 1
            while j < len(lines) and not lines[j].strip().startswith("```"):
                j += 1
            if fence[3:].strip() in ("cpp", "c++"):
                m = MARKER.search(lines[i - 1]) if i > 0 else None
                wrapper = m.group(1) if m else "function"
                if wrapper not in ("function", "continues", "file"):
                    sys.exit(f"{path}:{i}: unknown snippet wrapper '{wrapper}'")
                yield i + 2, wrapper, lines[i + 1 : j]
            i = j
        i += 1


def main():
    out_path, sources = sys.argv[1], sys.argv[2:]
    out = ['#include "prelude.hpp"', "using namespace vkrc_snippets;  // for namespace-scope blocks", ""]
    functions = 0
    open_function = False
    for path in sources:
        for line, wrapper, code in blocks(path):
            if wrapper != "continues" and open_function:
                out += ["}", "return 0;", "}", "}  // namespace vkrc_snippets", ""]
                open_function = False
            if wrapper == "continues" and not open_function:
                sys.exit(f"{path}:{line - 1}: 'continues' with no function block before it")
            if wrapper == "function":
                functions += 1
                # In prelude.hpp's namespace, so that its names hide global ones (::log).
                out += ["namespace vkrc_snippets {", f"[[maybe_unused]] static int snippet_{functions}() {{", "VKRC_SNIPPET_LOCALS", "{"]
                open_function = True
            out.append(f'#line {line} "{path}"')
            out += ["" if ELIDED.fullmatch(c) else c for c in code]
            out.append(f'#line {len(out) + 2} "{out_path}"')
        if open_function:
            out += ["}", "return 0;", "}", "}  // namespace vkrc_snippets", ""]
            open_function = False
    open(out_path, "w", encoding="utf-8").write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
