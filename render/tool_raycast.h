// Tools as the renderer sees them: a shape at a pose per frame (render::ToolDrawable), and the
// CPU twin of the tool pass's ray cast (render/shaders/tool_common.glsl, tool_visibility.comp):
// the nearest entry of a ray into a ball or a capsule (the segment from the tip along the
// axis, swept by the radius, engine/geometry/tool.h), and per pixel of an eye the nearest tool,
// its linear depth and eye-space normal, exactly as the shader casts it (in double).
#pragma once

#include <cstddef>
#include <vector>

#include "engine/scene/tool_desc.h"
#include "render/camera.h"

namespace phyxel::render {

// One tool to draw in a frame: its shape and where it is now.
struct ToolDrawable {
  ToolShape shape;
  ToolPose pose;
};

// Every tool of a scene at simulated time t: pose_at(path, t) (haptic tools too: their path
// holds their starting pose; a viewer that moves them passes its own poses).
std::vector<ToolDrawable> tool_drawables(const std::vector<ToolDesc>& tools, double t);

// The nearest entry t > 0 of the ray origin + t dir (dir a unit vector) into the tool, and the
// outward unit normal there; hit is false when the ray misses it or starts inside it.
struct ToolRayHit {
  bool hit = false;
  double t = 0;
  Vec3 normal = Vec3::UnitZ();
};
ToolRayHit intersect_tool(const ToolShape& shape, const ToolPose& pose, const Vec3& origin,
                          const Vec3& dir);

// What the tool pass finds at the centre of pixel (x, y) (integers, rows top to bottom) of an
// eye of width x height pixels: the nearest tool whose entry lies between the near and far
// planes (tool = -1: none), its linear depth (0 at near, 1 at far, as project_to_pixel) and
// the eye-space normal (the camera looks down -z).
struct ToolPixel {
  int tool = -1;
  double depth = 1;
  Vec3 normal = Vec3::UnitZ();
};
ToolPixel tool_at_pixel(const EyeView& eye, uint32_t width, uint32_t height,
                        const std::vector<ToolDrawable>& tools, uint32_t x, uint32_t y);

}  // namespace phyxel::render
