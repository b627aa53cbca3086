#include "engine/gpu/vulkan_check.h"

namespace strata {

const char* to_string(VkResult result) {
  switch (result) {
#define STRATA_RESULT(name) \
  case name:                \
    return #name;
    STRATA_RESULT(VK_SUCCESS)
    STRATA_RESULT(VK_NOT_READY)
    STRATA_RESULT(VK_TIMEOUT)
    STRATA_RESULT(VK_INCOMPLETE)
    STRATA_RESULT(VK_SUBOPTIMAL_KHR)
    STRATA_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    STRATA_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    STRATA_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    STRATA_RESULT(VK_ERROR_DEVICE_LOST)
    STRATA_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    STRATA_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    STRATA_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    STRATA_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    STRATA_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    STRATA_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    STRATA_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    STRATA_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    STRATA_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    STRATA_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
#undef STRATA_RESULT
    default:
      return "VK_ERROR_(unknown)";
  }
}

DeviceLost::DeviceLost(const std::string& when)
    : Error("the GPU device was lost (VK_ERROR_DEVICE_LOST) " + when +
            "; the driver gave it up after a hang or a fault (the kernel log, e.g. `journalctl "
            "-k`, may say which), and nothing submitted to it will finish"),
      when_(when) {}

void check_vk(VkResult result, const char* what) {
  if (result == VK_SUCCESS) return;
  if (result == VK_ERROR_DEVICE_LOST) {
    // (the call's name up to its argument list: "in vkQueueSubmit2")
    const std::string call(what);
    throw DeviceLost("in " + call.substr(0, call.find('(')));
  }
  throw Error(std::string(what) + " failed: " + to_string(result));
}

}  // namespace strata
