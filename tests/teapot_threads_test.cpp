// The teapot benchmark's threaded command stage (issue 17): the harness's
// ThreadPool, and the vkrc-mt variant recording its draws on several threads
// into secondaries (bench/teapot/variants/vkrc.cpp, the benchmark's own
// code). Labelled mt, so scripts/test.sh also runs it under ThreadSanitizer.
#include "harness/thread_pool.hpp"
#include "harness/variant.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace teapot {
std::unique_ptr<Variant> make_vkrc_mt_variant();
}

namespace {

using teapot::ThreadPool;

TEST(TeapotThreadPool, RunsEveryIndexOnceAndTheFirstOnTheCaller) {
    ThreadPool pool(4);
    std::vector<std::atomic<int>> calls(4);
    std::thread::id first;
    for (int round = 0; round < 200; ++round) {
        auto job = [&](int i) {
            calls[std::size_t(i)].fetch_add(1);
            if (i == 0) first = std::this_thread::get_id();
        };
        pool.run(job);
    }
    for (const std::atomic<int>& c : calls) EXPECT_EQ(c.load(), 200);
    EXPECT_EQ(first, std::this_thread::get_id());
}

TEST(TeapotThreadPool, RethrowsAWorkersExceptionAndKeepsWorking) {
    ThreadPool pool(3);
    auto failing = [](int i) {
        if (i == 2) throw std::runtime_error("worker 2");
    };
    EXPECT_THROW(pool.run(failing), std::runtime_error);
    int sum = 0;
    std::vector<int> seen(3);
    auto job = [&](int i) { seen[std::size_t(i)] = i + 1; };
    pool.run(job);
    for (int s : seen) sum += s;
    EXPECT_EQ(sum, 6);
}

TEST(TeapotThreadPool, SplitsDrawsEvenlyInOrder) {
    std::size_t next = 0;
    for (int i = 0; i < 7; ++i) {
        const teapot::DrawRange r = teapot::draw_range(i, 7, 25);
        EXPECT_EQ(r.first, next);
        EXPECT_GE(r.last - r.first, 3u);
        EXPECT_LE(r.last - r.first, 4u);
        next = r.last;
    }
    EXPECT_EQ(next, 25u);
}

// Frames through the stages, as the harness's timed loop runs them.
void run_frames(teapot::Variant& variant, int frames, double& t) {
    for (int f = 0; f < frames; ++f) {
        variant.acquire();
        variant.uniform();
        variant.command();
        variant.submit();
        variant.present();
        variant.wait();
        variant.update(t += 1.0 / 60.0);
    }
}

// The benchmark's vkrc-mt variant with 4 recording threads renders what it
// renders with one, frame after frame, under validation.
TEST(TeapotThreads, VkrcMtOnFourThreadsRendersAsOnOne) {
    teapot::Config config;
    config.teapots = 30;
    config.tessellation = 2;
    config.width = 96;
    config.height = 64;
    config.validation = true;
    const teapot::Mesh mesh = teapot::tessellate(teapot::newell_teapot(), config.tessellation);
    ThreadPool recorders(4);
    const teapot::SceneData scene{&mesh, teapot::camera(config.teapots, config.width, config.height), &recorders};
    teapot::Config threaded = config;
    threaded.threads = recorders.size();
    const int before = teapot::validation_messages.load();

    std::vector<std::uint8_t> images[2];
    for (int v = 0; v < 2; ++v) {
        std::unique_ptr<teapot::Variant> variant = teapot::make_vkrc_mt_variant();
        variant->init(v ? threaded : config, scene);
        double t = 0;
        variant->update(t);
        run_frames(*variant, 12, t);
        variant->drain();
        images[v] = variant->read_back_last_frame(t);
        EXPECT_EQ(images[v].size(), std::size_t(config.width) * config.height * 4);
    }
    EXPECT_TRUE(images[0] == images[1]) << "4 recording threads rendered a different image";
    EXPECT_EQ(teapot::validation_messages.load(), before);
}

}  // namespace
