// Image shapes: NIfTI label volumes written here (int16, uint8, float32; .nii and .nii.gz;
// NIfTI-1 and -2; sform, qform only, pixel sizes only, a flipped x axis, an oblique sform,
// metres) are sampled to the labelled volume and centroid in world space, with smooth normals.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/geometry/image_volume.h"
#include "engine/geometry/shape.h"
#include "engine/sampling/phyxel_set.h"
#include "image_helpers.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

enum class Placement { Sform, QformOnly, PixdimOnly, FlippedX, Oblique, SformMetres, NoUnits };

struct Case {
  const char* name;
  VoxelType type;
  const char* extension;
  int version;
  Placement placement;
  bool threshold;  // float volumes: select by threshold after scl_slope / scl_inter
};

const Vec3 kPixdim(1.0, 1.2, 0.9);                  // mm
const std::array<int64_t, 3> kDims = {36, 32, 40};  // voxels
const Vec3 kCentre(15.3, 17.0, 19.6);               // voxel coordinates of the ball
constexpr double kRadius = 11;                      // voxels
constexpr double kSpacing = 0.0013;                 // m: not the voxel size
const Eigen::Vector3d kOffset(-20, 10, 5);          // mm

Eigen::Matrix3d rotation(const Vec3& axis, double degrees) {
  return Eigen::AngleAxisd(degrees * M_PI / 180, axis.normalized()).toRotationMatrix();
}

// Writes the case's volume and returns the voxel -> world transform (m) it should be read with.
Eigen::Affine3d write_case(const Case& c, const std::filesystem::path& path, NiftiWriteSpec* out) {
  NiftiWriteSpec spec = ball_volume(kDims, kCentre, kRadius);
  spec.type = c.type;
  spec.version = c.version;
  spec.pixdim = kPixdim;
  if (c.threshold) {  // stored 0 / 1, scaled to -1 / 1
    spec.slope = 2;
    spec.inter = -1;
  }
  Eigen::Matrix4d world = Eigen::Matrix4d::Identity();  // in the file's units
  world.block<3, 1>(0, 3) = kOffset;
  Eigen::Matrix3d linear = kPixdim.asDiagonal();
  double unit = 1e-3;
  switch (c.placement) {
    case Placement::Sform:
      // A qform that disagrees: the sform wins.
      spec.qform = std::array<double, 7>{0, 0, 0.3, 50, 50, 50, 1};
      break;
    case Placement::QformOnly: {
      const double half = 15 * M_PI / 180;  // 30 degrees about z
      spec.qform =
          std::array<double, 7>{0, 0, std::sin(half), kOffset.x(), kOffset.y(), kOffset.z(), 1};
      linear = rotation(Vec3::UnitZ(), 30) * linear;
      break;
    }
    case Placement::PixdimOnly:
    case Placement::NoUnits:
      world.block<3, 1>(0, 3).setZero();
      if (c.placement == Placement::NoUnits) spec.xyz_units = 0;
      break;
    case Placement::FlippedX:
      linear(0, 0) = -linear(0, 0);
      break;
    case Placement::Oblique:
      linear = rotation(Vec3(1, 1, 0.3), 25) * linear;
      break;
    case Placement::SformMetres:
      spec.xyz_units = 1;
      linear *= 1e-3;
      world.block<3, 1>(0, 3) *= 1e-3;
      unit = 1;
      break;
  }
  world.block<3, 3>(0, 0) = linear;
  if (c.placement != Placement::QformOnly && c.placement != Placement::PixdimOnly &&
      c.placement != Placement::NoUnits)
    spec.sform = world;
  write_nifti_volume(path, spec);
  *out = spec;
  Eigen::Affine3d a;
  a.matrix() = world;
  a.matrix().topRows<3>() *= unit;
  return a;
}

const Case kCases[] = {
    {"int16_sform_nifti1", VoxelType::Int16, ".nii", 1, Placement::Sform, false},
    {"uint8_qform_only_gz", VoxelType::UInt8, ".nii.gz", 1, Placement::QformOnly, false},
    {"float32_pixdim_only_nifti2", VoxelType::Float32, ".nii", 2, Placement::PixdimOnly, true},
    {"int16_flipped_x_nifti2_gz", VoxelType::Int16, ".nii.gz", 2, Placement::FlippedX, false},
    {"uint8_oblique_sform", VoxelType::UInt8, ".nii", 1, Placement::Oblique, false},
    {"float32_sform_in_metres_gz", VoxelType::Float32, ".nii.gz", 1, Placement::SformMetres, true},
    {"int16_units_unset_are_mm", VoxelType::Int16, ".nii", 1, Placement::NoUnits, false},
};

TEST(ImageShape, SamplesTheLabelledVolumeAndCentroidInWorldSpace) {
  const auto dir = test_dir();
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    const auto path = dir / (std::string(c.name) + c.extension);
    NiftiWriteSpec spec;
    const Eigen::Affine3d world = write_case(c, path, &spec);
    const VoxelTruth truth = voxel_truth(spec, {1});
    const double true_volume = double(truth.count) * std::abs(world.linear().determinant());
    const Vec3 true_centroid = world * truth.centroid;

    VoxelSelection selection;
    if (c.threshold)
      selection.threshold = 0;
    else
      selection.labels = {1};
    const Shape shape = image_shape(path, selection);
    // NIfTI-1 stores pixel sizes and the sform in single precision.
    EXPECT_NEAR(shape.image->labelled_volume(), true_volume, 1e-6 * true_volume);
    EXPECT_LT((shape.image->labelled_centroid() - true_centroid).norm(), 1e-7);
    EXPECT_TRUE(shape_contains(shape, true_centroid));

    const PhyxelSet set = sample_scene(scene_of({object("ball", shape, kSpacing)}));
    const double volume = total_volume(set);
    Vec3 centroid = Vec3::Zero();
    for (size_t p = 0; p < set.size(); ++p) centroid += set.volume[p] * set.rest[p];
    centroid /= volume;
    EXPECT_LT(std::abs(volume / true_volume - 1), 0.03) << volume << " vs " << true_volume;
    EXPECT_LT((centroid - true_centroid).norm(), kSpacing / 2)
        << centroid.transpose() << " vs " << true_centroid.transpose();

    // Normals: outward and smooth (a voxel staircase would give axis-aligned ones). The ball is
    // round in voxel coordinates v: its world normal at x is A^-T (v - centre), A = world.linear().
    const Eigen::Matrix3d inverse_transpose = world.linear().inverse().transpose();
    double sum = 0, worst = 1;
    int surface = 0;
    for (size_t p = 0; p < set.size(); ++p) {
      if (!(set.flags[p] & kSurface)) continue;
      const Vec3 v = world.inverse() * set.rest[p];
      const double d = set.normal[p].dot((inverse_transpose * (v - kCentre)).normalized());
      sum += d;
      worst = std::min(worst, d);
      ++surface;
      EXPECT_NEAR(set.splat_radius[p], 0.8 * kSpacing, 1e-12);
    }
    ASSERT_GT(surface, 100);
    EXPECT_GT(sum / surface, 0.99) << worst;
    EXPECT_GT(worst, 0.9) << sum / surface;
  }
}

TEST(ImageShape, FourDimensionalFilesGiveTheChosenFrame) {
  const auto path = test_dir() / "frames.nii.gz";
  NiftiWriteSpec a = ball_volume({20, 20, 20}, Vec3(6, 6, 6), 4);
  const NiftiWriteSpec b = ball_volume({20, 20, 20}, Vec3(13, 12, 11), 4);
  a.dims[3] = 2;
  a.values.insert(a.values.end(), b.values.begin(), b.values.end());
  write_nifti_volume(path, a);
  const LabelMask second(read_image_volume(path, 1), {{1}, std::nullopt});
  EXPECT_LT((second.labelled_centroid() - 1e-3 * Vec3(13, 12, 11)).norm(), 1e-9);
}

}  // namespace
}  // namespace phyxel::test
