// MultiThreadPolicy's lock slow paths: the futex calls and the spin (vkrc/handle.hpp).
#include "vkrc/handle.hpp"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

VKRC_BEGIN_NAMESPACE

namespace detail {

namespace {
static_assert(sizeof(Atomic<std::uint32_t>) == sizeof(std::uint32_t), "the futex word is the Atomic itself");

long futex(Atomic<std::uint32_t>& state, int op, std::uint32_t value) noexcept {
    // The word is the Atomic's only member.
    return syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&state), op, value, nullptr, nullptr, 0);
}
}  // namespace

void futex_lock_contended(Atomic<std::uint32_t>& state, std::uint32_t seen) noexcept {
    // Marks the mutex contended, so that its unlock wakes a waiter; sleeps
    // while it stays locked. Leaves it contended when taken: a waiter may remain.
    if (seen != 2) seen = state.exchange(2, __ATOMIC_ACQUIRE);
    while (seen != 0) {
        futex(state, FUTEX_WAIT_PRIVATE, 2);  // returns at once unless the word still reads 2
        seen = state.exchange(2, __ATOMIC_ACQUIRE);
    }
}

void futex_wake_one(Atomic<std::uint32_t>& state) noexcept { futex(state, FUTEX_WAKE_PRIVATE, 1); }

void spin_lock_contended(Atomic<bool>& locked) noexcept {
    do {
        // Reads until free, so waiters do not bounce the line with exchanges.
        while (locked.load(__ATOMIC_RELAXED)) {
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();
#endif
        }
    } while (locked.exchange(true, __ATOMIC_ACQUIRE));
}

}  // namespace detail

VKRC_END_NAMESPACE
