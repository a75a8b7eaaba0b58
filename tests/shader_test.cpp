#include "support/features.hpp"
#include "support/vk_test.hpp"

#include "shaders/fill_pattern.comp.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <vector>

namespace {

using vkrc_test::usage_error_of;
using vkrc_test::VulkanTest;

TEST_F(VulkanTest, ShaderModuleFromEmbeddedSpirv) {
    auto module = vkrc::ShaderModule::create(device, vkrc_shaders::fill_pattern_comp);
    EXPECT_NE(module.vk(), VK_NULL_HANDLE);
    EXPECT_TRUE(module.device() == device);
}

TEST_F(VulkanTest, ShaderModuleRejectsBadSpirv) {
    std::vector<std::uint32_t> none;
    EXPECT_EQ(usage_error_of([&] { vkrc::ShaderModule::create(device, std::span<const std::uint32_t>(none)); }),
              "vkrc::ShaderModule::create: the SPIR-V module is empty");

    std::vector<std::uint32_t> wrong(vkrc_shaders::fill_pattern_comp.begin(), vkrc_shaders::fill_pattern_comp.end());
    wrong[0] = 0x12345678;
    EXPECT_EQ(usage_error_of([&] { vkrc::ShaderModule::create(device, std::span<const std::uint32_t>(wrong)); }),
              "vkrc::ShaderModule::create: not SPIR-V (magic number 0x12345678, expected 0x07230203)");

    auto bytes = std::as_bytes(vkrc_shaders::fill_pattern_comp);
    EXPECT_EQ(usage_error_of([&] { vkrc::ShaderModule::create(device, bytes.first(bytes.size() - 2)); }),
              "vkrc::ShaderModule::create: the SPIR-V size (" + std::to_string(bytes.size() - 2) +
                  " bytes) is not a multiple of 4");
    EXPECT_TRUE(vkrc::ShaderModule::create(device, bytes));
}

TEST_F(VulkanTest, ShaderModuleFromFile) {
    auto dir = std::filesystem::temp_directory_path() /
               ("vkrc-shader-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
                std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    std::filesystem::create_directories(dir);
    auto good = dir / "fill.spv";
    {
        std::ofstream out(good, std::ios::binary);
        auto bytes = std::as_bytes(vkrc_shaders::fill_pattern_comp);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    }
    EXPECT_TRUE(vkrc::ShaderModule::load(device, good.c_str()));
    auto odd = dir / "odd.spv";
    {
        std::ofstream out(odd, std::ios::binary);
        out.write("\x03\x02\x23\x07\x00", 5);
    }
    EXPECT_EQ(usage_error_of([&] { vkrc::ShaderModule::load(device, odd.c_str()); }),
              "vkrc::ShaderModule::load: " + odd.string() + ": the SPIR-V size (5 bytes) is not a multiple of 4");
    auto empty = dir / "empty.spv";
    std::ofstream(empty).close();
    EXPECT_EQ(usage_error_of([&] { vkrc::ShaderModule::load(device, empty.c_str()); }),
              "vkrc::ShaderModule::load: " + empty.string() + ": the SPIR-V module is empty");
    EXPECT_EQ(usage_error_of([&] { vkrc::ShaderModule::load(device, (dir / "missing.spv").c_str()); }),
              "vkrc::ShaderModule::load: cannot open " + (dir / "missing.spv").string());
    std::filesystem::remove_all(dir);
}

}  // namespace
