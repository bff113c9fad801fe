// libFuzzer target: the OBJ reader on arbitrary bytes, parsed from memory (parse_obj_mesh, the
// reader of load_obj_mesh after it has read the file): no temporary file, so nothing is left
// behind however the process ends. Its contract is std::runtime_error with a one-line reason;
// any other exception escapes and libFuzzer reports it. A mesh that loads is queried once.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "engine/geometry/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const phyxel::TriangleMesh mesh = phyxel::parse_obj_mesh(text, "fuzz.obj", 1.0);
    (void)mesh.contains(mesh.bounds.center());
  } catch (const std::runtime_error&) {
  }
  return 0;
}
