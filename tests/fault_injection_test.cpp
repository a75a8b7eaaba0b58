// For every failable Vulkan call a scenario makes, run it again with that
// call failing: it must end in vkrc::Error carrying the injected result
// (DeviceLostError for VK_ERROR_DEVICE_LOST), or carry on where vkrc absorbs
// the failure by design (only as docs/reliability.md lists, and with the
// reference result), never crash or hang, and leave nothing behind: the
// validation layer's object tracker reports leaked Vulkan objects at
// vkDestroyInstance, LeakSanitizer reports host memory in the ASan build.
// The scenarios: the teapot scene (tests/support/teapot_scenario.cpp), the
// descriptor references and bindless table below, and compute, render pass,
// streaming, non-coherent memory, acceleration structures, a ray tracing
// pipeline and presentation (under a private Xvfb;
// tests/support/fault_scenarios.cpp). A report checks that together they
// reach every failable function vkrc calls. The same over a user allocator
// that fails at each of its allocations.
#include "support/fault_injection.hpp"
#include "support/fault_scenarios.hpp"
#include "support/features.hpp"
#include "support/teapot_scenario.hpp"
#include "support/vk_test.hpp"
#include "support/watchdog.hpp"
#include "support/wrapped_allocator.hpp"
#include "support/xvfb.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>

namespace {

namespace faults = vkrc_test::faults;

constexpr std::array<VkResult, 4> injected_errors{VK_ERROR_OUT_OF_HOST_MEMORY, VK_ERROR_OUT_OF_DEVICE_MEMORY,
                                                  VK_ERROR_INITIALIZATION_FAILED, VK_ERROR_DEVICE_LOST};

vkrc::InstanceCreateInfo injected_instance_info(const std::shared_ptr<vkrc_test::ValidationLog>& log) {
    auto info = vkrc_test::validated_instance_info(log);
    info.get_instance_proc_addr = faults::get_instance_proc_addr();
    return info;
}

// A device of the test's default requirements on an injected instance (the
// device keeps the instance alive).
vkrc::Device injected_device(const std::shared_ptr<vkrc_test::ValidationLog>& log) {
    auto instance = vkrc::Instance::create(injected_instance_info(log));
    return vkrc::Device::create(vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements()));
}

// Each of the four errors at every call (12 s in Debug, 19 s under ASan on
// the 2-core CI machine); under ThreadSanitizer, slower still, call
// k gets injected_errors[k % 4] so that every call is still covered once.
// VKRC_FAULT_ALL_ERRORS=0/1 overrides.
// The scene's frame: the teapots cover the centre and leave the corners to
// the black background, and a plausible share of the pixels (on lavapipe
// and NVIDIA about a quarter; a blank or a cleared-to-colour frame fails).
::testing::AssertionResult frame_is_the_scene(const std::vector<std::array<std::uint8_t, 4>>& frame) {
    constexpr std::size_t side = 64;
    if (frame.size() != side * side) return ::testing::AssertionFailure() << frame.size() << " pixels";
    const auto covered = vkrc_test::covered_pixels(frame);
    if (covered < frame.size() / 10 || covered > frame.size() / 2) {
        return ::testing::AssertionFailure() << covered << " of " << frame.size() << " pixels covered";
    }
    for (std::size_t corner : {std::size_t{0}, side - 1, side * (side - 1), side * side - 1}) {
        if (vkrc_test::covered_pixels({frame[corner]}) != 0) {
            return ::testing::AssertionFailure() << "corner pixel " << corner << " is not background";
        }
    }
    return ::testing::AssertionSuccess();
}

std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// The functions of the table vkrc's sources call: every vkX read as a member
// (fn.vkX(...), fn().vkX, ->vkX) or named as one (&DeviceFunctions::vkX).
std::set<std::string> functions_vkrc_calls() {
    std::set<std::string> out;
    const std::filesystem::path root = VKRC_SOURCE_DIR;
    for (const char* dir : {"src", "include/vkrc"}) {
        for (const auto& entry : std::filesystem::recursive_directory_iterator(root / dir)) {
            if (!entry.is_regular_file()) continue;
            const std::string text = read_text(entry.path());
            for (std::size_t at = text.find("vk"); at != std::string::npos; at = text.find("vk", at + 2)) {
                if (at == 0 || !std::strchr(".>:", text[at - 1]) || !std::isupper(text[at + 2])) continue;
                std::size_t end = at + 2;
                while (end < text.size() && (std::isalnum(text[end]) || text[end] == '_')) ++end;
                // An assignment (a table slot cleared) is no call.
                const std::size_t next = text.find_first_not_of(' ', end);
                if (next != std::string::npos && text[next] == '=' && text[next + 1] != '=') continue;
                out.insert(text.substr(at, end - at));
            }
        }
    }
    return out;
}

// The functions docs/reliability.md lists under "Failures vkrc absorbs by
// design": every `vkX` from that line to the end of its bullet list.
std::set<std::string> documented_absorptions() {
    const std::string text = read_text(std::filesystem::path(VKRC_SOURCE_DIR) / "docs/reliability.md");
    const std::size_t begin = text.find("Failures vkrc absorbs by design");
    std::set<std::string> out;
    if (begin == std::string::npos) return out;
    const std::size_t first_bullet = text.find("\n- ", begin);
    std::size_t end = text.find("\n\n", first_bullet);
    if (end == std::string::npos) end = text.size();
    for (std::size_t at = text.find("`vk", begin); at < end; at = text.find("`vk", at + 1)) {
        const std::size_t close = text.find('`', at + 1);
        out.insert(text.substr(at + 1, close - at - 1));
    }
    return out;
}

bool all_errors() {
    if (const char* v = std::getenv("VKRC_FAULT_ALL_ERRORS")) return *v && *v != '0';
#if defined(__SANITIZE_THREAD__)
    return false;
#else
    return true;
#endif
}

// The errors injected into call k: all four (per_call 4: the teapot and
// descriptor scenarios); device loss (vkrc's other way out) and one of the
// other three in turn (2: the scenarios that repeat the setup, injected after
// it); or one of the four in turn (1: presentation, whose frames repeat the
// same calls). Under ThreadSanitizer (all_errors() false) always one.
std::vector<VkResult> errors_at(std::uint64_t k, int per_call) {
    if (!all_errors() || per_call == 1) return {injected_errors[k % injected_errors.size()]};
    if (per_call == 4) return {injected_errors.begin(), injected_errors.end()};
    return {injected_errors[k % 3], VK_ERROR_DEVICE_LOST};
}

// Runs scenario once to count its failable calls and take its reference
// result (which plausible must accept), then once per call and error with
// that call failing (see the file comment): a run whose failure vkrc
// absorbed must give the reference result again.
template <class Scenario, class Plausible>
void inject_into_every_call(const char* what, const Scenario& scenario, const Plausible& plausible,
                            std::uint64_t min_points, int errors_per_call = 2) {
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    const auto info = injected_instance_info(log);
    faults::arm(0, VK_SUCCESS);
    const auto start = std::chrono::steady_clock::now();
    // The reference frame: a run vkrc absorbed a failure in must draw it again.
    faults::forget_called();
    const auto reference = scenario(info);
    const std::uint64_t points = faults::failable_calls();
    // Scenarios that mark the end of their setup are injected after it.
    const std::uint64_t setup = faults::setup_calls();
    const auto reference_calls = faults::called_functions(setup != 0);
    std::set<std::string> failed;  // the functions a failure was injected into
    EXPECT_TRUE(plausible(reference)) << what << ": the scenario did not run";
    vkrc_test::expect_no_validation_messages(*log);
    ASSERT_GT(points - setup, min_points) << "the wrapper does not see vkrc's calls";

    std::uint64_t runs = 0, thrown = 0, not_reached = 0;
    std::map<std::string, int> absorbed;  // calls whose failure vkrc handled without throwing
    // VKRC_FAULT_FIRST=k starts at call k and prints each run (to find a hang).
    const char* first = std::getenv("VKRC_FAULT_FIRST");
    // One run with the failure armed by arm(), described by where.
    auto run_once = [&](const std::string& where, VkResult error, const std::function<void()>& arm) {
        ++runs;
        if (first) std::fprintf(stderr, "%s: %s\n", where.c_str(), vkrc::to_string(error));
        arm();
        try {
            const auto frame = scenario(info);
            absorbed[faults::fired_in() ? faults::fired_in() : "-"]++;
            EXPECT_TRUE(frame == reference) << "injecting " << vkrc::to_string(error) << " into " << where << " ("
                                            << faults::fired_in() << ") was absorbed, but the frame differs";
        } catch (const vkrc::Error& ex) {
            ++thrown;
            EXPECT_EQ(ex.result(), error) << where << " (" << faults::fired_in() << "): " << ex.what();
            if (error == VK_ERROR_DEVICE_LOST) {
                EXPECT_NE(dynamic_cast<const vkrc::DeviceLostError*>(&ex), nullptr) << ex.what();
            }
        } catch (const std::exception& ex) {
            ADD_FAILURE() << where << " (" << faults::fired_in() << "): unexpected exception " << ex.what();
        }
        if (faults::fired()) failed.insert(faults::fired_in());
        auto messages = log->take();
        EXPECT_TRUE(messages.empty()) << "injecting " << vkrc::to_string(error) << " into " << where << " ("
                                      << faults::fired_in() << "): " << messages.size()
                                      << " validation message(s), first: " << messages.front();
    };
    for (std::uint64_t k = first ? std::strtoull(first, nullptr, 10) : setup + 1; k <= points; ++k) {
        for (const VkResult error : errors_at(k, errors_per_call)) {
            run_once("call " + std::to_string(k), error, [&] { faults::arm(k, error); });
            // How often vkrc polls its queue timelines (vkGetSemaphoreCounterValue)
            // depends on how far the GPU got, so a run may make fewer calls.
            if (!faults::fired()) {
                ++not_reached;
                EXPECT_LT(faults::failable_calls(), k) << "call " << k << " was made but the failure not returned";
            }
        }
    }
    // Fewer polls move the calls after them forward: a function whose calls
    // all came late (the teardown's vkDeviceWaitIdle) may have been passed
    // over. Its first call (after the setup) fails now.
    for (const auto& name : reference_calls) {
        if (failed.contains(name)) continue;
        for (const VkResult error : errors_at(0, errors_per_call)) {
            run_once("the first " + name, error, [&] { faults::arm_function(name.c_str(), error, setup != 0); });
        }
    }
    faults::arm(0, VK_SUCCESS);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf(
        "fault injection (%s): %llu injection points exercised (after %llu setup calls) in %llu runs (%.1f s), %llu "
        "ended in vkrc::Error, %llu not reached (fewer timeline polls)\n",
        what, static_cast<unsigned long long>(points - setup), static_cast<unsigned long long>(setup),
        static_cast<unsigned long long>(runs), seconds, static_cast<unsigned long long>(thrown),
        static_cast<unsigned long long>(not_reached));
    const auto documented = documented_absorptions();
    EXPECT_FALSE(documented.empty()) << "no absorbed failures found in docs/reliability.md";
    for (const auto& [name, count] : absorbed) {
        std::printf("  absorbed by vkrc: %s x%d\n", name.c_str(), count);
        if (name != "-") {
            EXPECT_TRUE(documented.contains(name))
                << what << ": vkrc absorbed a failure of " << name
                << ", which docs/reliability.md does not list under \"Failures vkrc absorbs by design\"";
        }
    }
    for (const auto& name : reference_calls) {
        EXPECT_TRUE(failed.contains(name)) << what << ": " << name << " was called but no failure injected into it";
    }
    EXPECT_GT(thrown, runs / 2);
}

TEST(FaultInjection, EveryFailableCallOfTheTeapotSceneFailsCleanly) {
    inject_into_every_call(
        "teapot scene", [](const vkrc::InstanceCreateInfo& info) { return vkrc_test::run_teapot_scenario(info); },
        frame_is_the_scene, 50, 4);
}

// Descriptor references and the bindless table (issue 30): a table made,
// filled and bound, a set written and dropped and its pool reset, with work
// in flight; every failable call on the way fails cleanly.
std::size_t run_descriptor_scenario(const vkrc::InstanceCreateInfo& info) {
    auto instance = vkrc::Instance::create(info);
    auto physical_device = vkrc::PhysicalDevice::select(instance, vkrc_test::test_device_requirements());
    vkrc::DeviceCreateInfo device_info;
    device_info.vulkan12_features.descriptorBindingPartiallyBound = VK_TRUE;
    device_info.vulkan12_features.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
    device_info.vulkan12_features.descriptorBindingStorageBufferUpdateAfterBind = VK_TRUE;
    device_info.vulkan12_features.descriptorBindingUpdateUnusedWhilePending = VK_TRUE;
    auto device = vkrc::Device::create(physical_device, device_info);
    auto queue = device.default_queue();
    auto table = vkrc::BindlessTable::create(device, {.image_capacity = 4, .buffer_capacity = 4});
    auto buffer = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    const auto first = table.add(buffer);
    auto layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}});
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}}});
    auto set = pool.allocate(layout);
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer);
    auto commands = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = commands.allocate();
    auto pipeline_layout = vkrc::PipelineLayout::create(device, {.set_layouts = {table.layout()}});
    cmd.begin();
    const VkDescriptorSet raw = table.set().vk();
    cmd.bind_descriptor_sets(VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout.vk(), 0, vkrc::Span(&raw, 1));
    cmd.end();
    auto fence = vkrc::Fence::create(device);
    vkrc::submit(queue, {.command_buffers = vkrc::Span(&cmd, 1)}, fence);
    table.remove(first);
    buffer.reset();
    set.reset();
    pool.reset_sets();
    const auto second =
        table.add(vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT}));
    if (fence.wait() != VK_SUCCESS) return 0;
    table.remove(second);
    device.wait_idle();
    return table.live_count(vkrc::BindlessKind::buffer) + 1;
}

TEST(FaultInjection, EveryFailableCallOfDescriptorReferencesAndTheBindlessTableFailsCleanly) {
    inject_into_every_call(
        "descriptors and bindless table", run_descriptor_scenario, [](std::size_t live) { return live > 0; }, 10, 4);
}

// A private display and a window for the presentation scenario.
struct Display {
    vkrc_test::Xvfb xvfb;
    std::optional<vkrc::glfw::Window> window;
    Display() {
        if (xvfb.running()) window = vkrc::glfw::Window::create({.width = 64, .height = 64, .title = "vkrc faults"});
    }
};

vkrc_test::ScenarioResult run_presentation(const vkrc::InstanceCreateInfo& info, const vkrc::glfw::Window& window) {
    auto with_glfw = info;
    for (const char* name : vkrc::glfw::required_instance_extensions())
        with_glfw.enabled_extension_names.push_back(name);
    return vkrc_test::run_presentation_scenario(with_glfw, window);
}

struct NamedScenario {
    const char* name;
    std::function<void(const vkrc::InstanceCreateInfo&)> run;
};

// Every scenario the tests below inject failures into.
std::vector<NamedScenario> every_scenario(const vkrc::glfw::Window& window) {
    return {{"teapot scene", [](const auto& info) { vkrc_test::run_teapot_scenario(info); }},
            {"descriptors and bindless table", run_descriptor_scenario},
            {"compute", vkrc_test::run_compute_scenario},
            {"render pass", vkrc_test::run_render_pass_scenario},
            {"streaming", vkrc_test::run_streaming_scenario},
            {"non-coherent memory", vkrc_test::run_non_coherent_scenario},
            {"acceleration structures", vkrc_test::run_acceleration_structure_scenario},
            {"ray tracing pipeline", vkrc_test::run_ray_tracing_pipeline_scenario},
            {"presentation", [&window](const auto& info) { run_presentation(info, window); }}};
}

// Samplers, buffer views, Y'CbCr, compute pipelines, pipeline caches, update
// templates, queries, events, private data, timeline semaphores.
TEST(FaultInjection, EveryFailableCallOfTheComputeScenarioFailsCleanly) {
    inject_into_every_call(
        "compute", vkrc_test::run_compute_scenario,
        [](const vkrc_test::ScenarioResult& r) {
            return r.size() == 73 && r[0] == 1 && r[2] == 1 && r[3] == 2 && r[4] == 0x5eed && r[68] == 1 &&
                   r[69] == 1 && r[70] == 1 && r[71] == 42 && r[72] == 43;
        },
        20);
}

TEST(FaultInjection, EveryFailableCallOfARenderPassAndFramebufferFailsCleanly) {
    inject_into_every_call(
        "render pass", vkrc_test::run_render_pass_scenario,
        [](const vkrc_test::ScenarioResult& r) {
            return r.size() == 16 && r[0] != 0 && std::ranges::count(r, r[0]) == 16;
        },
        10);
}

TEST(FaultInjection, EveryFailableCallOfTheUploaderAndFrameRingFailsCleanly) {
    inject_into_every_call(
        "streaming", vkrc_test::run_streaming_scenario,
        [](const vkrc_test::ScenarioResult& r) {
            const vkrc_test::ScenarioResult frames{1, 2, 3, 4, 2, 3, 4, 5, 3, 4, 5, 6};
            return r.size() == 44 && r[0] == 0x1000 && r[15] == 0x100f && r[16] == 0x1000 && r[31] == 0x100f &&
                   std::equal(frames.begin(), frames.end(), r.begin() + 32);
        },
        10);
}

TEST(FaultInjection, EveryFailableCallOnNonCoherentMemoryFailsCleanly) {
    inject_into_every_call(
        "non-coherent memory", vkrc_test::run_non_coherent_scenario,
        [](const vkrc_test::ScenarioResult& r) {
            return r == vkrc_test::ScenarioResult{0, 7, 11, 13, 17};
        },
        10);
}

// The traced 8x8: the two instances of the compacted square cover x < 8,
// y < 4 (custom 5 then 7), every other ray misses; then the compacted size.
::testing::AssertionResult traced_the_squares(const vkrc_test::ScenarioResult& r) {
    constexpr std::uint64_t side = 8, miss = 0xFFFFFFFFu;
    if (r.size() != side * side + 1) return ::testing::AssertionFailure() << r.size() << " values";
    for (std::uint64_t y = 0; y < side; ++y) {
        for (std::uint64_t x = 0; x < side; ++x) {
            const std::uint64_t want = y < 4 ? (x < 4 ? 5u : 7u) << 8 : miss;
            if (r[y * side + x] != want) {
                return ::testing::AssertionFailure() << "pixel (" << x << ", " << y << "): " << r[y * side + x];
            }
        }
    }
    if (r.back() == 0) return ::testing::AssertionFailure() << "compacted size 0";
    return ::testing::AssertionSuccess();
}

// Acceleration structures: builds, the compacted-size query, compaction, a
// descriptor write of the top level and a ray query trace.
TEST(FaultInjection, EveryFailableCallOfAccelerationStructuresFailsCleanly) {
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    if (!vkrc_test::device_has_ray_queries(vkrc_test::validated_instance_info(log))) {
        GTEST_SKIP() << "the device lacks acceleration structures or ray queries";
    }
    inject_into_every_call("acceleration structures", vkrc_test::run_acceleration_structure_scenario,
                           traced_the_squares, 20);
}

// The traced 16x4 (rt_scene's shaders, as tests/ray_tracing_test.cpp
// computes them): the square's pixels x < 4 hit (custom 5, geometry 0,
// primitive 0 below the diagonal y = x - 0.25), shadowed by the occluder in
// rows 2 and 3; every other ray misses; each with the callable's bits.
::testing::AssertionResult traced_the_ray_tracing_scene(const vkrc_test::ScenarioResult& r) {
    using namespace vkrc_test;
    if (r.size() != rt_width * rt_height) return ::testing::AssertionFailure() << r.size() << " values";
    for (std::uint32_t y = 0; y < rt_height; ++y) {
        for (std::uint32_t x = 0; x < rt_width; ++x) {
            const float lx = float(x) + 0.25f, ly = float(y) + 0.5f;
            const std::uint32_t primitive = ly < lx ? 0 : 1, shadowed = y >= 2 ? 1 : 0;
            const std::uint64_t want =
                (x < 4 ? rt_hit_tag << 28 | 5u << 20 | primitive << 8 | shadowed : rt_miss_value) | rt_callable_bits;
            if (r[y * rt_width + x] != want) {
                std::ostringstream text;  // AssertionResult takes each << apart, dropping std::hex
                text << "pixel (" << x << ", " << y << "): 0x" << std::hex << r[y * rt_width + x] << ", expected 0x"
                     << want;
                return ::testing::AssertionFailure() << text.str();
            }
        }
    }
    return ::testing::AssertionSuccess();
}

// A ray tracing pipeline: structure builds, shader modules, the pipeline,
// its shader binding table (the group handles read, its buffer written), a
// trace_rays read back.
TEST(FaultInjection, EveryFailableCallOfARayTracingPipelineFailsCleanly) {
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    if (!vkrc_test::device_has_ray_tracing_pipelines(vkrc_test::validated_instance_info(log))) {
        GTEST_SKIP() << "the device lacks ray tracing pipelines";
    }
    inject_into_every_call("ray tracing pipeline", vkrc_test::run_ray_tracing_pipeline_scenario,
                           traced_the_ray_tracing_scene, 20);
}

TEST(FaultInjection, EveryFailableCallOfPresentationFailsCleanly) {
    Display display;
    ASSERT_TRUE(display.window) << display.xvfb.error();
    inject_into_every_call(
        "presentation", [&](const auto& info) { return run_presentation(info, *display.window); },
        [](const vkrc_test::ScenarioResult& r) {
            // acquire and present of three frames, recreate, one more frame: all success.
            return r.size() == 11 && std::count(r.begin(), r.begin() + 9, 0u) == 9 && r[9] == 64 && r[10] == 64;
        },
        20, 1);
}

// The table's functions that return VkResult and that vkrc's sources call,
// but that no scenario above calls (so no failure is ever injected into
// them), with the reason each is acceptable. Any other fails the test below.
// vkCreateAccelerationStructureKHR is reached on a device with ray queries,
// the ray tracing pipeline's calls on one with ray tracing pipelines (lavapipe
// has both); elsewhere the scenario that calls them cannot run.
std::map<std::string, std::string> never_injected_allowed(const vkrc::InstanceCreateInfo& info) {
    std::map<std::string, std::string> allowed;
    if (!vkrc_test::device_has_ray_queries(info))
        allowed.emplace("vkCreateAccelerationStructureKHR", "the device lacks acceleration structures or ray queries");
    if (!vkrc_test::device_has_ray_tracing_pipelines(info)) {
        allowed.emplace("vkCreateRayTracingPipelinesKHR", "the device lacks ray tracing pipelines");
        allowed.emplace("vkGetRayTracingShaderGroupHandlesKHR", "the device lacks ray tracing pipelines");
    }
    return allowed;
}

// The report: every failable function vkrc calls is called by some scenario
// (and so, by the tests above, has a failure injected into it), or is on the
// short list above.
TEST(FaultInjection, EveryFailableFunctionVkrcCallsIsInjected) {
    Display display;
    ASSERT_TRUE(display.window) << display.xvfb.error();
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    const auto info = injected_instance_info(log);
    // What each scenario's test injects failures into: its calls after its
    // setup when it marks one, else all its calls.
    std::set<std::string> called;
    for (const auto& scenario : every_scenario(*display.window)) {
        faults::arm(0, VK_SUCCESS);
        faults::forget_called();
        scenario.run(info);
        for (auto& name : faults::called_functions(faults::setup_calls() != 0)) called.insert(std::move(name));
    }
    vkrc_test::expect_no_validation_messages(*log);

    const auto vkrc_calls = functions_vkrc_calls();
    std::size_t failable_called = 0;
    std::vector<std::string> never;
    for (const auto& name : faults::failable_functions()) {
        if (!vkrc_calls.contains(name)) continue;
        ++failable_called;
        if (!called.contains(name)) never.push_back(name);
    }
    EXPECT_GT(failable_called, 50u) << "the scan of src/ and include/vkrc/ found too few calls";
    std::printf("fault injection: %zu failable functions vkrc calls, %zu reached by the scenarios, %zu never:\n",
                failable_called, failable_called - never.size(), never.size());
    const auto allowed = never_injected_allowed(info);
    for (const auto& name : never) {
        const auto reason = allowed.find(name);
        std::printf("  %s: %s\n", name.c_str(), reason == allowed.end() ? "NOT ALLOWED" : reason->second.c_str());
        EXPECT_TRUE(reason != allowed.end()) << name << " is called by vkrc but no scenario calls it";
    }
    for (const auto& [name, reason] : allowed) {
        EXPECT_TRUE(std::ranges::find(never, name) != never.end())
            << name << " is on the allow-list but a scenario now reaches it (or vkrc no longer calls it)";
    }
}

// Frames on one device: an image cleared to a colour by dynamic rendering and
// copied to a readback buffer, all made once.
class ClearedFrames {
public:
    static constexpr std::uint32_t side = 16;

    explicit ClearedFrames(const vkrc::Queue& queue)
        : queue_(queue),
          image_(vkrc::Image::create(queue.device(),
                                     {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                      .extent = {side, side, 1},
                                      .usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT})),
          view_(vkrc::ImageView::create(image_)),
          readback_(vkrc::Buffer::create(queue.device(), {.size = side * side * 4,
                                                          .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                          .memory = {.usage = vkrc::MemoryUsage::readback}})),
          pool_(vkrc::CommandPool::create(queue.device(), {.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                                                           .queue_family_index = queue.family_index()})),
          cmd_(pool_.allocate()),
          fence_(vkrc::Fence::create(queue.device())) {}

    // Renders a frame cleared to rgba; whether every pixel read back is it.
    ::testing::AssertionResult render(std::array<std::uint8_t, 4> rgba) const {
        cmd_.reset_commands();
        cmd_.begin();
        const auto to_attachment =
            vkrc::image_barrier(image_.vk(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        cmd_.pipeline_barrier({}, {}, std::span(&to_attachment, 1));
        vkrc::RenderingAttachment target{.image_view = view_.vk()};
        for (int c = 0; c < 4; ++c) target.clear_value.color.float32[c] = float(rgba[c]) / 255.0f;
        cmd_.begin_rendering({.render_area = {{0, 0}, {side, side}}, .color_attachments = std::span(&target, 1)});
        cmd_.end_rendering();
        const auto to_copy = vkrc::image_barrier(
            image_.vk(), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        cmd_.pipeline_barrier({}, {}, std::span(&to_copy, 1));
        vkrc_test::record_readback(cmd_, image_.vk(), readback_.vk(), side, side);
        cmd_.end();
        fence_.unsignal();
        vkrc::submit(queue_, {.command_buffers = std::span(&cmd_, 1)}, fence_);
        if (fence_.wait() != VK_SUCCESS) return ::testing::AssertionFailure() << "the fence wait failed";
        std::vector<vkrc_test::Rgba> pixels(side * side);
        readback_.allocation().read(0, std::span(pixels));
        for (std::size_t i = 0; i < pixels.size(); ++i) {
            if (!vkrc_test::within_one(pixels[i], rgba)) return ::testing::AssertionFailure() << "pixel " << i;
        }
        return ::testing::AssertionSuccess();
    }

private:
    vkrc::Queue queue_;
    vkrc::Image image_;
    vkrc::ImageView view_;
    vkrc::Buffer readback_;
    vkrc::CommandPool pool_;
    vkrc::CommandBuffer cmd_;
    vkrc::Fence fence_;
};

// Out of device memory, caught, is not the end: while no memory can be
// allocated (every vkAllocateMemory fails, the PoolAllocator's smaller retry
// too), creating a 64 MiB image or buffer throws vkrc::Error naming the
// call, the device is not lost and renders correct frames with what it has;
// once memory is back, it allocates and renders again.
TEST(FaultInjection, RenderingGoesOnAfterACaughtOutOfDeviceMemory) {
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    faults::arm(0, VK_SUCCESS);
    {
        auto device = injected_device(log);
        ClearedFrames frames(device.default_queue());
        EXPECT_TRUE(frames.render({255, 0, 0, 255}));

        faults::fail_every("vkAllocateMemory", VK_ERROR_OUT_OF_DEVICE_MEMORY);
        auto expect_out_of_memory = [](const std::function<void()>& allocate, const char* what) {
            try {
                allocate();
                ADD_FAILURE() << what << ": no error while out of device memory";
            } catch (const vkrc::Error& e) {
                EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY) << what << ": " << e.what();
                EXPECT_NE(std::string(e.what()).find("vkAllocateMemory"), std::string::npos) << e.what();
            }
        };
        constexpr std::uint32_t big = 4096;  // 64 MiB of RGBA8: more than any block made so far
        expect_out_of_memory(
            [&] {
                vkrc::Image::create(
                    device,
                    {.format = VK_FORMAT_R8G8B8A8_UNORM, .extent = {big, big, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
            },
            "image");
        expect_out_of_memory(
            [&] {
                vkrc::Buffer::create(device, {.size = big * big * 4,
                                              .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                              .memory = {.usage = vkrc::MemoryUsage::upload}});
            },
            "buffer");
        EXPECT_TRUE(faults::fired()) << "vkAllocateMemory was not called";
        EXPECT_FALSE(device.lost());
        EXPECT_TRUE(frames.render({0, 255, 0, 255})) << "while out of memory";
        EXPECT_TRUE(frames.render({0, 0, 255, 255})) << "while out of memory";

        faults::arm(0, VK_SUCCESS);  // memory is back
        auto later = vkrc::Buffer::create(device, {.size = big * big * 4, .usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
        EXPECT_TRUE(frames.render({255, 255, 255, 255})) << "after memory came back";
        EXPECT_TRUE(ClearedFrames(device.default_queue()).render({64, 128, 192, 255})) << "on new objects";
    }
    vkrc_test::expect_no_validation_messages(*log);
}

// A vkQueueSubmit2 that fails leaves its fence as it was: unsubmitted, so
// the same fence is submitted again and waited for, and a fence dropped
// after its failed submit is destroyed without waiting for a signal that
// never comes (the watchdog catches that wait). The failed submit's number
// stays unused: a buffer dropped after it is destroyed once the next
// submission is seen complete.
TEST(FaultInjection, AFailedSubmitLeavesItsFenceUnsubmitted) {
    vkrc_test::Watchdog watchdog("a fence after a failed submit");
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    faults::arm(0, VK_SUCCESS);
    {
        auto device = injected_device(log);
        auto queue = device.default_queue();
        auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
        auto cmd = pool.allocate();
        cmd.begin();
        cmd.end();
        auto fence = vkrc::Fence::create(device);
        auto fail_submit = [&](const vkrc::Fence& f) {
            faults::arm_function("vkQueueSubmit2", VK_ERROR_OUT_OF_HOST_MEMORY, false);
            EXPECT_THROW(vkrc::submit(queue, {.command_buffers = vkrc::Span(&cmd, 1)}, f), vkrc::Error);
            EXPECT_TRUE(faults::fired());
            faults::arm(0, VK_SUCCESS);
        };
        fail_submit(vkrc::Fence::create(device));  // dropped at once
        fail_submit(fence);
        auto buffer = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        buffer.reset();
        vkrc::submit(queue, {.command_buffers = vkrc::Span(&cmd, 1)}, fence);
        EXPECT_EQ(fence.wait(), VK_SUCCESS);
        EXPECT_EQ(device.deferred_count(), 0u) << "the buffer dropped after the failed submit";
    }
    vkrc_test::expect_no_validation_messages(*log);
}

// Device loss reported while the GPU is held busy: a copy waits behind a
// gate only the host opens when the device is lost (without the injector
// letting the work finish first). The fence wait, the queue and device
// waits raise DeviceLostError at once (none waits for the held work), and
// the device reads lost; then the gate opens, the copy really runs (lavapipe
// is not lost) and its result is read back; every handle then drops without
// a validation message.
TEST(FaultInjection, LossIsReportedWhileTheGpuIsHeldBusy) {
    vkrc_test::Watchdog watchdog("device loss while the GPU is held busy");
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    faults::arm(0, VK_SUCCESS);
    {
        auto device = injected_device(log);
        auto queue = device.default_queue();
        const std::array<std::uint32_t, 4> values{3, 5, 7, 9};
        auto src = vkrc::Buffer::create(device, {.size = sizeof values,
                                                 .usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                                 .memory = {.usage = vkrc::MemoryUsage::upload}});
        src.allocation().write(0, values.data(), values.size());
        auto dst = vkrc::Buffer::create(device, {.size = sizeof values,
                                                 .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                 .memory = {.usage = vkrc::MemoryUsage::readback}});
        dst.allocation().write(0, std::array<std::uint32_t, 4>{}.data(), values.size());
        auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
        auto cmd = pool.allocate();
        cmd.begin();
        const VkBufferCopy region{0, 0, sizeof values};
        cmd.copy_buffer(src, dst, {&region, 1});
        const auto to_host = vkrc::memory_barrier(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                  VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        cmd.pipeline_barrier(std::span(&to_host, 1), {}, {});
        cmd.end();
        auto gate = vkrc::Semaphore::create_timeline(device);
        auto fence = vkrc::Fence::create(device);
        const vkrc::SemaphoreSubmit wait{gate, 1};
        vkrc::submit(queue, {.waits = std::span(&wait, 1), .command_buffers = std::span(&cmd, 1)}, fence);

        faults::lose_device_in_flight();
        EXPECT_THROW(fence.wait(), vkrc::DeviceLostError);
        EXPECT_TRUE(device.lost());
        EXPECT_THROW(queue.wait_idle(), vkrc::DeviceLostError);
        EXPECT_THROW(device.wait_idle(), vkrc::DeviceLostError);
        EXPECT_EQ(device.deferred_count(), 0u);
        std::array<std::uint32_t, 4> copied{};
        dst.allocation().read(0, copied.data(), copied.size());
        EXPECT_EQ(copied, (std::array<std::uint32_t, 4>{})) << "the held copy ran before the gate opened";

        gate.signal(1);  // vkSignalSemaphore does not report loss
        faults::finish_real_work();
        dst.allocation().read(0, copied.data(), copied.size());
        EXPECT_EQ(copied, values) << "the held copy did not run once the gate opened";
    }
    faults::arm(0, VK_SUCCESS);
    vkrc_test::expect_no_validation_messages(*log);
}

// A user allocator that fails its k-th allocation in one of three ways.
enum class AllocatorFailure { bad_alloc, vk_error, no_memory };

class FailingAllocator final : public vkrc_test::WrappedPoolAllocator {
public:
    FailingAllocator(std::uint64_t fail_at, AllocatorFailure how) : fail_at_(fail_at), how_(how) {}
    vkrc::AllocationInfo allocate(vkrc::DeviceView device, const vkrc::AllocationRequest& request) override {
        if (++calls_ == fail_at_) {
            switch (how_) {
                case AllocatorFailure::bad_alloc: throw std::bad_alloc();
                case AllocatorFailure::vk_error: throw vkrc::Error(VK_ERROR_OUT_OF_DEVICE_MEMORY, "vkAllocateMemory");
                case AllocatorFailure::no_memory: {
                    vkrc::AllocationInfo none;
                    none.allocator = this;
                    return none;
                }
            }
        }
        return WrappedPoolAllocator::allocate(device, request);
    }
    std::uint64_t calls() const { return calls_; }

private:
    std::uint64_t calls_ = 0;
    std::uint64_t fail_at_;
    AllocatorFailure how_;
};

TEST(FaultInjection, EveryAllocationOfAUserAllocatorFailsCleanly) {
    auto log = std::make_shared<vkrc_test::ValidationLog>();
    const auto info = vkrc_test::validated_instance_info(log);
    auto counting = vkrc::make_allocator<FailingAllocator>(0, AllocatorFailure::bad_alloc);
    vkrc_test::run_teapot_scenario(info, {.allocator = counting});
    const std::uint64_t points = counting->calls();
    counting.reset();
    vkrc_test::expect_no_validation_messages(*log);
    ASSERT_GT(points, 5u);

    for (auto how : {AllocatorFailure::bad_alloc, AllocatorFailure::vk_error, AllocatorFailure::no_memory}) {
        for (std::uint64_t k = 1; k <= points; ++k) {
            auto failing = vkrc::make_allocator<FailingAllocator>(k, how);
            try {
                vkrc_test::run_teapot_scenario(info, {.allocator = failing});
                ADD_FAILURE() << "allocation " << k << " failed and nothing was thrown";
            } catch (const std::bad_alloc&) {
                EXPECT_EQ(how, AllocatorFailure::bad_alloc);
            } catch (const vkrc::Error& e) {
                EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY) << e.what();
                EXPECT_NE(how, AllocatorFailure::bad_alloc) << e.what();
            } catch (const std::exception& e) {
                ADD_FAILURE() << "allocation " << k << ": unexpected exception " << e.what();
            }
            EXPECT_EQ(failing->use_count(), 1u) << "the device that kept the allocator is gone";
            auto messages = log->take();
            EXPECT_TRUE(messages.empty()) << "allocation " << k << ": " << messages.size()
                                          << " validation message(s), first: " << messages.front();
        }
    }
    std::printf("allocator fault injection: %llu allocations x 3 failure kinds\n",
                static_cast<unsigned long long>(points));
}

}  // namespace
