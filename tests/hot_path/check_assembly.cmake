# cmake -DOBJDUMP=... -DOBJECT=record.o -DFUNCTIONS=7 -P check_assembly.cmake
# Only .text, where record.cpp's functions are (clang puts its
# __clang_call_terminate helper in a section of its own); -r shows the
# symbol each call or jump in the object file goes to.
execute_process(COMMAND ${OBJDUMP} -d -r --no-show-raw-insn --section=.text ${OBJECT} OUTPUT_VARIABLE asm
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "objdump failed on ${OBJECT}")
endif()
# The recording methods are noexcept and call the driver through a C function
# pointer, which clang cannot prove nothrow, so clang (unlike GCC, where the
# personality routine terminates) adds landing pads after the function's code:
# "mov %rax,%rdi; call __clang_call_terminate". The unwinder enters them,
# through the exception tables, only if the driver throws, and they end the
# program: never part of recording a command. Removing them would take calling
# the driver through a noexcept-typed pointer, which the standard does not
# allow for a function defined without noexcept. So they are not counted; any
# other call or tail jump to a function still fails the check.
string(REGEX REPLACE
  "[^\n]*[\t ]mov[ \t]+%rax,%rdi\n[^\n]*[\t ]call[ \t]+[0-9a-f]+ <[^\n]*\n[^\n]*R_X86_64_PLT32[ \t]+__clang_call_terminate[^\n]*\n"
  "        (landing pad calling __clang_call_terminate: not counted)\n" asm "${asm}")
string(REGEX MATCHALL "\\(landing pad calling __clang_call_terminate" pads "${asm}")
string(REGEX MATCHALL "[\t ](call|jmp)[a-z]*[ \t]+\\*[^\n]*" indirect "${asm}")
# Direct calls, and jumps that leave the function (a relocation follows them).
string(REGEX MATCHALL "[\t ]call[a-z]*[ \t]+[0-9a-f]+ <[^\n]*|[\t ]j[a-z]*[ \t]+[0-9a-f]+ <[^\n]*\n[^\n]*R_X86_64_[^\n]*"
       direct "${asm}")
# xchg with a memory operand is locked; "xchg %ax,%ax" is padding (clang).
string(REGEX MATCHALL "[\t ](lock|mfence|cmpxchg)[^\n]*|[\t ]xchg[^\n]*\\([^\n]*" atomics "${asm}")
list(LENGTH pads n_pads)
list(LENGTH indirect n_indirect)
list(LENGTH direct n_direct)
list(LENGTH atomics n_atomics)
message(STATUS "indirect calls: ${n_indirect}, direct calls: ${n_direct}, atomic/lock instructions: ${n_atomics} "
               "(terminate landing pads, not counted: ${n_pads})")
if(NOT n_indirect EQUAL FUNCTIONS OR n_direct GREATER 0 OR n_atomics GREATER 0)
  message(FATAL_ERROR "recording is not one indirect call per command:\n${asm}")
endif()
