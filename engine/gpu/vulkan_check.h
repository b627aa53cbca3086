// Vulkan results as strata errors: every call that can fail goes through STRATA_VK.
#pragma once

#include <string>

#include <vulkan/vulkan.h>

#include "engine/core/error.h"

namespace strata {

const char* to_string(VkResult result);

// The device is gone (VK_ERROR_DEVICE_LOST: the driver gave it up after a hang or a fault).
// Nothing submitted to it will finish; the program reports it and ends. `when` says what strata
// was doing ("in vkQueueSubmit2", "during frame 42"), so a caller that knows more (the viewer's
// frame number) throws it again with its own.
class DeviceLost : public Error {
 public:
  explicit DeviceLost(const std::string& when);
  const std::string& when() const { return when_; }

 private:
  std::string when_;
};

// A wait for the GPU that took longer than Context::gpu_timeout(): the device seems hung.
class GpuTimeout : public Error {
 public:
  using Error::Error;
};

// Throws Error("<what> failed: VK_ERROR_...") when a Vulkan call does not return VK_SUCCESS, and
// DeviceLost for VK_ERROR_DEVICE_LOST.
void check_vk(VkResult result, const char* what);

}  // namespace strata

#define STRATA_VK(call) ::strata::check_vk((call), #call)
