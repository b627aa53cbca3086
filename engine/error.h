// One error type for everything strata reports to a user: it carries the context (which file,
// which device, which pass) up to the one place in app/ that prints it and exits non-zero.
#pragma once

#include <stdexcept>
#include <string>

#include <vulkan/vulkan.h>

namespace strata {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

const char* to_string(VkResult result);

// Throws Error("<what> failed: VK_ERROR_...") when a Vulkan call does not return VK_SUCCESS.
void check_vk(VkResult result, const char* what);

}  // namespace strata

#define STRATA_VK(call) ::strata::check_vk((call), #call)
