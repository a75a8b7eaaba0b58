// The reference-counting core, independent of Vulkan.
#include <vkrc/handle.hpp>

#include <gtest/gtest.h>

#include <thread>
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

}  // namespace
