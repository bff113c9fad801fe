// What a pipeline needs to know of a SPIR-V module, read from its words: the workgroup size and
// the descriptor bindings (set, binding, type, count, name). Pipeline checks the layout it
// declares against them once, at creation, so a pass cannot bind what its shader does not read.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "compute/vk_check.h"

namespace phyxel::gpu {

// SPIR-V words embedded in the binary.
struct ShaderCode {
  const uint32_t* words = nullptr;
  size_t bytes = 0;
  const char* name = "";
};

// The ShaderCode of a shader compiled by phyxel_add_shaders (after including its header).
#define PHYXEL_SHADER(name)                             \
  ::phyxel::gpu::ShaderCode {                           \
    phyxel_spv_##name, sizeof(phyxel_spv_##name), #name \
  }

// One descriptor binding of a shader.
struct SpirvBinding {
  uint32_t set = 0;
  uint32_t binding = 0;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  uint32_t count = 1;  // array length; 0 for a runtime-sized array
  // A buffer's or uniform's block name (`buffer Offset { ... }` -> "Offset"), else the
  // variable's name; "" where the module was stripped of names.
  std::string name;
};

// The LocalSize execution mode of the shader's entry point, read from the SPIR-V; throws when
// the module is malformed or sizes its workgroup through specialization constants.
std::array<uint32_t, 3> spirv_workgroup_size(const ShaderCode& code);

// Every variable of the module decorated with a binding, sorted by set, then binding. Throws a
// VulkanError naming the shader when the module is malformed or a binding has a type that has
// no descriptor type.
std::vector<SpirvBinding> spirv_bindings(const ShaderCode& code);

// Throws a VulkanError naming the shader, the binding and both sides unless `declared` (what
// the code builds its descriptor set layouts from; names are ignored) lists exactly the
// shader's bindings with the same types and counts.
void check_bindings(const ShaderCode& code, const std::vector<SpirvBinding>& shader,
                    const std::vector<SpirvBinding>& declared);

// "storage buffer", "combined image sampler", ...
std::string descriptor_type_name(VkDescriptorType type);

}  // namespace phyxel::gpu
