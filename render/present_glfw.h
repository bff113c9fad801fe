// Presents host RGBA8 frames in a GLFW window through a Vulkan swapchain (the viewer).
//
// The compute core's context (compute/context.h) enables neither VK_KHR_surface nor
// VK_KHR_swapchain, and the renderer must run on the solver's context, so the presenter has
// an instance and device of its own (through GLFW's loader): each frame is copied from the
// renderer's readback buffer into a staging buffer and from there into the swapchain image
// (vkCmdCopyBufferToImage; R and B swapped for BGRA swapchains). For window-sized frames that
// is a few MB per frame, far below what the copy costs to render.
#pragma once

#include <cstdint>
#include <memory>

#include "render/image.h"

struct GLFWwindow;

namespace phyxel::render {

class Presenter {
 public:
  // Throws std::runtime_error (one line) when Vulkan cannot present to the window.
  explicit Presenter(GLFWwindow* window);
  ~Presenter();
  Presenter(const Presenter&) = delete;
  Presenter& operator=(const Presenter&) = delete;

  // Shows `frame` (top-left aligned; the rest of the window in the background colour).
  // Recreates the swapchain when the window changed size.
  void present(const RgbaImage& frame);
  std::string device_name() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace phyxel::render
