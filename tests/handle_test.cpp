// The reference-counting core, independent of Vulkan.
#include <vkrc/error.hpp>
#include <vkrc/handle.hpp>
#include <vkrc/detail/list.hpp>
#include <vkrc/detail/object_registry.hpp>
#include <vkrc/detail/span.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <span>
#include <thread>
#include <type_traits>
#include <vector>

namespace {

int destroyed = 0;

struct Counted final : vkrc::detail::RefCounted {
    ~Counted() override { ++destroyed; }
};

class Thing : public vkrc::Handle<Counted> {
public:
    Thing() = default;
    static Thing make() { return Thing(vkrc::detail::Ref<Counted>(new Counted)); }

private:
    using Handle::Handle;
};

TEST(Handle, CopySharesAndLastOwnerDestroys) {
    destroyed = 0;
    Thing a = Thing::make();
    EXPECT_EQ(a.use_count(), 1u);
    {
        Thing b = a;
        EXPECT_EQ(a.use_count(), 2u);
        EXPECT_TRUE(a == b);
    }
    EXPECT_EQ(a.use_count(), 1u);
    EXPECT_EQ(destroyed, 0);
    a.reset();
    EXPECT_EQ(destroyed, 1);
    EXPECT_FALSE(a);
}

TEST(Handle, MoveTransfersWithoutCounting) {
    destroyed = 0;
    Thing a = Thing::make();
    Thing b = std::move(a);
    EXPECT_FALSE(a);  // NOLINT(bugprone-use-after-move): moved-from is empty by contract
    EXPECT_EQ(b.use_count(), 1u);
    Thing c;
    c = std::move(b);
    EXPECT_EQ(c.use_count(), 1u);
    EXPECT_EQ(destroyed, 0);
    c = Thing();
    EXPECT_EQ(destroyed, 1);
}

TEST(Handle, SelfAssignmentKeepsTheObject) {
    destroyed = 0;
    Thing a = Thing::make();
    Thing& alias = a;
    a = alias;
    EXPECT_EQ(a.use_count(), 1u);
    a = std::move(alias);
    EXPECT_TRUE(a);
    EXPECT_EQ(a.use_count(), 1u);
    EXPECT_EQ(destroyed, 0);
}

TEST(Handle, AssignmentReleasesThePreviousObject) {
    destroyed = 0;
    Thing a = Thing::make();
    Thing b = Thing::make();
    a = b;
    EXPECT_EQ(destroyed, 1);
    EXPECT_EQ(b.use_count(), 2u);
}

// Both policies' counters are compiled into every build, so each is tested
// directly whichever policy the library under test uses.
template <class Policy>
void count_up_and_down() {
    typename Policy::Count c{1};
    Policy::increment(c);
    EXPECT_EQ(Policy::load(c), 2u);
    EXPECT_FALSE(Policy::decrement(c));
    EXPECT_TRUE(Policy::decrement(c));
}

TEST(Policy, SingleThreadCounts) { count_up_and_down<vkrc::SingleThreadPolicy>(); }
TEST(Policy, MultiThreadCounts) { count_up_and_down<vkrc::MultiThreadPolicy>(); }

TEST(Policy, MatchesTheBuild) {
#if VKRC_IS_MULTI_THREAD
    EXPECT_TRUE(vkrc::ThreadPolicy::multi_thread);
    EXPECT_FALSE((std::is_same_v<vkrc::Mutex, vkrc::SingleThreadPolicy::Mutex>));
#else
    EXPECT_FALSE(vkrc::ThreadPolicy::multi_thread);
    EXPECT_TRUE((std::is_same_v<vkrc::Mutex, vkrc::SingleThreadPolicy::Mutex>));
#endif
}

#if VKRC_IS_MULTI_THREAD
TEST(Handle, SixteenThreadsCopyAndDrop) {
    destroyed = 0;
    Thing shared = Thing::make();
    std::vector<std::thread> threads;
    for (int t = 0; t < 16; ++t) {
        threads.emplace_back([&shared] {
            for (int i = 0; i < 20000; ++i) {
                Thing copy = shared;
                Thing moved = std::move(copy);
                moved.reset();
            }
        });
    }
    for (auto& t : threads) t.join();
    EXPECT_EQ(shared.use_count(), 1u);
    EXPECT_EQ(destroyed, 0);
    shared.reset();
    EXPECT_EQ(destroyed, 1);
}
#endif

// vkrc::Span views what std::span views, and no more: an array of a derived
// type is not an array of its base, and const elements are not writable ones.
struct Base {
    int x = 0;
};
struct Derived : Base {
    int y = 0;
};
static_assert(std::is_convertible_v<std::vector<int>&, vkrc::Span<const int>>);
static_assert(std::is_convertible_v<std::span<int>, vkrc::Span<const int>>);
static_assert(std::is_convertible_v<vkrc::Span<int>, vkrc::Span<const int>>);
static_assert(!std::is_convertible_v<vkrc::Span<const int>, vkrc::Span<int>>);
static_assert(!std::is_convertible_v<const std::vector<int>&, vkrc::Span<int>>);
static_assert(!std::is_convertible_v<std::vector<Derived>&, vkrc::Span<const Base>>);
static_assert(!std::is_convertible_v<std::vector<unsigned>&, vkrc::Span<const int>>);
static_assert(!std::is_constructible_v<vkrc::List<Base>, const std::vector<Derived>&>);  // List copies by the same rule

int sum(vkrc::Span<const int> values) {
    int total = 0;
    for (int v : values) total += v;
    return total;
}

TEST(Span, TakesEveryContiguousRange) {
    std::vector<int> vector{1, 2, 3};
    const std::array<int, 2> array{4, 5};
    int c_array[] = {6, 7};
    vkrc::List<int> list{8, 9};
    EXPECT_EQ(sum(vector), 6);
    EXPECT_EQ(sum(array), 9);
    EXPECT_EQ(sum(c_array), 13);
    EXPECT_EQ(sum(list), 17);
    EXPECT_EQ(sum(std::span(vector).subspan(1, 2)), 5);
    EXPECT_EQ(sum({vector.data(), 2}), 3);
    EXPECT_EQ(sum({}), 0);
    const vkrc::Span view(vector);
    EXPECT_EQ(view.size_bytes(), 3 * sizeof(int));
    EXPECT_EQ(view.back(), 3);
    EXPECT_EQ(view.subspan(1, 1).front(), 2);
    const std::span<const int> back = view;  // a std::span takes it back
    EXPECT_EQ(back.size(), 3u);
}

// Raw<VkX> takes a raw handle, or any wrapper whose vk() returns one.
struct FakeBuffer {
    VkBuffer vk() const { return reinterpret_cast<VkBuffer>(std::uintptr_t{0x1000}); }
};
static_assert(std::is_convertible_v<VkBuffer, vkrc::Raw<VkBuffer>>);
static_assert(std::is_convertible_v<const FakeBuffer&, vkrc::Raw<VkBuffer>>);
static_assert(!std::is_convertible_v<const FakeBuffer&, vkrc::Raw<VkImage>>);

TEST(Raw, ReadsTheWrappersHandle) {
    const vkrc::Raw<VkBuffer> from_wrapper = FakeBuffer{};
    const vkrc::Raw<VkBuffer> from_raw = VK_NULL_HANDLE;
    EXPECT_EQ(static_cast<VkBuffer>(from_wrapper), FakeBuffer{}.vk());
    EXPECT_EQ(*from_wrapper.get(), FakeBuffer{}.vk());
    EXPECT_EQ(static_cast<VkBuffer>(from_raw), VK_NULL_HANDLE);
}

// A wrapper of a Vulkan object keeps a copy of the raw handle: copies carry
// it, a move or reset() empties the source, copy included.
struct FakeObjectState final : vkrc::detail::VulkanObjectState<VkBuffer> {
    static constexpr const char* type_name = "FakeObject";
};
class FakeObject : public vkrc::VulkanObject<FakeObjectState, VkBuffer> {
public:
    FakeObject() = default;
    static FakeObject make(std::uintptr_t raw) {
        vkrc::detail::Ref<FakeObjectState> s(new FakeObjectState);
        s->handle = reinterpret_cast<VkBuffer>(raw);
        return FakeObject(std::move(s));
    }

private:
    using VulkanObject::VulkanObject;
};

TEST(VulkanObject, CopiesCarryTheRawHandleAndMovesEmptyTheSource) {
    const VkBuffer raw_a = reinterpret_cast<VkBuffer>(std::uintptr_t{0x10});
    const VkBuffer raw_b = reinterpret_cast<VkBuffer>(std::uintptr_t{0x20});
    FakeObject a = FakeObject::make(0x10);
    FakeObject copy = a;
    EXPECT_EQ(copy.vk(), raw_a);
    FakeObject moved = std::move(copy);
    EXPECT_FALSE(copy);  // NOLINT(bugprone-use-after-move): the moved-from state is what is tested
    EXPECT_EQ(moved.vk(), raw_a);
    moved = FakeObject::make(0x20);  // move-assigned: the old object's count goes, the new handle comes
    EXPECT_EQ(moved.vk(), raw_b);
    EXPECT_EQ(a.use_count(), 1u);
    moved = a;
    EXPECT_EQ(moved.vk(), raw_a);
    FakeObject& alias = moved;
    moved = std::move(alias);  // self-move keeps the object and its handle
    EXPECT_EQ(moved.vk(), raw_a);
    moved.reset();
    EXPECT_FALSE(moved);
#if VKRC_RUNTIME_CHECKS
    EXPECT_THROW(moved.vk(), vkrc::UsageError);
    a.state()->handle = raw_b;  // what no vkrc code does once a wrapper exists
    EXPECT_THROW(a.vk(), vkrc::UsageError) << "checked builds compare the copy with the state's handle";
#endif
}

// The multi-thread policy's futex mutex under contention (both builds
// compile it): every increment made under it survives, so the waiters that
// went to the kernel were woken and excluded.
TEST(Policy, MultiThreadMutexExcludesUnderContention) {
    vkrc::MultiThreadPolicy::Mutex mutex;
    std::uint64_t count = 0;
    constexpr int threads = 8, rounds = 20000;
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t) {
        workers.emplace_back([&] {
            for (int i = 0; i < rounds; ++i) {
                vkrc::LockGuard<vkrc::MultiThreadPolicy::Mutex> lock(mutex);
                ++count;
            }
        });
    }
    for (auto& w : workers) w.join();
    EXPECT_EQ(count, std::uint64_t{threads} * rounds);
    EXPECT_TRUE(mutex.try_lock());
    EXPECT_FALSE(mutex.try_lock());
    mutex.unlock();
}

}  // namespace

// The descriptor-reference registry's table through collisions, growth and
// removals in any order: every live handle finds its object, no removed one
// does; a remove naming another object (a later adoption of the same handle
// replaced it) leaves the entry.
TEST(ObjectRegistry, FindsEveryLiveHandleThroughCollisionsGrowthAndRemovals) {
    using vkrc::detail::DescribedKind;
    vkrc::detail::ObjectRegistry registry;
    std::vector<vkrc::detail::Ref<Counted>> objects;
    std::vector<std::uint64_t> bits;
    for (std::uint64_t i = 1; i <= 3000; ++i) {
        objects.emplace_back(new Counted);
        // Aligned pointers and dispatchable-style handles: alike in most bits.
        bits.push_back(i % 2 ? 0x7f0000000000ull + i * 64 : i << 32);
        registry.add(DescribedKind::buffer, bits.back(), objects.back().get());
    }
    std::vector<std::size_t> order(objects.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    std::vector<bool> live(objects.size(), true);
    for (std::size_t k = 0; k < order.size() / 2; ++k) {
        const std::size_t i = order[k];
        registry.remove(DescribedKind::buffer, bits[i], objects[(i + 1) % objects.size()].get());  // not its object
        registry.remove(DescribedKind::buffer, bits[i], objects[i].get());
        live[i] = false;
    }
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const auto found = registry.find(DescribedKind::buffer, bits[i]);
        EXPECT_EQ(found.get(), live[i] ? objects[i].get() : nullptr) << "handle " << i;
        EXPECT_FALSE(registry.find(DescribedKind::image_view, bits[i])) << "another kind's table";
    }
    registry.add(DescribedKind::buffer, bits[order[0]], objects[0].get());  // re-added after its removal
    EXPECT_EQ(registry.find(DescribedKind::buffer, bits[order[0]]).get(), objects[0].get());
}
