// Vulkan results as strata errors: every call that can fail goes through STRATA_VK.
#pragma once

#include <vulkan/vulkan.h>

#include "engine/core/error.h"

namespace strata {

const char* to_string(VkResult result);

// Throws Error("<what> failed: VK_ERROR_...") when a Vulkan call does not return VK_SUCCESS.
void check_vk(VkResult result, const char* what);

}  // namespace strata

#define STRATA_VK(call) ::strata::check_vk((call), #call)
