// The viewer of a build without PHYXEL_WITH_WINDOW: says how to get one.
#include <stdexcept>

#include "render/viewer.h"

namespace phyxel::render {

bool viewer_available() {
  return false;
}

void run_viewer(const Scene& scene, const ViewerOptions&) {
  throw std::runtime_error(scene.file.string() +
                           ": this phyxel was built without the window viewer (configure with "
                           "-DPHYXEL_WITH_WINDOW=ON, needs libglfw3-dev); for frames without a "
                           "display use: phyxel run SCENE --render mono|stereo --out DIR");
}

}  // namespace phyxel::render
