// Device choice and the requirement check, on hand-made device reports: no device needed.
#include <doctest/doctest.h>

#include "engine/core/error.h"
#include "engine/gpu/context.h"

namespace strata {
namespace {

DeviceCapabilities everything() {
  DeviceCapabilities c;
  c.api_version = VK_API_VERSION_1_3;
  c.shader_int64 = c.buffer_int64_atomics = c.shared_int64_atomics = true;
  c.fragment_stores_and_atomics = true;
  c.synchronization2 = c.dynamic_rendering = c.maintenance4 = c.timeline_semaphore =
      c.push_descriptor = true;
  c.subgroup_arithmetic_in_compute = c.graphics_compute_queue_with_timestamps = true;
  return c;
}

DeviceReport device(uint32_t index, std::string name, VkPhysicalDeviceType type,
                    DeviceCapabilities caps = everything()) {
  return {index, std::move(name), type, "driver", caps, missing_requirements(caps)};
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("missing_requirements_lists_every_missing_feature_at_once") {
    CHECK(missing_requirements(everything()).empty());
    DeviceCapabilities c = everything();
    c.buffer_int64_atomics = false;
    c.synchronization2 = false;
    c.dynamic_rendering = false;
    const auto missing = missing_requirements(c);
    REQUIRE(missing.size() == 3);
    CHECK(missing[0].find("shaderBufferInt64Atomics") != std::string::npos);
    CHECK(missing[1] == "synchronization2");
    CHECK(missing[2] == "dynamicRendering");
  }

  TEST_CASE("choice_prefers_discrete_then_integrated_then_cpu") {
    const std::vector<DeviceReport> devices = {
        device(0, "llvmpipe", VK_PHYSICAL_DEVICE_TYPE_CPU),
        device(1, "Intel UHD", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU),
        device(2, "NVIDIA H100", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)};
    CHECK(choose_device(devices, "") == 2);
    CHECK(choose_device({devices[0], devices[1]}, "") == 1);
    CHECK(choose_device({devices[0]}, "") == 0);
  }

  TEST_CASE("an_unusable_discrete_gpu_is_passed_over_by_default") {
    DeviceCapabilities old = everything();
    old.api_version = VK_API_VERSION_1_2;
    const std::vector<DeviceReport> devices = {
        device(0, "old GPU", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, old),
        device(1, "llvmpipe", VK_PHYSICAL_DEVICE_TYPE_CPU)};
    CHECK(choose_device(devices, "") == 1);
  }

  TEST_CASE("selector_picks_by_index_or_by_part_of_the_name") {
    const std::vector<DeviceReport> devices = {
        device(0, "llvmpipe (LLVM 15)", VK_PHYSICAL_DEVICE_TYPE_CPU),
        device(1, "NVIDIA H100 PCIe", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)};
    CHECK(choose_device(devices, "0") == 0);
    CHECK(choose_device(devices, "LLVMPIPE") == 0);
    CHECK(choose_device(devices, "h100") == 1);
    CHECK_THROWS_WITH_AS(choose_device(devices, "radeon"),
                         doctest::Contains("no Vulkan device matches 'radeon'"), Error);
    CHECK_THROWS_AS(choose_device(devices, "7"), Error);
  }

  TEST_CASE("a_device_lacking_features_is_refused_with_one_message_naming_them") {
    DeviceCapabilities c = everything();
    c.fragment_stores_and_atomics = false;
    c.timeline_semaphore = false;
    const std::vector<DeviceReport> devices = {
        device(0, "tiny GPU", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU, c)};
    CHECK_THROWS_WITH_AS(choose_device(devices, "0"),
                         "device 0 'tiny GPU' lacks what strata needs: fragmentStoresAndAtomics, "
                         "timelineSemaphore",
                         Error);
    CHECK_THROWS_WITH_AS(choose_device(devices, ""), doctest::Contains("no usable Vulkan device"),
                         Error);
  }

  TEST_CASE("no_device_at_all_is_one_clear_error") {
    CHECK_THROWS_WITH_AS(choose_device({}, ""), doctest::Contains("no Vulkan device found"), Error);
  }
}

}  // namespace strata
