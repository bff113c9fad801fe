// Label volumes from medical images: NIfTI-1 and NIfTI-2 files (.nii, .nii.gz) read with
// Debian's NIfTI library (libnifti2), placed in world space (metres), and the voxels selected
// by labels or a threshold as a smooth inside field with outward normals.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "engine/geometry/vec3.h"

namespace phyxel {

// Voxel types that a label or intensity volume may have (NIfTI's scalar DT_ codes).
enum class VoxelType { UInt8, Int8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

// One 3D frame of a NIfTI file, as stored, with its placement.
struct ImageVolume {
  std::filesystem::path path;
  std::array<int64_t, 3> dims{};  // voxels along i, j, k
  VoxelType type = VoxelType::UInt8;
  std::vector<uint8_t> bytes;   // dims[0] * dims[1] * dims[2] values, i fastest, host order
  double slope = 0, inter = 0;  // scl_slope, scl_inter (slope 0: the values are not scaled)
  // Voxel (i, j, k) -> world (m): the sform where its code is > 0, else the qform, else the
  // pixel sizes; units from xyzt_units (mm when unset).
  Eigen::Affine3d voxel_to_world = Eigen::Affine3d::Identity();
  std::string placement;  // "sform", "qform" or "pixel sizes"

  size_t voxels() const { return size_t(dims[0] * dims[1] * dims[2]); }
  // The stored value of voxel n, and the same after scl_slope / scl_inter.
  double raw(size_t n) const;
  double scaled(size_t n) const { return slope != 0 ? slope * raw(n) + inter : raw(n); }
};

// Reads frame `frame` of a NIfTI file (a 4D file needs one; a 3D file takes none or 0).
// Throws std::runtime_error "PATH: problem; what to do" for a missing, truncated or corrupt
// file, an unsupported data type, 4D without a frame, or an unusable placement.
ImageVolume read_image_volume(const std::filesystem::path& path, std::optional<int64_t> frame);

// Which voxels are inside: those whose stored value is one of `labels`, or (labels empty)
// whose scaled value is >= `threshold`.
struct VoxelSelection {
  std::vector<int64_t> labels;
  std::optional<double> threshold;
};

// The selected voxels as a field over world space: the trilinear interpolation of the 0/1
// mask between voxel centres, inside where it is >= 1/2 (so a block of voxels keeps its
// volume). Only the box of the selected voxels (one voxel of margin) is kept.
class LabelMask {
 public:
  // Throws std::runtime_error naming the file: a label that no voxel has, or no voxel selected.
  LabelMask(const ImageVolume& volume, const VoxelSelection& selection);

  double field(const Vec3& world) const;
  // Inside or on the boundary (a point on a voxel face, as lattice sites of a sheet are, is in
  // despite rounding).
  bool contains(const Vec3& world) const { return field(world) >= 0.5 - 1e-9; }
  // Outward unit normal near p: minus the gradient of the mask blurred by a Gaussian of
  // support `radius` (m), so smooth across voxel steps; zero where the mask has no slope.
  Vec3 normal(const Vec3& p, double radius) const;
  // World box of the selected voxels' cells.
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  // Selected voxels x voxel volume (m^3), and their centroid (m).
  double labelled_volume() const { return labelled_volume_; }
  const Vec3& labelled_centroid() const { return centroid_; }
  // Largest edge of a voxel in world space (m).
  double voxel_size() const { return voxel_size_; }

 private:
  bool at(int64_t i, int64_t j, int64_t k) const;

  std::array<int64_t, 3> lo_{}, n_{};  // kept box: voxels lo_ + [0, n_)
  std::vector<uint8_t> mask_;
  Eigen::Affine3d to_world_, to_voxel_;
  Eigen::AlignedBox3d bounds_;
  double labelled_volume_ = 0, voxel_size_ = 0;
  Vec3 centroid_ = Vec3::Zero();
};

// How a test or benchmark writes a volume (NIfTI-1 or -2; .nii.gz compresses).
struct NiftiWriteSpec {
  std::array<int64_t, 4> dims{1, 1, 1, 1};  // i, j, k, frames
  VoxelType type = VoxelType::UInt8;
  std::vector<double> values;  // dims product, i fastest
  int version = 1;
  Vec3 pixdim = Vec3::Ones();
  int xyz_units = 2;                     // NIfTI code: 0 unknown, 1 m, 2 mm, 3 um
  std::optional<Eigen::Matrix4d> sform;  // code 1 when set (units of xyz_units)
  // qform (code 1 when set): quaternion b, c, d, offsets, qfac.
  std::optional<std::array<double, 7>> qform;
  double slope = 0, inter = 0;
};
void write_nifti_volume(const std::filesystem::path& path, const NiftiWriteSpec& spec);

}  // namespace phyxel
