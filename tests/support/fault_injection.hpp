// Fault injection: wraps every Vulkan entry point vkrc loads, so that the k-th
// call returning VkResult fails with a chosen error. Lives in the tests only:
// vkrc takes the wrapper through InstanceCreateInfo::get_instance_proc_addr,
// the same hook any application has, and its hot path is untouched.
#pragma once

#include <vulkan/vulkan_core.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vkrc_test::faults {

// Pass as InstanceCreateInfo::get_instance_proc_addr. Device-level functions
// are wrapped too, through the vkGetDeviceProcAddr it hands out.
PFN_vkGetInstanceProcAddr get_instance_proc_addr();

// From now on, the call-th failable call (1-based) returns error; 0 disarms.
// VK_ERROR_DEVICE_LOST is simulated faithfully: before returning it the
// wrapper waits for the device to finish its work (a lost device runs
// nothing), so destroying what was in use is then valid.
void arm(std::uint64_t call, VkResult error);
// The same for the first call of the function named name (after
// end_of_setup() when after_setup).
void arm_function(const char* name, VkResult error, bool after_setup);
// Every call of the function named name fails with error, until the next
// arm() (e.g. vkAllocateMemory while the device is out of memory).
void fail_every(const char* name, VkResult error);
// The device is lost from now on (until the next arm()): its work so far is
// finished, and every call that reports loss (submits, waits, status
// queries, present, acquire) returns VK_ERROR_DEVICE_LOST; other calls work.
void lose_device();
// The same without waiting for the device's work first: what was submitted
// keeps running on lavapipe (behind a gate, it waits), while vkrc sees the
// loss. finish_real_work() then waits for it through the real vkDeviceWaitIdle.
void lose_device_in_flight();
void finish_real_work();
// Failable calls made since the last arm().
std::uint64_t failable_calls();
// Whether the armed failure has been returned, and by which function.
bool fired();
const char* fired_in();

// The wrapped functions that return VkResult (the ones a failure can be
// injected into), by name.
std::vector<std::string> failable_functions();
// The failable functions called since the last forget_called(), by name
// (after_setup: only those called after end_of_setup()): a scenario's
// reference run names what its injection runs will fail.
std::vector<std::string> called_functions(bool after_setup = false);
void forget_called();

// Marks the end of a scenario's setup (instance, device): the calls before
// it are those of every scenario, injected already by the teapot scene's
// test, so the other scenarios' tests start injecting after it.
void end_of_setup();
// The failable calls made before end_of_setup() since the last arm() (0: not marked).
std::uint64_t setup_calls();

// While on, vkGetPhysicalDeviceMemoryProperties(2) report every host-visible
// memory type without HOST_COHERENT, so that vkrc flushes and invalidates
// (lavapipe has coherent memory only; flushing it is valid all the same).
void hide_host_coherence(bool on);

}  // namespace vkrc_test::faults
