// The SCNI band's passes (compute/gpu_solver_band.cpp; shaders/band_stress.comp,
// band_force.comp), with layout.h's rules. The band's boxes, their coefficients and the
// transposed lists are CutBand's (engine/solver/cut_band.h) in float:
//   boxes    uvec4 per box: (phyxel of its cell, first coefficient, end, volume as float bits)
//   coeff    vec4 per (box, node): (c.xyz, node index as float bits); G = sum u_node c^T
//   stress   vec4[3] per box: the columns of V_b P(I + G_b) (0 for a removed phyxel's cell);
//            the first's w: the box's energy V_b W(I + G_b)
//   nodes    uvec4 per phyxel a box lists: (phyxel, first entry, end, 0)
//   entries  uint[2] per entry: (box, coefficient)
//   ext      vec4 per phyxel: ext + the band's force on it (its w: ext's, the mass); the force
//            pass reads it for ext while the band has cells
#ifndef PHYXEL_COMPUTE_SHADERS_LAYOUT_BAND_H
#define PHYXEL_COMPUTE_SHADERS_LAYOUT_BAND_H

#include "layout.h"

#ifdef __cplusplus
namespace phyxel::gpu::layout {
#endif

struct BandPush {
  uint count;  // boxes (band_stress) or nodes (band_force)
  uint pad0, pad1, pad2;
};
PHYXEL_ASSERT_SIZE(BandPush, 16);

PHYXEL_CONST uint kBandStressBindingBoxes = 0;
PHYXEL_CONST uint kBandStressBindingCoeff = 1;
PHYXEL_CONST uint kBandStressBindingDisp = 2;
PHYXEL_CONST uint kBandStressBindingFlags = 3;
PHYXEL_CONST uint kBandStressBindingClasses = 4;
PHYXEL_CONST uint kBandStressBindingStress = 5;

PHYXEL_CONST uint kBandForceBindingNodes = 0;
PHYXEL_CONST uint kBandForceBindingEntries = 1;
PHYXEL_CONST uint kBandForceBindingCoeff = 2;
PHYXEL_CONST uint kBandForceBindingStress = 3;
PHYXEL_CONST uint kBandForceBindingExt = 4;
PHYXEL_CONST uint kBandForceBindingBandExt = 5;

#ifdef __cplusplus
}  // namespace phyxel::gpu::layout
#endif

#endif  // PHYXEL_COMPUTE_SHADERS_LAYOUT_BAND_H
