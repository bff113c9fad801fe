// Adapts CpuSolver<Real> to the Solver interface.
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "engine/solver/solver.h"

namespace phyxel {
namespace {

template <class Real>
class CpuBackend final : public SolverWithAllFacets {
 public:
  CpuBackend(const PhyxelSet& set, const Vec3& gravity, int threads)
      : threads_(threads > 0 ? threads : omp_get_max_threads()) {
    omp_set_num_threads(threads_);
    solver_ = std::make_unique<CpuSolver<Real>>(set, gravity);
    solver_->set_threads(threads_);
  }
  std::string device() const override {
    char text[96];
    std::snprintf(text, sizeof text, "cpu (%s, %d thread%s)",
                  sizeof(Real) == 8 ? "double" : "float", threads_, threads_ == 1 ? "" : "s");
    return text;
  }
  void advance(int64_t substeps, double dt) override {
    if (!motion_.empty()) solver_->set_tool_motion(motion_, Real(dt));
    motion_.clear();
    for (int64_t s = 0; s < substeps; ++s) solver_->step(Real(dt));
    solver_->sort_severed_from(logged_);  // the advance's pairs ascending, as on the GPU
    logged_ = solver_->severed_log().size();
  }
  Energies energies() override { return solver_->energies(); }
  long first_non_finite() override { return solver_->first_non_finite(); }
  PointState read_state(bool with_stress) override {
    PointState s;
    const size_t n = solver_->size();
    s.displacement.resize(n);
    s.velocity.resize(n);
    for (size_t i = 0; i < n; ++i) {
      s.displacement[i] = solver_->displacement()[i].template cast<double>();
      s.velocity[i] = solver_->velocity()[i].template cast<double>();
    }
    if (with_stress) s.von_mises = solver_->von_mises_stress();
    if (with_stress && solver_->principal_stress()) {
      const auto& sigma = solver_->max_principal_stress();
      s.max_principal_stress.assign(sigma.begin(), sigma.end());
    }
    s.contact = solver_->contact();
    return s;
  }
  void set_state(const std::vector<Vec3>& displacement,
                 const std::vector<Vec3>& velocity) override {
    const size_t n = solver_->size();
    if (displacement.size() != n || velocity.size() != n)
      throw std::invalid_argument("set_state: expected " + std::to_string(n) +
                                  " displacements and velocities");
    for (size_t i = 0; i < n; ++i) {
      solver_->displacement()[i] = displacement[i].template cast<Real>();
      solver_->velocity()[i] = velocity[i].template cast<Real>();
    }
    solver_->compute_forces();
  }
  std::vector<ObjectMotion> object_motion(const PhyxelSet& set) override {
    return sum_object_motion(set, solver_->velocity());  // no copy of the state
  }
  size_t regularised_count() const override { return solver_->regularised_count(); }
  const NeighbourLists& neighbours() const override { return solver_->neighbours(); }
  void set_pass_selection(bool enabled) override { solver_->set_pass_selection(enabled); }
  void set_object_awake(uint32_t object, bool awake) override {
    solver_->set_object_awake(object, awake);
  }
  size_t stress_pass_size() const override { return solver_->stress_pass_size(); }
  size_t force_pass_size() const override { return solver_->force_pass_size(); }
  void set_external_forces(const std::vector<Vec3>& f) override { solver_->set_external_forces(f); }
  void set_tools(const std::vector<ContactTool>& tools) override { solver_->set_tools(tools); }
  void set_tool_motion(const std::vector<ToolMotion>& motion) override { motion_ = motion; }
  std::vector<ToolContactSample> tool_samples() override { return solver_->tool_samples(); }
  size_t contact_candidates() const override { return solver_->contact_candidates(); }
  bool blades_near() const override { return solver_->blades_near(); }
  std::vector<uint32_t> held_phyxels(size_t tool) override {
    std::vector<uint32_t> held;
    for (const GripEntry& e : solver_->grip(tool).held) held.push_back(e.phyxel);
    return held;
  }
  std::vector<Grip> grips() override { return solver_->grips(); }
  void restore_grips(const std::vector<Grip>& grips) override { solver_->restore_grips(grips); }
  void set_principal_stress(bool on) override { solver_->set_principal_stress(on); }
  void set_tearing(bool on) override { solver_->set_tearing(on); }
  void remove_phyxels(const std::vector<uint32_t>& ids) override { solver_->remove_phyxels(ids); }
  size_t severed_pairs() const override { return solver_->severed_log().size(); }
  std::vector<SeveredPair> severed_since(size_t first) override {
    const auto& log = solver_->severed_log();
    return {log.begin() + std::min(first, log.size()), log.end()};
  }
  std::vector<uint8_t> pair_alive() override {
    const auto& w = solver_->pair_weights();
    std::vector<uint8_t> alive(w.size());
    for (size_t k = 0; k < w.size(); ++k) alive[k] = w[k] != Real(0);
    return alive;
  }
  void sever_pairs(const std::vector<SeveredPair>& pairs) override {
    solver_->sever_pairs(pairs);
    solver_->sort_severed_from(logged_);
    logged_ = solver_->severed_log().size();
  }
  CutBandState cut_band_state() override { return solver_->cut_band_state(); }
  void restore_cut_band(const CutBandState& state) override { solver_->restore_cut_band(state); }
  std::vector<std::vector<BladeSide>> blade_sides() override {
    std::vector<std::vector<BladeSide>> sides(solver_->tool_count());
    for (size_t t = 0; t < sides.size(); ++t) sides[t] = solver_->blade_sides(t);
    return sides;
  }
  void restore_blade_sides(const std::vector<std::vector<BladeSide>>& sides) override {
    for (size_t t = 0; t < sides.size(); ++t) solver_->restore_blade_sides(t, sides[t]);
  }
  std::vector<uint8_t> blades_cutting() override {
    std::vector<uint8_t> on(solver_->tool_count());
    for (size_t t = 0; t < on.size(); ++t) on[t] = solver_->blade_cutting(t) ? 1 : 0;
    return on;
  }
  void restore_blades_cutting(const std::vector<uint8_t>& on) override {
    for (size_t t = 0; t < on.size(); ++t) solver_->restore_blade_cutting(t, on[t] != 0);
  }

 private:
  int threads_;
  std::unique_ptr<CpuSolver<Real>> solver_;
  std::vector<ToolMotion> motion_;  // for the next advance()
  size_t logged_ = 0;               // severed pairs before the current advance
};

}  // namespace

std::unique_ptr<Solver> make_cpu_solver(const PhyxelSet& set, const Vec3& gravity, int threads,
                                        bool single_precision) {
  if (single_precision) return std::make_unique<CpuBackend<float>>(set, gravity, threads);
  return std::make_unique<CpuBackend<double>>(set, gravity, threads);
}

}  // namespace phyxel
