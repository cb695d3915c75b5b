// SPDX-License-Identifier: MIT
// `vkcloth devices`: the Vulkan devices the loader reports, which one a solver would take, and the
// backend `--backend auto` (render, view, the samples) picks on each, with the reason, and the
// solver's per-device layout (buffer access, workgroup size) on the selected one.
#include <fmt/format.h>

#include "commands.hpp"
#include "vkcloth/gpu/backend_choice.hpp"
#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/layout.hpp"

namespace vkcloth::cli {
namespace {

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return "discrete";
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return "integrated";
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return "virtual";
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return "cpu";
  default:
    return "other";
  }
}

int devices_command() {
  auto list = gpu::Context::list_devices();
  if (!list)
    return report(list.error());
  int usable = 0;
  for (const gpu::DeviceInfo& d : *list) {
    fmt::print("{}: {} ({}, Vulkan {}.{}){}\n", d.index, d.name, type_name(d.type),
               VK_API_VERSION_MAJOR(d.api_version), VK_API_VERSION_MINOR(d.api_version),
               d.usable ? "" : " - not usable (needs Vulkan 1.2 and compute)");
    if (d.usable) {
      const gpu::BackendChoice c = gpu::choose_backend(d.type, d.name);
      fmt::print("   auto backend: {}: {}\n", gpu::to_string(c.backend), c.reason);
    }
    usable += d.usable;
  }
  if (usable == 0)
    return report(make_error(ErrorCode::no_device,
                             "no usable Vulkan device (install mesa-vulkan-drivers for lavapipe)"));
  gpu::ContextOptions options;
  options.validation = false;
  auto context = gpu::Context::create(options);
  if (!context)
    return report(context.error());
  fmt::print("selected: {} (set VKCLOTH_DEVICE to a name or an index to choose)\n", context->device_name());
  fmt::print("auto backend there: {} (render, view and the samples; --backend cpu | vulkan to choose)\n",
             gpu::to_string(gpu::choose_backend(*context).backend));
  const gpu::DeviceLayout layout = gpu::device_layout(*context);
  fmt::print("solver layout there: {} reads, workgroups of {} ({}; GpuSolverOptions::buffer_access and "
             "workgroup_size to choose)\n",
             gpu::to_string(layout.access), layout.workgroup_size, layout.reason);
  return exit_ok;
}

} // namespace

void add_devices_command(CLI::App& app, int* exit) {
  CLI::App* cmd = app.add_subcommand(
      "devices", "List the Vulkan devices and the one a solver would use (exit 4 if none)");
  cmd->footer(exit_codes_footer);
  cmd->callback([exit] { *exit = devices_command(); });
}

} // namespace vkcloth::cli
