# Compiles each public header alone, included with -I as a user project's
# build would, under the warnings a strict project turns on, as errors: a
# vkrc header must add no diagnostic to its includer's build.
# -DCXX=compiler -DINCLUDE_DIRS="dir;dir" -DDEFINES="-D..." (the policy)
# -DSKIP="header;..." (headers whose dependencies are not installed)
cmake_policy(SET CMP0057 NEW)  # if(IN_LIST) in script mode
set(flags -std=c++20 -fsyntax-only -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wsign-conversion
          -Wold-style-cast -Wnon-virtual-dtor -Werror)
set(includes)
foreach(dir IN LISTS INCLUDE_DIRS)
  list(APPEND includes -I${dir})
endforeach()
list(GET INCLUDE_DIRS 0 public_dir)
file(GLOB headers RELATIVE ${public_dir} ${public_dir}/vkrc/*.hpp)
list(LENGTH headers count)
if(count LESS 20)
  message(FATAL_ERROR "only ${count} public headers found in ${public_dir}/vkrc")
endif()
set(failed)
foreach(header IN LISTS headers)
  if(header IN_LIST SKIP)
    continue()
  endif()
  execute_process(COMMAND ${CXX} ${flags} ${DEFINES} ${includes} -x c++ -include ${header} /dev/null
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out STREQUAL "")
    list(APPEND failed ${header})
    message("${header}:\n${out}")
  endif()
endforeach()
if(failed)
  message(FATAL_ERROR "headers with diagnostics under ${CXX} ${DEFINES}: ${failed}")
endif()
message("${count} headers compile cleanly under ${CXX} ${DEFINES}")
