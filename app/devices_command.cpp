#include <cstdio>

#include "app/commands.h"

namespace strata::app {

void add_devices_command(CLI::App& app, DeviceOptions& device) {
  CLI::App* cmd =
      app.add_subcommand("devices", "List Vulkan devices and whether strata can use each");
  cmd->callback([&device] {
    const ContextOptions options = device.context();
    Instance instance(options.validation, {});
    const std::vector<DeviceReport> devices = instance.devices();
    if (devices.empty()) {
      choose_device(devices, "");  // throws the one message for this case
    }
    std::string chosen_error;
    int chosen = -1;
    try {
      chosen = static_cast<int>(choose_device(devices, options.device_selector));
    } catch (const strata::Error& e) {
      chosen_error = e.what();
    }
    for (const DeviceReport& d : devices) {
      std::printf("%s%u: %s (%s), Vulkan %u.%u.%u, driver %s\n",
                  int(d.index) == chosen ? "* " : "  ", d.index, d.name.c_str(), to_string(d.type),
                  VK_API_VERSION_MAJOR(d.caps.api_version),
                  VK_API_VERSION_MINOR(d.caps.api_version),
                  VK_API_VERSION_PATCH(d.caps.api_version), d.driver.c_str());
      if (d.missing.empty()) {
        std::printf("     usable: has everything strata needs\n");
        std::printf("     optional: conditional rendering %s, pipeline statistics %s\n",
                    d.caps.conditional_rendering ? "yes" : "no",
                    d.caps.pipeline_statistics ? "yes" : "no");
      } else {
        std::printf("     not usable, lacks:");
        for (const auto& m : d.missing) std::printf(" [%s]", m.c_str());
        std::printf("\n");
      }
    }
    if (chosen < 0) throw strata::Error(chosen_error);
    std::printf("* = the device strata uses\n");
  });
}

}  // namespace strata::app
