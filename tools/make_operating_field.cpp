// make_operating_field OUT.png [SIZE]: writes procedural_operating_field (render/image.h), a
// surgical field seen from above for render.environment. scenes/operating_field.png is its
// output at the default size of 512: `make_operating_field scenes/operating_field.png`.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "render/image.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: make_operating_field OUT.png [SIZE (16 ... 4096, default 512)]\n");
    return 2;
  }
  const long size = argc == 3 ? std::strtol(argv[2], nullptr, 10) : 512;
  if (size < 16 || size > 4096) {
    std::fprintf(stderr, "make_operating_field: SIZE %s: allowed 16 ... 4096\n", argv[2]);
    return 2;
  }
  try {
    phyxel::render::write_png(argv[1], phyxel::render::procedural_operating_field(uint32_t(size)));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_operating_field: %s\n", e.what());
    return 1;
  }
  return 0;
}
