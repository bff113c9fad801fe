// Shared by GLSL (compute/shaders/*.comp, `#include "layout.h"`) and C++
// (`#include "compute/shaders/layout.h"`): workgroup sizes, binding numbers, and the structs
// of push constants and storage buffers. A struct written here is one definition for both
// languages, so it may use only `uint`, `int`, `float`, `vec4`, `uvec4` and `ivec4` (never a
// bare vec3: its std430 alignment differs from any C++ struct of three floats), and each one
// gets a PHYXEL_ASSERT_SIZE with its std430 size.
//
// Binding numbers are the positions in dispatch()'s buffer list.
#ifndef PHYXEL_COMPUTE_SHADERS_LAYOUT_H
#define PHYXEL_COMPUTE_SHADERS_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
namespace phyxel::gpu::layout {
using uint = std::uint32_t;
struct alignas(16) vec4 {
  float x, y, z, w;
};
struct alignas(16) uvec4 {
  uint x, y, z, w;
};
struct alignas(16) ivec4 {
  int x, y, z, w;
};
#define PHYXEL_CONST inline constexpr
#define PHYXEL_ASSERT_SIZE(T, bytes) \
  static_assert(sizeof(T) == (bytes), #T " must match its std430 size in GLSL")
#else
#define PHYXEL_CONST const
// In GLSL the size becomes a constant, <T>_kStd430Size.
#define PHYXEL_ASSERT_SIZE(T, bytes) const uint T##_kStd430Size = bytes
#endif

// Threads per workgroup of the 1D kernels (a multiple of every subgroup size in use; never
// assume the subgroup size itself: lavapipe's is 8, NVIDIA's 32, AMD's 32 or 64).
#define PHYXEL_WORKGROUP_SIZE 64

PHYXEL_ASSERT_SIZE(vec4, 16);
PHYXEL_ASSERT_SIZE(uvec4, 16);
PHYXEL_ASSERT_SIZE(ivec4, 16);

// iota.comp: dst[i] = base + i for i < count (writes its global index; proves dispatch).
PHYXEL_CONST uint kIotaBindingDst = 0;
struct IotaPush {
  uint count;
  uint base;
};
PHYXEL_ASSERT_SIZE(IotaPush, 8);

// axpy.comp: y[i] = a * x[i] + y[i] for i < count.
PHYXEL_CONST uint kAxpyBindingX = 0;
PHYXEL_CONST uint kAxpyBindingY = 1;
struct AxpyPush {
  float a;
  uint count;
};
PHYXEL_ASSERT_SIZE(AxpyPush, 8);

#ifdef __cplusplus
}  // namespace phyxel::gpu::layout
#else
// The flat index of this invocation in a 1D dispatch() (which spreads more than
// maxComputeWorkGroupCount[0] groups over y); compare it with the element count. A macro, as
// gl_WorkGroupSize only exists after the shader's local_size declaration.
#define PHYXEL_GLOBAL_INDEX \
  (gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x)
#endif

#endif  // PHYXEL_COMPUTE_SHADERS_LAYOUT_H
