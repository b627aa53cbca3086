// One error type for everything strata reports to a user: it carries the context (which file,
// which device, which pass) up to the one place in app/ that prints it and exits non-zero.
// Plain C++: the scene library uses it without Vulkan (engine/gpu/vulkan_check.h adds the
// VkResult check).
#pragma once

#include <stdexcept>
#include <string>

namespace strata {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace strata
