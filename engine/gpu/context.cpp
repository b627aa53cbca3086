#include "engine/gpu/context.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "engine/gpu/vulkan_check.h"

namespace strata {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL
on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  std::string message = data->pMessage ? data->pMessage : "(no message)";
  std::fprintf(stderr, "strata: validation: %s\n", message.c_str());
  static_cast<ValidationLog*>(user)->add(std::move(message));
  return VK_FALSE;
}

bool has_layer(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

bool has_device_extension(VkPhysicalDevice device, const char* name) {
  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  return std::any_of(extensions.begin(), extensions.end(), [&](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, name) == 0;
  });
}

std::vector<VkQueueFamilyProperties> queue_families(VkPhysicalDevice device) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  return families;
}

// The first queue family with all of `need`, none of `exclude`, and timestamps; -1 if none.
int queue_family_with(VkPhysicalDevice device, VkQueueFlags need, VkQueueFlags exclude) {
  const std::vector<VkQueueFamilyProperties> families = queue_families(device);
  for (size_t i = 0; i < families.size(); ++i) {
    const VkQueueFlags flags = families[i].queueFlags;
    if ((flags & need) == need && (flags & exclude) == 0u && families[i].timestampValidBits > 0) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

// The family of the frames' queue: graphics and compute.
int graphics_compute_family(VkPhysicalDevice device) {
  return queue_family_with(device, VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT, 0);
}

// A family for the placement beside the frames: compute without graphics (asynchronous compute).
int compute_only_family(VkPhysicalDevice device) {
  return queue_family_with(device, VK_QUEUE_COMPUTE_BIT, VK_QUEUE_GRAPHICS_BIT);
}

uint32_t queue_count(VkPhysicalDevice device, uint32_t family) {
  return queue_families(device).at(family).queueCount;
}

// Whether the device has `extension` and its feature `flag`, asked through `feature` (the
// extension's feature struct).
template <typename Feature>
bool has_feature(VkPhysicalDevice device, const char* extension, Feature feature,
                 VkBool32 Feature::*flag) {
  if (!has_device_extension(device, extension)) return false;
  VkPhysicalDeviceFeatures2 query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &feature};
  vkGetPhysicalDeviceFeatures2(device, &query);
  return feature.*flag == VK_TRUE;
}

DeviceReport describe(VkPhysicalDevice device, uint32_t index) {
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES,
                                              &driver};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &subgroup};
  vkGetPhysicalDeviceProperties2(device, &props);
  const bool is13 = props.properties.apiVersion >= VK_API_VERSION_1_3;
  if (is13) vkGetPhysicalDeviceFeatures2(device, &features);

  DeviceReport report;
  report.index = index;
  report.name = props.properties.deviceName;
  report.type = props.properties.deviceType;
  report.driver = std::string(driver.driverName) + " " + driver.driverInfo;
  DeviceCapabilities& caps = report.caps;
  caps.api_version = props.properties.apiVersion;
  caps.shader_int64 = features.features.shaderInt64;
  caps.buffer_int64_atomics = f12.shaderBufferInt64Atomics;
  caps.shared_int64_atomics = f12.shaderSharedInt64Atomics;
  caps.fragment_stores_and_atomics = features.features.fragmentStoresAndAtomics;
  caps.timeline_semaphore = f12.timelineSemaphore;
  caps.synchronization2 = f13.synchronization2;
  caps.dynamic_rendering = f13.dynamicRendering;
  caps.maintenance4 = f13.maintenance4;
  caps.push_descriptor = has_device_extension(device, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  caps.subgroup_arithmetic_in_compute =
      (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
      (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT);
  caps.graphics_compute_queue_with_timestamps = graphics_compute_family(device) >= 0;
  caps.pipeline_statistics =
      is13 &&
      has_feature(
          device, VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME,
          VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR{
              VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR},
          &VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR::pipelineExecutableInfo);
  caps.conditional_rendering =
      is13 && has_feature(device, VK_EXT_CONDITIONAL_RENDERING_EXTENSION_NAME,
                          VkPhysicalDeviceConditionalRenderingFeaturesEXT{
                              VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONDITIONAL_RENDERING_FEATURES_EXT},
                          &VkPhysicalDeviceConditionalRenderingFeaturesEXT::conditionalRendering);
  report.missing = missing_requirements(caps);
  return report;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

int type_rank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

std::string unusable(const DeviceReport& d) {
  return "device " + std::to_string(d.index) + " '" + d.name +
         "' lacks what strata needs: " + join(d.missing);
}

// 10 s on GPUs, 300 s on CPU devices, or STRATA_GPU_TIMEOUT seconds (Context::gpu_timeout()).
std::chrono::nanoseconds gpu_timeout_for(VkPhysicalDeviceType type) {
  double seconds = type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 300.0 : 10.0;
  if (const char* env = std::getenv("STRATA_GPU_TIMEOUT")) {
    char* end = nullptr;
    seconds = std::strtod(env, &end);
    if (end == env || *end != '\0' || !(seconds > 0.0 && seconds < 1e6)) {
      throw Error(std::string("STRATA_GPU_TIMEOUT: '") + env +
                  "' is not a number of seconds (above 0, below 1000000)");
    }
  }
  return std::chrono::nanoseconds(static_cast<int64_t>(seconds * 1e9));
}

}  // namespace

std::vector<std::string> missing_requirements(const DeviceCapabilities& caps) {
  std::vector<std::string> missing;
  auto need = [&](bool ok, const char* what) {
    if (!ok) missing.emplace_back(what);
  };
  need(caps.api_version >= VK_API_VERSION_1_3, "Vulkan 1.3");
  need(caps.shader_int64, "shaderInt64");
  need(caps.buffer_int64_atomics, "shaderBufferInt64Atomics (64-bit buffer atomics)");
  need(caps.shared_int64_atomics, "shaderSharedInt64Atomics (64-bit shared memory atomics)");
  need(caps.fragment_stores_and_atomics, "fragmentStoresAndAtomics");
  need(caps.synchronization2, "synchronization2");
  need(caps.dynamic_rendering, "dynamicRendering");
  need(caps.maintenance4, "maintenance4");
  need(caps.timeline_semaphore, "timelineSemaphore");
  need(caps.push_descriptor, "VK_KHR_push_descriptor");
  need(caps.subgroup_arithmetic_in_compute, "subgroup arithmetic in compute shaders");
  need(caps.graphics_compute_queue_with_timestamps,
       "a graphics+compute queue with timestamp queries");
  return missing;
}

const char* to_string(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

uint32_t choose_device(const std::vector<DeviceReport>& devices, std::string_view selector) {
  if (devices.empty()) {
    throw Error(
        "no Vulkan device found (is a Vulkan driver installed? on Debian: mesa-vulkan-drivers)");
  }
  if (!selector.empty()) {
    uint32_t index = 0;
    const auto [end, ec] =
        std::from_chars(selector.data(), selector.data() + selector.size(), index);
    const bool numeric = ec == std::errc() && end == selector.data() + selector.size();
    const DeviceReport* match = nullptr;
    for (const auto& d : devices) {
      if (numeric ? d.index == index : lower(d.name).find(lower(selector)) != std::string::npos) {
        match = &d;
        break;
      }
    }
    if (!match) {
      throw Error("no Vulkan device matches '" + std::string(selector) + "' (" +
                  std::to_string(devices.size()) + " found; 'strata devices' lists them)");
    }
    if (!match->missing.empty()) throw Error(unusable(*match));
    return match->index;
  }
  const DeviceReport* best = nullptr;
  for (const auto& d : devices) {
    if (d.missing.empty() && (!best || type_rank(d.type) < type_rank(best->type))) best = &d;
  }
  if (!best) {
    std::string why;
    for (const auto& d : devices) why += "\n  " + unusable(d);
    throw Error("no usable Vulkan device:" + why);
  }
  return best->index;
}

void ValidationLog::add(std::string message) {
  std::lock_guard lock(mutex_);
  messages_.push_back(std::move(message));
}

std::vector<std::string> ValidationLog::take() {
  std::lock_guard lock(mutex_);
  return std::exchange(messages_, {});
}

size_t ValidationLog::count() const {
  std::lock_guard lock(mutex_);
  return messages_.size();
}

Instance::Instance(bool validation, const std::vector<const char*>& extensions) {
  if (validation && !has_layer(kValidationLayer)) {
    throw Error(std::string("validation was asked for but ") + kValidationLayer +
                " is not installed (Debian: vulkan-validationlayers)");
  }
  std::vector<const char*> exts = extensions;
  if (validation) exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "strata";
  app.apiVersion = VK_API_VERSION_1_3;

  VkDebugUtilsMessengerCreateInfoEXT messenger{
      VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;  // not performance hints
  messenger.pfnUserCallback = on_validation_message;
  messenger.pUserData = &log_;

  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT, &messenger};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pNext = validation ? &features : nullptr;
  info.pApplicationInfo = &app;
  info.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  info.ppEnabledExtensionNames = exts.data();
  info.enabledLayerCount = validation ? 1 : 0;
  info.ppEnabledLayerNames = &kValidationLayer;
  const VkResult result = vkCreateInstance(&info, nullptr, &instance_);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
    throw Error("no Vulkan 1.3 driver found (on Debian: mesa-vulkan-drivers)");
  }
  check_vk(result, "vkCreateInstance");
  if (validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    check_vk(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
}

Instance::~Instance() {
  if (abandoned_) return;
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
  }
  vkDestroyInstance(instance_, nullptr);
}

std::vector<DeviceReport> Instance::devices() const {
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> handles(count);
  vkEnumeratePhysicalDevices(instance_, &count, handles.data());
  std::vector<DeviceReport> reports;
  for (uint32_t i = 0; i < count; ++i) reports.push_back(describe(handles[i], i));
  return reports;
}

namespace {

VkPhysicalDevice physical_device_at(VkInstance instance, uint32_t index) {
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> handles(count);
  vkEnumeratePhysicalDevices(instance, &count, handles.data());
  return handles[index];
}

// The features strata needs, chained from `features`, with those of the optional extensions the
// device has; the extensions to enable with them. Not copied: the chain points into it.
struct DeviceFeatures {
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executables{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  VkPhysicalDeviceConditionalRenderingFeaturesEXT conditional{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONDITIONAL_RENDERING_FEATURES_EXT};
  std::vector<const char*> extensions = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};

  DeviceFeatures(const DeviceCapabilities& caps, bool presentation, bool memory_budget) {
    f13.synchronization2 = VK_TRUE;
    f13.dynamicRendering = VK_TRUE;
    f13.maintenance4 =
        VK_TRUE;  // core in 1.3; SPIR-V 1.6 declares workgroup sizes with LocalSizeId
    f12.pNext = &f13;
    f12.shaderBufferInt64Atomics = VK_TRUE;
    f12.shaderSharedInt64Atomics = VK_TRUE;
    f12.timelineSemaphore = VK_TRUE;
    features.pNext = &f12;
    features.features.shaderInt64 = VK_TRUE;
    features.features.fragmentStoresAndAtomics = VK_TRUE;
    if (presentation) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    if (memory_budget) extensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
    executables.pipelineExecutableInfo = VK_TRUE;
    if (caps.pipeline_statistics) {
      enable(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME, executables);
    }
    conditional.conditionalRendering = VK_TRUE;
    if (caps.conditional_rendering)
      enable(VK_EXT_CONDITIONAL_RENDERING_EXTENSION_NAME, conditional);
  }
  DeviceFeatures(const DeviceFeatures&) = delete;
  DeviceFeatures& operator=(const DeviceFeatures&) = delete;

  // An optional extension the device has, its feature struct chained in.
  template <class Feature>
  void enable(const char* extension, Feature& feature) {
    extensions.push_back(extension);
    feature.pNext = f13.pNext;
    f13.pNext = &feature;
  }
};

struct DeviceQueues {
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;            // the frames'
  VkQueue placement_queue = VK_NULL_HANDLE;  // the placement's beside them (or the frames')
  uint32_t placement_family = 0;
};

// The placement beside the frames gets a queue of a compute-only family (asynchronous compute)
// or else a second one of the frames' family, where the device has either (the frames' queue
// first: the placement may wait, the picture not).
DeviceQueues create_device(VkPhysicalDevice physical, uint32_t family,
                           const DeviceFeatures& features) {
  DeviceQueues out;
  const float priorities[] = {1.0f, 0.5f};
  const int compute = compute_only_family(physical);
  out.placement_family = compute >= 0 ? uint32_t(compute) : family;
  VkDeviceQueueCreateInfo queues[2] = {{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO},
                                       {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO}};
  queues[0].queueFamilyIndex = family;
  queues[0].queueCount = compute < 0 && queue_count(physical, family) >= 2 ? 2 : 1;
  queues[0].pQueuePriorities = priorities;
  queues[1].queueFamilyIndex = out.placement_family;
  queues[1].queueCount = 1;
  queues[1].pQueuePriorities = priorities + 1;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &features.features};
  info.queueCreateInfoCount = compute >= 0 ? 2 : 1;
  info.pQueueCreateInfos = queues;
  info.enabledExtensionCount = static_cast<uint32_t>(features.extensions.size());
  info.ppEnabledExtensionNames = features.extensions.data();
  STRATA_VK(vkCreateDevice(physical, &info, nullptr, &out.device));
  vkGetDeviceQueue(out.device, family, 0, &out.queue);
  out.placement_queue = out.queue;
  if (compute >= 0) {
    vkGetDeviceQueue(out.device, out.placement_family, 0, &out.placement_queue);
  } else if (queues[0].queueCount == 2) {
    vkGetDeviceQueue(out.device, family, 1, &out.placement_queue);
  }
  return out;
}

}  // namespace

Context::Context(const ContextOptions& options)
    : instance_(options.validation, options.instance_extensions) {
  std::string selector = options.device_selector;
  if (selector.empty()) {
    if (const char* env = std::getenv("STRATA_DEVICE")) selector = env;
  }
  const std::vector<DeviceReport> reports = instance_.devices();
  const uint32_t index = choose_device(reports, selector);
  report_ = reports[index];
  physical_ = physical_device_at(instance_.handle(), index);
  VkPhysicalDeviceVulkan13Properties p13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
  VkPhysicalDeviceVulkan11Properties p11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES,
                                         &p13};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p11};
  vkGetPhysicalDeviceProperties2(physical_, &props);
  properties_ = props.properties;
  max_allocation_ = p11.maxMemoryAllocationSize;
  max_buffer_ = p13.maxBufferSize;
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
  heap_bytes_.assign(memory_.memoryHeapCount, 0);
  timeout_ = gpu_timeout_for(report_.type);
  queue_family_ = static_cast<uint32_t>(graphics_compute_family(physical_));
  if (!options.quiet) {
    std::fprintf(stderr, "strata: device %u: %s (%s)\n", index, report_.name.c_str(),
                 to_string(report_.type));
  }

  memory_budget_ = has_device_extension(physical_, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
  const DeviceFeatures features(report_.caps, options.presentation, memory_budget_);
  const DeviceQueues queues = create_device(physical_, queue_family_, features);
  device_ = queues.device;
  queue_ = queues.queue;
  placement_queue_ = queues.placement_queue;
  placement_family_ = queues.placement_family;

  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = queue_family_;
  STRATA_VK(vkCreateCommandPool(device_, &pool, nullptr, &pool_));
}

Context::~Context() {
  if (!device_) return;
  if (!drain() && !lost_) {
    // A wait timed out: the GPU may still run work that uses the device. It is left to the
    // process's end (which follows: the error is being reported), not destroyed under the work.
    instance_.abandon();
    return;
  }
  vkDestroyCommandPool(device_, pool_, nullptr);
  vkDestroyDevice(device_, nullptr);
}

uint32_t Context::memory_type(uint32_t allowed_types, VkMemoryPropertyFlags wanted,
                              VkMemoryPropertyFlags preferred) const {
  for (const VkMemoryPropertyFlags flags : {wanted | preferred, wanted}) {
    for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
      if ((allowed_types & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & flags) == flags) {
        return i;
      }
    }
  }
  throw Error("device '" + report_.name + "' has no memory type with the properties needed");
}

void Context::run_now(const std::function<void(VkCommandBuffer)>& record) {
  const VkCommandBuffer cmd = begin_commands();
  try {
    record(cmd);
  } catch (...) {
    // (a recording that failed, e.g. on an undeclared resource, leaves nothing behind)
    vkEndCommandBuffer(cmd);
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
    throw;
  }
  submit_and_wait(cmd);
}

VkCommandBuffer Context::begin_commands() {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  STRATA_VK(vkAllocateCommandBuffers(device_, &alloc, &cmd));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  STRATA_VK(vkBeginCommandBuffer(cmd, &begin));
  return cmd;
}

void Context::submit_and_wait(VkCommandBuffer cmd) {
  STRATA_VK(vkEndCommandBuffer(cmd));

  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  STRATA_VK(vkCreateFence(device_, &fence_info, nullptr, &fence));
  VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cmd_info.commandBuffer = cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cmd_info;
  const VkResult result = vkQueueSubmit2(queue_, 1, &submit, fence);
  if (result == VK_ERROR_DEVICE_LOST) lost_ = true;
  const auto release = [&] {
    vkDestroyFence(device_, fence, nullptr);
    vkFreeCommandBuffers(device_, pool_, 1, &cmd);
  };
  try {
    if (result == VK_SUCCESS) wait_for(fence, "a one-off submission (an upload, a readback)");
  } catch (...) {
    if (may_destroy()) release();  // (else the GPU may still use them)
    throw;
  }
  release();
  check_vk(result, "vkQueueSubmit2");
}

void Context::wait_for(VkFence fence, const std::string& what) {
  const VkResult result =
      vkWaitForFences(device_, 1, &fence, VK_TRUE, static_cast<uint64_t>(timeout_.count()));
  if (result == VK_SUCCESS) {
    hung_ = false;
    return;
  }
  if (result == VK_TIMEOUT) {
    hung_ = true;
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%g", std::chrono::duration<double>(timeout_).count());
    throw GpuTimeout("the GPU did not finish " + what + " within " + seconds +
                     " s (VK_TIMEOUT): the device seems hung (STRATA_GPU_TIMEOUT=SECONDS waits "
                     "longer)");
  }
  if (result == VK_ERROR_DEVICE_LOST) {
    lost_ = true;
    throw DeviceLost("while waiting for " + what);
  }
  check_vk(result, "vkWaitForFences");
}

void Context::wait_idle(const std::string& what) {
  if (placement_queue_ != queue_) wait_queue_idle(placement_queue_, what);
  wait_queue_idle(queue_, what);
}

void Context::wait_queue_idle(VkQueue queue, const std::string& what) {
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  STRATA_VK(vkCreateFence(device_, &fence_info, nullptr, &fence));
  // (no command buffers: the fence signals once everything submitted before it has finished)
  const VkResult result = vkQueueSubmit2(queue, 0, nullptr, fence);
  if (result == VK_ERROR_DEVICE_LOST) lost_ = true;
  try {
    check_vk(result, "vkQueueSubmit2");
    wait_for(fence, what);
  } catch (...) {
    if (may_destroy()) vkDestroyFence(device_, fence, nullptr);
    throw;
  }
  vkDestroyFence(device_, fence, nullptr);
}

bool Context::drain() noexcept {
  if (lost_ || hung_) return false;
  try {
    wait_idle("the work in flight");
    return true;
  } catch (...) {
    return false;
  }
}

void Context::check_allocation(VkDeviceSize bytes, uint32_t type, const char* what) const {
  const std::string amount = std::string(what) + " of " + std::to_string(bytes) + " bytes";
  if (max_allocation_ != 0 && bytes > max_allocation_) {
    throw Error(amount + " is more than device '" + report_.name +
                "' allocates at once (maxMemoryAllocationSize: " + std::to_string(max_allocation_) +
                " bytes)");
  }
  const uint32_t heap = memory_.memoryTypes[type].heapIndex;
  const VkDeviceSize size = memory_.memoryHeaps[heap].size;
  VkDeviceSize held = 0;
  {
    std::lock_guard lock(memory_mutex_);
    held = heap_bytes_[heap];
  }
  if (held + bytes > size) {
    throw Error(amount + ", with the " + std::to_string(held) +
                " bytes strata holds already, is more than device '" + report_.name +
                "' has in memory heap " + std::to_string(heap) + " (" + std::to_string(size) +
                " bytes)");
  }
}

void Context::count_allocation(uint32_t type, VkDeviceSize bytes) noexcept {
  std::lock_guard lock(memory_mutex_);
  heap_bytes_[memory_.memoryTypes[type].heapIndex] += bytes;
  use_.bytes += bytes;
  ++use_.allocations;
  use_.peak = std::max(use_.peak, use_.bytes);
}

void Context::count_free(uint32_t type, VkDeviceSize bytes) noexcept {
  std::lock_guard lock(memory_mutex_);
  heap_bytes_[memory_.memoryTypes[type].heapIndex] -= bytes;
  use_.bytes -= bytes;
  --use_.allocations;
}

DeviceMemoryUse Context::memory_use() const {
  std::lock_guard lock(memory_mutex_);
  return use_;
}

std::optional<VkDeviceSize> Context::heap_usage() const {
  if (!memory_budget_) return std::nullopt;
  VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
  VkPhysicalDeviceMemoryProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2,
                                          &budget};
  vkGetPhysicalDeviceMemoryProperties2(physical_, &props);
  VkDeviceSize used = 0;
  for (uint32_t h = 0; h < props.memoryProperties.memoryHeapCount; ++h) {
    used += budget.heapUsage[h];
  }
  return used;
}

}  // namespace strata
