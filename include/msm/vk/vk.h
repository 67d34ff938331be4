// Umbrella header of the msm::vk layer (headless Vulkan 1.3 compute on lavapipe or a GPU).
#pragma once

#include "msm/vk/commands.h"
#include "msm/vk/common.h"
#include "msm/vk/context.h"
#include "msm/vk/graphics.h"
#include "msm/vk/program.h"
#include "msm/vk/resources.h"
#include "msm/vk/shaders.h"
#include "msm/vk/timer.h"
