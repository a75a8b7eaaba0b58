# Wraps glslangValidator's --vn output (a bare uint32_t array) in a namespace
# with a std::span view, so that several shaders can be included together.
file(READ "${RAW}" words)
string(REPLACE "#pragma once" "" words "${words}")
string(REGEX REPLACE "const uint32_t ${SYMBOL}_words\\[\\]" "inline constexpr std::uint32_t ${SYMBOL}_words[]" words "${words}")
file(WRITE "${OUT}" "// Generated from GLSL by glslangValidator; do not edit.\n#pragma once\n#include <cstdint>\n#include <span>\nnamespace vkrc_shaders {\n${words}\ninline constexpr std::span<const std::uint32_t> ${SYMBOL}{${SYMBOL}_words};\n}\n")
