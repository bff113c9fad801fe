// Writing NIfTI volumes (libnifti2), for tests and benchmarks that need images of known shape.
#include <nifti2_io.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "engine/geometry/image_types.h"
#include "engine/geometry/image_volume.h"

namespace phyxel {

void write_nifti_volume(const std::filesystem::path& path, const NiftiWriteSpec& spec) {
  nifti_set_debug_level(0);
  const int64_t frames = spec.dims[3];
  const int64_t dims[8] = {
      frames > 1 ? 4 : 3, spec.dims[0], spec.dims[1], spec.dims[2], frames, 1, 1, 1};
  const size_t count = size_t(spec.dims[0] * spec.dims[1] * spec.dims[2] * frames);
  if (spec.values.size() != count)
    throw std::invalid_argument(path.string() +
                                ": write_nifti_volume: " + std::to_string(spec.values.size()) +
                                " values for " + std::to_string(count) + " voxels");
  std::unique_ptr<nifti_image, void (*)(nifti_image*)> image(
      nifti_make_new_nim(dims, nifti_datatype(spec.type), 1), &nifti_image_free);
  if (!image) throw std::runtime_error(path.string() + ": cannot make a NIfTI image");
  with_typed(spec.type, static_cast<uint8_t*>(image->data), [&](auto* values) {
    using T = std::remove_pointer_t<decltype(values)>;
    for (size_t n = 0; n < count; ++n)
      values[n] = std::is_floating_point_v<T> ? T(spec.values[n]) : T(std::llround(spec.values[n]));
  });
  image->dx = image->pixdim[1] = spec.pixdim.x();
  image->dy = image->pixdim[2] = spec.pixdim.y();
  image->dz = image->pixdim[3] = spec.pixdim.z();
  image->xyz_units = spec.xyz_units;
  image->scl_slope = spec.slope;
  image->scl_inter = spec.inter;
  image->qform_code = image->sform_code = 0;
  if (spec.sform) {
    image->sform_code = 1;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) image->sto_xyz.m[r][c] = (*spec.sform)(r, c);
  }
  if (spec.qform) {
    const auto& q = *spec.qform;
    image->qform_code = 1;
    image->quatern_b = q[0];
    image->quatern_c = q[1];
    image->quatern_d = q[2];
    image->qoffset_x = q[3];
    image->qoffset_y = q[4];
    image->qoffset_z = q[5];
    image->qfac = q[6];
  }
  image->nifti_type = spec.version == 2 ? NIFTI_FTYPE_NIFTI2_1 : NIFTI_FTYPE_NIFTI1_1;
  if (nifti_set_filenames(image.get(), path.c_str(), 0, 1) != 0)
    throw std::runtime_error(path.string() + ": not a NIfTI file name (.nii or .nii.gz)");
  nifti_set_iname_offset(image.get(), spec.version == 2 ? 2 : 1);
  std::error_code ec;
  std::filesystem::remove(path, ec);
  nifti_image_write(image.get());
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error(path.string() + ": the NIfTI library did not write the file");
}

}  // namespace phyxel
