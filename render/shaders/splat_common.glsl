// Shared by the raster shaders: the eye's projection (the off-axis frustum of glFrustum, y
// flipped for Vulkan's framebuffer), the viewing ray of a pixel, linear depth, and the
// perspective-correct ray-disc intersection.
#ifndef PHYXEL_SPLAT_COMMON_GLSL
#define PHYXEL_SPLAT_COMMON_GLSL

// Background of pixels no splat covers (the C++ side has the same, render/splat_renderer.h).
const vec3 kBackground = vec3(20.0, 23.0, 28.0) / 255.0;

// Clip coordinates of an eye-space point: glFrustum(l, r, b, t, n, f) with y negated (Vulkan
// framebuffers run top to bottom) and depth in [0, 1].
vec4 project_eye(EyePush e, vec3 p) {
  const float l = e.frustum.x, r = e.frustum.y, b = e.frustum.z, t = e.frustum.w;
  const float n = e.depth.x, f = e.depth.y;
  vec4 c;
  c.x = (2.0 * n * p.x + (r + l) * p.z) / (r - l);
  c.y = -(2.0 * n * p.y + (t + b) * p.z) / (t - b);
  c.z = (f * p.z + n * f) / (n - f);
  c.w = -p.z;
  return c;
}

// Eye-space direction (not normalised; z = -near) of the ray through this fragment's centre.
vec3 pixel_ray(EyePush e, vec2 frag_coord) {
  const vec2 a = (frag_coord - e.viewport.xy) / e.viewport.zw;
  return vec3(mix(e.frustum.x, e.frustum.y, a.x), mix(e.frustum.w, e.frustum.z, a.y), -e.depth.x);
}

// Depth written by the splat passes: linear in the eye-space distance along -z, 0 at near,
// 1 at far (uniform precision; the quads' own depth is replaced).
float linear_depth(EyePush e, vec3 p) {
  return (-p.z - e.depth.x) / (e.depth.y - e.depth.x);
}

struct DiscHit {
  vec3 point;  // where the ray meets the disc's plane, eye space
  float q2;    // squared distance from the centre in radii
  bool hit;    // in front of the eye, inside the disc, between near and far
};

// The ray through the fragment against the disc (centre c, radius r, unit normal n; eye space).
DiscHit intersect_disc(EyePush e, vec3 dir, vec3 c, float r, vec3 n) {
  DiscHit h;
  const float dn = dot(dir, n);
  const bool facing = abs(dn) > 1e-12 * length(dir);
  const float t = facing ? dot(c, n) / dn : 0.0;
  h.point = t * dir;
  const vec3 d = h.point - c;
  h.q2 = r > 0.0 ? dot(d, d) / (r * r) : 2.0;
  const float depth = linear_depth(e, h.point);
  h.hit = facing && t > 0.0 && h.q2 <= 1.0 && depth >= 0.0 && depth <= 1.0;
  return h;
}

#endif  // PHYXEL_SPLAT_COMMON_GLSL
