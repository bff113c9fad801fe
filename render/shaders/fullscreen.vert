// One triangle covering the viewport (the shading pass).
#version 450

void main() {
  const vec2 p = vec2((gl_VertexIndex & 1) != 0 ? 3.0 : -1.0, (gl_VertexIndex & 2) != 0 ? 3.0 : -1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
