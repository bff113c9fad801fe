// Shared by the render shaders (render/shaders/*, `#include "render_layout.h"`) and C++
// (`#include "render/shaders/render_layout.h"`): the surfel and splat structs, push constants
// and binding numbers of the splat renderer. Written like compute/shaders/layout.h: only
// uint, float, vec4 and mat4 (column-major, 64 bytes) members, a size assert after each struct.
#ifndef PHYXEL_RENDER_SHADERS_RENDER_LAYOUT_H
#define PHYXEL_RENDER_SHADERS_RENDER_LAYOUT_H

#ifdef __cplusplus
#include "compute/shaders/layout.h"
namespace phyxel::render::layout {
using gpu::layout::uint;
using gpu::layout::uvec4;
using gpu::layout::vec4;
struct alignas(16) mat4 {
  float m[16];  // column-major, as GLSL
};
#else
#include "layout.h"
#endif

PHYXEL_ASSERT_SIZE(mat4, 64);

// One surface phyxel, uploaded once (render/surfels.h builds the table). Texture coordinates
// (s, t) in [0, 1]^2 come from the rest position through the dome mapping (texture_map.h);
// ds_dx, dt_dx are their gradients along the rest tangent plane, so that a point at rest
// offset d from the centre has s = s_c + dot(ds_dx, d) (the texture then varies inside a
// splat, not only from splat to splat).
struct SurfelStatic {
  uint index;     // phyxel index into rest / displacement / nbr_offset
  float radius;   // splat radius at rest, m
  float support;  // the object's support radius h, m (poly6 weights of grad u)
  uint flags;     // unused by the shaders; the phyxel flags at build time
  vec4 normal;    // rest outward unit normal (w unused)
  vec4 ds_dx;     // xyz: gradient of s at rest; w: s at the centre
  vec4 dt_dx;     // xyz: gradient of t at rest; w: t at the centre
};
PHYXEL_ASSERT_SIZE(SurfelStatic, 64);

// One deformed splat, written by deform_surfels.comp every frame, read by the raster passes.
struct Splat {
  vec4 centre;  // xyz: x0 + u; w: radius (0: not drawn)
  vec4 normal;  // xyz: unit n' ~ (I + grad u)^-T n; w: 1 when grad u was usable, 0 fallback
  vec4 ds_dx;   // xyz: gradient of s in the deformed state, (ds/dx0) F^-1; w: s at the centre
  vec4 dt_dx;   // the same for t
};
PHYXEL_ASSERT_SIZE(Splat, 64);

// deform_surfels.comp
PHYXEL_CONST uint kDeformBindingRest = 0;
PHYXEL_CONST uint kDeformBindingDisplacement = 1;
PHYXEL_CONST uint kDeformBindingNbrOffset = 2;
PHYXEL_CONST uint kDeformBindingNbrIndex = 3;
PHYXEL_CONST uint kDeformBindingSurfels = 4;
PHYXEL_CONST uint kDeformBindingSplats = 5;
struct DeformPush {
  uint count;                   // surfels
  uint phyxels;                 // entries of rest / displacement (indices are checked against it)
  float min_inverse_condition;  // det(A) / (tr(A)/3)^3 below this: A is ill-conditioned
  float max_stretch;            // radius growth limit under stretch
};
PHYXEL_ASSERT_SIZE(DeformPush, 16);

// The raster passes (splat_quad.vert, splat_depth.frag, splat_accumulate.frag,
// splat_shade.frag). Set 0 of the splat passes:
PHYXEL_CONST uint kSplatBindingSplats = 0;   // storage buffer of Splat
PHYXEL_CONST uint kSplatBindingTexture = 1;  // combined image sampler
// Set 0 of the shading pass (input attachments):
PHYXEL_CONST uint kShadeBindingColour = 0;
PHYXEL_CONST uint kShadeBindingNormal = 1;
struct EyePush {
  mat4 view;      // world -> eye space (camera looks down -z, y up)
  vec4 frustum;   // left, right, bottom, top of the view frustum at the near plane, m
  vec4 depth;     // near, far, visibility offset epsilon in splat radii, 0
  vec4 viewport;  // x0, y0, width, height of this eye's viewport in framebuffer pixels
};
PHYXEL_ASSERT_SIZE(EyePush, 112);

// anaglyph.comp: a side-by-side frame (2 width x height pixels, RGBA8 in uints) to one
// red/cyan frame (width x height): red from the left half, green and blue from the right.
PHYXEL_CONST uint kAnaglyphBindingStereo = 0;
PHYXEL_CONST uint kAnaglyphBindingOut = 1;
struct AnaglyphPush {
  uint width;  // of one eye
  uint height;
  uint pad0;
  uint pad1;
};
PHYXEL_ASSERT_SIZE(AnaglyphPush, 16);

#ifdef __cplusplus
}  // namespace phyxel::render::layout
#endif

#endif  // PHYXEL_RENDER_SHADERS_RENDER_LAYOUT_H
