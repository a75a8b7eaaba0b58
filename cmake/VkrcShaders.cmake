# vkrc_add_shaders(<target> <shader>...)
#
# Compiles GLSL files (stage from the extension: .vert .frag .comp ...) to
# SPIR-V with glslangValidator at build time and embeds each in a generated
# header, so binaries need no shader files beside them. For shaders/foo.frag,
# code in <target> writes
#     #include "shaders/foo.frag.h"      // defines vkrc_shaders::foo_frag (std::span<const uint32_t>)
# and passes vkrc_shaders::foo_frag to ShaderModule::create.
# Included by vkrc's own build and by the installed package's vkrcConfig.cmake
# (next to VkrcShaderWrap.cmake in both). glslangValidator (Debian:
# glslang-tools) is needed only when vkrc_add_shaders is called.
find_program(GLSLANG_VALIDATOR glslangValidator)

function(vkrc_add_shaders target)
  if(NOT GLSLANG_VALIDATOR)
    message(FATAL_ERROR "vkrc_add_shaders needs glslangValidator (Debian: glslang-tools), which was not found")
  endif()
  set(wrap_script "${CMAKE_CURRENT_FUNCTION_LIST_DIR}/VkrcShaderWrap.cmake")
  set(out_root "${CMAKE_CURRENT_BINARY_DIR}/${target}_shaders")
  foreach(shader IN LISTS ARGN)
    get_filename_component(abs "${shader}" ABSOLUTE)
    get_filename_component(file "${shader}" NAME)
    string(MAKE_C_IDENTIFIER "${file}" symbol)
    set(header "${out_root}/shaders/${file}.h")
    add_custom_command(
      OUTPUT "${header}"
      COMMAND ${CMAKE_COMMAND} -E make_directory "${out_root}/shaders"
      COMMAND ${GLSLANG_VALIDATOR} --target-env vulkan1.3 --quiet
              --vn "${symbol}_words" -o "${header}.raw" "${abs}"
      COMMAND ${CMAKE_COMMAND} -DRAW=${header}.raw -DOUT=${header} -DSYMBOL=${symbol}
              -P "${wrap_script}"
      DEPENDS "${abs}" "${wrap_script}"
      COMMENT "glslangValidator ${file}"
      VERBATIM)
    list(APPEND headers "${header}")
  endforeach()
  target_sources(${target} PRIVATE ${headers})
  target_include_directories(${target} PRIVATE "${out_root}")
endfunction()
