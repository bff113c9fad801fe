// phyxel info: lists every Vulkan physical device with the limits and features that matter to
// the GPU solver, and which one `--device gpu` (or the given --device) would use.
#include <cstdio>
#include <string>

#include "app/commands.h"
#include "compute/context.h"

namespace phyxel::app {
namespace {

void print_usage(std::FILE* out) {
  std::fputs(
      "usage: phyxel info [--validate] [--device SPEC]\n"
      "\n"
      "Lists the Vulkan devices.\n"
      "  --validate     load VK_LAYER_KHRONOS_validation and report what it says\n"
      "  --device SPEC  say which device SPEC selects (gpu, gpu:N or part of a name;\n"
      "                 default gpu)\n"
      "  PHYXEL_VULKAN_LOADER=PATH  open this Vulkan loader instead of libvulkan.so.1\n",
      out);
}

const char* yes_no(bool b) {
  return b ? "yes" : "no";
}

void print_device(const gpu::DeviceInfo& d) {
  std::printf("device %u: %s\n", d.index, d.name.c_str());
  std::printf("  type                  %s\n", gpu::device_type_name(d.type));
  if (!d.driver_name.empty()) {
    std::printf("  driver                %s (%s)\n", d.driver_name.c_str(), d.driver_info.c_str());
  }
  std::printf("  Vulkan API            %s\n", gpu::api_version_string(d.api_version).c_str());
  std::printf("  device-local memory   %s\n", gpu::format_bytes(d.device_local_bytes).c_str());
  std::printf("  max workgroup size    %u x %u x %u, %u invocations\n", d.max_workgroup_size[0],
              d.max_workgroup_size[1], d.max_workgroup_size[2], d.max_workgroup_invocations);
  std::printf("  max workgroup count   %u x %u x %u\n", d.max_workgroup_count[0],
              d.max_workgroup_count[1], d.max_workgroup_count[2]);
  std::printf("  max storage buffer    %s\n",
              gpu::format_bytes(d.max_storage_buffer_range).c_str());
  if (d.max_allocation_size != 0) {
    std::printf("  max allocation        %s\n", gpu::format_bytes(d.max_allocation_size).c_str());
  }
  std::printf("  max push constants    %u bytes\n", d.max_push_constants_size);
  std::printf("  subgroup size         %u\n", d.subgroup_size);
  if (d.timestamps()) {
    std::printf("  timestamps            yes (%u valid bits, %g ns per tick)\n",
                d.timestamp_valid_bits, static_cast<double>(d.timestamp_period_ns));
  } else {
    std::printf("  timestamps            no\n");
  }
  if (d.transfer_queue_family != UINT32_MAX) {
    std::printf("  transfer queue        family %u (frames copied out beside the solver)\n",
                d.transfer_queue_family);
  } else {
    std::printf("  transfer queue        none (frames copied out on the compute queue)\n");
  }
  std::printf("  float64               %s\n", yes_no(d.float64));
  std::printf("  int64 atomics         %s\n", yes_no(d.int64_atomics));
  std::printf("  push descriptors      %s\n", yes_no(d.push_descriptor));
  std::printf("  memory budget         %s\n", yes_no(d.memory_budget));
  const std::string why = d.unusable_reason();
  if (!why.empty()) std::printf("  unusable              %s\n", why.c_str());
}

}  // namespace

int info_command(const Args& args) {
  gpu::InstanceOptions options;
  std::string spec = "gpu";
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--validate") {
      options.validation = true;
    } else if (args[i] == "--device" && i + 1 < args.size()) {
      spec = args[++i];
    } else if (args[i] == "--help" || args[i] == "-h") {
      print_usage(stdout);
      return 0;
    } else {
      std::fprintf(stderr, "phyxel info: unknown argument '%s'\n", args[i].c_str());
      print_usage(stderr);
      return 2;
    }
  }

  // Throws VulkanError with one clear line when there is no loader or no driver; main()
  // prints it and exits 1.
  const gpu::Instance instance(options);
  const auto& devices = instance.devices();
  if (devices.empty()) gpu::select_device(devices, spec);  // throws the one-line "no device"
  std::printf("Vulkan loader %s (%s), instance API %s, %zu device%s\n",
              gpu::api_version_string(instance.loader_version()).c_str(),
              instance.loader_path().c_str(),
              gpu::api_version_string(instance.api_version()).c_str(), devices.size(),
              devices.size() == 1 ? "" : "s");
  for (const gpu::DeviceInfo& d : devices) print_device(d);
  const uint32_t chosen = gpu::select_device(devices, spec);
  std::printf("--device %s selects device %u (%s)\n", spec.c_str(), chosen,
              devices[chosen].name.c_str());
  if (instance.validation()) {
    const auto log = instance.validation_log();
    std::printf("validation: %u errors, %u warnings\n", log->error_count(), log->warning_count());
    if (log->error_count() > 0) return 1;
  }
  return 0;
}

}  // namespace phyxel::app
