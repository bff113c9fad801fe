// phyxel bench --sampling: reading and sampling image shapes. A synthetic two-label volume of
// N^3 voxels (1 mm, uint8, .nii.gz) is read, masked and sampled at the spacing that gives about
// P phyxels; with --scene FILE, that scene's loading (its images read and masked) and sampling.
// Median seconds of repeats, per phase.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "bench/benches.h"
#include "bench/timing.h"
#include "engine/geometry/image_volume.h"
#include "engine/sampling/phyxel_set.h"

namespace phyxel::bench {
namespace {

// Label 1 in an ellipsoid of semi-axes (0.45, 0.42, 0.40) N voxels, label 2 in the same shape
// at 0.6 of that size inside it: about a brain's proportions.
NiftiWriteSpec brain_like_volume(int64_t n) {
  NiftiWriteSpec spec;
  spec.dims = {n, n, n, 1};
  spec.values.resize(size_t(n * n * n));
  const Vec3 centre = Vec3::Constant(double(n - 1) / 2);
  const Vec3 radii = double(n) * Vec3(0.45, 0.42, 0.40);
  size_t i = 0;
  for (int64_t z = 0; z < n; ++z)
    for (int64_t y = 0; y < n; ++y)
      for (int64_t x = 0; x < n; ++x, ++i) {
        const double q =
            (Vec3(double(x), double(y), double(z)) - centre).cwiseQuotient(radii).norm();
        spec.values[i] = q <= 0.6 ? 2 : q <= 1 ? 1 : 0;
      }
  return spec;
}

Scene image_scene(const Shape& shape, double spacing) {
  Scene scene;
  ObjectDesc o;
  o.name = "image";
  o.shape = shape;
  o.spacing = spacing;
  o.support_radius = 2 * spacing;
  o.material = {2000, 0.45, 1040, 0, std::nullopt, 0.05, std::nullopt};
  scene.objects.push_back(o);
  return scene;
}

}  // namespace

int bench_sampling(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--sampling");
  const int64_t size = opts.integer("--size", 256, 16, 1024);
  const int64_t target = opts.integer("--phyxels", 1000000, 1000, 1000000000);
  const int64_t repeats = opts.integer("--repeats", 5, 1, 1000);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string scene_file = opts.value("--scene", "");
  const std::string out = opts.value("--out", "");
  const std::string json_file = opts.value("--json", "");
  opts.finish();
  if (threads > 0) omp_set_num_threads(threads);
  nlohmann::json rows = nlohmann::json::array();
  std::printf("threads %d\n%-34s %10s %9s %9s %9s %9s\n", omp_get_max_threads(), "input", "phyxels",
              "read s", "mask s", "sample s", "total s");
  if (scene_file.empty()) {
    const std::filesystem::path dir =
        out.empty() ? std::filesystem::temp_directory_path() / "phyxel-bench-sampling"
                    : std::filesystem::path(out);
    std::filesystem::create_directories(dir);
    const auto file = dir / ("labels_" + std::to_string(size) + ".nii.gz");
    write_nifti_volume(file, brain_like_volume(size));
    // Each repeat reads, masks and samples in turn: three phases timed apart.
    std::optional<ImageVolume> volume;
    Shape shape;
    shape.type = Shape::Type::Image;
    size_t phyxels = 0;
    const std::vector<Timing> t = time_interleaved(
        {[&] { volume = read_image_volume(file, std::nullopt); },
         [&] {
           shape.image =
               std::make_shared<const LabelMask>(*volume, VoxelSelection{{1, 2}, std::nullopt});
         },
         [&] {
           const double spacing = std::cbrt(shape.image->labelled_volume() / double(target));
           phyxels = sample_scene(image_scene(shape, spacing)).size();
         }},
        repeats);
    const double read = t[0].median, mask = t[1].median, sample = t[2].median;
    const std::string input = std::to_string(size) + "^3 uint8 .nii.gz";
    const double total = read + mask + sample;
    std::printf("%-34s %10zu %9.3f %9.3f %9.3f %9.3f\n", input.c_str(), phyxels, read, mask, sample,
                total);
    rows.push_back({{"input", input},
                    {"phyxels", phyxels},
                    {"read_s", read},
                    {"mask_s", mask},
                    {"sample_s", sample},
                    {"total_s", total},
                    {"repeats", repeats},
                    {"threads", omp_get_max_threads()}});
  } else {
    std::optional<Scene> scene;
    size_t phyxels = 0;
    const std::vector<Timing> t = time_interleaved(
        {[&] { scene = load_scene(scene_file); }, [&] { phyxels = sample_scene(*scene).size(); }},
        repeats);
    const double load = t[0].median, sample = t[1].median, total = load + sample;
    std::printf("%-34s %10zu %19.3f %9.3f %9.3f   (read s: the scene's loading)\n",
                scene_file.c_str(), phyxels, load, sample, total);
    rows.push_back({{"input", scene_file},
                    {"phyxels", phyxels},
                    {"load_s", load},
                    {"sample_s", sample},
                    {"total_s", total},
                    {"repeats", repeats},
                    {"threads", omp_get_max_threads()}});
  }
  write_json_file(json_file, rows);
  return 0;
}

}  // namespace phyxel::bench
