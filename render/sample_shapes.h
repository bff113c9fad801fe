// Small self-contained phyxel sets for the render bench and the render tests: lattice shapes
// with the flags, normals and splat radii the sampler gives surface phyxels (kSurface where a
// face neighbour is missing, splat radius 0.8 spacing), independent of the scene sampler so
// that golden images do not move when sampling changes.
#pragma once

#include <cstdint>

#include "engine/sampling/phyxel_set.h"

namespace phyxel::render {

// The lattice points (spacing s, centred on `centre`) with |x - centre| <= radius and, when
// shell > 0, |x - centre| > radius - shell: a ball or a spherical shell (thick enough, e.g.
// 3 s, every outer surface phyxel has all its neighbours within support radius 2 s).
// Surface phyxels are those with a face neighbour outside the ball; normal radial.
PhyxelSet lattice_sphere(const Vec3& centre, double radius, double spacing, double shell = 0);

// The lattice box [min, max] (corners included, spacing s); normals the sum of the missing
// face directions, normalised.
PhyxelSet lattice_box(const Vec3& min, const Vec3& max, double spacing);

}  // namespace phyxel::render
