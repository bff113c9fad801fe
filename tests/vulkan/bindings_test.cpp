// Bindings checked against the SPIR-V: the reader on a hand-built module and on the real
// shaders, a pipeline whose declared layout differs from its shader's, and a dispatch whose
// buffer list names the shader's blocks in another order.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "compute/gpu_solver_kernels.h"
#include "compute/kernels.h"
#include "tests/support/support.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

using phyxel::test::error_of;

// A SPIR-V module assembled word by word (only what the reader looks at).
class ModuleBuilder {
 public:
  ModuleBuilder() : words_{0x07230203, 0x00010500, 0, 100, 0} {
    op(16, {1, 17, 64, 1, 1});  // OpExecutionMode %1 LocalSize 64 1 1
  }
  void op(uint32_t opcode, const std::vector<uint32_t>& operands) {
    words_.push_back(uint32_t(operands.size() + 1) << 16 | opcode);
    words_.insert(words_.end(), operands.begin(), operands.end());
  }
  void name(uint32_t id, const std::string& text) {
    std::vector<uint32_t> operands = {id};
    for (size_t i = 0; i <= text.size(); i += 4) {
      uint32_t w = 0;
      for (size_t b = 0; b < 4 && i + b < text.size(); ++b)
        w |= uint32_t(uint8_t(text[i + b])) << (8 * b);
      operands.push_back(w);
    }
    op(5, operands);
  }
  void decorate(uint32_t id, uint32_t decoration, std::vector<uint32_t> literals = {}) {
    literals.insert(literals.begin(), {id, decoration});
    op(71, literals);
  }
  // `binding` of `set` holding a variable %var of pointer type %ptr to `type`.
  void variable(uint32_t var, uint32_t ptr, uint32_t storage, uint32_t type, uint32_t set,
                uint32_t binding) {
    decorate(var, 34, {set});
    decorate(var, 33, {binding});
    op(32, {ptr, storage, type});  // OpTypePointer
    op(59, {ptr, var, storage});   // OpVariable
  }
  ShaderCode code(const char* shader) const { return {words_.data(), words_.size() * 4, shader}; }

 private:
  std::vector<uint32_t> words_;
};

// `buffer Src { uint src[]; }` at set 0 binding 0 and `buffer Dst { ... }` at binding 1.
ModuleBuilder two_buffers() {
  ModuleBuilder m;
  m.op(21, {2, 32, 0});  // %2 = OpTypeInt 32 unsigned
  m.op(29, {3, 2});      // %3 = OpTypeRuntimeArray %2
  m.op(30, {4, 3});      // %4 = OpTypeStruct %3 ("Src")
  m.op(30, {5, 3});      // %5 = OpTypeStruct %3 ("Dst")
  m.name(4, "Src");
  m.name(5, "Dst");
  m.decorate(4, 2);
  m.decorate(5, 2);
  m.variable(10, 11, 12, 4, 0, 0);
  m.variable(12, 13, 12, 5, 0, 1);
  return m;
}

std::vector<SpirvBinding> storage_buffers(uint32_t count) {
  std::vector<SpirvBinding> out;
  for (uint32_t i = 0; i < count; ++i)
    out.push_back({0, i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, ""});
  return out;
}

std::vector<std::string> names_of(const Pipeline& p) {
  std::vector<std::string> out;
  for (const SpirvBinding& b : p.shader_bindings()) out.push_back(b.name);
  return out;
}

TEST(SpirvBindings, ReadsBuffersUniformsAndImages) {
  ModuleBuilder m = two_buffers();
  m.op(22, {20, 32});                    // %20 = OpTypeFloat 32
  m.op(25, {21, 20, 1, 0, 0, 0, 1, 0});  // %21 = OpTypeImage 2D sampled
  m.op(27, {22, 21});                    // %22 = OpTypeSampledImage %21
  m.op(43, {2, 23, 4});                  // %23 = OpConstant 4
  m.op(28, {24, 22, 23});                // %24 = OpTypeArray %22 [4]
  m.name(25, "textures");
  m.variable(25, 26, 0, 24, 1, 2);
  m.op(30, {27, 20});  // a uniform block
  m.name(27, "Params");
  m.decorate(27, 2);
  m.variable(28, 29, 2, 27, 1, 0);
  m.op(30, {30, 3});  // an old-style storage buffer (Uniform + BufferBlock)
  m.decorate(30, 3);
  m.variable(31, 32, 2, 30, 1, 1);
  const std::vector<SpirvBinding> b = spirv_bindings(m.code("hand"));
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b[0].name, "Src");
  EXPECT_EQ(b[1].name, "Dst");
  EXPECT_EQ(b[1].type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  EXPECT_EQ(b[2].set, 1u);
  EXPECT_EQ(b[2].type, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER);
  EXPECT_EQ(b[2].name, "Params");
  EXPECT_EQ(b[3].type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  EXPECT_EQ(b[4].binding, 2u);
  EXPECT_EQ(b[4].type, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
  EXPECT_EQ(b[4].count, 4u);
  EXPECT_EQ(b[4].name, "textures");
}

TEST(SpirvBindings, RejectsMalformedModules) {
  const uint32_t junk[] = {1, 2, 3, 4, 5, 6};
  EXPECT_THROW(spirv_bindings({junk, sizeof junk, "junk"}), VulkanError);
  const uint32_t truncated[] = {0x07230203, 0x00010500, 0, 10, 0, (9u << 16) | 5u, 1};
  EXPECT_THROW(spirv_bindings({truncated, sizeof truncated, "cut"}), VulkanError);
  ModuleBuilder dangling;
  dangling.variable(10, 11, 12, 50, 0, 0);  // points to an undefined type
  EXPECT_NE(error_of([&] { spirv_bindings(dangling.code("dangling")); }).find("not defined"),
            std::string::npos);
}

TEST(SpirvBindings, LayoutMismatchNamesShaderBindingAndBothSides) {
  const ModuleBuilder module = two_buffers();
  const ShaderCode code = module.code("pair");
  const std::vector<SpirvBinding> shader = spirv_bindings(code);
  EXPECT_NO_THROW(check_bindings(code, shader, storage_buffers(2)));
  const std::string fewer = error_of([&] { check_bindings(code, shader, storage_buffers(1)); });
  EXPECT_NE(fewer.find("shader 'pair': set 0 binding 1 ('Dst') is a storage buffer in the SPIR-V "
                       "but missing"),
            std::string::npos)
      << fewer;
  EXPECT_NE(fewer.find("shader: set 0: 0-1 storage buffer; code declares: set 0: 0 storage"),
            std::string::npos)
      << fewer;
  const std::string more = error_of([&] { check_bindings(code, shader, storage_buffers(3)); });
  EXPECT_NE(more.find("declares set 0 binding 2 (storage buffer) but the SPIR-V has no such"),
            std::string::npos)
      << more;
  std::vector<SpirvBinding> uniform = storage_buffers(2);
  uniform[1].type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  const std::string type = error_of([&] { check_bindings(code, shader, uniform); });
  EXPECT_NE(type.find("binding 1 ('Dst') is a storage buffer in the SPIR-V but a uniform buffer"),
            std::string::npos)
      << type;
}

class BindingsTest : public VulkanTest {};

TEST_F(BindingsTest, PipelineRefusesALayoutOtherThanTheShaders) {
  const ModuleBuilder module = two_buffers();
  const ShaderCode code = module.code("pair");
  const std::string fewer = error_of([&] { Pipeline(ctx(), code, 1, 0); });
  EXPECT_NE(fewer.find("shader 'pair': set 0 binding 1 ('Dst')"), std::string::npos) << fewer;
  const std::string set1 = error_of([&] {
    const VkDescriptorSetLayoutBinding texture{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                               VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    Pipeline(ctx(), code, 2, 0, CallerSet{VK_NULL_HANDLE, {texture}});
  });
  EXPECT_NE(set1.find("needs its layout and bindings"), std::string::npos) << set1;
}

TEST_F(BindingsTest, RealShadersAreReadAndEveryPassMatchesItsLayout) {
  const CoreKernels core(ctx());
  EXPECT_EQ(names_of(core.axpy), (std::vector<std::string>{"X", "Y"}));
  EXPECT_EQ(core.axpy.shader_bindings()[1].type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  // Every solver pipeline is checked when it is made, split or not.
  const SolverKernels kernels(ctx(), false, 0);
  const SolverKernels split(ctx(), true, 64);
  EXPECT_EQ(names_of(kernels.force),
            (std::vector<std::string>{"Offset", "IndexLo", "WeightLo", "Local", "DispIn", "DispOut",
                                      "Stress", "Vel", "Force", "Ext", "Flags", "Classes", "List",
                                      "IndexHi", "WeightHi"}));
  EXPECT_EQ(names_of(split.von_mises).size(), 13u);
}

TEST_F(BindingsTest, ASwappedListIsRefusedWithBothNames) {
  const CoreKernels core(ctx());
  const uint32_t n = 64;
  const Buffer x(ctx(), n * sizeof(float), MemoryIntent::Device, "x");
  const Buffer y(ctx(), n * sizeof(float), MemoryIntent::Device, "y");
  Recorder rec(ctx(), "named");
  const layout::AxpyPush push{2.0f, n};
  const std::string swapped = error_of([&] {
    dispatch(rec, core.axpy, push, {{"Y", y}, {"X", x}}, n);
  });
  EXPECT_EQ(swapped,
            "dispatch of 'axpy': binding 0 ('y') is listed as 'Y', but the shader's binding 0 "
            "is 'X'");
  const std::string mixed = error_of([&] { dispatch(rec, core.axpy, push, {{"X", x}, y}, n); });
  EXPECT_NE(mixed.find("binding 1 ('y') has no block name"), std::string::npos) << mixed;
  // The solver's force pass with its displacements in and out swapped.
  const SolverKernels kernels(ctx(), false, 0);
  const Buffer b(ctx(), 1024, MemoryIntent::Device, "u[0]");
  const std::string force = error_of([&] {
    dispatch(rec, kernels.force, layout::StepPush{},
             {{"Offset", b},
              {"IndexLo", b},
              {"WeightLo", b},
              {"Local", b},
              {"DispOut", b},
              {"DispIn", b},
              {"Stress", b},
              {"Vel", b},
              {"Force", b},
              {"Ext", b},
              {"Flags", b},
              {"Classes", b},
              {"List", b},
              {"IndexHi", b},
              {"WeightHi", b}},
             1);
  });
  EXPECT_EQ(force,
            "dispatch of 'solver_force': binding 4 ('u[0]') is listed as 'DispOut', but the "
            "shader's binding 4 is 'DispIn'");
  EXPECT_EQ(rec.dispatch_count(), 0u);
  // In the shader's order it is recorded.
  dispatch(rec, core.axpy, push, {{"X", x}, {"Y", y}}, n);
  EXPECT_EQ(rec.dispatch_count(), 1u);
  rec.submit_and_wait();
}

}  // namespace
}  // namespace phyxel::gpu
