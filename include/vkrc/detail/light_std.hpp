// std::function, std::mutex and std::lock_guard for vkrc's headers, without
// the rest of <functional> and <mutex>.
//
// Every translation unit that uses vkrc parses its headers, so their cost is
// paid everywhere. libstdc++ defines these three in internal headers of their
// own; <functional> adds searchers, hash maps and std::bind, <mutex> adds
// <chrono>, timed mutexes and call_once: together about 0.15 s per
// translation unit with g++ 12 (bench/header_cost). Other standard libraries
// get the standard headers.
#pragma once

#include <version>  // defines __GLIBCXX__ for libstdc++, and little else

#if defined(__GLIBCXX__) && __has_include(<bits/std_function.h>) && __has_include(<bits/std_mutex.h>)
#  include <bits/std_function.h>
#  include <bits/std_mutex.h>
#else
#  include <functional>
#  include <mutex>
#endif
