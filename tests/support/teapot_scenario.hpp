// A compact teapot scene written with vkrc, for the reliability tests: the
// setup of the teapot benchmark (device, mesh buffers uploaded through
// staging, mapped uniform buffers, a descriptor set per frame, a depth-tested
// pipeline, a ring of offscreen colour+depth targets, command buffers and
// fences) and three frames of record, submit and wait, then a readback.
// Everything it makes is dropped when it returns or throws.
#pragma once

#include <vkrc/vkrc.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace vkrc_test {

struct TeapotScenarioOptions {
    // The allocator of every buffer and image (null: the device's default).
    vkrc::SharedAllocator allocator;
    int frames = 3;
};

// Runs the scene on a new instance made from info; returns the last frame,
// 64 x 64 RGBA8 pixels row by row.
std::vector<std::array<std::uint8_t, 4>> run_teapot_scenario(const vkrc::InstanceCreateInfo& info,
                                                             const TeapotScenarioOptions& options = {});

// The pixels of frame the teapots cover (not the black background).
std::size_t covered_pixels(const std::vector<std::array<std::uint8_t, 4>>& frame);

}  // namespace vkrc_test
