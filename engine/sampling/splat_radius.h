// The splat radius the sampler gives surface phyxels, shared with the renderer's cut faces.
#pragma once

namespace phyxel {

// Splat radius of a surface phyxel, in units of its object's spacing (sampling.cpp gives surface
// phyxels this x spacing; render/cut_surfels.cpp gives cut faces the same). Discs centred on a
// square lattice of spacing s cover the plane when their radius is at least s / sqrt(2) ~ 0.707 s
// (the distance from a cell's centre to its corner); 0.8 s also closes the gaps where the surface
// cuts the lattice obliquely.
inline constexpr double kSplatRadiusSpacings = 0.8;

}  // namespace phyxel
