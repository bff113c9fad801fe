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
//
// Cut faces (render/cut_surfels.h): a phyxel next to a cut gets a second surfel with
// kSurfelCutFace in `flags`, the normal of the face the blade left (out of the phyxel's piece),
// its disc centred on that face (normal.w: the offset from the phyxel along the rest normal)
// and (s, t) the face's own rest-plane coordinates in spacings, which the accumulation pass
// turns into the procedural cut-tissue colour instead of sampling the texture. A torn face
// (kSurfelTornFace as well) has the rough normal and offset of the fracture noise and is drawn
// in torn tissue.
struct SurfelStatic {
  uint index;     // phyxel index into rest / displacement / nbr_offset
  float radius;   // splat radius at rest, m
  float support;  // the object's support radius h, m (poly6 weights of grad u)
  uint flags;     // the phyxel flags at build time; kSurfelCutFace for a cut face
  vec4 normal;    // xyz: rest unit normal (outward); w: the disc centre's offset along it, m
  vec4 ds_dx;     // xyz: gradient of s at rest; w: s at the centre
  vec4 dt_dx;     // xyz: gradient of t at rest; w: t at the centre
};
PHYXEL_ASSERT_SIZE(SurfelStatic, 64);
// SurfelStatic::flags bit of a cut-face surfel (the phyxel flags use the low bits).
PHYXEL_CONST uint kSurfelCutFace = 0x80000000u;
// ... and of a torn face (a cut face with kSurfelCutFace too, whose phyxel has a pair torn by
// its stress): drawn rough (normal and offset from engine/surgery/fracture_surface.h) in the
// torn tissue of torn_tissue.glsl instead of the clean cut's.
PHYXEL_CONST uint kSurfelTornFace = 0x40000000u;
// SurfelStatic::flags bits 16-23: the surface's `mirror` fraction (scene objects and
// inclusions) x 255, the share of its colour that reflects the environment.
PHYXEL_CONST uint kSurfelMirrorShift = 16;
PHYXEL_CONST uint kMirrorLevels = 255;

// One deformed splat, written by deform_surfels.comp every frame, read by the splat passes.
struct Splat {
  vec4 centre;  // xyz: x0 + u; w: radius (0: not drawn)
  vec4 normal;  // xyz: unit n' ~ (I + grad u)^-T n; w: kSplatUsable | kSplatCutFace bits
  vec4 ds_dx;   // xyz: gradient of s in the deformed state, (ds/dx0) F^-1; w: s at the centre
  vec4 dt_dx;   // the same for t
};
PHYXEL_ASSERT_SIZE(Splat, 64);
// Bits of Splat::normal.w (a small integer stored as a float): grad u was usable (else the
// rest normal), the splat is a cut face (the accumulation pass draws cut tissue), and a torn
// one (torn tissue; kSplatCutFace is set too).
PHYXEL_CONST uint kSplatUsable = 1;
PHYXEL_CONST uint kSplatCutFace = 2;
PHYXEL_CONST uint kSplatTornFace = 4;
// A backdrop splat (render/backdrop.h, SplatRenderer::set_backdrop): static, its look baked
// on the CPU; ds_dx.xyz holds its colour (RGB in [0, 1]) instead of a texture gradient.
PHYXEL_CONST uint kSplatBaked = 8;
// Bits 8-15 of Splat::normal.w: the surfel's mirror level (0 ... kMirrorLevels).
PHYXEL_CONST uint kSplatMirrorShift = 8;

// deform_surfels.comp
PHYXEL_CONST uint kDeformBindingRest = 0;
PHYXEL_CONST uint kDeformBindingDisplacement = 1;
PHYXEL_CONST uint kDeformBindingNbrOffset = 2;
PHYXEL_CONST uint kDeformBindingNbrIndex = 3;
PHYXEL_CONST uint kDeformBindingSurfels = 4;
PHYXEL_CONST uint kDeformBindingSplats = 5;
// float per CSR pair (the GPU solver's pair weights; 0: severed or removed), read only when
// DeformPush::pair_weights is 1 (else a one-word placeholder is bound).
PHYXEL_CONST uint kDeformBindingPairWeight = 6;
// The pairs past the first binding of a large GPU solver's index and weights (its lo and hi
// parts, compute/shaders/pair_buffers.glsl); the lo buffers again where all fit in one.
PHYXEL_CONST uint kDeformBindingNbrIndexHi = 7;
PHYXEL_CONST uint kDeformBindingPairWeightHi = 8;
// Invocations per surfel (a divisor of PHYXEL_WORKGROUP_SIZE): dispatch count x kDeformLanes.
PHYXEL_CONST uint kDeformLanes = 8;
struct DeformPush {
  uint count;         // surfels
  uint phyxels;       // entries of rest / displacement (indices are checked against it)
  float max_stretch;  // radius growth limit under stretch
  uint pair_weights;  // 1: skip pairs whose kDeformBindingPairWeight entry is 0
  uint pad0, pad1, pad2, pad3;
};
PHYXEL_ASSERT_SIZE(DeformPush, 32);

// The splat passes, one eye at a time, one invocation per splat (splat_visibility.comp,
// splat_accumulate.comp, both built on splat_raster.glsl). Per-pixel buffers of an eye have
// `width x height` entries, rows top to bottom; the renderer binds each eye's range.
PHYXEL_CONST uint kRasterBindingSplats = 0;  // Splat[]
PHYXEL_CONST uint kRasterBindingDepth = 1;   // uint per pixel: bits of the visible depth + epsilon
PHYXEL_CONST uint kRasterBindingAccum = 2;   // accumulation only: kAccumChannels ints per pixel
PHYXEL_CONST uint kRasterSetTexture = 1;     // accumulation only: set 1, binding 0, the texture
// Accumulated per pixel, in fixed point (kAccumScale = 1.0), so that sums are exact and the
// same in any order: colour x w (3), w, normal x w (3), the nearest tool's hit (kAccumTool,
// written by tool_visibility.comp), w of the cut-face discs alone (kAccumCut: the shading
// pass makes that fraction of the pixel wet), and mirror x w (kAccumMirror: that fraction of
// the pixel reflects the environment). 2^16 leaves room for sums of 65535 full-weight discs
// (the shading pass reads the sums of values >= 0 unsigned; 32767 for the normal's signed
// ones) before a 32-bit int wraps (silently: that frame's pixel is wrong). Planes of pairs: an
// eye's range holds kAccumChannels / 2 planes of eye_stride pairs of ints (channel c of pixel i at
// accum_index(c, eye_stride, i)), so that neighbouring pixels' atomics of one pair share
// cache lines and the shading pass reads only w and the tool (one pair) where nothing was
// drawn. A pair is one 64-bit word, low int first: with 64-bit atomics the accumulation adds
// both of a pair at once (splat_accumulate.glsl). Every low channel is added only non-negative
// values, so a pair's high int gets no carry while its low sum stays below 2^32, and the ints
// are those of two 32-bit atomics. The shading pass zeroes what it read non-zero: the buffer
// is clear again for the next frame without a fill (SplatRenderer::Impl::accum_dirty).
PHYXEL_CONST uint kAccumChannels = 10;
// The pairs: (red, normal x), (green, normal y), (blue, normal z), (w, tool), (cut, mirror).
PHYXEL_CONST uint kAccumRed = 0;
PHYXEL_CONST uint kAccumNormalX = 1;
PHYXEL_CONST uint kAccumGreen = 2;
PHYXEL_CONST uint kAccumNormalY = 3;
PHYXEL_CONST uint kAccumBlue = 4;
PHYXEL_CONST uint kAccumNormalZ = 5;
PHYXEL_CONST uint kAccumWeight = 6;
PHYXEL_CONST uint kAccumCut = 8;
PHYXEL_CONST uint kAccumMirror = 9;
// Channel of the tool hit: 0 for none, else kToolHitFlag | the eye-space unit normal of the
// hit in octahedral coordinates, (u, v) in [-1, 1] to 15 bits each (u in bits 0-14, v in
// bits 15-29). The high int of w's pair: w's low sum below 2^32 leaves it as written.
PHYXEL_CONST uint kAccumTool = 7;
PHYXEL_CONST uint kToolHitFlag = 0x80000000u;
PHYXEL_CONST float kAccumScale = 65536.0;
#ifndef __cplusplus
// The int index of channel c of pixel i in an eye's range of `plane` pixels per channel.
uint accum_index(uint c, uint plane, uint i) {
  return (c >> 1) * 2 * plane + 2 * i + (c & 1);
}
#endif
// The depth buffer's clear value: the bits of 1.0f (the far plane in linear depth).
PHYXEL_CONST uint kDepthClear = 0x3f800000u;
// A splat whose pixel bounds hold more pixels than this is drawn by its whole workgroup.
PHYXEL_CONST uint kOwnPixels = 64;
struct RasterPush {
  mat4 view;     // world -> eye space (camera looks down -z, y up)
  vec4 frustum;  // left, right, bottom, top of the view frustum at the near plane, m
  vec4 depth;    // near, far, visibility offset epsilon in splat radii, 0
  uvec4 target;  // width, height of the eye in pixels, splat count, slices (splat_raster.glsl)
};
PHYXEL_ASSERT_SIZE(RasterPush, 112);

// tool_visibility.comp: the tools ray-cast per pixel of one eye, one invocation per pixel
// (every tool against the pixel's ray; the nearest hit between near and far counts). Writes
// the hit's exact linear depth with the splats' atomicMin encoding (no epsilon) and its
// normal into the kAccumTool channel of the eye's accumulation range.
PHYXEL_CONST uint kToolBindingTools = 0;  // RenderTool[]
PHYXEL_CONST uint kToolBindingDepth = 1;  // as kRasterBindingDepth
PHYXEL_CONST uint kToolBindingAccum = 2;  // as kRasterBindingAccum
// One tool (render/tool_raycast.h, engine/geometry/tool.h): a sphere of radius r around the
// tip, or a capsule, the segment from the tip along the axis swept by r.
struct RenderTool {
  vec4 tip;   // xyz: the tip, world, m; w: radius, m
  vec4 axis;  // xyz: unit axis, world; w: capsule length, m (0: a sphere)
};
PHYXEL_ASSERT_SIZE(RenderTool, 32);
struct ToolPush {
  mat4 view;     // world -> eye space, as RasterPush
  vec4 frustum;  // left, right, bottom, top of the view frustum at the near plane, m
  vec4 depth;    // near, far, 0, 0
  uvec4 target;  // width, height of the eye in pixels, tool count, 0
};
PHYXEL_ASSERT_SIZE(ToolPush, 112);

// splat_shade.comp: normalisation and Phong shading of the accumulated attributes of both
// eyes (the accumulation buffer holds eye 1 at `eye_stride` pixels after eye 0) into the frame;
// a pixel that no splat reached but a tool did shows the tool (steel); one that neither
// reached shows the environment (render/environment_map.h) when there is one.
PHYXEL_CONST uint kShadeBindingAccum = 0;  // kAccumChannels ints per pixel
PHYXEL_CONST uint kShadeBindingFrame = 1;  // RGBA8 per pixel of the frame, one uint
// The backdrop layer (SplatRenderer::set_backdrop), read only with kShadeBackdropBit: the
// frame's depth buffer (kRasterBindingDepth's, both eyes), and per pixel of each eye (the
// accumulation's indexing) the backdrop's own visible depth and its shaded colour (RGBA8,
// the environment where no backdrop disc is), drawn once per view.
PHYXEL_CONST uint kShadeBindingDepth = 2;
PHYXEL_CONST uint kShadeBindingBackdropDepth = 3;
PHYXEL_CONST uint kShadeBindingBackdrop = 4;
PHYXEL_CONST uint kShadeSetEnvironment = 1;  // set 1, binding 0: the environment image
PHYXEL_CONST uint kShadeLayoutMono = 0;
PHYXEL_CONST uint kShadeLayoutSideBySide = 1;  // eye 0 left, eye 1 right: 2 width x height
PHYXEL_CONST uint kShadeLayoutAnaglyph = 2;    // red from eye 0, green and blue from eye 1
PHYXEL_CONST uint kShadeLayoutMask = 0xffu;    // frame.z: the layout in the low bits ...
// ... and this bit with a backdrop layer: a pixel that no disc reached shows the layer,
// unless a tool was hit nearer than the layer's depth.
PHYXEL_CONST uint kShadeBackdropBit = 0x100u;
struct ShadePush {
  vec4 frustum0;  // eye 0: left, right, bottom, top at the near plane
  vec4 frustum1;  // eye 1
  vec4 near;      // x: eye 0, y: eye 1; z: 1 with an environment, else 0; w: its area ratio K
  uvec4 frame;    // eye width, height, layout (kShadeLayout* | kShadeBackdropBit), eye_stride
  mat4 eye_to_environment;  // rotation: eye space (both eyes) -> the environment cube's frame
};
PHYXEL_ASSERT_SIZE(ShadePush, 128);

#ifdef __cplusplus
}  // namespace phyxel::render::layout
#endif

#endif  // PHYXEL_RENDER_SHADERS_RENDER_LAYOUT_H
