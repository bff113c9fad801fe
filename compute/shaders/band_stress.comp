// The SCNI band's stress, one invocation per box b of a band cell (layout_band.h):
//   G_b = sum_k u_node(k) c_k^T, S_b = V_b P(I + G_b), 0 for a removed phyxel's cell,
// and in the w of its first column the box's energy V_b W(I + G_b) (GpuSolver::energies).
// The twin of CpuSolver::band_stress and band_energy (engine/solver/cpu_solver_band.cpp).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "layout_band.h"
#include "solver_mls.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { BandPush p; };
layout(std430, binding = kBandStressBindingBoxes) readonly buffer Boxes { uvec4 boxes[]; };
layout(std430, binding = kBandStressBindingCoeff) readonly buffer Coeff { vec4 coeff[]; };
layout(std430, binding = kBandStressBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kBandStressBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kBandStressBindingClasses) readonly buffer Classes {
  SolverClass classes[];
};
layout(std430, binding = kBandStressBindingStress) writeonly buffer Stress { vec4 box_stress[]; };

void main() {
  const uint b = PHYXEL_GLOBAL_INDEX;
  if (b >= p.count) return;
  const uvec4 box = boxes[b];
  const uint fl = flags[box.x];
  mat3 s = mat3(0.0);
  float energy = 0.0;
  if ((fl & kFlagRemoved) == 0u) {
    mat3 g = mat3(0.0);
    for (uint k = box.y; k < box.z; ++k) {
      const vec4 c = coeff[k];
      g += outerProduct(disp[floatBitsToUint(c.w)].xyz, c.xyz);
    }
    const SolverClass cls = classes[fl >> kFlagClassShift];
    const Strain strain = strain_of(g);
    const float volume = uintBitsToFloat(box.w);
    s = volume * first_piola(strain, cls.elastic.xyz);
    energy = volume * energy_density(strain, cls.elastic.xyz);
  }
  box_stress[3u * b] = vec4(s[0], energy);
  box_stress[3u * b + 1u] = vec4(s[1], 0.0);
  box_stress[3u * b + 2u] = vec4(s[2], 0.0);
}
