// The Vulkan instance, the chosen device, its graphics+compute queue and, where it has one, a
// second queue (compute-only where it can) for the placement beside the frames.
//
// Device choice: discrete GPU first, then integrated, virtual, CPU (lavapipe). `--device
// NAME|INDEX` or STRATA_DEVICE overrides. What strata needs (64-bit buffer atomics, fragment stores
// and atomics, synchronization2, dynamic rendering, timeline semaphores, ...) is checked up front,
// and a device that lacks any of it is refused with one message that lists everything missing.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
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
  // Optional: dispatches skipped by a predicate the GPU wrote (VK_EXT_conditional_rendering; the
  // tidy-up's idle rounds).
  bool conditional_rendering = false;
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
  // Left to the process's end, not destroyed (a device that may still run work is left with it).
  void abandon() { abandoned_ = true; }

 private:
  bool abandoned_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  ValidationLog log_;
};

// What strata's own Buffers and Images hold in device memory (VkDeviceMemory), live now.
struct DeviceMemoryUse {
  VkDeviceSize bytes = 0;    // all heaps
  uint64_t allocations = 0;  // VkDeviceMemory objects
  VkDeviceSize peak = 0;     // the most `bytes` has been
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
  // The queue a placement beside the frames is submitted to: one of a compute-only family where
  // the device has one (asynchronous compute: it runs alongside the frames), else a second queue
  // of the frames' family, else the frames' own queue.
  VkQueue placement_queue() const { return placement_queue_; }
  uint32_t placement_family() const { return placement_family_; }
  bool separate_placement_queue() const { return placement_queue_ != queue_; }
  const DeviceReport& report() const { return report_; }
  // Pipelines are created with their statistics captured (VK_KHR_pipeline_executable_properties).
  bool pipeline_statistics() const { return report_.caps.pipeline_statistics; }
  // VK_EXT_conditional_rendering is enabled (graph::Use::conditional).
  bool conditional_rendering() const { return report_.caps.conditional_rendering; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  double timestamp_period_ns() const { return properties_.limits.timestampPeriod; }
  ValidationLog& validation_log() { return instance_.validation_log(); }

  // The first memory type with `wanted` and `preferred` among `allowed_types`, else the first
  // with `wanted`.
  uint32_t memory_type(uint32_t allowed_types, VkMemoryPropertyFlags wanted,
                       VkMemoryPropertyFlags preferred = 0) const;

  // Records `record` into a fresh command buffer, submits it and waits: for uploads, readbacks and
  // tests, never inside a frame.
  void run_now(const std::function<void(VkCommandBuffer)>& record);

  // Every wait for the GPU ends within this, or it is a GpuTimeout naming what was waited for:
  // a hung device ends with a message, not a hang. 10 s on GPUs (their drivers reset a hung
  // device sooner, which is VK_ERROR_DEVICE_LOST); 300 s on CPU devices, where one frame of a
  // large image takes tens of seconds. STRATA_GPU_TIMEOUT (seconds) sets it.
  std::chrono::nanoseconds gpu_timeout() const { return timeout_; }
  void set_gpu_timeout(std::chrono::nanoseconds timeout) { timeout_ = timeout; }
  // Waits for `fence`; GpuTimeout or DeviceLost naming `what` ("frame 12") when it does not end.
  void wait_for(VkFence fence, const std::string& what);
  // Waits until the queues have finished all work submitted so far (a fence submitted behind the
  // work of each: it signals after everything before it), like wait_for.
  void wait_idle(const std::string& what);
  // For destructors: wait_idle that never throws. False when the device is lost or a wait timed
  // out; then nothing is waited for, and objects the GPU may still use are left, not destroyed.
  bool drain() noexcept;
  // The device was lost, or the last wait timed out (a later wait that finishes clears it).
  bool lost() const { return lost_; }
  bool hung() const { return hung_; }
  // Whether objects may be destroyed: the GPU is not still running work that uses them.
  bool may_destroy() const { return lost_ || !hung_; }

  // Device memory: a check before each allocation, and the running count (Buffer, Image).
  // Throws an Error naming the limit when `bytes` of memory type `type` can never be had: more
  // than maxMemoryAllocationSize, or with what strata holds already more than the type's heap.
  void check_allocation(VkDeviceSize bytes, uint32_t type, const char* what) const;
  void count_allocation(uint32_t type, VkDeviceSize bytes) noexcept;
  void count_free(uint32_t type, VkDeviceSize bytes) noexcept;
  DeviceMemoryUse memory_use() const;
  // The driver's own count of the device memory this process uses, all heaps (ImGui's buffers
  // and driver-internal memory included), when the device has VK_EXT_memory_budget.
  std::optional<VkDeviceSize> heap_usage() const;
  VkDeviceSize max_allocation() const { return max_allocation_; }
  VkDeviceSize max_buffer() const { return max_buffer_; }

 private:
  // run_now's halves: a fresh command buffer in the recording state; its submission, a wait and
  // its release.
  VkCommandBuffer begin_commands();
  void submit_and_wait(VkCommandBuffer cmd);
  void wait_queue_idle(VkQueue queue, const std::string& what);

  Instance instance_;
  DeviceReport report_;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkQueue placement_queue_ = VK_NULL_HANDLE;
  uint32_t placement_family_ = 0;
  uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::chrono::nanoseconds timeout_{0};
  bool lost_ = false, hung_ = false;
  bool memory_budget_ = false;  // VK_EXT_memory_budget enabled
  VkDeviceSize max_allocation_ = 0, max_buffer_ = 0;
  mutable std::mutex memory_mutex_;
  std::vector<VkDeviceSize> heap_bytes_;  // per heap: strata's live allocations
  DeviceMemoryUse use_;
};

}  // namespace strata
