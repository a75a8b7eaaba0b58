// Compile-time configuration: the thread policy and the namespace it selects.
//
// VKRC_MULTI_THREAD=1 selects the multi-thread policy (atomic reference
// counts, real locks where Vulkan demands external synchronisation); anything
// else the single-thread one. The CMake targets vkrc::st and vkrc::mt set it
// for their users. Each policy lives in its own inline namespace (vkrc::st or
// vkrc::mt) so both libraries can be linked into one program, while a
// translation unit compiled for one policy cannot link against the other.

// clang-format off
// (the preprocessor layout below is kept as written)
// Deliberately outside the include guard: a translation unit that includes
// vkrc headers, changes VKRC_MULTI_THREAD and includes them again would
// silently mix two object layouts, so it must not compile.
#if defined(VKRC_MULTI_THREAD) && VKRC_MULTI_THREAD
#  define VKRC_DETAIL_POLICY_NOW 2
#else
#  define VKRC_DETAIL_POLICY_NOW 1
#endif
#if defined(VKRC_DETAIL_POLICY_SEEN) && VKRC_DETAIL_POLICY_SEEN != VKRC_DETAIL_POLICY_NOW
#  error "vkrc: this translation unit includes vkrc under both thread policies (VKRC_MULTI_THREAD changed between includes); use one policy per translation unit"
#endif
#ifndef VKRC_DETAIL_POLICY_SEEN
#  if VKRC_DETAIL_POLICY_NOW == 2
#    define VKRC_DETAIL_POLICY_SEEN 2
#  else
#    define VKRC_DETAIL_POLICY_SEEN 1
#  endif
#endif
#undef VKRC_DETAIL_POLICY_NOW

#ifndef VKRC_CONFIG_HPP
#define VKRC_CONFIG_HPP

// VKRC_POLICY_NAMESPACE may be set to another name (e.g. -DVKRC_POLICY_NAMESPACE=
// st_checked) to link a second copy of vkrc, built with other options, into
// the same program; the library and its users must agree on it.
#if VKRC_DETAIL_POLICY_SEEN == 2
#  ifndef VKRC_POLICY_NAMESPACE
#    define VKRC_POLICY_NAMESPACE mt
#  endif
#  define VKRC_IS_MULTI_THREAD 1
#else
#  ifndef VKRC_POLICY_NAMESPACE
#    define VKRC_POLICY_NAMESPACE st
#  endif
#  define VKRC_IS_MULTI_THREAD 0
#endif

// Hot-path checks that cost time (bounds of mapped writes, device identity of
// recorded handles) are compiled in when VKRC_RUNTIME_CHECKS is 1: on by
// default in debug builds, off with NDEBUG. Checks that are free stay on.
#ifndef VKRC_RUNTIME_CHECKS
#  ifdef NDEBUG
#    define VKRC_RUNTIME_CHECKS 0
#  else
#    define VKRC_RUNTIME_CHECKS 1
#  endif
#endif

#define VKRC_BEGIN_NAMESPACE namespace vkrc { inline namespace VKRC_POLICY_NAMESPACE {
#define VKRC_END_NAMESPACE } }

// A policy mismatch at link time names the missing define: every translation
// unit that includes vkrc references a symbol that only the library of its
// policy defines (src/error.cpp), so linking libvkrc_mt into code compiled
// without -DVKRC_MULTI_THREAD=1 fails with, among vkrc::st:: symbols,
//   undefined reference to `vkrc_st_library_missing__code_compiled_without_VKRC_MULTI_THREAD_1__link_libvkrc_st_or_define_VKRC_MULTI_THREAD_1'
// (and the reverse for libvkrc_st under -DVKRC_MULTI_THREAD=1). The vkrc::st
// and vkrc::mt CMake targets set the define; this is for builds without them.
#define VKRC_DETAIL_CAT3(a, b, c) a##b##c
#define VKRC_DETAIL_EXPAND_CAT3(a, b, c) VKRC_DETAIL_CAT3(a, b, c)
#if VKRC_IS_MULTI_THREAD
#  define VKRC_DETAIL_POLICY_SYMBOL VKRC_DETAIL_EXPAND_CAT3(vkrc_, VKRC_POLICY_NAMESPACE, \
      _library_missing__code_compiled_with_VKRC_MULTI_THREAD_1__link_libvkrc_mt_or_remove_the_define)
#else
#  define VKRC_DETAIL_POLICY_SYMBOL VKRC_DETAIL_EXPAND_CAT3(vkrc_, VKRC_POLICY_NAMESPACE, \
      _library_missing__code_compiled_without_VKRC_MULTI_THREAD_1__link_libvkrc_st_or_define_VKRC_MULTI_THREAD_1)
#endif
extern "C" const char VKRC_DETAIL_POLICY_SYMBOL;
namespace vkrc::detail_policy_check {
// One pointer per translation unit, kept (used) so the reference stays.
[[gnu::used]] static const char* const policy_symbol = &VKRC_DETAIL_POLICY_SYMBOL;
}

#endif
// clang-format on
