// The backdrop of a surgical field (`render.backdrop`, docs/scene-format.md): rigid surfaces
// around the simulated objects (drapes, scalp, skull, chest wall) drawn as static splats. They
// are never simulated: the solver never sees them. Their look (colour, fold shading, weave,
// speckle, the wound margin at a hole's rim) is baked once per splat on the CPU here, so the
// splat passes draw them as cheaply as any tissue disc (a constant colour per disc, no texture
// and no per-pixel procedure; SplatRenderer::set_backdrop).
//
//   sample_backdrop_surface  the whole surface of a shape, about area / spacing^2 samples with
//                            outward normals (box faces on grids, ellipsoids and spheres on a
//                            Fibonacci lattice, meshes per triangle)
//   bake_backdrop            every item's samples facing `eye`, outside its hole (inside its
//                            `within`), as splats with the baked colour (kSplatBaked)
#pragma once

#include <vector>

#include "engine/scene/scene.h"
#include "render/shaders/render_layout.h"

namespace phyxel::render {

struct BackdropSample {
  Vec3 position = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // outward, unit
  double radius = 0;            // disc radius that covers the surface between samples, m
};

// About area / spacing^2 samples of the surface of `shape`, their discs covering it. Throws
// std::invalid_argument for spacing <= 0.
std::vector<BackdropSample> sample_backdrop_surface(const Shape& shape, double spacing);

// An estimate of the distance from p to the surface of `shape` (0 on it, exact for spheres
// and boxes, scaled for ellipsoids; meshes: infinity, no margin).
double distance_to_surface(const Shape& shape, const Vec3& p);

// The colour of `item` at a sample (its look, baked): RGB in [0, 1], and the normal perturbed
// by the look's relief (folds of a drape), unit.
struct BakedLook {
  Vec3 colour;
  Vec3 normal;
};
BakedLook bake_look(const BackdropItem& item, const BackdropSample& sample);

// Splats of every item: the samples whose outward normal faces `eye` (the scene camera's
// position; the far sides of closed shapes are never seen from it), outside the item's hole
// and inside its `within` (when set),
// with the baked look in ds_dx.xyz and kSplatBaked | kSplatUsable in normal.w.
std::vector<layout::Splat> bake_backdrop(const std::vector<BackdropItem>& items, const Vec3& eye);

}  // namespace phyxel::render
