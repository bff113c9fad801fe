// The driver of the two splat passes (splat_visibility.comp, splat_accumulate.comp): one
// invocation per splat of one eye. It moves the splat to eye space, bounds the pixels its
// disc can cover, and calls the pass's
//     void splat_pixel(EyeSplat s, uint x, uint y);
// for each of them (the pass intersects the pixel's ray with the disc). A splat with up to
// kOwnPixels pixels is drawn by its own invocation; larger ones (close to the eye) are queued
// in shared memory and drawn by the whole workgroup, pixel i by invocation i mod the
// workgroup size, so that one large splat does not hold up its neighbours; and by
// p.target.w workgroups (slices) when there are few splats.
#ifndef PHYXEL_SPLAT_RASTER_GLSL
#define PHYXEL_SPLAT_RASTER_GLSL

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { RasterPush p; };
layout(std430, binding = kRasterBindingSplats) readonly buffer Splats { Splat splats[]; };

struct EyeSplat {
  vec3 c;    // centre
  float r;   // radius (0: not drawn)
  vec3 n;    // unit normal
  vec4 ds;   // xyz: gradient of the texture coordinate s (baked: the colour); w: s at the centre
  vec4 dt;   // the same for t
  bool cut;   // a cut face (kSplatCutFace): cut tissue instead of the texture
  bool torn;  // a torn face (kSplatTornFace, cut too): torn tissue, bumped
  bool baked;  // a backdrop splat (kSplatBaked): its colour is ds.xyz
  float mirror;  // the fraction of its colour that reflects the environment
};

EyeSplat eye_splat(uint k) {
  const Splat s = splats[k];
  const mat3 rot = mat3(p.view);
  EyeSplat e;
  e.c = (p.view * vec4(s.centre.xyz, 1.0)).xyz;
  e.r = s.centre.w;
  e.n = rot * s.normal.xyz;
  const uint bits = uint(s.normal.w);
  e.baked = (bits & kSplatBaked) != 0u;
  e.ds = e.baked ? s.ds_dx : vec4(rot * s.ds_dx.xyz, s.ds_dx.w);
  e.dt = vec4(rot * s.dt_dx.xyz, s.dt_dx.w);
  e.cut = (bits & kSplatCutFace) != 0u;
  e.torn = (bits & kSplatTornFace) != 0u;
  e.mirror = float((bits >> kSplatMirrorShift) & kMirrorLevels) / float(kMirrorLevels);
  return e;
}

vec3 eye_ray(uint x, uint y) {
  return pixel_ray(p.frustum, p.depth.x, vec2(p.target.xy), vec2(x, y));
}

// Pixels [box.xy, box.zw] (inclusive) whose centres may see the disc; false when none. The
// disc lies in the box c +- r sqrt(1 - n^2) (per axis); its projection lies within the
// projections of the box's corners, which bound x / -z at (x, z) extremes.
bool pixel_bounds(EyeSplat s, out uvec4 box) {
  box = uvec4(0);
  const float near = p.depth.x, far = p.depth.y;
  const vec3 e = s.r * sqrt(max(vec3(1.0) - s.n * s.n, vec3(0.0)));
  const float z_front = s.c.z + e.z, z_back = s.c.z - e.z;
  if (!(s.r > 0.0) || z_back > -near || z_front < -far) return false;
  const vec2 size = vec2(p.target.xy);
  vec2 lo = vec2(0.0), hi = size - 1.0;
  if (z_front < -near) {  // wholly beyond the near plane: project (else: the whole eye)
    const vec2 inv = near / vec2(-z_front, -z_back);
    const vec2 xy0 = s.c.xy - e.xy, xy1 = s.c.xy + e.xy;
    const vec2 s_min = min(xy0 * inv.x, xy0 * inv.y);
    const vec2 s_max = max(xy1 * inv.x, xy1 * inv.y);
    const vec4 f = p.frustum;  // pixel x grows with x, pixel y with -y
    const vec2 p_min = vec2((s_min.x - f.x) / (f.y - f.x), (f.w - s_max.y) / (f.w - f.z)) * size;
    const vec2 p_max = vec2((s_max.x - f.x) / (f.y - f.x), (f.w - s_min.y) / (f.w - f.z)) * size;
    lo = floor(p_min - 0.5);
    hi = ceil(p_max - 0.5);
    if (any(greaterThan(lo, size - 1.0)) || any(lessThan(hi, vec2(0.0)))) return false;
    lo = max(lo, vec2(0.0));
    hi = min(hi, size - 1.0);
  }
  box = uvec4(uvec2(lo), uvec2(hi));
  return true;
}

void splat_pixel(EyeSplat s, uint x, uint y);

shared uint big_count;
shared uint big_splat[PHYXEL_WORKGROUP_SIZE];
shared uvec4 big_box[PHYXEL_WORKGROUP_SIZE];

void main() {
  if (gl_LocalInvocationIndex == 0) big_count = 0;
  barrier();
  // p.target.w slices of the splats, each rounded up to whole workgroups (so a workgroup lies
  // in one slice): slice 0 draws the small splats, and slice j the pixels j, j + S, ... (in
  // units of the workgroup) of the large ones, so that a few thousand large splats (a backdrop,
  // tissue close to the eye) still fill the GPU. The sums are of integers: the image does not
  // depend on who drew which pixel.
  const uint slices = max(p.target.w, 1u);
  const uint padded = (p.target.z + PHYXEL_WORKGROUP_SIZE - 1) / PHYXEL_WORKGROUP_SIZE *
                      PHYXEL_WORKGROUP_SIZE;
  const uint index = PHYXEL_GLOBAL_INDEX;
  const uint slice = index / padded;
  const uint k = index - slice * padded;
  if (k < p.target.z && slice < slices) {
    const EyeSplat s = eye_splat(k);
    uvec4 box;
    if (pixel_bounds(s, box)) {
      if ((box.z - box.x + 1) * (box.w - box.y + 1) <= kOwnPixels) {
        if (slice == 0) {
          for (uint y = box.y; y <= box.w; ++y)
            for (uint x = box.x; x <= box.z; ++x) splat_pixel(s, x, y);
        }
      } else {
        const uint slot = atomicAdd(big_count, 1u);
        big_splat[slot] = k;
        big_box[slot] = box;
      }
    }
  }
  barrier();
  const uint queued = big_count;
  for (uint b = 0; b < queued; ++b) {
    const EyeSplat s = eye_splat(big_splat[b]);
    const uvec4 box = big_box[b];
    const uint w = box.z - box.x + 1;
    const uint pixels = w * (box.w - box.y + 1);
    for (uint i = gl_LocalInvocationIndex + slice * PHYXEL_WORKGROUP_SIZE; i < pixels;
         i += PHYXEL_WORKGROUP_SIZE * slices) {
      const uint row = i / w;
      splat_pixel(s, box.x + (i - row * w), box.y + row);
    }
  }
}

#endif  // PHYXEL_SPLAT_RASTER_GLSL
