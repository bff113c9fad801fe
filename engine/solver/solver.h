// What the run loop needs from a solver, CPU reference or GPU.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/solver/contact.h"
#include "engine/solver/cpu_solver.h"

namespace phyxel {

// A copy of the per-phyxel state in double precision, for outputs and checks.
struct PointState {
  std::vector<Vec3> displacement;
  std::vector<Vec3> velocity;
  std::vector<double> von_mises;
  std::vector<uint8_t> contact;  // 1 where a tool touched the phyxel in the last substep
  // The largest principal Cauchy stress per phyxel, Pa, as the last substep computed it; only
  // while the solver computes it (set_principal_stress) and read with the stress.
  std::vector<double> max_principal_stress;
};

// One object's motion (its phyxels' range in the PhyxelSet): what the run loop's rest, sleep
// and runaway checks need.
struct ObjectMotion {
  double kinetic = 0;    // J
  double max_speed = 0;  // m/s
};

// The host's sums behind Solver::object_motion, in double, in phyxel order.
template <class V3>
std::vector<ObjectMotion> sum_object_motion(const PhyxelSet& set, const std::vector<V3>& velocity) {
  std::vector<ObjectMotion> out(set.objects.size());
  for (size_t o = 0; o < set.objects.size(); ++o) {
    const ObjectRange& obj = set.objects[o];
    double max_v2 = 0;
    for (uint32_t i = obj.first; i < obj.first + obj.count; ++i) {
      const double v2 = velocity[i].template cast<double>().squaredNorm();
      out[o].kinetic += 0.5 * set.mass[i] * v2;
      if (!(v2 <= max_v2) && !std::isnan(max_v2)) max_v2 = v2;  // a NaN speed is kept
    }
    out[o].max_speed = std::sqrt(max_v2);
  }
  return out;
}

class Solver {
 public:
  virtual ~Solver() = default;
  virtual std::string device() const = 0;  // e.g. "cpu (double, 2 threads)"
  // substeps of size dt. A solver may return before the last of its device work is done (the
  // GPU solver, where nothing of the advance is left for the host: its next call waits for it,
  // and work submitted to its queue meanwhile, a frame, runs after it). Code that times an
  // advance calls finish() before it reads the clock.
  virtual void advance(int64_t substeps, double dt) = 0;
  virtual void finish() {}  // waits for what the last advance left running
  virtual Energies energies() = 0;
  virtual long first_non_finite() = 0;  // phyxel index or -1
  virtual PointState read_state(bool with_stress) = 0;
  virtual size_t regularised_count() const = 0;  // ill-conditioned moment matrices
  virtual const NeighbourLists& neighbours() const = 0;
  // The largest |u| and |v| over all phyxels (m, m/s): what the run loop's checks and the
  // contact broad phase need without reading the whole state back.
  virtual std::pair<double, double> max_norms();
  // Per object of `set` (the set the solver was made from): its kinetic energy, the sum of
  // m |v|^2 / 2 over its phyxels in their order, and its largest speed. The GPU solver reduces
  // them on the device (16 bytes per object back) instead of reading u and v back.
  virtual std::vector<ObjectMotion> object_motion(const PhyxelSet& set);
  // Replaces u and v (converted to the solver's precision: values read_state gave convert back
  // exactly) and recomputes the forces for the new u, so the next advance continues exactly
  // as the solver that read them would (checkpoint resume). Throws where unsupported.
  virtual void set_state(const std::vector<Vec3>& displacement, const std::vector<Vec3>& velocity) {
    (void)displacement;
    (void)velocity;
    throw std::logic_error(device() + " cannot restore a state");
  }

  // Optional abilities; a solver without one says so and the run loop does without it.
  // Pass selection (skip fixed-only regions and sleeping objects): see CpuSolver.
  virtual bool supports_pass_selection() const { return false; }
  virtual void set_pass_selection(bool) {}
  virtual void set_object_awake(uint32_t, bool) {}
  // Phyxels visited by the stress and force passes of one substep now.
  virtual size_t stress_pass_size() const { return 0; }
  virtual size_t force_pass_size() const { return 0; }
  // Loads that switch on or off during the run (scene loads with from/until).
  virtual bool supports_load_changes() const { return false; }
  virtual void set_external_forces(const std::vector<Vec3>&) {}
  // Tools (engine/solver/contact.h): their shapes and friction, set once; then before each
  // advance(n, dt) the motion of every tool over each of the n substeps (n x tools, row-major
  // by substep), and after it what each tool felt in each substep (n x tools).
  virtual bool supports_tools() const { return false; }
  virtual void set_tools(const std::vector<ContactTool>&) {}
  virtual void set_tool_motion(const std::vector<ToolMotion>&) {}
  virtual std::vector<ToolContactSample> tool_samples() { return {}; }
  // The phyxels a grasper's jaws hold now (ascending; empty for other tools and open jaws;
  // engine/solver/grasper.h).
  virtual std::vector<uint32_t> held_phyxels(size_t tool) {
    (void)tool;
    return {};
  }
  // The graspers' grips (per tool: closed, and what the jaws hold with its offsets), for
  // checkpoints; restore_grips puts them back after set_tools. No grasper: none held.
  virtual std::vector<Grip> grips() { return {}; }
  virtual void restore_grips(const std::vector<Grip>& grips) {
    for (const Grip& g : grips)
      if (g.closed) throw std::logic_error(device() + " cannot restore a grasper's grip");
  }
  // Phyxels the broad phase handed to the narrow phase in the last advance (0 without tools).
  virtual size_t contact_candidates() const { return 0; }
  // Principal stress (tearing, Scene::tearing_possible): while on, every substep computes the
  // largest principal value of each stressed phyxel's Cauchy stress into a per-phyxel buffer
  // (CpuSolver::max_principal_stress; a GPU pass), for the tearing passes and the outputs;
  // off (the default), nothing of it is computed or allocated.
  virtual bool supports_principal_stress() const { return false; }
  virtual void set_principal_stress(bool on) {
    if (on) throw std::logic_error(device() + " cannot compute principal stresses");
  }
  // Tearing (engine/solver/tearing.h, docs/tearing.md): while on, every substep ends by
  // severing the live pairs whose material is overstressed, logged like cuts (below) with
  // `torn` set. Turning it on turns the principal stress on.
  virtual bool supports_tearing() const { return false; }
  virtual void set_tearing(bool on) {
    if (on) throw std::logic_error(device() + " cannot tear");
  }
  // Removal (aspiration, engine/surgery/aspiration.h): the phyxels leave the physics for good,
  // flagged kRemoved, every pair touching them severed on both sides (not logged: the pieces and
  // faces follow from the flags), the precompute rerun for their neighbours and the forces
  // recomputed. Their u and v stay as they were.
  virtual bool supports_removal() const { return false; }
  virtual void remove_phyxels(const std::vector<uint32_t>& ids) {
    if (!ids.empty()) throw std::logic_error(device() + " cannot remove phyxels");
  }
  // What aspiration reads after every advance: u and the largest principal stress (empty
  // while off), as read_state(true) gives them. With set_advance_readback(true) a solver may
  // copy them at the end of each advance, in the advance's own submission (the GPU solver),
  // and hand that copy out here as long as nothing changed the state since; otherwise, and by
  // default, this reads the state.
  virtual void set_advance_readback(bool on) { (void)on; }
  virtual void read_advanced_state(std::vector<Vec3>& displacement,
                                   std::vector<double>& principal) {
    PointState s = read_state(true);
    displacement = std::move(s.displacement);
    principal = std::move(s.max_principal_stress);
  }
  // Cutting (engine/solver/cutting.h, docs/cutting.md): tools with a blade sever neighbour
  // pairs during advance(). The solver keeps a log of every severed pair (i < j; each advance's
  // pairs ascending by (i, j), appended in order): severed_pairs() is its length and
  // severed_since(k) its entries from k on, so each reader keeps its own cursor. pair_alive: 1
  // per CSR pair of neighbours() still joined. sever_pairs: severs the given pairs as a cut
  // would and logs them (checkpoint resume, tests).
  virtual bool supports_cutting() const { return false; }
  virtual size_t severed_pairs() const { return 0; }
  virtual std::vector<SeveredPair> severed_since(size_t first) {
    (void)first;
    return {};
  }
  virtual std::vector<uint8_t> pair_alive() {
    return std::vector<uint8_t>(neighbours().index.size(), 1);
  }
  virtual void sever_pairs(const std::vector<SeveredPair>& pairs) {
    if (!pairs.empty()) throw std::logic_error(device() + " cannot sever pairs");
  }
};

// The CPU reference solver behind the Solver interface. threads <= 0: all cores.
std::unique_ptr<Solver> make_cpu_solver(const PhyxelSet& set, const Vec3& gravity, int threads,
                                        bool single_precision = false);

}  // namespace phyxel
