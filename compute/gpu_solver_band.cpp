// GpuSolver: the SCNI band round a blade's cut, with CpuSolver's semantics
// (engine/solver/cpu_solver_band.cpp; docs/cutting.md, "Stiffness of a cut body"). The host
// keeps the quads (from each advance's samples, as CpuSolver's cut pass stores them) and builds
// the cells with the CPU's code (CutBand) at the same moments; their boxes go to the GPU in
// float. In every stress pass (after the nodal one), band_stress computes V_b P(I + G_b) per box
// and band_force writes ext - sum V_b P_b c per node it lists into the band's copy of ext, which
// the force pass then reads as ext. A band phyxel's precompute (kFlagBand) gives it no elastic
// volume and no hourglass stiffness, so its nodal D is 0, as CpuSolver's.
#include "compute/gpu_solver_band.h"

#include <algorithm>
#include <bit>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"
#include "compute/shaders/layout_band.h"
#include "compute/spirv.h"
#include "engine/solver/cutting.h"
#include "phyxel_spv/band_force.spv.h"
#include "phyxel_spv/band_stress.spv.h"

namespace phyxel::gpu {

using namespace layout;

GpuBand::GpuBand(Context& ctx, const PhyxelSet& set, const std::vector<double>& volume)
    : cells(set, volume),
      stress(ctx, PHYXEL_SHADER(band_stress), 6, sizeof(BandPush)),
      force(ctx, PHYXEL_SHADER(band_force), 6, sizeof(BandPush)) {}

void GpuSolver::make_band(const PhyxelSet& set) {
  bool on = false;
  for (const ObjectRange& o : set.objects) on = on || o.cut_band > 0;
  if (!on) return;
  std::vector<double> volume(set.size());  // as rest_ holds them (float)
  for (size_t i = 0; i < volume.size(); ++i) volume[i] = double(float(set.volume[i]));
  band_ = std::make_unique<GpuBand>(*ctx_, set, volume);
}

const std::vector<std::array<Vec3, 4>>& GpuSolver::cut_quads() const {
  static const std::vector<std::array<Vec3, 4>> none;
  return band_ ? band_->cells.quads() : none;
}

size_t GpuSolver::band_size() const {
  return band_ ? band_->cells.cells().size() : 0;
}

bool GpuSolver::in_band(size_t i) const {
  return band_ && band_->cells.in_band(i);
}

void GpuSolver::collect_band_quads() {
  const size_t nt = tools_.size();
  if (!band_ || !cutting_ || nt == 0 || samples_.size() < nt || candidates_ == 0) return;
  // CpuSolver's cut pass: per substep and blade whose edge force reached its threshold, the
  // quad it swept (the advance's rows of the cut table; past the chunk, the held end pose).
  const size_t substeps = samples_.size() / nt, first = motion_step_ - substeps;
  for (size_t s = 0; s < substeps; ++s) {
    const size_t row = std::min(first + s, motion_steps_);
    for (size_t t = 0; t < nt; ++t) {
      const Blade& blade = tools_[t].blade;
      if (!blade.cuts()) continue;
      ToolMotion m = motion_[std::min(row, motion_steps_ - 1) * nt + t];
      if (row == motion_steps_) m.from = m.to;
      const double reach = blade_reach(blade, contact_spacing_);
      const phyxel::CutQuad quad = swept_quad(blade, m.from, m.to, reach);
      if (cut_force(samples_[s * nt + t].force, quad) < blade.threshold) continue;
      band_->cells.add_cut(quad.corner, reach);
    }
  }
}

CutBandState GpuSolver::cut_band_state() {
  return band_ ? band_->cells.state() : CutBandState{};
}

void GpuSolver::restore_cut_band(const CutBandState& state) {
  if (!band_) {
    Cutting::restore_cut_band(state);  // throws unless it is empty
    return;
  }
  settle();
  use_band(band_->cells.restore(state, phyxel_flags_, 0));
}

void GpuSolver::refresh_band(bool all) {
  if (!band_) return;
  settle();
  CutBand& band = band_->cells;
  use_band(all ? band.refresh_all(phyxel_flags_, 0) : band.start_chunk(phyxel_flags_, 0));
}

void GpuSolver::use_band(const CutBand::Refresh& r) {
  if (r.built.empty()) return;
  upload_band();
  if (!r.joined.empty()) {  // kFlagBand, and their precompute again (no hourglass term)
    std::vector<uint32_t> edits;
    for (const uint32_t i : r.joined) edits.insert(edits.end(), {i, kFlagBand});
    apply_removal(edits, {}, r.joined);  // and the forces
    return;
  }
  compute_forces();
}

void GpuSolver::upload_band() {
  const CutBand& band = band_->cells;
  std::vector<uvec4> boxes, nodes;
  std::vector<vec4> coeff;
  std::vector<uint32_t> first_box(band.cells().size()), entries;
  for (size_t c = 0; c < band.cells().size(); ++c) {
    first_box[c] = uint32_t(boxes.size());
    for (const CutBand::Box& box : band.cells()[c].box) {
      const uint32_t at = uint32_t(coeff.size());
      boxes.push_back({band.cells()[c].phyxel, at, at + uint32_t(box.node.size()),
                       std::bit_cast<uint32_t>(float(box.volume))});
      for (size_t k = 0; k < box.node.size(); ++k) {
        const Vec3& x = box.coeff[k];
        coeff.push_back(
            {float(x.x()), float(x.y()), float(x.z()), std::bit_cast<float>(box.node[k])});
      }
    }
  }
  const std::vector<uint32_t>& offset = band.gather_offset();
  for (uint32_t k = 0; k + 1 < offset.size(); ++k) {
    if (offset[k + 1] == offset[k]) continue;
    const uint32_t at = uint32_t(entries.size() / 2);
    nodes.push_back({k, at, at + (offset[k + 1] - offset[k]), 0u});
    for (uint32_t e = offset[k]; e < offset[k + 1]; ++e) {
      const CutBand::GatherEntry& g = band.gather()[e];
      const uint32_t b = first_box[g.cell] + g.box;
      entries.insert(entries.end(), {b, boxes[b].y + g.slot});
    }
  }
  GpuBand& gb = *band_;
  Context& ctx = *ctx_;
  auto fit = [&](Buffer& buffer, uint64_t bytes, const char* name) {
    if (buffer.size() < bytes) buffer = Buffer(ctx, bytes * 2, MemoryIntent::Device, name);
  };
  fit(gb.boxes, boxes.size() * sizeof(uvec4), "band boxes");
  fit(gb.coeff, coeff.size() * sizeof(vec4), "band coefficients");
  fit(gb.box_stress, boxes.size() * 3 * sizeof(vec4), "band box stress");
  fit(gb.nodes, nodes.size() * sizeof(uvec4), "band nodes");
  fit(gb.entries, entries.size() * sizeof(uint32_t), "band entries");
  fit(gb.ext, uint64_t{count_} * sizeof(vec4), "band ext (ext + the band's force)");
  upload(ctx, gb.boxes, boxes);
  upload(ctx, gb.coeff, coeff);
  upload(ctx, gb.nodes, nodes);
  upload(ctx, gb.entries, entries);
  gb.box_count = uint32_t(boxes.size());
  gb.node_count = uint32_t(nodes.size());
  copy_band_ext();
}

void GpuSolver::copy_band_ext() {
  if (!band_built()) return;
  Recorder& rec = *rec_[0];
  rec.barrier();
  rec.copy(ext_, band_->ext, uint64_t{count_} * sizeof(vec4));  // nodes no box lists: ext
  rec.submit_and_wait();
}

bool GpuSolver::band_built() const {
  return band_ && band_->box_count > 0;
}

const Buffer& GpuSolver::force_ext() const {
  return band_built() ? band_->ext : ext_;
}

void GpuSolver::record_band_stress(Recorder& rec, const Buffer& disp) {
  GpuBand& b = *band_;
  dispatch(rec, b.stress, BandPush{b.box_count, 0, 0, 0},
           {{"Boxes", b.boxes},
            {"Coeff", b.coeff},
            {"Disp", disp},
            {"Flags", flags_},
            {"Classes", classes_},
            {"Stress", b.box_stress}},
           b.box_count);
}

double GpuSolver::band_energy() {
  if (!band_built()) return 0;
  Recorder& rec = *rec_[0];
  rec.barrier();
  record_band_stress(rec, disp_[0]);  // the next stress pass writes them again before a force
  rec.submit_and_wait();
  const std::vector<vec4> s = download<vec4>(*ctx_, band_->box_stress, 3 * band_->box_count);
  double total = 0;
  for (uint32_t b = 0; b < band_->box_count; ++b) total += double(s[3 * b].w);
  return total;
}

void GpuSolver::record_band(Recorder& rec, const Buffer& disp) {
  if (!band_built()) return;
  GpuBand& b = *band_;
  rec.barrier();  // u and the nodal stress pass
  record_band_stress(rec, disp);
  rec.barrier();
  dispatch(rec, b.force, BandPush{b.node_count, 0, 0, 0},
           {{"Nodes", b.nodes},
            {"Entries", b.entries},
            {"Coeff", b.coeff},
            {"Stress", b.box_stress},
            {"Ext", ext_},
            {"BandExt", b.ext}},
           b.node_count);
}

}  // namespace phyxel::gpu
