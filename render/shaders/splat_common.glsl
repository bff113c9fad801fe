// Shared by the splat passes: the viewing ray of a pixel, linear depth, and the
// perspective-correct ray-disc intersection (all in eye space: the camera at the origin
// looking down -z, y up, pixel rows top to bottom).
#ifndef PHYXEL_SPLAT_COMMON_GLSL
#define PHYXEL_SPLAT_COMMON_GLSL

// Background of pixels no splat covers (the C++ side has the same, render/splat_renderer.h).
const vec3 kBackground = vec3(20.0, 23.0, 28.0) / 255.0;

// Direction (not normalised; z = -near) of the ray through the centre of `pixel` of an eye
// of `size` pixels whose frustum at the near plane is (left, right, bottom, top).
vec3 pixel_ray(vec4 frustum, float near, vec2 size, vec2 pixel) {
  const vec2 a = (pixel + 0.5) / size;
  return vec3(mix(frustum.x, frustum.y, a.x), mix(frustum.w, frustum.z, a.y), -near);
}

// Linear depth: 0 at near, 1 at far (uniform precision for the epsilon comparison).
float linear_depth(float near, float far, vec3 p) {
  return (-p.z - near) / (far - near);
}

struct DiscHit {
  vec3 point;   // where the ray meets the disc's plane
  float q2;     // squared distance from the centre in radii
  float depth;  // linear depth of point
  bool hit;     // in front of the eye, inside the disc, between near and far
};

// The ray along `dir` from the eye against the disc (centre c, radius r, unit normal n).
DiscHit intersect_disc(vec3 dir, vec3 c, float r, vec3 n, float near, float far) {
  DiscHit h;
  const float dn = dot(dir, n);
  const bool facing = abs(dn) > 1e-12 * length(dir);
  const float t = facing ? dot(c, n) / dn : 0.0;
  h.point = t * dir;
  const vec3 d = h.point - c;
  h.q2 = r > 0.0 ? dot(d, d) / (r * r) : 2.0;
  h.depth = linear_depth(near, far, h.point);
  h.hit = facing && t > 0.0 && h.q2 <= 1.0 && h.depth >= 0.0 && h.depth <= 1.0;
  return h;
}

#endif  // PHYXEL_SPLAT_COMMON_GLSL
