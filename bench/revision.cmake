# Writes the source revision a benchmark build was made from into OUT, at
# build time: the results' '# git:' line reads it, so a copy of the build
# run elsewhere (where the checkout's git metadata may be stale or absent)
# still names the code it measured. Usage: cmake -DSOURCE=dir -DOUT=file -P revision.cmake
execute_process(COMMAND git -C ${SOURCE} rev-parse --short HEAD
                OUTPUT_VARIABLE revision OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
if(failed OR revision STREQUAL "")
  set(revision "unknown")
else()
  execute_process(COMMAND git -C ${SOURCE} status --porcelain --untracked-files=no
                  OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NOT changes STREQUAL "")
    string(APPEND revision " (with local changes)")
  endif()
endif()
set(old "")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT old STREQUAL "${revision}\n")
  file(WRITE ${OUT} "${revision}\n")
endif()
