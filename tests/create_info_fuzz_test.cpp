// Seeded create-info fuzz (issue 33 item 6): random buffer, image, image view
// and sampler create-infos, valid and not, tried on a validated device. Each
// must be created or refused with vkrc::UsageError before Vulkan sees it: a
// validation message after an attempt fails the test there. VKRC_TEST_SEED
// replays a run; otherwise the seed is random and printed.
//
// What the fuzz leaves out, because vkrc does not check it: pNext chains,
// extension-only bits and enum values, view formats other than uncompressed
// colour ones (vkrc knows their texel sizes only), VkImageViewUsageCreateInfo,
// and custom border colours.
#include "support/vk_test.hpp"

#include <cstdio>
#include <cstdlib>
#include <deque>
#include <initializer_list>
#include <random>
#include <string>

namespace {

using vkrc_test::VulkanTest;

class Fuzzer {
public:
    explicit Fuzzer(unsigned seed) : rng_(seed) {}
    bool chance(int percent) { return between(0, 99) < static_cast<std::uint32_t>(percent); }
    std::uint32_t between(std::uint32_t low, std::uint32_t high) {
        return std::uniform_int_distribution<std::uint32_t>(low, high)(rng_);
    }
    float real(float low, float high) { return std::uniform_real_distribution<float>(low, high)(rng_); }
    template <class T>
    T pick(std::initializer_list<T> values) {
        return values.begin()[between(0, static_cast<std::uint32_t>(values.size() - 1))];
    }
    // Each bit of candidates with the given chance.
    std::uint32_t bits(std::uint32_t candidates, int percent) {
        std::uint32_t out = 0;
        for (std::uint32_t bit = 1; bit != 0; bit <<= 1) {
            if ((candidates & bit) && chance(percent)) out |= bit;
        }
        return out;
    }

private:
    std::mt19937 rng_;
};

constexpr VkFormat colour_formats[] = {
    VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_UNORM,      VK_FORMAT_R32_UINT,
    VK_FORMAT_R32_SFLOAT,     VK_FORMAT_R8_UNORM,      VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT};
constexpr VkFormat other_formats[] = {VK_FORMAT_D32_SFLOAT, VK_FORMAT_D16_UNORM, VK_FORMAT_D24_UNORM_S8_UINT,
                                      VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32};

template <std::size_t N>
VkFormat pick_format(Fuzzer& f, const VkFormat (&formats)[N]) {
    return formats[f.between(0, N - 1)];
}

void fuzz_sharing(Fuzzer& f, VkSharingMode& mode, vkrc::List<std::uint32_t>& families) {
    if (!f.chance(15)) return;
    mode = VK_SHARING_MODE_CONCURRENT;
    for (std::uint32_t i = f.between(0, 3); i > 0; --i) families.push_back(f.between(0, 2));
}

vkrc::BufferCreateInfo fuzz_buffer(Fuzzer& f) {
    vkrc::BufferCreateInfo info;
    info.size = f.chance(5) ? 0 : f.pick<VkDeviceSize>({1, 16, 256, 4096, 65536, 1u << 20});
    info.usage = f.bits(VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                            VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT |
                            VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                            VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                            VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                        25);
    if (f.chance(5)) info.flags = VK_BUFFER_CREATE_SPARSE_BINDING_BIT;
    fuzz_sharing(f, info.sharing_mode, info.queue_family_indices);
    return info;
}

// An extent of mostly small sizes; now and then one dimension past the
// device's limit for the type (the others 1, so that a miss stays small).
VkExtent3D fuzz_extent(Fuzzer& f, VkImageType type, const VkPhysicalDeviceLimits& limits) {
    VkExtent3D e{f.between(1, 64), f.between(1, 64), f.between(1, 16)};
    if (type != VK_IMAGE_TYPE_3D && !f.chance(10)) e.depth = 1;
    if (type == VK_IMAGE_TYPE_1D && !f.chance(10)) e.height = 1;
    if (f.chance(5)) {
        const std::uint32_t max = type == VK_IMAGE_TYPE_1D   ? limits.maxImageDimension1D
                                  : type == VK_IMAGE_TYPE_2D ? limits.maxImageDimension2D
                                                             : limits.maxImageDimension3D;
        e = {max + 1, 1, 1};
    }
    return e;
}

vkrc::ImageCreateInfo fuzz_image(Fuzzer& f, const VkPhysicalDeviceLimits& limits) {
    vkrc::ImageCreateInfo info;
    info.image_type = f.pick({VK_IMAGE_TYPE_1D, VK_IMAGE_TYPE_2D, VK_IMAGE_TYPE_2D, VK_IMAGE_TYPE_3D});
    info.format = f.chance(25) ? pick_format(f, other_formats) : pick_format(f, colour_formats);
    info.extent = fuzz_extent(f, info.image_type, limits);
    if (f.chance(10)) info.extent.height = info.extent.width;  // square, for cubes
    info.flags = f.bits(VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT | VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT |
                            VK_IMAGE_CREATE_2D_ARRAY_COMPATIBLE_BIT,
                        15);
    info.mip_levels = f.chance(60) ? 1 : f.between(1, 9);
    info.array_layers = f.pick<std::uint32_t>({1, 1, 1, 2, 6, 12});
    if (f.chance(3)) {
        info.array_layers = limits.maxImageArrayLayers + 1;
        info.extent = {1, 1, 1};
    }
    info.samples = f.chance(75) ? VK_SAMPLE_COUNT_1_BIT
                                : f.pick({VK_SAMPLE_COUNT_2_BIT, VK_SAMPLE_COUNT_4_BIT, VK_SAMPLE_COUNT_8_BIT,
                                          VK_SAMPLE_COUNT_16_BIT, VK_SAMPLE_COUNT_64_BIT});
    info.tiling = f.chance(20) ? VK_IMAGE_TILING_LINEAR : VK_IMAGE_TILING_OPTIMAL;
    info.usage = f.bits(VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                            VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                            VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT |
                            VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT,
                        20);
    info.initial_layout =
        f.chance(90) ? VK_IMAGE_LAYOUT_UNDEFINED : f.pick({VK_IMAGE_LAYOUT_PREINITIALIZED, VK_IMAGE_LAYOUT_GENERAL});
    fuzz_sharing(f, info.sharing_mode, info.queue_family_indices);
    return info;
}

vkrc::ImageViewCreateInfo fuzz_view(Fuzzer& f, const vkrc::Image& image) {
    vkrc::ImageViewCreateInfo info;
    info.view_type =
        f.pick({VK_IMAGE_VIEW_TYPE_1D, VK_IMAGE_VIEW_TYPE_2D, VK_IMAGE_VIEW_TYPE_3D, VK_IMAGE_VIEW_TYPE_CUBE,
                VK_IMAGE_VIEW_TYPE_1D_ARRAY, VK_IMAGE_VIEW_TYPE_2D_ARRAY, VK_IMAGE_VIEW_TYPE_CUBE_ARRAY});
    if (f.chance(20) && vkrc::format_texel_size(image.format()) != 0) info.format = pick_format(f, colour_formats);
    auto& r = info.subresource_range;
    r.baseMipLevel = f.chance(80) ? 0 : f.between(0, image.mip_levels());
    r.levelCount = f.chance(50) ? VK_REMAINING_MIP_LEVELS : f.between(0, image.mip_levels());
    r.baseArrayLayer = f.chance(80) ? 0 : f.between(0, image.array_layers());
    r.layerCount = f.chance(40) ? VK_REMAINING_ARRAY_LAYERS : f.pick<std::uint32_t>({0, 1, 1, 2, 6, 12});
    return info;
}

vkrc::SamplerCreateInfo fuzz_sampler(Fuzzer& f) {
    vkrc::SamplerCreateInfo info;
    info.mag_filter = f.pick({VK_FILTER_NEAREST, VK_FILTER_LINEAR});
    info.min_filter = f.pick({VK_FILTER_NEAREST, VK_FILTER_LINEAR});
    info.mipmap_mode = f.pick({VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_MIPMAP_MODE_LINEAR});
    auto address = [&] {
        return f.pick({VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT,
                       VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
                       VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE});
    };
    info.address_mode_u = address();
    info.address_mode_v = address();
    info.address_mode_w = address();
    info.mip_lod_bias = f.chance(70) ? 0.0f : f.real(-20.0f, 20.0f);
    info.anisotropy_enable = f.chance(30);
    info.max_anisotropy = f.real(0.0f, 20.0f);
    info.compare_enable = f.chance(20);
    info.compare_op = f.pick({VK_COMPARE_OP_NEVER, VK_COMPARE_OP_LESS, VK_COMPARE_OP_GREATER, VK_COMPARE_OP_ALWAYS});
    info.min_lod = f.chance(50) ? 0.0f : f.real(0.0f, 12.0f);
    info.max_lod = f.chance(30) ? VK_LOD_CLAMP_NONE : f.chance(30) ? 0.0f : f.real(0.0f, 12.0f);
    info.border_color = f.pick({VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK, VK_BORDER_COLOR_INT_OPAQUE_BLACK,
                                VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE});
    info.unnormalized_coordinates = f.chance(20);
    return info;
}

struct Tally {
    int created = 0;
    int refused = 0;
    int failed = 0;  // a vkrc::Error from a valid call (e.g. out of memory)
};

// Runs one attempt; fails the test (naming the attempt) on any validation message.
template <class Make>
void attempt(vkrc_test::ValidationLog& log, Tally& tally, const std::string& what, Make&& make) {
    try {
        make();
        ++tally.created;
    } catch (const vkrc::UsageError&) {
        ++tally.refused;
    } catch (const vkrc::Error&) {
        ++tally.failed;
    }
    const auto messages = log.take();
    EXPECT_TRUE(messages.empty()) << what << " reached Vulkan invalid: " << messages.front();
}

std::string image_text(const vkrc::ImageCreateInfo& i) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "image type %d format %d extent %ux%ux%u flags 0x%x mips %u layers %u samples %d tiling %d "
                  "usage 0x%x layout %d sharing %d/%zu",
                  i.image_type, i.format, i.extent.width, i.extent.height, i.extent.depth, i.flags, i.mip_levels,
                  i.array_layers, i.samples, i.tiling, i.usage, i.initial_layout, i.sharing_mode,
                  i.queue_family_indices.size());
    return text;
}

std::string view_text(const vkrc::ImageViewCreateInfo& v, const vkrc::Image& image) {
    const auto& r = v.subresource_range;
    char text[256];
    std::snprintf(text, sizeof text,
                  "view type %d format %d mips %u+%u layers %u+%u of an image of type %d format %d flags 0x%x mips "
                  "%u layers %u samples %d usage 0x%x",
                  v.view_type, v.format, r.baseMipLevel, r.levelCount, r.baseArrayLayer, r.layerCount,
                  image.image_type(), image.format(), image.state()->flags, image.mip_levels(), image.array_layers(),
                  image.samples(), image.usage());
    return text;
}

TEST_F(VulkanTest, CreateInfoFuzzNeverReachesVulkanInvalid) {
    const unsigned seed = vkrc_test::test_seed();
    SCOPED_TRACE("seed " + std::to_string(seed));
    Fuzzer f(seed);
    const VkPhysicalDeviceLimits limits = physical_device.properties().limits;
    Tally tally;
    std::deque<vkrc::Image> images;  // recent valid images, for views
    constexpr int attempts = 6000;
    for (int n = 0; n < attempts && !HasFailure(); ++n) {
        const std::string at = "attempt " + std::to_string(n) + ": ";
        switch (f.between(0, 3)) {
            case 0: {
                const auto info = fuzz_buffer(f);
                attempt(*log, tally, at + "buffer", [&] { vkrc::Buffer::create(device, info); });
                break;
            }
            case 1: {
                const auto info = fuzz_image(f, limits);
                attempt(*log, tally, at + image_text(info), [&] {
                    images.push_back(vkrc::Image::create(device, info));
                    if (images.size() > 16) images.pop_front();
                });
                break;
            }
            case 2: {
                if (images.empty()) break;
                const vkrc::Image& image = images[f.between(0, static_cast<std::uint32_t>(images.size() - 1))];
                const auto info = fuzz_view(f, image);
                attempt(*log, tally, at + view_text(info, image), [&] { vkrc::ImageView::create(image, info); });
                break;
            }
            default: {
                const auto info = fuzz_sampler(f);
                attempt(*log, tally, at + "sampler", [&] { vkrc::Sampler::create(device, info); });
            }
        }
    }
    std::printf("created %d, refused %d, failed %d\n", tally.created, tally.refused, tally.failed);
    // Both sides must be exercised, or the fuzz proves nothing.
    EXPECT_GT(tally.created, attempts / 10);
    EXPECT_GT(tally.refused, attempts / 10);
}

}  // namespace
