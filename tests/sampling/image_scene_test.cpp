// Image shapes in scene files: labels as an object and its inclusion, and every bad input
// refused with one line naming the file, the JSON path and the problem.
#include <gtest/gtest.h>

#include <fstream>

#include "engine/geometry/image_volume.h"
#include "engine/sampling/phyxel_set.h"
#include "image_helpers.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

std::string scene_text(const std::string& shape, const std::string& inclusions = "") {
  return R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"name": "brain", "shape": )" +
         shape + R"(, "spacing": 0.0013, "material": {"young": 3000, "poisson": 0.45,
         "density": 1040})" +
         (inclusions.empty() ? "" : ", \"inclusions\": " + inclusions) + "}]}";
}

// A two-label volume: 1 in a ball of radius 12 voxels (1 mm), 2 in the inner ball of radius 6.
std::filesystem::path two_labels(const std::filesystem::path& dir, NiftiWriteSpec* spec = nullptr) {
  NiftiWriteSpec s = ball_volume({34, 34, 34}, Vec3(16, 16, 16), 12, 6);
  s.type = VoxelType::Int16;
  write_nifti_volume(dir / "labels.nii.gz", s);
  if (spec) *spec = s;
  return dir / "labels.nii.gz";
}

TEST(ImageScene, ALabelsInclusionGetsItsMaterial) {
  const auto dir = test_dir();
  NiftiWriteSpec spec;
  two_labels(dir, &spec);
  const Scene scene = parse_scene(
      scene_text(R"({"type": "image", "file": "labels.nii.gz", "labels": [1, 2]})",
                 R"([{"name": "white", "shape": {"type": "image", "file": "labels.nii.gz",
                     "labels": [2]}, "material": {"young": 6000, "poisson": 0.45,
                     "density": 1040}}])"),
      dir / "scene.json");
  ASSERT_EQ(scene.objects[0].inclusions.size(), 1u);
  // Both shapes were built from one reading of the file.
  const PhyxelSet set = sample_scene(scene);
  const Vec3 centre = 1e-3 * Vec3(16, 16, 16);
  double inclusion_volume = 0;
  for (size_t p = 0; p < set.size(); ++p) {
    const double r = (set.rest[p] - centre).norm() / 1e-3;  // voxels
    if (set.material[p] == 1) inclusion_volume += set.volume[p];
    if (r < 5.5) {
      EXPECT_EQ(set.material[p], 1u) << r;
    }
    if (r > 7) {
      EXPECT_EQ(set.material[p], 0u) << r;
    }
  }
  const double labelled = double(voxel_truth(spec, {2}).count) * 1e-9;
  EXPECT_NEAR(inclusion_volume / labelled, 1, 0.1);
  EXPECT_EQ(set.materials[1].young, 6000);
}

std::string error_of(const std::filesystem::path& dir, const std::string& shape) {
  return scene_error([&] { parse_scene(scene_text(shape), dir / "scene.json"); });
}

void expect_has(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << message << "\n  lacks: " << part;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

std::string image(const std::string& file, const std::string& rest = R"("labels": [1])") {
  return R"({"type": "image", "file": ")" + file + "\", " + rest + "}";
}

TEST(ImageScene, BadInputsAreRefusedWithTheirMessage) {
  const auto dir = test_dir();
  two_labels(dir);
  const std::string at = (dir / "scene.json").string() + ": objects[0].shape";
  expect_has(error_of(dir, image("none.nii.gz")),
             at + ".file: image file \"" + (dir / "none.nii.gz").string() + "\" does not exist");
  expect_has(error_of(dir, image("/usr/share/mricron/templates/none.nii.gz")),
             "Debian's mricron-data package");
  write_file(dir / "labels.hdr", "x");
  expect_has(error_of(dir, image("labels.hdr")), "reads NIfTI files named .nii or .nii.gz");
  write_file(dir / "garbage.nii", std::string(600, 'x'));
  expect_has(error_of(dir, image("garbage.nii")), at + ".file: cannot use image file \"" +
                                                      (dir / "garbage.nii").string() +
                                                      "\": " + (dir / "garbage.nii").string() +
                                                      ": not a readable NIfTI-1 or NIfTI-2 "
                                                      "header");

  // Truncated: an uncompressed file by its size, a compressed one when its data runs out.
  NiftiWriteSpec ball = ball_volume({20, 20, 20}, Vec3(10, 10, 10), 6);
  write_nifti_volume(dir / "short.nii", ball);
  std::filesystem::resize_file(dir / "short.nii", 352 + 4000);
  expect_has(error_of(dir, image("short.nii")), "the file is truncated: 4352 bytes");
  write_nifti_volume(dir / "short.nii.gz", ball);
  std::filesystem::resize_file(dir / "short.nii.gz",
                               std::filesystem::file_size(dir / "short.nii.gz") / 2);
  expect_has(error_of(dir, image("short.nii.gz")), "cannot read the voxel data");

  // An RGB image: datatype 128, 24 bits per voxel (NIfTI-1 header offsets 70 and 72).
  write_nifti_volume(dir / "rgb.nii", ball);
  {
    std::fstream f(dir / "rgb.nii", std::ios::in | std::ios::out | std::ios::binary);
    const int16_t type_and_bits[2] = {128, 24};
    f.seekp(70);
    f.write(reinterpret_cast<const char*>(type_and_bits), sizeof type_and_bits);
  }
  expect_has(error_of(dir, image("rgb.nii")), "unsupported data type RGB24");

  NiftiWriteSpec frames = ball;
  frames.dims[3] = 3;
  frames.values.resize(3 * ball.values.size());
  write_nifti_volume(dir / "frames.nii.gz", frames);
  expect_has(error_of(dir, image("frames.nii.gz")),
             "the image is 4D with 3 frames; choose one with \"frame\" (0 to 2)");
  expect_has(error_of(dir, image("frames.nii.gz", R"("labels": [1], "frame": 3)")),
             "frame 3 does not exist");

  expect_has(error_of(dir, image("labels.nii.gz", R"("labels": [1, 7])")),
             at + ".labels: " + (dir / "labels.nii.gz").string() +
                 ": no voxel has label 7 (the values range from 0 to 2)");
  expect_has(error_of(dir, image("labels.nii.gz", R"("threshold": 2.5)")),
             at + ".threshold: " + (dir / "labels.nii.gz").string() +
                 ": no voxel's value reaches the threshold 2.5");
  expect_has(error_of(dir, image("labels.nii.gz", R"("labels": [1], "threshold": 1)")),
             "both labels and threshold are given");
  expect_has(error_of(dir, image("labels.nii.gz", "\"frame\": 0")),
             "neither labels nor threshold is given");
  expect_has(error_of(dir, image("labels.nii.gz", R"("labels": [])")), "empty array");
}

TEST(ImageScene, ATooSmallLabelIsRefusedLikeOtherShapes) {
  const auto dir = test_dir();
  // A sheet one voxel (1 mm) thick, sampled at a spacing of 1.3 mm: one plane of phyxels.
  NiftiWriteSpec sheet = ball_volume({9, 9, 9}, Vec3(4, 4, 4), 0);
  for (int64_t j = 1; j <= 7; ++j)
    for (int64_t i = 1; i <= 7; ++i) sheet.values[size_t((4 * 9 + j) * 9 + i)] = 1;
  write_nifti_volume(dir / "sheet.nii", sheet);
  const Scene scene = parse_scene(scene_text(image("sheet.nii")), dir / "scene.json");
  const std::string message = scene_error([&] { sample_scene(scene); });
  expect_has(message, "objects[0] \"brain\" (image of bounds 7 x 7 x 1 mm)");
  expect_has(message, "use a spacing of at most about");
}

TEST(ImageScene, SpecklesThinnerThanTheSpacingAreLeftOut) {
  const auto dir = test_dir();
  // A ball of radius 8 voxels and, apart from it, one labelled voxel: a speck with no MLS fit.
  NiftiWriteSpec spec = ball_volume({30, 20, 20}, Vec3(9, 9, 9), 8);
  spec.values[size_t((10 * 20 + 10) * 30 + 25)] = 1;
  write_nifti_volume(dir / "speck.nii", spec);
  const PhyxelSet set =
      sample_scene(parse_scene(scene_text(image("speck.nii")), dir / "scene.json"));
  ASSERT_GT(set.size(), 500u);
  for (size_t p = 0; p < set.size(); ++p)
    EXPECT_LT((set.rest[p] - 1e-3 * Vec3(9, 9, 9)).norm(), 1e-3 * 9.5) << p;
}

}  // namespace
}  // namespace phyxel::test
