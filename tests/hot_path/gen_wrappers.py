#!/usr/bin/env python3
"""Finds every public recording method of vkrc::CommandRecorder (the
recording part of CommandBuffer) in the public headers and writes one wrapper
per method (per overload) for the hot-path check (check_wrappers.py), so that
a new recording method is covered without anyone listing it. The methods are
CommandRecorder's own (vkrc/command.hpp) and those of each base its class
head names as Name<CommandRecorder> (the topic headers,
vkrc/command_transfer.hpp...), found by name in any header.

A method records when its inline body calls the device table (fn_->vkCmd...,
fn_->*member) or calls another method that records. Each wrapper takes the
method's own parameters as its own (nothing is constant-folded away) and is
extern "C", so that its symbol is its name in objdump's output.

Usage: gen_wrappers.py INCLUDE_DIR OUT.cpp OUT.manifest
The manifest lists "wrapper method" per line, then "helper NAME" for the
private recording helpers the wrapped methods reach.
"""
import glob
import os
import re
import sys

# Template methods get these instantiations (template parameter -> type);
# one without an entry stops the generator rather than going unchecked.
TEMPLATE_ARGS = {
    "push_constants": [{"Layout": "PipelineLayout", "T": "HotPushData"},
                       {"Layout": "VkPipelineLayout", "T": "HotPushData"}],
}
HEADER = "vkrc/command.hpp"
CLASS = "CommandRecorder"
RECORDS = re.compile(r"\bfn_\s*->\s*(\*|vkCmd\w+)")


def strip_comments_and_directives(text):
    """Comments and preprocessor lines out, string literals kept."""
    text = re.sub(r'//[^\n]*|/\*.*?\*/|("(?:\\.|[^"\\])*")', lambda m: m.group(1) or "", text, flags=re.S)
    return "\n".join(line for line in text.split("\n") if not line.lstrip().startswith("#"))


def matching(text, i, open_ch, close_ch):
    """Index just past the bracket that closes the one at text[i]."""
    depth = 0
    for j in range(i, len(text)):
        if text[j] == open_ch:
            depth += 1
        elif text[j] == close_ch:
            depth -= 1
            if depth == 0:
                return j + 1
    raise SystemExit(f"gen_wrappers: unbalanced {open_ch} in the headers")


def class_definition(text, name):
    """(head up to its "{", body) of class name's definition in text, or None."""
    m = re.search(r"\bclass\s+" + name + r"\s*(?::[^{;]*)?\{", text)
    return (m.group(0), text[m.end():matching(text, m.end() - 1, "{", "}") - 1]) if m else None


def recording_classes(include_dir):
    """[(name, body)]: CommandRecorder, then each base its head names as
    Name<CommandRecorder>, defined in exactly one header of include_dir/vkrc."""
    headers = {}
    for path in sorted(glob.glob(os.path.join(include_dir, "vkrc", "**", "*.hpp"), recursive=True)):
        with open(path, encoding="utf-8") as f:
            headers[os.path.relpath(path, include_dir)] = strip_comments_and_directives(f.read())
    own = class_definition(headers[HEADER], CLASS)
    if not own:
        raise SystemExit(f"gen_wrappers: class {CLASS} not found in {HEADER}")
    classes = [(CLASS, own[1])]
    for base in re.findall(r"(\w+)\s*<\s*" + CLASS + r"\s*>", own[0]):
        found = [(h, d) for h, text in headers.items() if (d := class_definition(text, base))]
        if len(found) != 1:
            raise SystemExit(f"gen_wrappers: {CLASS}'s base {base} is defined in {len(found)} headers "
                             f"({', '.join(h for h, _ in found) or 'none'}), not one")
        classes.append((base, found[0][1][1]))
    return classes


def members(body):
    """(access, head, body or None) per member declaration or definition."""
    access, i, start, out = "private", 0, 0, []
    while i < len(body):
        c = body[i]
        if c == "(":
            i = matching(body, i, "(", ")")
            continue
        if c == "<" and re.search(r"\btemplate\s*$", body[start:i]):
            i = matching(body, i, "<", ">")
            continue
        if c == ":" and body[start:i].strip() in ("public", "private", "protected"):
            access, start = body[start:i].strip(), i + 1
        elif c == ";":
            out.append((access, body[start:i].strip(), None))
            start = i + 1
        elif c == "{":
            end = matching(body, i, "{", "}")
            out.append((access, body[start:i].strip(), body[i + 1:end - 1]))
            start = i = end
            continue
        i += 1
    return out


def split_top(text, sep=","):
    parts, depth, cur = [], 0, ""
    for c in text:
        depth += c in "(<[{"
        depth -= c in ")>]}"
        if c == sep and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += c
    return parts + [cur] if cur.strip() else parts


class Method:
    def __init__(self, access, head, body):
        self.access, self.body = access, body
        m = re.match(r"(template\s*<(.*?)>\s*)?(.*?)\b(\w+)\s*\(", head, re.S)
        self.template = [p.split()[-1] for p in split_top(m.group(2))] if m.group(1) else []
        self.returns, self.name = m.group(3).strip(), m.group(4)
        close = matching(head, m.end() - 1, "(", ")")
        self.params = [self.param(p) for p in split_top(head[m.end():close - 1])]

    @staticmethod
    def param(text):
        text = split_top(text, "=")[0].strip()  # no default argument
        declarator = re.search(r"\(\s*[&*]\s*(\w+)\s*\)", text) or list(re.finditer(r"\b\w+\b", text))[-1]
        return text, declarator.start(1 if declarator.re.groups else 0), declarator.end(1 if declarator.re.groups else 0)

    def calls(self, name):
        return re.search(r"(?<![\w.>])" + name + r"\s*(<[^;]*?>)?\s*\(", self.body) is not None


def recording_methods(include_dir):
    methods = [Method(a, h, b) for _, body in recording_classes(include_dir) for a, h, b in members(body)
               if b is not None and "(" in h]
    methods = [m for m in methods if m.returns and not m.returns.startswith(("static", "explicit"))]
    recording = {m.name for m in methods if RECORDS.search(m.body)}
    grew = True
    while grew:  # methods that record through other recording methods
        grew = False
        for m in methods:
            if m.name not in recording and any(m.calls(r) for r in recording):
                recording.add(m.name)
                grew = True
    public = [m for m in methods if m.access == "public" and m.name in recording]
    helpers = sorted({m.name for m in methods if m.access != "public" and m.name in recording})
    return public, helpers


def instantiations(m):
    if not m.template:
        return [{}]
    if m.name not in TEMPLATE_ARGS or any(set(m.template) != set(a) for a in TEMPLATE_ARGS[m.name]):
        raise SystemExit(f"gen_wrappers: template method {m.name}<{', '.join(m.template)}> has no "
                         f"instantiation in TEMPLATE_ARGS")
    return TEMPLATE_ARGS[m.name]


def wrapper(name, m, args):
    params, names = ["const CommandRecorder& cmd"], []
    for k, (text, start, end) in enumerate(m.params):
        decl = text[:start] + f"a{k}" + text[end:]
        for t, ty in args.items():
            decl = re.sub(rf"\b{t}\b", ty, decl)
        params.append(decl)
        names.append(f"a{k}")
    return f'extern "C" void {name}({", ".join(params)}) {{ cmd.{m.name}({", ".join(names)}); }}\n'


def wrappers(public):
    """(wrapper name, method, template arguments); overloads get an index."""
    counts, seen, out = {}, {}, []
    for m in public:
        counts[m.name] = counts.get(m.name, 0) + len(instantiations(m))
    for m in public:
        for args in instantiations(m):
            k = seen[m.name] = seen.get(m.name, -1) + 1
            out.append((f"hot_{m.name}" + (f"_{k}" if counts[m.name] > 1 else ""), m, args))
    return out


def main():
    include_dir, out_cpp, out_manifest = sys.argv[1:4]
    public, helpers = recording_methods(include_dir)
    listed = wrappers(public)
    with open(out_cpp, "w", encoding="utf-8") as f:
        f.write("// Generated by tests/hot_path/gen_wrappers.py from the public headers: one\n"
                "// wrapper per public recording method of CommandRecorder, for check_wrappers.py.\n"
                f"#include <{HEADER}>\n\nVKRC_BEGIN_NAMESPACE\n\n"
                "struct HotPushData {\n    float m[16];\n};\n\n" + "".join(wrapper(*w) for w in listed)
                + "\nVKRC_END_NAMESPACE\n")
    with open(out_manifest, "w", encoding="utf-8") as f:
        f.writelines(f"wrapper {name} {m.name}\n" for name, m, _ in listed)
        f.writelines(f"helper {h}\n" for h in helpers)


if __name__ == "__main__":
    main()
