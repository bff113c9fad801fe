// Image shapes of the scene format: a NIfTI file, the voxels inside (labels or a threshold)
// and, for a 4D file, the frame (docs/scene-format.md, "Shapes").
#include <string>

#include "engine/geometry/image_volume.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/scene_json_tools.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using json_reader::Limits;
using json_reader::Node;

constexpr std::string_view kImageExpected =
    "an image {\"type\": \"image\", \"file\": \"labels.nii.gz\", \"labels\": [1, 2]} or "
    "{..., \"threshold\": x}";
// The MRI templates of the example scenes come with this Debian package.
constexpr std::string_view kTemplatesFolder = "/usr/share/mricron/";

std::string allowed_file(const fs::path& folder) {
  std::string allowed =
      "allowed a NIfTI-1 or NIfTI-2 file (.nii or .nii.gz), relative to the scene file's folder (";
  allowed += folder.empty() ? std::string("the working directory") : folder.string();
  allowed += ")";
  return allowed;
}

std::shared_ptr<const ImageVolume> read_volume(const Node& file_node, const Shape& s,
                                               const fs::path& folder, ImageReads* images) {
  const std::pair<fs::path, int64_t> key{s.path, s.frame.value_or(-1)};
  if (images)
    if (const auto it = images->find(key); it != images->end()) return it->second;
  std::error_code ec;
  if (!fs::is_regular_file(s.path, ec)) {
    std::string problem = "image file \"" + s.path.string() + "\" does not exist";
    if (s.path.string().rfind(kTemplatesFolder, 0) == 0)
      problem += " (it comes with Debian's mricron-data package: run scripts/install-deps.sh)";
    file_node.fail(problem, allowed_file(folder));
  }
  std::shared_ptr<const ImageVolume> volume;
  try {
    volume = std::make_shared<const ImageVolume>(read_image_volume(s.path, s.frame));
  } catch (const std::exception& e) {
    file_node.fail("cannot use image file \"" + s.path.string() + "\": " + e.what(),
                   allowed_file(folder));
  }
  if (images) images->emplace(key, volume);
  return volume;
}

}  // namespace

Shape read_image_shape(const Node& node, const fs::path& folder, ImageReads* images) {
  node.expect_object(kImageExpected, {"type", "file", "labels", "threshold", "frame"});
  Shape s;
  s.type = Shape::Type::Image;
  const Node file_node = node.at("file", "the NIfTI file, relative to the scene file's folder");
  s.path = folder / file_node.text();
  const auto labels = node.find("labels");
  const auto threshold = node.find("threshold");
  if (labels && threshold)
    threshold->fail("both labels and threshold are given",
                    "allowed one of them: labels (voxel values inside) or threshold");
  if (!labels && !threshold)
    node.fail("neither labels nor threshold is given",
              "allowed \"labels\": [integers] (voxel values inside) or \"threshold\": x "
              "(voxels whose value is >= x are inside)");
  VoxelSelection selection;
  if (labels) {
    for (const Node& l : labels->elements("an array of integer voxel values"))
      selection.labels.push_back(l.integer(Limits::any()));
    if (selection.labels.empty())
      labels->fail("empty array", "allowed one or more integer voxel values");
    s.labels = selection.labels;
  } else {
    selection.threshold = s.threshold = threshold->number(Limits::any(), "");
  }
  if (const auto frame = node.find("frame")) s.frame = frame->integer(Limits::at_least(0));
  const auto volume = read_volume(file_node, s, folder, images);
  try {
    s.image = std::make_shared<const LabelMask>(*volume, selection);
  } catch (const std::exception& e) {
    (labels ? *labels : *threshold)
        .fail(e.what(), labels ? "allowed voxel values that the image has"
                               : "allowed a threshold that some voxel reaches");
  }
  return s;
}

}  // namespace phyxel
