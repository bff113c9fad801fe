#include "engine/solver/cut_band.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/solver/cutting.h"

namespace phyxel {

CutBand::CutBand(const PhyxelSet& set, const std::vector<double>& volume) {
  const size_t no = set.objects.size();
  band_width_.resize(no);
  spacing_.resize(no);
  support_.resize(no);
  for (size_t o = 0; o < no; ++o) {
    spacing_[o] = set.objects[o].spacing;
    support_[o] = set.objects[o].support_radius;
    max_support_ = std::max(max_support_, support_[o]);
    band_width_[o] = set.objects[o].cut_band * set.objects[o].spacing;
    on_ = on_ || band_width_[o] > 0;
  }
  if (!on_) return;  // nothing per phyxel kept
  rest_ = set.rest;
  object_ = set.object;
  volume_ = volume;
  object_lo_.assign(no, Vec3::Constant(std::numeric_limits<double>::infinity()));
  object_hi_.assign(no, Vec3::Constant(-std::numeric_limits<double>::infinity()));
  for (size_t i = 0; i < rest_.size(); ++i) {
    object_lo_[object_[i]] = object_lo_[object_[i]].cwiseMin(rest_[i]);
    object_hi_[object_[i]] = object_hi_[object_[i]].cwiseMax(rest_[i]);
  }
}

CutBand::Refresh CutBand::start_chunk(const std::vector<uint32_t>& flags, int threads) {
  Refresh r = refresh(quads_before_chunk_, flags, threads);
  quads_before_chunk_ = quads_.size();
  return r;
}

CutBand::Refresh CutBand::refresh(size_t upto, const std::vector<uint32_t>& flags, int threads) {
  Refresh out;
  if (upto <= quads_built_) return out;
  const size_t first = quads_built_, n = rest_.size();
  quads_built_ = upto;
  if (cell_of_.empty()) cell_of_.assign(n, -1);
  // Phyxels within the band width of the new quads join the band; band cells whose Gauss points
  // see across them (within h + s) are to be built again, once no quad newer than `upto` (the
  // cut still passing) reaches them.
  const auto nearest = [&](size_t i, size_t from, size_t to, double enough) {
    double d = std::numeric_limits<double>::infinity();
    for (size_t q = from; q < to && d >= enough; ++q)
      d = std::min(d, distance_to_quad(rest_[i], quads_[q]));
    return d;
  };
  std::vector<uint32_t> build;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t o = object_[i];
    if (!(band_width_[o] > 0) || (flags[i] & kRemoved)) continue;
    const double rebuild = std::max(band_width_[o], support_[o] + spacing_[o]);
    const double d = nearest(i, first, upto, band_width_[o]);
    if (d < band_width_[o] && cell_of_[i] < 0) {
      cell_of_[i] = int32_t(cells_.size());
      cells_.push_back(Cell{uint32_t(i), {}, true});
    }
    if (cell_of_[i] < 0) continue;
    Cell& cell = cells_[size_t(cell_of_[i])];
    cell.dirty = cell.dirty || d < rebuild;
    if (cell.dirty && !(nearest(i, upto, quads_.size(), rebuild) < rebuild)) {
      build.push_back(uint32_t(cell_of_[i]));
      if (cell.box.empty()) out.joined.push_back(uint32_t(i));
    }
  }
  if (build.empty()) return out;
  std::sort(build.begin(), build.end());
  for (const uint32_t c : build) cells_[c].built_with = quads_.size();
  build_cells(build, flags, threads);
  out.built = std::move(build);
  return out;
}

void CutBand::build_cells(const std::vector<uint32_t>& cells, const std::vector<uint32_t>& flags,
                          int threads) {
  const long nb = long(cells.size());
  const PointGrid grid(rest_, max_support_);
#pragma omp parallel for schedule(dynamic, 4) \
    num_threads(threads > 0 ? threads : omp_get_max_threads())
  for (long k = 0; k < nb; ++k) build_cell(cells[k], grid, flags, cells_[cells[k]].built_with);
  build_gather();
}

CutBandState CutBand::state() const {
  CutBandState s;
  if (!on_) return s;
  s.quads = quads_;
  s.quads_built = quads_built_;
  s.quads_before_chunk = quads_before_chunk_;
  for (const Cell& c : cells_) {
    s.phyxel.push_back(c.phyxel);
    s.dirty.push_back(c.dirty ? 1 : 0);
    s.built_with.push_back(c.box.empty() ? 0 : c.built_with);
  }
  return s;
}

CutBand::Refresh CutBand::restore(const CutBandState& s, const std::vector<uint32_t>& flags,
                                  int threads) {
  const size_t nq = s.quads.size(), nc = s.phyxel.size();
  bool fits = s.quads_built <= nq && s.quads_before_chunk <= nq && s.dirty.size() == nc &&
              s.built_with.size() == nc && (on_ || (nq == 0 && nc == 0));
  for (size_t c = 0; c < nc && fits; ++c)
    fits = s.phyxel[c] < rest_.size() && band_width_[object_[s.phyxel[c]]] > 0 &&
           s.built_with[c] <= nq;
  if (!fits)
    throw std::invalid_argument(
        "the SCNI band's state (cut_band) does not fit this scene's "
        "phyxels; resume with the scene it was written with");
  Refresh out;
  if (!on_) return out;
  quads_ = s.quads;
  quads_built_ = s.quads_built;
  quads_before_chunk_ = s.quads_before_chunk;
  cell_of_.assign(rest_.size(), -1);
  cells_.assign(nc, Cell{});
  for (size_t c = 0; c < nc; ++c) {
    if (cell_of_[s.phyxel[c]] >= 0)
      throw std::invalid_argument("the SCNI band's state (cut_band) lists a phyxel twice");
    cell_of_[s.phyxel[c]] = int32_t(c);
    cells_[c] = Cell{s.phyxel[c], {}, s.dirty[c] != 0, s.built_with[c]};
    if (s.built_with[c] > 0) {
      out.built.push_back(uint32_t(c));
      out.joined.push_back(s.phyxel[c]);
    }
  }
  std::sort(out.joined.begin(), out.joined.end());
  build_cells(out.built, flags, threads);
  for (size_t c = 0; c < nc; ++c) cells_[c].dirty = s.dirty[c] != 0;  // build_cell clears it
  return out;
}

void CutBand::build_cell(size_t c, const PointGrid& grid, const std::vector<uint32_t>& flags,
                         size_t quads) {
  const uint32_t i = cells_[c].phyxel, o = object_[i];
  const double s = spacing_[o], h = support_[o];
  ScniCell cell = lattice_cell(rest_[i], s, object_lo_[o], object_hi_[o]);
  // A fixed phyxel's cell holds the body on the wall where its face on the object's bounds
  // faces a free phyxel: that face takes u = 0 (the clamp), not the fit.
  if (flags[i] & kFixed)
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const double bound = side ? object_hi_[o][axis] : object_lo_[o][axis];
        const double face = side ? cell.hi[axis] : cell.lo[axis];
        if (std::abs(face - bound) > 1e-9 * s) continue;
        Vec3 inward = rest_[i];
        inward[axis] += side ? -s : s;
        for (const uint32_t j : grid.within(inward))
          if ((rest_[j] - inward).norm() < 1e-3 * s && !(flags[j] & kFixed))
            cell.clamped[2 * axis + side] = true;
      }
  std::vector<const std::array<Vec3, 4>*> near;  // quads a line of sight from the cell may cross
  for (size_t q = 0; q < quads; ++q)
    if (distance_to_quad(rest_[i], quads_[q]) < h + s) near.push_back(&quads_[q]);
  const PairWeight visible = [&](const Vec3& from, uint32_t j, double w0) {
    if (object_[j] != o || (flags[j] & kRemoved)) return 0.0;
    for (const auto* q : near)
      if (blade_severs<double>(from, rest_[j], *q)) return 0.0;
    return w0;
  };
  const std::vector<ScniBox> boxes = scni_boxes(rest_, grid, h, cell, visible);
  double total = 0;
  for (const ScniBox& b : boxes) total += b.volume;
  cells_[c].dirty = false;
  std::vector<Box>& out = cells_[c].box;
  out.assign(boxes.size(), Box{});
  for (size_t b = 0; b < boxes.size(); ++b) {
    // The boxes' energy weights add up to the phyxel's quadrature volume (the cell's part
    // inside the shape); their gradients are the geometric boxes'.
    out[b].volume = boxes[b].volume * volume_[i] / total;
    out[b].node = boxes[b].node;
    out[b].coeff = boxes[b].coeff;
  }
}

void CutBand::build_gather() {
  const size_t n = rest_.size();
  gather_offset_.assign(n + 1, 0);
  for (const Cell& cell : cells_)
    for (const Box& box : cell.box)
      for (const uint32_t j : box.node) ++gather_offset_[j + 1];
  for (size_t k = 0; k < n; ++k) gather_offset_[k + 1] += gather_offset_[k];
  gather_.assign(gather_offset_[n], GatherEntry{});
  std::vector<uint32_t> fill(gather_offset_.begin(), gather_offset_.end() - 1);
  for (uint32_t c = 0; c < cells_.size(); ++c)
    for (uint32_t b = 0; b < cells_[c].box.size(); ++b)
      for (uint32_t k = 0; k < cells_[c].box[b].node.size(); ++k)
        gather_[fill[cells_[c].box[b].node[k]]++] = GatherEntry{c, b, k};
}

void CutBand::add_cut(const std::array<Vec3, 4>& c, double reach) {
  const double area =
      ((c[2] - c[0]).cross(c[1] - c[0]).norm() + (c[3] - c[0]).cross(c[2] - c[0]).norm()) / 2;
  if (area > 1e-12 * reach * reach) quads_.push_back(c);
}

}  // namespace phyxel
