#!/usr/bin/env python3
"""The hot-path rule on the machine code, per recording method: checks each
wrapper that gen_wrappers.py wrote (one per public recording method of
CommandRecorder, the recording part of CommandBuffer), compiled with -O2 -DNDEBUG (unchecked) into OBJECT.

Usage: check_wrappers.py OBJDUMP OBJECT MANIFEST INCLUDE_DIR

First the coverage: the manifest the object was built from must list what
the headers hold now (gen_wrappers.py run again), and a grep independent of
that parser finds every vkCmd in the headers' code and fails unless it lies in
a wrapped method (or a private helper the wrapped methods reach) of
CommandRecorder or of one of the bases gen_wrappers.py reads its methods from.

Then each wrapper, with what it reaches by direct call or jump inside the
object (an inline method the compiler did not inline), must have:
- exactly CALLS indirect calls or jumps (the vkCmd function pointers);
- no other call or jump out of it (clang's terminate landing pads aside);
- no lock prefix, xchg with memory, cmpxchg, xadd or fence;
- no store except to its own stack frame, addressed from %rsp or from a
  register that holds an address in it (see track_stack_registers): the
  outgoing arguments past the sixth and the temporaries whose address Vulkan
  takes (a Raw handle's or an offset's pointer, a VkDependencyInfo, the stack
  arrays of the exceptions); pushes are the frame (callee-saved registers,
  alignment) or outgoing arguments. A store through any other register or
  %rip writes memory that is not this call's (the handle, the state, a
  global): that is what the rule forbids. String stores (rep stos, movs)
  write through %rdi and fail too;
- at most BRANCHES conditional branches and at most INSTRUCTIONS instructions
  (padding and the landing pads not counted), or the wrapper's EXCEPTIONS.
An atomic load is a plain mov on x86-64: only the instruction bound sees one.
"""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.dont_write_bytecode = True  # no __pycache__ in the source tree: running the tests leaves git status clean
import gen_wrappers  # noqa: E402

# Default bounds, for a method that is one call with its arguments. They
# compile to 4 to 14 instructions (GCC 12 and clang 14, both policies, the
# same code): load the table and the raw handle, move the arguments into
# place (a Raw handle's address, the stack arguments past the sixth),
# set up the frame. 16 is the largest plus 2, for a compiler's register
# shuffle; a check, a loop or a struct built field by field does not fit.
# No conditional branch (the stride and nullptr defaults are cmovs).
INSTRUCTIONS = 16
BRANCHES = 0
CALLS = 1
# Reasoned exceptions, (calls, branches, instructions) by wrapper, each
# bound the larger of GCC's and clang's counts (in the comment) plus a margin.
EXCEPTIONS = {
    # VkRenderPassBeginInfo built on the stack (22, 22).
    "hot_begin_render_pass": (1, 0, 26),
    # VkCopyAccelerationStructureInfoKHR built on the stack (17, 12): GCC
    # spends one register move more since the method moved to a class
    # template (vkrc/command_ray_tracing.hpp); 16 as a member of the class.
    "hot_copy_acceleration_structure": (1, 0, 19),
    # Up to 8 VkRenderingAttachmentInfo copied into a stack array in a loop,
    # the optional depth and stencil ones and VkRenderingInfo on the stack;
    # not inlined by either compiler, so the wrapper jumps to the method's
    # out-of-line copy, counted here with it (145 and 5 branches, 128 and 4).
    "hot_begin_rendering": (1, 6, 160),
    # Viewport, then scissor: two calls, each struct on the stack (38, 37).
    "hot_set_viewport_and_scissor": (2, 0, 42),
    # The span overload builds VkDependencyInfo on the stack (21, 22).
    "hot_pipeline_barrier_1": (1, 0, 26),
    # CommandBuffer secondaries copied to a stack array in chunks of 32, one
    # call per chunk: a loop, which clang vectorises (51 and 5 branches, 124
    # and 9). One call in the code, run once per chunk.
    "hot_execute_commands_0": (1, 10, 140),
    # No-ops without VK_EXT_debug_utils: one test of the function pointer;
    # begin and insert build VkDebugUtilsLabelEXT on the stack (16, 15; 10, 9).
    "hot_begin_label": (1, 1, 18),
    "hot_end_label": (1, 1, 12),
    "hot_insert_label": (1, 1, 18),
    # sizes and strides: an empty span passes nullptr, which clang branches
    # on (18 and 0 branches, 19 and 2).
    "hot_bind_vertex_buffers2": (1, 2, 21),
    # The bind point, the layout and the set are read through the Pipeline's
    # and the DescriptorSet's states (pointer chases before the call; the set
    # is passed by address from the stack): 20, 25; 17, 17.
    "hot_bind_descriptor_set": (1, 0, 28),
    "hot_bind_descriptor_sets_0": (1, 0, 20),
    # vkCmdTraceRaysKHR takes eight arguments: the four regions' addresses
    # (one load of the table's state, four offsets from it) and height and
    # depth on the stack, pushed and popped around the call (18, 18).
    "hot_trace_rays": (1, 0, 20),
}

FUNCTION = re.compile(r"^[0-9a-f]+ <([^>]+)>:$")
INSN = re.compile(r"^\s*([0-9a-f]+):\s+(.*)$")
# With -w, a relocation follows its instruction on the line: "\t b1: R_X86_64_PLT32\tsym-0x4".
RELOC = re.compile(r"\s+[0-9a-f]+: R_X86_64_\w+\s+(\S+?)(?:[-+]0x[0-9a-f]+)?$")
# A direct branch's target as objdump names it: "jmp 802 <f+0x122>".
ANNOTATION = re.compile(r"<([^>+]+)(?:\+0x[0-9a-f]+)?>")
PADDING = re.compile(r"^(nop|xchg\s+%ax,%ax|int3|data16|cs nop|ud2)")
# Instructions with a memory last operand that do not write it.
NO_WRITE = re.compile(r"^(cmp|test|bt|ucomis|comis|prefetch|nop|call|jmp|j[a-z]+|push|lea)\b")
ATOMIC = re.compile(r"(^|\s)(lock|cmpxchg\w*|xadd\w*|mfence|lfence|sfence)\b|^xchg\w*\s+[^\n]*\(")


class Function:
    def __init__(self, name):
        self.name, self.insns = name, []


def disassemble(objdump, obj):
    """Functions of every executable section; GCC's name.cold parts go to name."""
    out = subprocess.run([objdump, "-d", "-r", "-w", "--no-show-raw-insn", obj], check=True, capture_output=True,
                         text=True).stdout
    functions, cur = {}, None
    for line in out.split("\n"):
        if m := FUNCTION.match(line):
            name = m.group(1).removesuffix(".cold")
            cur = functions.setdefault(name, Function(name))
        elif cur and (m := INSN.match(line)):
            cur.insns.append(instruction(cur.name, m.group(2)))
    return functions


def instruction(function, text):
    """(text, target): target is the function a direct branch goes to when
    that is not this one (by relocation, else by objdump's annotation)."""
    reloc = RELOC.search(text)
    text = text[:reloc.start()].strip() if reloc else text.strip()
    ann = ANNOTATION.search(text)
    target = reloc.group(1) if reloc else ann.group(1).removesuffix(".cold") if ann else None
    return text, (target if target != function else None)


def without_landing_pads(insns):
    """clang's landing pads, "mov %rax,%rdi; call __clang_call_terminate":
    the driver is called through a C function pointer, which clang cannot
    prove nothrow, so a noexcept method gets them (GCC's personality routine
    terminates instead). Only the unwinder enters them, if the driver throws,
    and they end the program: not part of recording a command. Removing them
    would take a noexcept-typed pointer to a function not defined noexcept,
    which the standard does not allow."""
    out, i = [], 0
    while i < len(insns):
        if (i + 1 < len(insns) and insns[i][0].replace(" ", "") == "mov%rax,%rdi"
                and insns[i + 1][1] == "__clang_call_terminate"):
            i += 2
            continue
        out.append(insns[i])
        i += 1
    return out


def reached(functions, name):
    """The wrapper's instructions plus those of the functions it calls or
    jumps to that this object defines (inline methods emitted out of line)."""
    seen, todo, insns, leaving = {name}, [name], [], []
    while todo:
        for insn in without_landing_pads(functions[todo.pop()].insns):
            text, target = insn
            if PADDING.match(text):
                continue
            insns.append(text)
            m, ops = operands(text)
            if target and m in ("call", "jmp") and not ops[0].startswith("*"):
                if target in functions and target not in seen:
                    seen.add(target)
                    todo.append(target)
                elif target not in functions:
                    leaving.append(f"{text} -> {target}")
    return insns, leaving


def operands(text):
    """(mnemonic, operands), branch prefixes (notrack, bnd) dropped."""
    parts = re.sub(r"^(notrack|bnd)\s+", "", text).split(None, 1)
    return parts[0], (gen_wrappers.split_top(parts[1]) if len(parts) > 1 else [])


def is_conditional(text):
    return re.match(r"j(?!mp)", operands(text)[0]) is not None


def violations(name, insns, leaving):
    calls, branches, count = EXCEPTIONS.get(name, (CALLS, BRANCHES, INSTRUCTIONS))
    mnemonic = [operands(t) for t in insns]
    indirect = [t for t, (m, ops) in zip(insns, mnemonic) if m in ("call", "jmp") and ops and ops[0].startswith("*")]
    conditional = [t for t in insns if is_conditional(t)]
    bad = [f"{len(indirect)} indirect calls or jumps, expected {calls}"] if len(indirect) != calls else []
    bad += [f"call or jump out of the wrapper: {t}" for t in leaving]
    bad += [f"atomic or locked: {t}" for t in insns if ATOMIC.search(t)]
    stack = set()  # registers holding an address in this frame
    for t, (m, ops) in zip(insns, mnemonic):
        if "%es:(" in t:
            bad.append(f"string store through %rdi: {t}")
        elif ops and "(" in ops[-1] and not NO_WRITE.match(m) and not on_stack(ops[-1], stack):
            bad.append(f"store not to the stack: {t}")
        track_stack_registers(m, ops, stack)
    if len(conditional) > branches:
        bad.append(f"{len(conditional)} conditional branches, at most {branches}")
    if len(insns) > count:
        bad.append(f"{len(insns)} instructions, at most {count}")
    return bad


REGISTER = re.compile(r"%(r[a-d]x|e[a-d]x|[a-d][lh]|[a-d]x|r[sd]i|e[sd]i|[sd]il?|r[sb]p|e[sb]p|[sb]pl?|r\d+[dwb]?)$")
CALLER_SAVED = {"rax", "rcx", "rdx", "rsi", "rdi", "r8", "r9", "r10", "r11"}


def register64(op):
    """%edx, %dl, %r9d... -> rdx, r9; None for anything but a general register."""
    if not (m := REGISTER.match(op)):
        return None
    r = m.group(1)
    if r.startswith("r") and r[1:2].isdigit():
        return r.rstrip("dwb")
    core = r.lstrip("re").rstrip("lh") if r[-1] in "lh" and len(r) == 2 else r.lstrip("re").removesuffix("l")
    return "r" + (core + "x" if len(core) == 1 else core)


def on_stack(address, stack):
    base = re.search(r"\((%\w+)", address)
    return base is not None and (base.group(1) == "%rsp" or register64(base.group(1)) in stack)


def track_stack_registers(m, ops, stack):
    """Which registers hold a stack address after this instruction: set by
    lea from one or a move of %rsp or of one, kept by adding a constant,
    lost on any other write and, for the caller-saved, on a call. A linear
    scan of the code as laid out, enough for the arrays the exceptions fill
    in a loop from a pointer set before it."""
    if m.startswith("call"):
        stack -= CALLER_SAVED
        return
    dst = register64(ops[-1]) if ops else None
    if dst is None or (NO_WRITE.match(m) and not m.startswith("lea")):
        return
    src = ops[0]
    if m.startswith("lea") and on_stack(src, stack):
        stack.add(dst)
    elif m.startswith("mov") and (src == "%rsp" or register64(src) in stack) and src.startswith("%r"):
        stack.add(dst)
    elif not (m.startswith(("add", "sub")) and src.startswith("$") and dst in stack):
        stack.discard(dst)


def code_lines(path):
    with open(path, encoding="utf-8") as f:
        text = f.read()
    # Comments and string literals blanked, line breaks kept.
    blank = lambda m: re.sub(r"[^\n]", " ", m.group(0))  # noqa: E731
    text = re.sub(r'//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\])*"', blank, text, flags=re.S)
    return ["" if line.lstrip().startswith("#") else line for line in text.split("\n")]


def recording_sites(include_dir):
    """(file:line, enclosing class, method) for each vkCmd or fn_->* in code:
    by indentation (clang-format's 4), not by gen_wrappers' parser."""
    sites = []
    for root, _, files in os.walk(include_dir):
        for file in sorted(f for f in files if f.endswith(".hpp")):
            lines = code_lines(os.path.join(root, file))
            for n, line in enumerate(lines):
                if not re.search(r"\bvkCmd\w+|\bfn_\s*->\s*\*", line):
                    continue
                head = next((l for l in reversed(lines[:n + 1]) if l.strip() and len(l) - len(l.lstrip()) <= 4),
                            "")
                m = re.match(r" {0,4}\S.*?\b(\w+)\s*\(", head)
                cls = None  # a free function's head is not indented
                if head.startswith(" "):
                    cls = next((c.group(1) for l in reversed(lines[:n + 1]) if (c := re.match(r"class (\w+)\b", l))),
                               None)
                sites.append((f"{file}:{n + 1}", cls, m.group(1) if m else None))
    return sites


def coverage(manifest, include_dir):
    with open(manifest, encoding="utf-8") as f:
        rows = [line.split() for line in f if line.strip()]
    built = [(r[1], r[2]) for r in rows if r[0] == "wrapper"]
    helpers = {r[1] for r in rows if r[0] == "helper"}
    public, now_helpers = gen_wrappers.recording_methods(include_dir)
    bad = []
    if built != [(n, m.name) for n, m, _ in gen_wrappers.wrappers(public)] or helpers != set(now_helpers):
        bad.append("the wrappers were generated from other headers than these: rebuild")
    covered = {m for _, m in built} | helpers
    classes = {name for name, _ in gen_wrappers.recording_classes(include_dir)}
    for where, cls, method in recording_sites(include_dir):
        if cls not in classes or method not in covered:
            bad.append(f"{where}: vkCmd in {(cls + '::') if cls else ''}{method or '?'}, which no wrapper covers "
                       f"(extend tests/hot_path/gen_wrappers.py)")
    return built, bad


def main():
    objdump, obj, manifest, include_dir = sys.argv[1:5]
    built, bad = coverage(manifest, include_dir)
    functions = disassemble(objdump, obj)
    for name, method in built:
        if name not in functions:
            bad.append(f"{name} ({method}): not in {obj}")
            continue
        insns, leaving = reached(functions, name)
        problems = violations(name, insns, leaving)
        calls, branches, count = EXCEPTIONS.get(name, (CALLS, BRANCHES, INSTRUCTIONS))
        print(f"{'FAIL' if problems else 'ok  '} {name}: {len(insns)}/{count} instructions, "
              f"{sum(map(is_conditional, insns))}/{branches} branches, {calls} call(s)"
              + (" (exception)" if name in EXCEPTIONS else ""))
        bad += [f"{name} ({method}): {p}" for p in problems]
        if problems:
            print("\n".join("    " + t for t in insns))
    unknown = set(EXCEPTIONS) - {n for n, _ in built}
    bad += [f"exception for {n}, which is not a wrapper any more" for n in sorted(unknown)]
    print(f"{len(built)} wrappers of {len({m for _, m in built})} recording methods, {len(EXCEPTIONS)} exceptions")
    if bad:
        sys.exit("hot path violated:\n" + "\n".join("  " + b for b in bad))


if __name__ == "__main__":
    main()
