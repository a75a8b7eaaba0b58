// Bad input gets a UsageError naming the function and the problem, before
// Vulkan sees it, and leaks nothing (the fixture fails on any validation
// message, including the object tracker's leak reports at teardown).
#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"

#include <array>
#include <cstring>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace {

using vkrc_test::expect_usage_error;
using vkrc_test::VulkanTest;

TEST_F(VulkanTest, InvalidSpirvIsRejected) {
    expect_usage_error([&] { vkrc::ShaderModule::create(device, std::span<const std::uint32_t>()); },
                       {"vkrc::ShaderModule::create", "empty"});
    const std::array<std::byte, 5> odd{std::byte{0x03}, std::byte{0x02}, std::byte{0x23}, std::byte{0x07}, {}};
    expect_usage_error([&] { vkrc::ShaderModule::create(device, std::span<const std::byte>(odd)); },
                       {"vkrc::ShaderModule::create", "5 bytes", "not a multiple of 4"});
    const std::array<std::uint32_t, 5> bad_magic{0xdeadbeef, 0x00010000, 0, 1, 0};
    expect_usage_error([&] { vkrc::ShaderModule::create(device, std::span<const std::uint32_t>(bad_magic)); },
                       {"vkrc::ShaderModule::create", "not SPIR-V", "0xdeadbeef"});
}

TEST_F(VulkanTest, ZeroAndOverflowingBufferSizesAreRejected) {
    expect_usage_error([&] { vkrc::Buffer::create(device, {.size = 0, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT}); },
                       {"vkrc::Buffer::create", "size is 0"});
    expect_usage_error(
        [&] { vkrc::Buffer::create(device, {.size = UINT64_MAX - 3, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT}); },
        {"vkrc::Buffer::create", "18446744073709551612", "larger than every memory heap"});
}

TEST_F(VulkanTest, ImageSizeThatOverflowsInStagingIsRejected) {
    auto real =
        vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT});
    // An adopted image is described by the application; a description whose
    // byte size wraps 64 bits must not turn into a small staging buffer.
    auto huge = vkrc::Image::adopt(device, real.vk(),
                                   {.format = VK_FORMAT_R32G32B32A32_SFLOAT,
                                    .extent = {UINT32_MAX, UINT32_MAX, 2},
                                    .array_layers = 1u << 20,
                                    .usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT},
                                   vkrc::Ownership::borrowed);
    expect_usage_error([&] { vkrc::image_data_size(huge); }, {"vkrc::image_data_size", "overflows 64 bits"});
    expect_usage_error([&] { vkrc::upload_image(queue, huge, {}); }, {"overflows 64 bits"});
}

TEST_F(VulkanTest, MappingMemoryThatIsNotHostVisibleIsRejected) {
    auto gpu = vkrc::Buffer::create(device, {.size = 64, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT});
    const std::uint32_t value = 1;
    expect_usage_error([&] { gpu.allocation().write_value(0, value); }, {"vkrc::Allocation::write", "host-visible"});
    expect_usage_error([&] { (void)gpu.allocation().read_value<std::uint32_t>(0); },
                       {"vkrc::Allocation::read", "host-visible"});
}

#if VKRC_RUNTIME_CHECKS
TEST_F(VulkanTest, WritingPastTheEndOfAMappingIsRejected) {
    auto upload = vkrc::Buffer::create(
        device,
        {.size = 16, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, .memory = {.usage = vkrc::MemoryUsage::upload}});
    const std::size_t size = upload.allocation().size();
    std::vector<std::uint32_t> words(size / 4 + 1);
    expect_usage_error([&] { upload.allocation().write(0, std::span<const std::uint32_t>(words)); },
                       {"vkrc::Allocation::write"});
    expect_usage_error([&] { upload.allocation().write_value(size - 2, std::uint32_t{7}); },
                       {"vkrc::Allocation::write"});
    expect_usage_error([&] { upload.allocation().write(UINT64_MAX - 1, words.data(), 1); },
                       {"vkrc::Allocation::write"});
}
#endif

TEST_F(VulkanTest, ComputePipelineRejectsAShaderOfAnotherDevice) {
    auto other = vkrc::Device::create(physical_device);
    auto layout = vkrc::PipelineLayout::create(device, {});
    auto module = vkrc::ShaderModule::create(other, vkrc_shaders::fill_pattern_comp);
    expect_usage_error([&] { vkrc::ComputePipeline::create(layout, module); },
                       {"vkrc::ComputePipeline::create", "another device"});
}

TEST_F(VulkanTest, ObjectsOfOneDeviceAreRejectedByAnother) {
    auto other = vkrc::Device::create(physical_device);
    auto buffer = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT});
    auto layout = vkrc::DescriptorSetLayout::create(
        device, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}}});
    auto other_layout = vkrc::DescriptorSetLayout::create(
        other, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}}});
    auto other_pool =
        vkrc::DescriptorPool::create(other, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1}}});
    auto other_set = other_pool.allocate(other_layout);

    expect_usage_error([&] { other_set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer); },
                       {"vkrc::DescriptorSet::write_buffer", "another device"});
    expect_usage_error([&] { other_pool.allocate(layout); }, {"vkrc::DescriptorPool::allocate", "another device"});
    expect_usage_error([&] { vkrc::PipelineLayout::create(other, {.set_layouts = {layout}}); },
                       {"vkrc::PipelineLayout::create", "another device"});
    expect_usage_error([&] { vkrc::upload_buffer(other.default_queue(), buffer, 0, {}); },
                       {"vkrc::upload_buffer", "another device"});
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM, .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    auto view = vkrc::ImageView::create(image);
    auto other_image_layout = vkrc::DescriptorSetLayout::create(
        other, {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE}}});
    auto other_image_pool =
        vkrc::DescriptorPool::create(other, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 1}}});
    auto other_image_set = other_image_pool.allocate(other_image_layout);
    expect_usage_error(
        [&] {
            other_image_set.write_image(0, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, view,
                                        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        },
        {"vkrc::DescriptorSet::write_image", "another device"});
#if VKRC_RUNTIME_CHECKS
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    cmd.end();
    const vkrc::CommandBuffer cmds[] = {cmd};
    expect_usage_error([&] { vkrc::submit(other.default_queue(), {.command_buffers = cmds}); },
                       {"vkrc::submit", "another device"});
    auto fence = vkrc::Fence::create(device);
    expect_usage_error([&] { vkrc::submit(other.default_queue(), vkrc::SubmitBatch{}, fence); },
                       {"vkrc::submit", "another device"});
#endif
}

TEST_F(VulkanTest, DescriptorWritesMustMatchTheLayout) {
    auto layout = vkrc::DescriptorSetLayout::create(
        device,
        {.bindings = {{.binding = 0, .descriptor_type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, .descriptor_count = 2}}});
    auto pool =
        vkrc::DescriptorPool::create(device, {.max_sets = 1, .pool_sizes = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 2}}});
    auto set = pool.allocate(layout);
    auto buffer = vkrc::Buffer::create(
        device, {.size = 256, .usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT});
    expect_usage_error(
        [&] { set.write_buffer(0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, buffer); },
        {"vkrc::DescriptorSet::write_buffer", "binding 0 has descriptor type VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER",
         "the write has type VK_DESCRIPTOR_TYPE_STORAGE_BUFFER"});
    expect_usage_error([&] { set.write_buffer(3, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer); },
                       {"vkrc::DescriptorSet::write_buffer", "no binding 3"});
    expect_usage_error([&] { set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer, 0, VK_WHOLE_SIZE, 2); },
                       {"vkrc::DescriptorSet::write_buffer", "array element 2"});
    expect_usage_error(
        [&] { set.write_image(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL); },
        {"vkrc::DescriptorSet::write_image", "descriptor type VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER",
         "not an image or sampler type"});
    auto vertex_only = vkrc::Buffer::create(device, {.size = 256, .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT});
    expect_usage_error([&] { set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, vertex_only); },
                       {"vkrc::DescriptorSet::write_buffer", "lacks the usage"});
    set.write_buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, buffer, 0, VK_WHOLE_SIZE, 1);  // fits
}

TEST_F(VulkanTest, ImageViewsMustFitTheirImage) {
    auto image = vkrc::Image::create(device, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                                              .extent = {8, 8, 1},
                                              .mip_levels = 2,
                                              .array_layers = 2,
                                              .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    expect_usage_error(
        [&] {
            vkrc::ImageView::create(image, {.subresource_range = {0, 2, 1, 0, 1}});
        },
        {"vkrc::ImageView::create", "mip levels 2+1", "2 levels"});
    expect_usage_error(
        [&] {
            vkrc::ImageView::create(image, {.subresource_range = {0, 1, 2, 0, 1}});
        },
        {"vkrc::ImageView::create", "mip levels 1+2"});
    expect_usage_error(
        [&] {
            vkrc::ImageView::create(image,
                                    {.view_type = VK_IMAGE_VIEW_TYPE_2D_ARRAY, .subresource_range = {0, 0, 1, 1, 5}});
        },
        {"vkrc::ImageView::create", "array layers 1+5", "2 layers"});
    expect_usage_error([&] { vkrc::ImageView::create(image, {.format = VK_FORMAT_R32_SFLOAT}); },
                       {"vkrc::ImageView::create", "MUTABLE_FORMAT_BIT"});
    auto mutable_image = vkrc::Image::create(device, {.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT,
                                                      .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                      .extent = {8, 8, 1},
                                                      .usage = VK_IMAGE_USAGE_SAMPLED_BIT});
    expect_usage_error([&] { vkrc::ImageView::create(mutable_image, {.format = VK_FORMAT_R16G16B16A16_SFLOAT}); },
                       {"vkrc::ImageView::create", "8-byte texels", "has 4"});
    // Same texel size with MUTABLE_FORMAT_BIT, and a range within the image: fine.
    vkrc::ImageView::create(mutable_image, {.format = VK_FORMAT_R32_UINT});
    vkrc::ImageView::create(image, {.subresource_range = {0, 1, 1, 1, 1}});
}

#if VKRC_RUNTIME_CHECKS
TEST_F(VulkanTest, MoreThanEightColourAttachmentsAreRejected) {
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    std::array<vkrc::RenderingAttachment, 9> colors{};
    expect_usage_error(
        [&] {
            cmd.begin_rendering({.render_area = {{0, 0}, {8, 8}}, .color_attachments = colors});
        },
        {"vkrc::CommandBuffer::begin_rendering", "9 colour attachments", "at most 8"});
    cmd.end();
}

// Issue 34: the validation layer alone reported VUID-vkCmdPushConstants-offset-01795
// here, then (under ASan) read past its buffer.
TEST_F(VulkanTest, PushConstantsOutsideTheLayoutsRangesAreRejected) {
    const auto layout = vkrc::PipelineLayout::create(
        device, {.push_constant_ranges = {{VK_SHADER_STAGE_VERTEX_BIT, 0, 16}, {VK_SHADER_STAGE_FRAGMENT_BIT, 8, 8}}});
    auto pool = vkrc::CommandPool::create(device, {.queue_family_index = queue.family_index()});
    auto cmd = pool.allocate();
    cmd.begin();
    const std::array<std::uint32_t, 6> data{};
    const auto push = [&](VkShaderStageFlags stages, std::uint32_t offset, std::uint32_t size) {
        return [&cmd, &layout, &data, stages, offset, size] {
            cmd.push_constants(layout, stages, offset, size, data.data());
        };
    };
    const VkShaderStageFlags vertex = VK_SHADER_STAGE_VERTEX_BIT, both = vertex | VK_SHADER_STAGE_FRAGMENT_BIT;
    // Past the end (the case: 16 bytes where the range has 8).
    expect_usage_error(push(both, 8, 16), {"vkrc::CommandBuffer::push_constants", "[8, 24) of stage flags 0x11",
                                           "byte 16 is in no push constant range",
                                           "[0, 16) of stage flags 0x1, [8, 16) of stage flags 0x10"});
    // A stage no range at those bytes has.
    expect_usage_error(push(both, 0, 8), {"[0, 8) of stage flags 0x11", "byte 0", "for stage flags 0x10"});
    // Fewer stages than a range that holds the bytes (01796).
    expect_usage_error(push(vertex, 8, 4),
                       {"[8, 12) of stage flags 0x1 overlaps the layout's range [8, 16) of stage flags 0x10",
                        "must include all of its stages"});
    expect_usage_error(push(vertex, 2, 4), {"offset 2 and size 4 must be multiples of 4"});
    expect_usage_error(push(vertex, 0, 0), {"size not 0"});
    expect_usage_error(push(0, 0, 4), {"the stage flags are 0"});
    // Within the ranges: recorded (the validation layer stays silent), both ways of calling.
    push(vertex, 0, 8)();
    push(both, 8, 8)();
    cmd.push_constants(layout, vertex, data[0], 4);
    cmd.push_constants(layout.vk(), vertex, 0, 4, data.data());
    cmd.end();
}
#endif

// What the device's limits, features and format properties rule out is
// refused at creation, naming the value and the limit (docs/validation.md).
int format_queries = 0;
PFN_vkGetPhysicalDeviceImageFormatProperties real_format_query = nullptr;
VKAPI_ATTR VkResult VKAPI_CALL counting_format_query(VkPhysicalDevice physical, VkFormat format, VkImageType type,
                                                     VkImageTiling tiling, VkImageUsageFlags usage,
                                                     VkImageCreateFlags flags, VkImageFormatProperties* properties) {
    ++format_queries;
    return real_format_query(physical, format, type, tiling, usage, flags, properties);
}

// vkGetPhysicalDeviceImageFormatProperties answers the same for the same
// arguments: Image::create asks once per device and kind of image (on each
// thread), and still refuses an unsupported kind every time.
TEST_F(VulkanTest, ImageCreationQueriesTheFormatOncePerDeviceAndKind) {
    auto& fn = instance.state()->fn;
    real_format_query = fn.vkGetPhysicalDeviceImageFormatProperties;
    fn.vkGetPhysicalDeviceImageFormatProperties = counting_format_query;
    struct Restore {
        vkrc::InstanceFunctions& fn;
        ~Restore() { fn.vkGetPhysicalDeviceImageFormatProperties = real_format_query; }
    } restore{fn};
    format_queries = 0;
    const vkrc::ImageCreateInfo sampled{
        .format = VK_FORMAT_R8G8B8A8_UNORM, .extent = {64, 64, 1}, .usage = VK_IMAGE_USAGE_SAMPLED_BIT};
    for (int i = 0; i < 3; ++i) vkrc::Image::create(device, sampled);
    EXPECT_EQ(format_queries, 1);
    vkrc::ImageCreateInfo unsupported = sampled;
    unsupported.format = VK_FORMAT_BC1_RGB_UNORM_BLOCK;  // never a colour attachment
    unsupported.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    for (int i = 0; i < 2; ++i) {
        expect_usage_error([&] { vkrc::Image::create(device, unsupported); }, {"is not supported by the device"});
    }
    EXPECT_EQ(format_queries, 2);
    const auto other = vkrc::Device::create(physical_device);  // another device asks again
    vkrc::Image::create(other, sampled);
    EXPECT_EQ(format_queries, 3);
}

TEST_F(VulkanTest, CreationRespectsTheDevicesLimitsFeaturesAndFormats) {
    vkrc::ImageCreateInfo image{.format = VK_FORMAT_R8G8B8A8_UNORM,
                                .extent = {1024, 1024, 1},
                                .mip_levels = 12,
                                .usage = VK_IMAGE_USAGE_SAMPLED_BIT};
    expect_usage_error([&] { vkrc::Image::create(device, image); },
                       {"vkrc::Image::create: mip_levels 12 exceeds the 11 levels a 1024x1024x1 image can have"});
    image.mip_levels = 1;
    image.samples = VK_SAMPLE_COUNT_64_BIT;  // lavapipe offers 1 and 4
    expect_usage_error(
        [&] { vkrc::Image::create(device, image); },
        {"samples VK_SAMPLE_COUNT_64_BIT not supported for VK_FORMAT_R8G8B8A8_UNORM", "sampleCounts 0x"});
    image.samples = VK_SAMPLE_COUNT_1_BIT;
    image.initial_layout = VK_IMAGE_LAYOUT_GENERAL;
    expect_usage_error([&] { vkrc::Image::create(device, image); },
                       {"initial_layout VK_IMAGE_LAYOUT_GENERAL is neither UNDEFINED nor PREINITIALIZED"});
    image.initial_layout = VK_IMAGE_LAYOUT_UNDEFINED;
    image.format = VK_FORMAT_BC1_RGB_UNORM_BLOCK;  // never a colour attachment
    image.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    expect_usage_error([&] { vkrc::Image::create(device, image); },
                       {"format VK_FORMAT_BC1_RGB_UNORM_BLOCK", "usage 0x10", "is not supported by the device"});
    image.format = VK_FORMAT_R8G8B8A8_UNORM;
    image.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    image.sharing_mode = VK_SHARING_MODE_CONCURRENT;
    image.queue_family_indices = {0};
    expect_usage_error([&] { vkrc::Image::create(device, image); },
                       {"concurrent sharing needs at least 2 queue_family_indices, got 1"});
    image.sharing_mode = VK_SHARING_MODE_EXCLUSIVE;
    const auto flat = vkrc::Image::create(device, image);
    expect_usage_error([&] { vkrc::ImageView::create(flat, {.view_type = VK_IMAGE_VIEW_TYPE_CUBE}); },
                       {"vkrc::ImageView::create: view_type VK_IMAGE_VIEW_TYPE_CUBE cannot view a VK_IMAGE_TYPE_2D"});
    expect_usage_error([&] { vkrc::Sampler::create(device, {.min_lod = 4.0f, .max_lod = 2.0f}); },
                       {"vkrc::Sampler::create: max_lod 2 is less than min_lod 4"});
    expect_usage_error([&] { vkrc::Sampler::create(device, {.anisotropy_enable = true, .max_anisotropy = 4.0f}); },
                       {"anisotropy_enable needs the samplerAnisotropy feature enabled"});
    const float bias = physical_device.properties().limits.maxSamplerLodBias * 2;
    expect_usage_error([&] { vkrc::Sampler::create(device, {.mip_lod_bias = bias}); },
                       {"mip_lod_bias", "exceeds maxSamplerLodBias"});
    expect_usage_error([&] { vkrc::Sampler::create(device, {.unnormalized_coordinates = true}); },
                       {"unnormalized_coordinates needs mipmap_mode NEAREST, not VK_SAMPLER_MIPMAP_MODE_LINEAR"});
}

TEST_F(VulkanTest, PresentingAFrameOfAnotherPresenterIsRejected) {
    // present() is inline; its refusal stays a UsageError naming the problem.
    auto a = vkrc::HeadlessPresenter::create(queue, {.extent = {4, 4}});
    auto b = vkrc::HeadlessPresenter::create(queue, {.extent = {4, 4}});
    vkrc::Frame frame;
    expect_usage_error([&] { a.present(frame); },
                       {"vkrc::HeadlessPresenter::present", "the frame was not acquired from this presenter"});
    ASSERT_EQ(b.acquire(frame), vkrc::PresentStatus::success);
    expect_usage_error([&] { a.present(frame); },
                       {"vkrc::HeadlessPresenter::present", "the frame was not acquired from this presenter"});
    EXPECT_EQ(b.present(frame), vkrc::PresentStatus::success);
    EXPECT_EQ(b.last_presented(), frame.image_index);
    EXPECT_EQ(a.last_presented(), UINT32_MAX);
}

}  // namespace
