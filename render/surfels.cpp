#include "render/surfels.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "render/texture_map.h"

namespace phyxel::render {
namespace {

layout::vec4 vec4_of(const Vec3& v, double w) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
          static_cast<float>(w)};
}

bool is_surfel(const PhyxelSet& set, size_t i) {
  return (set.flags[i] & kSurface) != 0 && (set.flags[i] & kRemoved) == 0 &&
         set.splat_radius[i] > 0;
}

}  // namespace

SurfelTable build_surfel_table(const PhyxelSet& set, const std::vector<double>& material_mirror) {
  SurfelTable table;
  table.phyxels = static_cast<uint32_t>(set.size());
  for (size_t o = 0; o < set.objects.size(); ++o) {
    const ObjectRange& range = set.objects[o];
    std::vector<Vec3> points;
    for (uint32_t i = range.first; i < range.first + range.count; ++i)
      if ((set.flags[i] & kRemoved) == 0) points.push_back(set.rest[i]);
    const Dome dome = fit_dome(points);
    for (uint32_t i = range.first; i < range.first + range.count; ++i) {
      if (!is_surfel(set, i)) continue;
      const Vec3& x = set.rest[i];
      const Vec3 n = set.normal[i].squaredNorm() > 0 ? set.normal[i].normalized() : Vec3::UnitZ();
      const Eigen::Vector2d st = dome_texcoord(dome, x);
      const Eigen::Matrix<double, 2, 3> grad = dome_texcoord_gradient(dome, x, n);
      layout::SurfelStatic s{};
      s.index = i;
      s.radius = static_cast<float>(set.splat_radius[i]);
      s.support = static_cast<float>(range.support_radius);
      s.flags = set.flags[i];
      const uint32_t material = set.material.empty() ? 0 : set.material[i];
      if (material < material_mirror.size()) {
        const double level =
            std::clamp(material_mirror[material], 0.0, 1.0) * layout::kMirrorLevels;
        s.flags |= static_cast<uint32_t>(std::lround(level)) << layout::kSurfelMirrorShift;
      }
      s.normal = vec4_of(n, 0);
      s.ds_dx = vec4_of(grad.row(0).transpose(), st.x());
      s.dt_dx = vec4_of(grad.row(1).transpose(), st.y());
      table.surfels.push_back(s);
      table.bounds.extend(x);
    }
  }
  return table;
}

HostInputs::HostInputs(gpu::Context& ctx, const PhyxelSet& set, const NeighbourLists& nbr)
    : ctx_(&ctx), count_(static_cast<uint32_t>(set.size())), pairs_(nbr.index.size()) {
  if (nbr.offset.size() != set.size() + 1) {
    throw std::invalid_argument("HostInputs: neighbour lists of " +
                                std::to_string(nbr.offset.size()) + " rows for " +
                                std::to_string(set.size()) + " phyxels");
  }
  std::vector<layout::vec4> rest(set.size());
  for (size_t i = 0; i < set.size(); ++i) rest[i] = vec4_of(set.rest[i], set.volume[i]);
  using gpu::MemoryIntent;
  rest_ = gpu::Buffer(ctx, rest.size() * sizeof(layout::vec4), MemoryIntent::Device, "render rest");
  nbr_offset_ = gpu::Buffer(ctx, nbr.offset.size() * sizeof(uint32_t), MemoryIntent::Device,
                            "render nbr_offset");
  nbr_index_ = gpu::Buffer(ctx, nbr.index.size() * sizeof(uint32_t), MemoryIntent::Device,
                           "render nbr_index");
  // Written every frame into the mapped staging buffer and copied in one transfer: the deform
  // pass gathers each displacement once per neighbour, which from host memory would cross the
  // bus every time.
  const size_t bytes = std::max<size_t>(set.size(), 1) * sizeof(layout::vec4);
  displacement_ = gpu::Buffer(ctx, bytes, MemoryIntent::Device, "render displacement");
  staging_ = gpu::Buffer(ctx, bytes, MemoryIntent::Upload, "render displacement staging");
  recorder_ = std::make_unique<gpu::Recorder>(ctx, "render displacement upload");
  gpu::upload(ctx, rest_, rest);
  gpu::upload(ctx, nbr_offset_, nbr.offset);
  if (!nbr.index.empty()) gpu::upload(ctx, nbr_index_, nbr.index);
  set_displacement(std::vector<Vec3>(set.size(), Vec3::Zero()));
}

void HostInputs::set_displacement(const std::vector<Vec3>& u) {
  if (u.size() != count_) {
    throw std::invalid_argument("HostInputs::set_displacement: " + std::to_string(u.size()) +
                                " displacements for " + std::to_string(count_) + " phyxels");
  }
  auto* out = static_cast<layout::vec4*>(staging_.mapped());
  for (size_t i = 0; i < u.size(); ++i) out[i] = vec4_of(u[i], 0);
  recorder_->barrier();  // earlier frames' reads of the displacement
  recorder_->copy(staging_, displacement_);
  recorder_->submit_and_wait();
}

void HostInputs::set_pair_alive(const std::vector<uint8_t>& alive) {
  if (alive.size() != pairs_) {
    throw std::invalid_argument("HostInputs::set_pair_alive: " + std::to_string(alive.size()) +
                                " entries for " + std::to_string(pairs_) + " pairs");
  }
  if (pairs_ == 0) return;
  std::vector<float> weight(alive.size());
  for (size_t e = 0; e < alive.size(); ++e) weight[e] = alive[e] != 0 ? 1.0f : 0.0f;
  if (!pair_weight_) {
    pair_weight_ =
        gpu::Buffer(*ctx_, pairs_ * sizeof(float), gpu::MemoryIntent::Device, "render pair weight");
  }
  gpu::upload(*ctx_, pair_weight_, weight);  // blocking, so no frame reads it meanwhile
}

RenderInputs HostInputs::inputs() const {
  return {&rest_,      &displacement_, &nbr_offset_,
          &nbr_index_, count_,         pair_weight_ ? &pair_weight_ : nullptr};
}

}  // namespace phyxel::render
