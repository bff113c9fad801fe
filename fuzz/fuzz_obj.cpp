// libFuzzer target: the OBJ reader (load_obj_mesh) on arbitrary bytes, through a temporary
// file as the reader takes a path. Its contract is std::runtime_error with a one-line reason;
// any other exception escapes and libFuzzer reports it. A mesh that loads is queried once.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "engine/geometry/mesh.h"

namespace {

std::filesystem::path input_file() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  return dir / ("phyxel_fuzz_obj_" + std::to_string(getpid()) + ".obj");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::filesystem::path path = input_file();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const phyxel::TriangleMesh mesh = phyxel::load_obj_mesh(path, 1.0);
    (void)mesh.contains(mesh.bounds.center());
  } catch (const std::runtime_error&) {
  }
  return 0;
}
