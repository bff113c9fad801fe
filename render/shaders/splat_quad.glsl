#ifndef PHYXEL_SPLAT_QUAD_GLSL
#define PHYXEL_SPLAT_QUAD_GLSL
// One splat as a quad: the square of side 2r around the disc in the disc's plane (drawn as a
// 4-vertex triangle strip per instance). Its projection contains the projected disc exactly,
// so every pixel whose ray meets the disc is rasterised; the fragment shaders intersect.
// Included by splat_quad.vert (accumulation pass) and splat_quad_depth.vert (visibility pass,
// PHYXEL_SPLAT_DEPTH_ONLY: no texture outputs, which that fragment shader does not read).

layout(push_constant) uniform Push { EyePush eye; };
layout(std430, set = 0, binding = kSplatBindingSplats) readonly buffer Splats { Splat splats[]; };

layout(location = 0) flat out vec4 v_centre;  // eye space centre, radius
layout(location = 1) flat out vec4 v_normal;  // eye space unit normal
#ifndef PHYXEL_SPLAT_DEPTH_ONLY
layout(location = 2) flat out vec4 v_ds;      // eye space gradient of s, s at the centre
layout(location = 3) flat out vec4 v_dt;      // eye space gradient of t, t at the centre
#endif

void main() {
  const Splat s = splats[gl_InstanceIndex];
  const mat3 rot = mat3(eye.view);
  const vec3 c = (eye.view * vec4(s.centre.xyz, 1.0)).xyz;
  const vec3 n = rot * s.normal.xyz;
  const float r = s.centre.w;
  const vec3 a = abs(n.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0);
  const vec3 t1 = normalize(cross(n, a));
  const vec3 t2 = cross(n, t1);
  const float cx = (gl_VertexIndex & 1) != 0 ? 1.0 : -1.0;
  const float cy = (gl_VertexIndex & 2) != 0 ? 1.0 : -1.0;
  // r = 0 (nothing to draw) collapses the quad to a point: no fragments.
  gl_Position = project_eye(eye, c + r * (cx * t1 + cy * t2));
  v_centre = vec4(c, r);
  v_normal = vec4(n, 0.0);
#ifndef PHYXEL_SPLAT_DEPTH_ONLY
  v_ds = vec4(rot * s.ds_dx.xyz, s.ds_dx.w);
  v_dt = vec4(rot * s.dt_dx.xyz, s.dt_dx.w);
#endif
}

#endif  // PHYXEL_SPLAT_QUAD_GLSL
