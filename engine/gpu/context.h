// The Vulkan instance, the chosen device and its one graphics+compute queue.
//
// Device choice: discrete GPU first, then integrated, virtual, CPU (lavapipe). `--device
// NAME|INDEX` or STRATA_DEVICE overrides. What strata needs (64-bit buffer atomics, fragment stores
// and atomics, synchronization2, dynamic rendering, timeline semaphores, ...) is checked up front,
// and a device that lacks any of it is refused with one message that lists everything missing.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>

namespace strata {

// What a device offers of strata's requirements; filled from Vulkan queries or by hand in tests.
struct DeviceCapabilities {
  uint32_t api_version = 0;
  bool shader_int64 = false;
  bool buffer_int64_atomics = false;
  bool shared_int64_atomics = false;
  bool fragment_stores_and_atomics = false;
  bool synchronization2 = false;
  bool dynamic_rendering = false;
  bool maintenance4 = false;
  bool timeline_semaphore = false;
  bool push_descriptor = false;
  bool subgroup_arithmetic_in_compute = false;
  bool graphics_compute_queue_with_timestamps = false;
  // Optional: the driver reports per-pipeline statistics (registers, ...; bench output only).
  bool pipeline_statistics = false;
};

// Names of the requirements `caps` does not meet, in a fixed order; empty when the device is
// usable.
std::vector<std::string> missing_requirements(const DeviceCapabilities& caps);

struct DeviceReport {
  uint32_t index = 0;
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::string driver;
  DeviceCapabilities caps;
  std::vector<std::string> missing;  // missing_requirements(caps)
};

const char* to_string(VkPhysicalDeviceType type);

// Picks a device: by `selector` (an index, or a case-insensitive part of the name) when it is not
// empty, else the best usable type. Throws Error naming the device and what it lacks, or saying
// that no device exists or none matches.
uint32_t choose_device(const std::vector<DeviceReport>& devices, std::string_view selector);

struct ContextOptions {
  std::string device_selector;  // --device; when empty, STRATA_DEVICE is read
  bool validation = false;      // Khronos validation with synchronization validation
  bool quiet = false;           // do not print the chosen device
  std::vector<const char*> instance_extensions;  // e.g. what GLFW needs for a surface
  bool presentation = false;                     // enable VK_KHR_swapchain on the device
};

// Validation-layer messages, collected so that tests can fail on any of them.
class ValidationLog {
 public:
  void add(std::string message);
  std::vector<std::string> take();
  size_t count() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

class Instance {
 public:
  Instance(bool validation, const std::vector<const char*>& extensions);
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  VkInstance handle() const { return instance_; }
  std::vector<DeviceReport> devices() const;
  ValidationLog& validation_log() { return log_; }

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  ValidationLog log_;
};

class Context {
 public:
  explicit Context(const ContextOptions& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_.handle(); }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  const DeviceReport& report() const { return report_; }
  // Pipelines are created with their statistics captured (VK_KHR_pipeline_executable_properties).
  bool pipeline_statistics() const { return report_.caps.pipeline_statistics; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  double timestamp_period_ns() const { return properties_.limits.timestampPeriod; }
  ValidationLog& validation_log() { return instance_.validation_log(); }

  uint32_t memory_type(uint32_t allowed_types, VkMemoryPropertyFlags wanted) const;

  // Records `record` into a fresh command buffer, submits it and waits: for uploads, readbacks and
  // tests, never inside a frame.
  void run_now(const std::function<void(VkCommandBuffer)>& record);
  // The two halves of run_now, for work that returns to the host part-way (GraphRunner::run_split):
  // a fresh command buffer in the recording state; and its submission, a wait, and its release.
  VkCommandBuffer begin_commands();
  void submit_and_wait(VkCommandBuffer cmd);

 private:
  Instance instance_;
  DeviceReport report_;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
};

}  // namespace strata
