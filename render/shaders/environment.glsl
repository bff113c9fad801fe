// Cube mirror environment mapping (the paper's eqs 33-34), the GLSL twin of
// render/environment_map.h's environment_st: the image coordinates (s, t) in [0, 1]^2 of the
// cube point that a direction `d` of the cube frame (+z the top face, the image's middle
// square; +x right, +y down) points at, for area ratio k of the top face. Side faces:
// (u, v) = (x, y) sqrt(K + 2/K - 4 z / (K D)) on the cube of side D = 2; the top face and,
// as its mirror image, the bottom face: sqrt(K) (x, y); the image's border is at
// sqrt(K + 4/K).
#ifndef PHYXEL_ENVIRONMENT_GLSL
#define PHYXEL_ENVIRONMENT_GLSL

vec2 environment_st(vec3 d, float k) {
  const vec3 a = abs(d);
  const float m = max(a.x, max(a.y, a.z));
  const vec3 q = m > 0.0 ? d / m : vec3(0.0, 0.0, 1.0);
  const float outer = sqrt(k + 4.0 / k);
  const float scale = a.z > max(a.x, a.y) ? sqrt(k) : sqrt(max(k + 2.0 / k - 2.0 * q.z / k, 0.0));
  return vec2(0.5) + 0.5 * q.xy * (scale / outer);
}

#endif  // PHYXEL_ENVIRONMENT_GLSL
