// The one translation unit holding the implementations of Debian's stb_image and
// stb_image_write (libstb-dev). Everything else includes the headers without the
// *_IMPLEMENTATION macros and links phyxel_stb.
//
// PNG files are deflated by zlib at Z_BEST_SPEED (STBIW_ZLIB_COMPRESS) with every row filtered
// by "Up", instead of stb's own deflate at level 8 and a per-row choice among the five filters:
// a 1920 x 1080 frame of cut tissue 162 -> 25 ms and 0.61 -> 0.54 MB on the development machine
// (docs/decisions.md, "PNG encoding"). The filter is stb's global, set once here before main().
#include <zlib.h>

#include <cstdlib>

namespace {

// stb's signature: returns a malloc'd zlib stream (stb frees it), its length in *out_len;
// nullptr where zlib fails (stb then reports that the image could not be written).
unsigned char* phyxel_zlib_compress(unsigned char* data, int data_len, int* out_len, int) {
  uLongf bound = compressBound(static_cast<uLong>(data_len));
  auto* out = static_cast<unsigned char*>(std::malloc(bound));
  if (out == nullptr) return nullptr;
  if (compress2(out, &bound, data, static_cast<uLong>(data_len), Z_BEST_SPEED) != Z_OK) {
    std::free(out);
    return nullptr;
  }
  *out_len = static_cast<int>(bound);
  return out;
}

}  // namespace

#define STBIW_ZLIB_COMPRESS phyxel_zlib_compress
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace {

constexpr int kPngFilterUp = 2;  // stb's filter numbering (PNG filter type 2)
[[maybe_unused]] const bool kPngFilterSet = (stbi_write_force_png_filter = kPngFilterUp, true);

}  // namespace
