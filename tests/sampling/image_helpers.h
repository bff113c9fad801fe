// Synthetic NIfTI label volumes written by the image tests: balls of labels on a voxel grid.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/geometry/image_volume.h"
#include "engine/scene/scene.h"

namespace phyxel::test {

// A grid of dims voxels holding `outer` inside the ball of radius r_outer (voxels) around
// `centre` (voxel coordinates), and `inner` inside the concentric ball of radius r_inner.
inline NiftiWriteSpec ball_volume(std::array<int64_t, 3> dims, const Vec3& centre, double r_outer,
                                  double r_inner = 0, double outer = 1, double inner = 2) {
  NiftiWriteSpec spec;
  spec.dims = {dims[0], dims[1], dims[2], 1};
  spec.values.resize(size_t(dims[0] * dims[1] * dims[2]));
  size_t n = 0;
  for (int64_t k = 0; k < dims[2]; ++k)
    for (int64_t j = 0; j < dims[1]; ++j)
      for (int64_t i = 0; i < dims[0]; ++i, ++n) {
        const double r = (Vec3(double(i), double(j), double(k)) - centre).norm();
        spec.values[n] = r <= r_inner ? inner : r <= r_outer ? outer : 0;
      }
  return spec;
}

// The voxels of `spec` whose value is in `labels`: their count and centroid (voxel coordinates).
struct VoxelTruth {
  int64_t count = 0;
  Vec3 centroid = Vec3::Zero();
};
inline VoxelTruth voxel_truth(const NiftiWriteSpec& spec, const std::vector<double>& labels) {
  VoxelTruth truth;
  size_t n = 0;
  for (int64_t k = 0; k < spec.dims[2]; ++k)
    for (int64_t j = 0; j < spec.dims[1]; ++j)
      for (int64_t i = 0; i < spec.dims[0]; ++i, ++n)
        for (double l : labels)
          if (spec.values[n] == l) {
            ++truth.count;
            truth.centroid += Vec3(double(i), double(j), double(k));
          }
  truth.centroid /= double(truth.count);
  return truth;
}

inline Shape image_shape(const std::filesystem::path& path, const VoxelSelection& selection) {
  Shape s;
  s.type = Shape::Type::Image;
  s.path = path;
  s.labels = selection.labels;
  s.threshold = selection.threshold;
  s.image = std::make_shared<const LabelMask>(read_image_volume(path, std::nullopt), selection);
  return s;
}

}  // namespace phyxel::test
