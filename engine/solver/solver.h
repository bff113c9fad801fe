// What the run loop needs from a solver, CPU reference or GPU.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
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

// What aspiration reads near the mouths (Solver::read_near): ascending phyxel ids, and per id
// u and the largest principal stress (as read_state(true) gives them; empty while off).
struct NearState {
  std::vector<uint32_t> ids;
  std::vector<Vec3> displacement;
  std::vector<double> principal;
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

// The surgical abilities of a solver, one facet each. Solver's accessors (cutting(), tools(),
// ...) give a facet or nullptr where the solver lacks it; a caller that needs one asks for it
// (the run loop refuses a scene needing an absent facet, naming the scene file). A new
// ability is a new facet, not a wider Solver. Facets are never deleted through.

// Pass selection (skip fixed-only regions and sleeping objects): see CpuSolver.
class PassSelection {
 public:
  virtual void set_pass_selection(bool enabled) = 0;
  virtual void set_object_awake(uint32_t object, bool awake) = 0;
  // Phyxels visited by the stress and force passes of one substep now.
  virtual size_t stress_pass_size() const = 0;
  virtual size_t force_pass_size() const = 0;

 protected:
  ~PassSelection() = default;
};

// Loads that switch on or off during the run (scene loads with from/until): the loads per
// phyxel (N; gravity stays), the forces recomputed for the current u.
class LoadChanges {
 public:
  virtual void set_external_forces(const std::vector<Vec3>& loads) = 0;

 protected:
  ~LoadChanges() = default;
};

// Tools (engine/solver/contact.h): their shapes and friction, set once; then before each
// advance(n, dt) the motion of every tool over each of the n substeps (n x tools, row-major
// by substep), and after it what each tool felt in each substep (n x tools).
class Tools {
 public:
  virtual void set_tools(const std::vector<ContactTool>& tools) = 0;
  virtual void set_tool_motion(const std::vector<ToolMotion>& motion) = 0;
  virtual std::vector<ToolContactSample> tool_samples() = 0;
  // The phyxels a grasper's jaws hold now (ascending; empty for other tools and open jaws;
  // engine/solver/grasper.h).
  virtual std::vector<uint32_t> held_phyxels(size_t tool) = 0;
  // The graspers' grips (per tool: closed, and what the jaws hold with its offsets), for
  // checkpoints; restore_grips puts them back after set_tools.
  virtual std::vector<Grip> grips() = 0;
  virtual void restore_grips(const std::vector<Grip>& grips) = 0;
  // Phyxels the broad phase handed to the narrow phase in the last advance (0 without tools).
  virtual size_t contact_candidates() const = 0;
  // Whether the last advance's cut pass had a candidate within the blades' reach (false where
  // it tested no pair, or no tool has a blade; cutting.h, blades_sever_in_reach_only).
  virtual bool blades_near() const = 0;

 protected:
  ~Tools() = default;
};

// Principal stress (tearing, Scene::tearing_possible): while on, every substep computes the
// largest principal value of each stressed phyxel's Cauchy stress into a per-phyxel buffer
// (CpuSolver::max_principal_stress; a GPU pass), for the tearing passes and the outputs;
// off (the default), nothing of it is computed or allocated.
class PrincipalStress {
 public:
  virtual void set_principal_stress(bool on) = 0;

 protected:
  ~PrincipalStress() = default;
};

// Tearing (engine/solver/tearing.h, docs/tearing.md): while on, every substep ends by
// severing the live pairs whose material is overstressed, logged like cuts (Cutting) with
// `torn` set. Turning it on turns the principal stress on.
class Tearing {
 public:
  virtual void set_tearing(bool on) = 0;

 protected:
  ~Tearing() = default;
};

// Removal (aspiration, engine/surgery/aspiration.h): the phyxels leave the physics for good,
// flagged kRemoved, every pair touching them severed on both sides (not logged: the pieces and
// faces follow from the flags), the precompute rerun for their neighbours and the forces
// recomputed. Their u and v stay as they were.
class Removal {
 public:
  virtual void remove_phyxels(const std::vector<uint32_t>& ids) = 0;

 protected:
  ~Removal() = default;
};

// Cutting (engine/solver/cutting.h, docs/cutting.md): tools with a blade sever neighbour
// pairs during advance(). The solver keeps a log of every severed pair (i < j; each advance's
// pairs ascending by (i, j), appended in order): severed_pairs() is its length and
// severed_since(k) its entries from k on, so each reader keeps its own cursor. pair_alive: 1
// per CSR pair of neighbours() still joined. sever_pairs: severs the given pairs as a cut
// would and logs them (checkpoint resume, tests).
class Cutting {
 public:
  virtual size_t severed_pairs() const = 0;
  virtual std::vector<SeveredPair> severed_since(size_t first) = 0;
  virtual std::vector<uint8_t> pair_alive() = 0;
  virtual void sever_pairs(const std::vector<SeveredPair>& pairs) = 0;
  // The SCNI band round the cuts (objects with cut_band; cut_band_state.h), for checkpoints:
  // its state, and the band rebuilt from one (after sever_pairs). Empty without a band.
  virtual CutBandState cut_band_state() { return {}; }
  virtual void restore_cut_band(const CutBandState& state) {
    if (!state.phyxel.empty() || !state.quads.empty())
      throw std::invalid_argument("this solver keeps no SCNI band (cut_band)");
  }
  // Per tool, the sides its blade keeps (cutting.h, BladeSide; empty for a tool without a
  // blade), for checkpoints; restore_blade_sides puts them back after set_tools.
  virtual std::vector<std::vector<BladeSide>> blade_sides() = 0;
  virtual void restore_blade_sides(const std::vector<std::vector<BladeSide>>& sides) = 0;
  // Per tool, 1 where its blade is in the cutting state (docs/cutting.md, "Rupture and the cutting
  // state"), for checkpoints; restore_blades_cutting puts them back after set_tools.
  virtual std::vector<uint8_t> blades_cutting() = 0;
  virtual void restore_blades_cutting(const std::vector<uint8_t>& on) = 0;

 protected:
  ~Cutting() = default;
};

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
  // An advance with pauses inside it (frames between the tool chunks' lines without ending
  // the advance, which reads the tools back): as advance(substeps, dt), the same states bit for
  // bit, calling at(k) once the work of its first k substeps is submitted, for each k of
  // `pauses` (ascending, each in (0, substeps)), u of substep k then being what the solver
  // shows for drawing (the GPU solver's buffers()). at(k) may submit work that reads it to the
  // solver's queue (a frame) and call nothing of the solver but neighbours() and
  // severed_since(), which give the cuts as of the advance's start. Where pauses_within_advance
  // is false (the default), advance_paused throws std::logic_error.
  virtual bool pauses_within_advance() const { return false; }
  virtual void advance_paused(int64_t substeps, double dt, const std::vector<int64_t>& pauses,
                              const std::function<void(int64_t)>& at);
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
  // as the solver that read them would (checkpoint resume, a long step cut short).
  virtual void set_state(const std::vector<Vec3>& displacement,
                         const std::vector<Vec3>& velocity) = 0;
  // Aspiration's reads without the whole state: the phyxels of `set` (the solver's) whose
  // current position rest + u lies in `box`, with u and the principal stress. The GPU solver
  // selects them on the device, in float (callers test exactly, in a box with a margin), and
  // downloads only those; by default this filters read_state(true).
  virtual NearState read_near(const PhyxelSet& set, const Bounds& box);
  // A hint before an advance: read_near(set, box) of its end state follows it. The GPU solver
  // records that read into the advance's last submission (no round trip of its own); a
  // read_near of the same box before any other call returns it. The CPU solver ignores it.
  virtual void prefetch_near(const Bounds& /*box*/) {}
  // u of each of `ids`, in their order (a gather on the GPU; by default from read_state).
  virtual std::vector<Vec3> read_displacements(const std::vector<uint32_t>& ids);

  // The facets (above): nullptr where the solver lacks the ability.
  virtual PassSelection* pass_selection() { return nullptr; }
  virtual LoadChanges* load_changes() { return nullptr; }
  virtual Tools* tools() { return nullptr; }
  virtual PrincipalStress* principal_stress() { return nullptr; }
  virtual Tearing* tearing() { return nullptr; }
  virtual Removal* removal() { return nullptr; }
  virtual Cutting* cutting() { return nullptr; }
};

// A solver that has every facet, each one itself: the CPU reference and the GPU solver.
class SolverWithAllFacets : public Solver,
                            public PassSelection,
                            public LoadChanges,
                            public Tools,
                            public PrincipalStress,
                            public Tearing,
                            public Removal,
                            public Cutting {
 public:
  PassSelection* pass_selection() final { return this; }
  LoadChanges* load_changes() final { return this; }
  Tools* tools() final { return this; }
  PrincipalStress* principal_stress() final { return this; }
  Tearing* tearing() final { return this; }
  Removal* removal() final { return this; }
  Cutting* cutting() final { return this; }
};

// A facet the caller cannot do without (a scene's tools, a checkpoint's cuts): the facet, or a
// std::logic_error "<device> cannot <ability>" where the solver lacks it.
template <class Facet>
Facet& need(Facet* facet, const Solver& solver, const char* ability) {
  if (!facet) throw std::logic_error(solver.device() + " cannot " + ability);
  return *facet;
}

// Cutting::severed_pairs, or 0 where the solver cannot cut.
inline size_t severed_pair_count(Solver& solver) {
  const Cutting* cut = solver.cutting();
  return cut ? cut->severed_pairs() : 0;
}

// Cutting::pair_alive, or every pair joined where the solver cannot cut.
inline std::vector<uint8_t> alive_pairs(Solver& solver) {
  if (Cutting* cut = solver.cutting()) return cut->pair_alive();
  return std::vector<uint8_t>(solver.neighbours().index.size(), 1);
}

// The CPU reference solver behind the Solver interface. threads <= 0: all cores.
std::unique_ptr<Solver> make_cpu_solver(const PhyxelSet& set, const Vec3& gravity, int threads,
                                        bool single_precision = false);

}  // namespace phyxel
