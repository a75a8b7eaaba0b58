// std::function for vkrc's headers, without the rest of <functional>.
//
// Every translation unit that uses vkrc parses its headers, so their cost is
// paid everywhere. libstdc++ defines std::function in an internal header of
// its own; <functional> adds searchers, hash maps and std::bind (about 0.1 s
// per translation unit with g++ 12, bench/header_cost). Other standard
// libraries get the standard header. (vkrc's mutex and lock guard are its own,
// in handle.hpp: libstdc++'s std::mutex header brings in <system_error> and
// <string>.)
#pragma once

#include <version>  // defines __GLIBCXX__ for libstdc++, and little else

#if defined(__GLIBCXX__) && __has_include(<bits/std_function.h>)
#  include <bits/std_function.h>
#else
#  include <functional>
#endif
