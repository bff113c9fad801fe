// RGBA8 images on the host: textures read with stb_image (PNG, JPEG), the built-in procedural
// tissue texture, and PNG output with stb_image_write.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace phyxel::render {

struct RgbaImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> pixels;  // rows top to bottom, 4 bytes per pixel

  RgbaImage() = default;
  RgbaImage(uint32_t w, uint32_t h) : width(w), height(h), pixels(size_t(w) * h * 4, 0) {}
  uint8_t* at(uint32_t x, uint32_t y) { return &pixels[(size_t(y) * width + x) * 4]; }
  const uint8_t* at(uint32_t x, uint32_t y) const { return &pixels[(size_t(y) * width + x) * 4]; }
};

// Reads a PNG or JPEG file as RGBA8. Throws SceneError "CONTEXT: problem; allowed ..." (context
// names the scene file and key, e.g. "scenes/x.json: render.texture") when the file is missing,
// unreadable, not an image stb_image decodes, or has a zero size.
RgbaImage load_image(const std::filesystem::path& file, const std::string& context);

// A deterministic soft-tissue texture (pink parenchyma, mottling, branching vessels), size x
// size pixels.
RgbaImage procedural_tissue_texture(uint32_t size = 512);

// A deterministic operating field seen from above, size x size pixels, for render.environment
// (render/environment_map.h): exposed pink tissue with sulci, vessels and wet glints over most
// of the image, a dark bloody rim, steel retractor blades with glints and green drapes with
// folds at the border (tools/make_operating_field writes scenes/operating_field.png).
RgbaImage procedural_operating_field(uint32_t size = 512);

// Writes a PNG; throws std::runtime_error naming the file when it cannot.
void write_png(const std::filesystem::path& file, const RgbaImage& image);

}  // namespace phyxel::render
