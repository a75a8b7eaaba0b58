// A compact teapot scene written with vkrc, for the reliability tests: the
// setup of the teapot benchmark (device, mesh buffers uploaded through
// staging, mapped uniform buffers, a descriptor set per frame, a depth-tested
// pipeline, a ring of offscreen colour+depth targets, command buffers and
// fences) and three frames of record, submit and wait, then a readback.
// Everything it makes is dropped when it returns or throws.
#pragma once

#include <vkrc/vkrc.hpp>

#include <memory>

namespace vkrc_test {

struct TeapotScenarioOptions {
    // The allocator of every buffer and image (null: the device's default).
    vkrc::SharedAllocator allocator;
    int frames = 3;
};

// Runs the scene on a new instance made from info; returns the number of
// pixels of the last frame the teapots covered (a sanity check of the run).
std::size_t run_teapot_scenario(const vkrc::InstanceCreateInfo& info, const TeapotScenarioOptions& options = {});

}  // namespace vkrc_test
