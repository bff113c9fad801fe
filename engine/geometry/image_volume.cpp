// NIfTI reading (libnifti2, which reads NIfTI-1 and NIfTI-2) and label masks (image_volume.h).
#include "engine/geometry/image_volume.h"

#include <nifti2_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "engine/geometry/image_types.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

// Largest frame we agree to read: 2^31 voxels.
constexpr int64_t kMaxVoxels = int64_t(1) << 31;

[[noreturn]] void fail(const fs::path& path, const std::string& problem) {
  throw std::runtime_error(path.string() + ": " + problem);
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

struct FreeImage {
  void operator()(nifti_image* image) const { nifti_image_free(image); }
};

bool has_nifti_extension(const fs::path& path) {
  const std::string name = path.filename().string();
  const auto ends = [&](const std::string& tail) {
    return name.size() > tail.size() &&
           name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  return ends(".nii") || ends(".nii.gz");
}

// Metres per unit of the file's xyzt_units (space part); 0 for units that are no length.
double metres_per_unit(int units) {
  switch (XYZT_TO_SPACE(units)) {
    case NIFTI_UNITS_UNKNOWN:  // the NIfTI convention: millimetres
    case NIFTI_UNITS_MM:
      return 1e-3;
    case NIFTI_UNITS_METER:
      return 1;
    case NIFTI_UNITS_MICRON:
      return 1e-6;
  }
  return 0;
}

Eigen::Matrix4d to_matrix(const nifti_dmat44& m) {
  Eigen::Matrix4d out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out(r, c) = m.m[r][c];
  return out;
}

// The voxel -> world (m) transform of the header, or a failure naming what is wrong.
Eigen::Affine3d placement(const nifti_image& image, const fs::path& path, std::string* how) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (image.sform_code > 0) {
    m = to_matrix(image.sto_xyz);
    *how = "sform";
  } else if (image.qform_code > 0) {
    m = to_matrix(image.qto_xyz);
    *how = "qform";
  } else {
    const Vec3 size(image.dx, image.dy, image.dz);
    if (!(size.array() > 0).all() || !size.allFinite())
      fail(path, "the pixel sizes (pixdim[1..3] = " + number(size.x()) + ", " + number(size.y()) +
                     ", " + number(size.z()) +
                     ") must be positive when the file has neither sform nor qform; fix the "
                     "header");
    m.diagonal().head<3>() = size;
    *how = "pixel sizes";
  }
  const double unit = metres_per_unit(image.xyz_units);
  if (unit == 0)
    fail(path, "the spatial units code " + std::to_string(XYZT_TO_SPACE(image.xyz_units)) +
                   " is not a length; use metres, millimetres or micrometres (xyzt_units)");
  Eigen::Affine3d a;
  a.matrix() = m;
  a.matrix().row(3) << 0, 0, 0, 1;
  a.matrix().topRows<3>() *= unit;
  const double det = a.linear().determinant();
  if (!a.matrix().allFinite() || !(std::abs(det) > 1e-30))
    fail(path, "the " + *how +
                   " does not map voxels to a volume (singular or not finite); fix "
                   "the header's " +
                   *how);
  return a;
}

// Checks the header and picks the frame; returns the frame index.
int64_t check_header(const nifti_image& image, const fs::path& path, std::optional<int64_t> frame) {
  if (!voxel_type_of(image.datatype))
    fail(path, std::string("unsupported data type ") + nifti_datatype_string(image.datatype) +
                   "; store labels or intensities as integers or real numbers (uint8, int16, "
                   "int32, float32, ...)");
  for (int d = 5; d <= 7; ++d)
    if (image.dim[0] >= d && image.dim[d] > 1)
      fail(path, "the image has " + std::to_string(image.dim[0]) +
                     " dimensions; an image shape reads 3D volumes or one frame of a 4D one");
  const int64_t frames = image.dim[0] >= 4 ? std::max<int64_t>(image.nt, 1) : 1;
  if (frames > 1 && !frame)
    fail(path, "the image is 4D with " + std::to_string(frames) +
                   " frames; choose one with \"frame\" (0 to " + std::to_string(frames - 1) + ")");
  const int64_t chosen = frame.value_or(0);
  if (chosen < 0 || chosen >= frames)
    fail(path, "frame " + std::to_string(chosen) + " does not exist: the image has " +
                   std::to_string(frames) + (frames == 1 ? " frame" : " frames") + " (0 to " +
                   std::to_string(frames - 1) + ")");
  if (!(image.nx >= 1 && image.ny >= 1 && image.nz >= 1) ||
      double(image.nx) * double(image.ny) * double(image.nz) > double(kMaxVoxels))
    fail(path, "the image's size " + std::to_string(image.nx) + " x " + std::to_string(image.ny) +
                   " x " + std::to_string(image.nz) + " is empty or above 2^31 voxels");
  return chosen;
}

}  // namespace

double ImageVolume::raw(size_t n) const {
  double out = 0;
  with_voxel_values(*this, [&](const auto* values) { out = double(values[n]); });
  return out;
}

ImageVolume read_image_volume(const fs::path& path, std::optional<int64_t> frame) {
  nifti_set_debug_level(0);  // the library prints its errors; ours are one line
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) fail(path, "cannot open the image: no such file");
  if (!has_nifti_extension(path))
    fail(path, "an image shape reads NIfTI files named .nii or .nii.gz; convert the image");
  std::unique_ptr<nifti_image, FreeImage> image(nifti_image_read(path.c_str(), 0));
  if (!image)
    fail(path,
         "not a readable NIfTI-1 or NIfTI-2 header (corrupt or truncated file); write the "
         "volume again as .nii or .nii.gz");
  const int64_t chosen = check_header(*image, path, frame);
  ImageVolume out;
  out.path = path;
  out.dims = {image->nx, image->ny, image->nz};
  out.type = *voxel_type_of(image->datatype);
  out.voxel_to_world = placement(*image, path, &out.placement);
  out.slope = std::isfinite(image->scl_slope) ? image->scl_slope : 0;
  out.inter = std::isfinite(image->scl_inter) ? image->scl_inter : 0;

  const size_t bytes = out.voxels() * size_t(image->nbyper);
  // An uncompressed file that ends early is named as such before the library reads it.
  const std::string name = path.filename().string();
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".nii") == 0) {
    const auto size = fs::file_size(path, ec);
    const auto need = uintmax_t(image->iname_offset) + uintmax_t(chosen + 1) * bytes;
    if (ec || size < need)
      fail(path, "the file is truncated: " + std::to_string(size) + " bytes, the header needs " +
                     std::to_string(need) + "; write the volume again");
  }
  // The frame's bytes, read through the library's znzlib (plain or gzip): its own readers print
  // their failures to stderr, and ours are one line.
  out.bytes.resize(bytes);
  znzFile file = znzopen(path.c_str(), "rb", nifti_is_gzfile(path.c_str()));
  if (znz_isnull(file)) fail(path, "cannot open the image for reading; check its permissions");
  const auto start = znz_off_t(image->iname_offset) + znz_off_t(chosen) * znz_off_t(bytes);
  const bool read =
      znzseek(file, start, SEEK_SET) >= 0 && znzread(out.bytes.data(), 1, bytes, file) == bytes;
  znzclose(file);
  if (!read)
    fail(path, "cannot read the voxel data (truncated or corrupt file); write the volume again");
  if (image->byteorder != nifti_short_order() && image->nbyper > 1)
    nifti_swap_Nbytes(int64_t(out.voxels()), image->nbyper, out.bytes.data());
  return out;
}

LabelMask::LabelMask(const ImageVolume& volume, const VoxelSelection& selection)
    : to_world_(volume.voxel_to_world), to_voxel_(volume.voxel_to_world.inverse()) {
  std::vector<int64_t> labels = selection.labels;
  std::sort(labels.begin(), labels.end());
  labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  const size_t voxels = volume.voxels();
  std::vector<uint8_t> full(voxels);
  std::vector<int64_t> hits(labels.size());
  double lowest = INFINITY, highest = -INFINITY;
  with_voxel_values(volume, [&](const auto* values) {
    for (size_t n = 0; n < voxels; ++n) {
      const double raw = double(values[n]);
      if (!labels.empty()) {
        lowest = std::min(lowest, raw);
        highest = std::max(highest, raw);
        // Only whole numbers in int64's range can be labels (the cast is then defined).
        if (!(std::abs(raw) < 9.2e18) || raw != std::floor(raw)) continue;
        const auto it = std::lower_bound(labels.begin(), labels.end(), int64_t(raw));
        if (it != labels.end() && double(*it) == raw) {
          full[n] = 1;
          ++hits[it - labels.begin()];
        }
      } else {
        const double v = volume.slope != 0 ? volume.slope * raw + volume.inter : raw;
        if (std::isfinite(v)) {
          lowest = std::min(lowest, v);
          highest = std::max(highest, v);
        }
        full[n] = v >= *selection.threshold;
      }
    }
  });
  const std::string range = "the values range from " + number(lowest) + " to " + number(highest);
  for (size_t l = 0; l < labels.size(); ++l)
    if (hits[l] == 0)
      fail(volume.path, "no voxel has label " + std::to_string(labels[l]) + " (" + range +
                            "); list labels that the image has");
  // The selected voxels' box, their count and centroid (voxel coordinates).
  std::array<int64_t, 3> lo = volume.dims, hi = {-1, -1, -1};
  Vec3 sum = Vec3::Zero();
  int64_t count = 0;
  const auto [nx, ny, nz] = volume.dims;
  for (int64_t k = 0; k < nz; ++k)
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i) {
        if (!full[size_t((k * ny + j) * nx + i)]) continue;
        const std::array<int64_t, 3> at = {i, j, k};
        for (int d = 0; d < 3; ++d) {
          lo[d] = std::min(lo[d], at[d]);
          hi[d] = std::max(hi[d], at[d]);
        }
        sum += Vec3(double(i), double(j), double(k));
        ++count;
      }
  if (count == 0)
    fail(volume.path, "no voxel's value reaches the threshold " + number(*selection.threshold) +
                          " (" + range + ", after scl_slope and scl_inter); lower the threshold");
  for (int d = 0; d < 3; ++d) {
    lo_[d] = lo[d] - 1;
    n_[d] = hi[d] - lo[d] + 3;
  }
  mask_.assign(size_t(n_[0] * n_[1] * n_[2]), 0);
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i)
        mask_[size_t(((k - lo_[2]) * n_[1] + (j - lo_[1])) * n_[0] + (i - lo_[0]))] =
            full[size_t((k * ny + j) * nx + i)];
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1 ? hi[0] + 0.5 : lo[0] - 0.5), (c & 2 ? hi[1] + 0.5 : lo[1] - 0.5),
                      (c & 4 ? hi[2] + 0.5 : lo[2] - 0.5));
    bounds_.extend(to_world_ * corner);
  }
  const double voxel_volume = std::abs(to_world_.linear().determinant());
  labelled_volume_ = double(count) * voxel_volume;
  centroid_ = to_world_ * Vec3(sum / double(count));
  voxel_size_ = to_world_.linear().colwise().norm().maxCoeff();
}

bool LabelMask::at(int64_t i, int64_t j, int64_t k) const {
  i -= lo_[0];
  j -= lo_[1];
  k -= lo_[2];
  if (i < 0 || j < 0 || k < 0 || i >= n_[0] || j >= n_[1] || k >= n_[2]) return false;
  return mask_[size_t((k * n_[1] + j) * n_[0] + i)] != 0;
}

double LabelMask::field(const Vec3& world) const {
  const Vec3 c = to_voxel_ * world;
  if (!c.allFinite()) return 0;
  const Vec3 base = c.array().floor();
  // Far outside the kept box: nothing (also keeps the casts below in range).
  for (int d = 0; d < 3; ++d)
    if (base[d] < double(lo_[d] - 1) || base[d] > double(lo_[d] + n_[d])) return 0;
  const Vec3 t = c - base;
  const auto i = int64_t(base.x()), j = int64_t(base.y()), k = int64_t(base.z());
  const int64_t a = i - lo_[0], b = j - lo_[1], e = k - lo_[2];
  if (a >= 0 && b >= 0 && e >= 0 && a + 1 < n_[0] && b + 1 < n_[1] && e + 1 < n_[2]) {
    // All eight corners in the kept box (nearly every query): direct loads.
    const size_t sy = size_t(n_[0]), sz = size_t(n_[0] * n_[1]);
    const uint8_t* m = &mask_[size_t((e * n_[1] + b) * n_[0] + a)];
    const auto lerp = [](double u, double v, double w) { return u + (v - u) * w; };
    const double y0 = lerp(lerp(m[0], m[1], t.x()), lerp(m[sy], m[sy + 1], t.x()), t.y());
    const double y1 =
        lerp(lerp(m[sz], m[sz + 1], t.x()), lerp(m[sz + sy], m[sz + sy + 1], t.x()), t.y());
    return lerp(y0, y1, t.z());
  }
  double value = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const int da = corner & 1, db = (corner >> 1) & 1, de = (corner >> 2) & 1;
    if (!at(i + da, j + db, k + de)) continue;
    value += (da ? t.x() : 1 - t.x()) * (db ? t.y() : 1 - t.y()) * (de ? t.z() : 1 - t.z());
  }
  return value;
}

Vec3 LabelMask::normal(const Vec3& p, double radius) const {
  // The voxel box of the ball of `radius` around p, clamped to the kept box.
  Eigen::AlignedBox3d box;
  for (int c = 0; c < 8; ++c)
    box.extend(to_voxel_ * (p + radius * Vec3(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1)));
  std::array<int64_t, 3> from{}, to{};
  for (int d = 0; d < 3; ++d) {
    from[d] = std::max(lo_[d], int64_t(std::ceil(std::max(box.min()[d], double(lo_[d])))));
    to[d] = std::min(lo_[d] + n_[d] - 1,
                     int64_t(std::floor(std::min(box.max()[d], double(lo_[d] + n_[d])))));
  }
  // -grad of the mask blurred by (1 - r^2/R^2)^4 is proportional to the sum of
  // (1 - r^2/R^2)^3 (p - x_v) over the selected voxels v within R.
  const double r2max = radius * radius;
  Vec3 sum = Vec3::Zero();
  for (int64_t k = from[2]; k <= to[2]; ++k)
    for (int64_t j = from[1]; j <= to[1]; ++j)
      for (int64_t i = from[0]; i <= to[0]; ++i) {
        if (!at(i, j, k)) continue;
        const Vec3 d = p - to_world_ * Vec3(double(i), double(j), double(k));
        const double q = 1 - d.squaredNorm() / r2max;
        if (q > 0) sum += q * q * q * d;
      }
  const double norm = sum.norm();
  return norm > 0 ? Vec3(sum / norm) : Vec3::Zero();
}

}  // namespace phyxel
