#include "vk_test.hpp"

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <random>
#include <span>
#include <string>

namespace vkrc_test {

::testing::AssertionResult within_one(const Rgba& actual, const Rgba& expected) {
    for (std::size_t c = 0; c < actual.size(); ++c) {
        if (std::abs(int(actual[c]) - int(expected[c])) > 1) {
            return ::testing::AssertionFailure()
                   << "pixel {" << int(actual[0]) << ", " << int(actual[1]) << ", " << int(actual[2]) << ", "
                   << int(actual[3]) << "} differs by more than one in channel " << c << " from {" << int(expected[0])
                   << ", " << int(expected[1]) << ", " << int(expected[2]) << ", " << int(expected[3]) << "}";
        }
    }
    return ::testing::AssertionSuccess();
}

ValidationLog::~ValidationLog() {
    if (messages_.empty()) return;
    ADD_FAILURE() << messages_.size() << " validation message(s) never asserted, first: " << messages_.front().id
                  << ": " << messages_.front().text;
}

void ValidationLog::add(const vkrc::DebugMessage& m) {
    std::lock_guard lock(mutex_);
    messages_.push_back({m.message_id_name ? m.message_id_name : "-", m.message ? m.message : ""});
}

std::vector<std::string> ValidationLog::take() {
    std::lock_guard lock(mutex_);
    std::vector<std::string> all;
    for (const auto& m : messages_) all.push_back(m.id + ": " + m.text);
    messages_.clear();
    return all;
}

::testing::AssertionResult ValidationLog::take_expected(std::string_view id, std::size_t count) {
    std::lock_guard lock(mutex_);
    const auto taken = std::erase_if(messages_, [&](const Message& m) { return m.id == id; });
    if (taken == count) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << taken << " message(s) with id " << id << ", expected " << count;
}

namespace {

// Synchronization validation always; GPU-assisted validation on request (it
// instruments every shader: see docs/validation.md for its cost on lavapipe).
const VkValidationFeaturesEXT* validation_features() {
    static const bool gpu_av = [] {
        const char* v = std::getenv("VKRC_TEST_GPU_AV");
        return v && *v && *v != '0';
    }();
    static const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT,
                                                           VK_VALIDATION_FEATURE_ENABLE_GPU_ASSISTED_EXT};
    static const VkValidationFeaturesEXT features{.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
                                                  .enabledValidationFeatureCount = gpu_av ? 2u : 1u,
                                                  .pEnabledValidationFeatures = enables};
    return &features;
}

}  // namespace

vkrc::InstanceCreateInfo validated_instance_info(const std::shared_ptr<ValidationLog>& log) {
    vkrc::InstanceCreateInfo info;
    info.application_name = "vkrc tests";
    info.validation = true;
    info.next = validation_features();
    info.debug_callback = [log](const vkrc::DebugMessage& m) {
        vkrc::print_debug_message(m);
        log->add(m);
    };
    return info;
}

vkrc::DeviceRequirements test_device_requirements() {
    vkrc::DeviceRequirements req;
    if (const char* name = std::getenv("VKRC_TEST_DEVICE")) req.name_contains = name;
    return req;
}

std::uint32_t test_seed() {
    static const std::uint32_t seed = [] {
        if (const char* v = std::getenv("VKRC_TEST_SEED"); v && *v) {
            return static_cast<std::uint32_t>(std::strtoul(v, nullptr, 0));
        }
        return static_cast<std::uint32_t>(std::random_device{}());
    }();
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::printf("%s.%s: VKRC_TEST_SEED=%u\n", test ? test->test_suite_name() : "-", test ? test->name() : "-", seed);
    std::fflush(stdout);  // before a crash can lose it
    return seed;
}

vkrc::DescriptorSetLayout sample_texels_set_layout(const vkrc::Device& device) {
    return vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT},
                              {.binding = 1,
                               .descriptor_type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                               .stage_flags = VK_SHADER_STAGE_COMPUTE_BIT}}});
}

void VulkanTest::SetUp() { create_all(validated_instance_info(log)); }

void SyncValidatedTest::SetUp() {
    const VkValidationFeatureEnableEXT enable = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = &enable;
    auto info = validated_instance_info(log);
    info.next = &features;
    create_all(info);
}

void VulkanTest::create_all(const vkrc::InstanceCreateInfo& instance_info) {
    instance = vkrc::Instance::create(instance_info);
    physical_device = vkrc::PhysicalDevice::select(instance, test_device_requirements());
    device = vkrc::Device::create(physical_device);
    queue = device.default_queue();
}

void VulkanTest::release_all() {
    queue = {};
    device.reset();
    physical_device.reset();
    instance.reset();
}

void VulkanTest::TearDown() {
    release_all();
    expect_no_validation_messages(*log);
}

GpuGate::~GpuGate() {
    if (device_) device_.wait_idle();
}

void GpuGate::submit(const vkrc::Queue& queue, const vkrc::CommandBuffer& cmd, const vkrc::Fence& fence) const {
    const auto gate = wait();
    vkrc::submit(queue, {.waits = std::span(&gate, 1), .command_buffers = std::span(&cmd, 1)}, fence);
}

namespace {
struct SetCalls {
    int allocated = 0;
    int refused = 0;
    int freed = 0;
    int capacity = 0;
    PFN_vkAllocateDescriptorSets real_allocate = nullptr;
    PFN_vkFreeDescriptorSets real_free = nullptr;
} set_calls;

VKAPI_ATTR VkResult VKAPI_CALL counting_allocate_sets(VkDevice device, const VkDescriptorSetAllocateInfo* info,
                                                      VkDescriptorSet* sets) {
    const int count = static_cast<int>(info->descriptorSetCount);
    if (set_calls.allocated - set_calls.freed + count > set_calls.capacity) {
        ++set_calls.refused;
        return VK_ERROR_OUT_OF_POOL_MEMORY;
    }
    const VkResult r = set_calls.real_allocate(device, info, sets);
    if (r == VK_SUCCESS) set_calls.allocated += count;
    return r;
}

VKAPI_ATTR VkResult VKAPI_CALL counting_free_sets(VkDevice device, VkDescriptorPool pool, std::uint32_t count,
                                                  const VkDescriptorSet* sets) {
    set_calls.freed += static_cast<int>(count);
    return set_calls.real_free(device, pool, count, sets);
}
}  // namespace

CountSetCalls::CountSetCalls(const vkrc::Device& device, int capacity) : fn_(device.state()->fn) {
    set_calls = {
        .capacity = capacity, .real_allocate = fn_.vkAllocateDescriptorSets, .real_free = fn_.vkFreeDescriptorSets};
    fn_.vkAllocateDescriptorSets = counting_allocate_sets;
    fn_.vkFreeDescriptorSets = counting_free_sets;
}

CountSetCalls::~CountSetCalls() {
    fn_.vkAllocateDescriptorSets = set_calls.real_allocate;
    fn_.vkFreeDescriptorSets = set_calls.real_free;
}

int CountSetCalls::allocated() const { return set_calls.allocated; }
int CountSetCalls::refused() const { return set_calls.refused; }
int CountSetCalls::freed() const { return set_calls.freed; }

void expect_no_validation_messages(ValidationLog& log) {
    const auto messages = log.take();
    EXPECT_TRUE(messages.empty()) << messages.size()
                                  << " validation message(s), first: " << (messages.empty() ? "" : messages.front());
}

void expect_usage_error(const std::function<void()>& f, std::initializer_list<const char*> parts) {
    try {
        f();
        ADD_FAILURE() << "no UsageError; expected one saying: " << *parts.begin();
    } catch (const vkrc::UsageError& e) {
        for (const char* part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
}

}  // namespace vkrc_test

#if defined(__SANITIZE_ADDRESS__)
#  include <dlfcn.h>
namespace {
// The loader unloads the driver and the layer at vkDestroyInstance; leaks
// inside them would then be reported from "<unknown module>" and could not be
// told from vkrc's. Pinning them keeps their names for lsan.supp.
[[maybe_unused]] const bool pinned_driver_modules = [] {
    for (const char* lib : {"libvulkan_lvp.so", "libVkLayer_khronos_validation.so"}) {
        dlopen(lib, RTLD_LAZY | RTLD_LOCAL | RTLD_NODELETE);
    }
    return true;
}();
}  // namespace
#endif
