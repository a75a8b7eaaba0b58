// The whole of vkrc. Each object family also has its own header.
#pragma once

#include "vkrc/command.hpp"
#include "vkrc/config.hpp"
#include "vkrc/descriptor.hpp"
#include "vkrc/device.hpp"
#include "vkrc/error.hpp"
#include "vkrc/functions.hpp"
#include "vkrc/handle.hpp"
#include "vkrc/instance.hpp"
#include "vkrc/memory.hpp"
#include "vkrc/pipeline.hpp"
#include "vkrc/resource.hpp"
#include "vkrc/shader.hpp"
#include "vkrc/surface.hpp"
#include "vkrc/swapchain.hpp"
#include "vkrc/sync.hpp"
#include "vkrc/upload.hpp"
