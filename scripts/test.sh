#!/usr/bin/env bash
# Checks the formatting, builds vkrc and runs every test: both thread policies
# under the validation layer, with GCC and with clang, the instruction budget
# of the teapot benchmark (optimised build, callgrind), then the whole suite
# under AddressSanitizer+UndefinedBehaviorSanitizer and the multi-thread tests
# under ThreadSanitizer. Installs missing Debian packages first.
# Usage: scripts/test.sh [--quick]   (--quick: no sanitizers)
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh

jobs=$(nproc)
# lavapipe needs a writable runtime directory.
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d /tmp/vkrc-xdg.XXXXXX)}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# The Vulkan driver, loader and layer are not built with sanitizers; their own
# leaks and races are theirs, suppressed by library name only.
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"
export TSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/tsan.supp:halt_on_error=1:second_deadlock_stack=1"

run_config() {  # name, ctest args, cmake args...
    local name=$1 ctest_args=$2
    shift 2
    echo "=== $name"
    cmake -S . -B "build-$name" -DCMAKE_BUILD_TYPE=Debug "$@" >/dev/null
    cmake --build "build-$name" -j "$jobs"
    (cd "build-$name" && ctest --output-on-failure -j "$jobs" $ctest_args)
}

echo "=== format"
bash scripts/format.sh --check
run_config test "" -DVKRC_BUILD_BENCH=ON -DVKRC_BUILD_EXAMPLES=ON
# clang: the library, the tests (hot_path included) and the consumer tests;
# the benchmarks and examples are GCC's only, to keep CI time down.
run_config clang "" -DCMAKE_CXX_COMPILER=clang++ -DVKRC_BUILD_BENCH=OFF -DVKRC_BUILD_EXAMPLES=OFF
# The instruction budget (issue 12): callgrind counts of an optimised teapot
# benchmark against raw-direct; only that target is built.
echo "=== budget"
cmake -S . -B build-budget -DCMAKE_BUILD_TYPE=Release -DVKRC_BUILD_BENCH=ON -DVKRC_BUILD_EXAMPLES=OFF \
    -DVKRC_INSTRUCTION_BUDGET=ON >/dev/null
cmake --build build-budget -j "$jobs" --target teapot
(cd build-budget && ctest --output-on-failure -L instructions)
if [ "${1:-}" != "--quick" ]; then
    san="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
    run_config asan "" -DVKRC_BUILD_BENCH=OFF -DVKRC_BUILD_EXAMPLES=OFF \
        -DCMAKE_CXX_FLAGS="$san" -DCMAKE_EXE_LINKER_FLAGS="$san"
    run_config tsan "-L mt" -DVKRC_POLICIES=mt -DVKRC_BUILD_BENCH=OFF -DVKRC_BUILD_EXAMPLES=OFF \
        -DCMAKE_CXX_FLAGS="-fsanitize=thread" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread"
fi
