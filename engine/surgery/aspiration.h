// The paper's hybrid tearing at an aspirator's mouth (section V.A, docs/suction.md), applied by
// the run loop between advances while a suction tool is on in a scene that can tear:
//
//  1. F: the failure points in the mouth's reach (solver/suction.h in_suction_reach) of the
//     phyxels that are neither fixed nor removed and whose material has a tear_stress: such a
//     phyxel whose largest principal stress reaches it (the paper's step 1), at the phyxel; and
//     the crack of each torn pair of such a phyxel with a live phyxel, at the pair's midpoint
//     (docs/tearing.md: tearing runs every substep, so the tissue the pull overloads has often
//     torn, relieving its stress, by the end of the advance); a phyxel torn loose (Tears), at
//     the phyxel. A crack is not its far phyxel: that phyxel lies up to a support radius
//     beyond it (docs/suction.md, "Resolution").
//  2. Of F, the overstressed phyxels on the tissue's surface (the outer surface, a fracture
//     surface an earlier aspiration exposed, or a face a tear or a cut opened), the cracks
//     (faces themselves) and the loose phyxels: the point farthest from the collision point c,
//     the mouth, gives the
//     breaking point (its phyxel) and the fracture radius R, its distance (step 2). No such
//     point: nothing tears yet (the overstressed tissue is still inside).
//  3. The phyxels within R of c whose material has a tear_stress are aspirated: removed from the
//     physics, their mass and volume accounted per material (objects' and inclusions'). Those
//     with R < |x - c| <= R + delta (delta: the largest object spacing) form the new fracture
//     surface (step 3): they are surface from now on (the next aspiration's step 2 sees them)
//     and the renderer draws them as torn (docs/tearing.md).
//
// Positions are current (rest + u), as the solver had them at the end of the advance: the
// sphere is where the mouth is now. What the event hands the renderer is in rest space, as
// everything the deform pass carries through F = I + grad u (map_fracture_to_rest): the new
// surface's normals n0 = F^T n / |F^T n| of the crater wall's current normals n, so that the
// drawn (F^-T n0, normalised) is n, and the sphere's centre and axis mapped back through the
// F of the aspirated phyxels. F is the deform pass's (engine/solver/mls_gradient.h), over the
// pairs still joined once the event's phyxels are gone.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

#include "engine/geometry/tool.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/scene/tool_desc.h"
#include "engine/solver/cutting.h"
#include "engine/solver/neighbours.h"

namespace phyxel {

class Solver;

struct AspirationEvent {
  size_t tool = 0;
  double time = 0;                // s, the end of the advance
  Vec3 mouth = Vec3::Zero();      // the collision point c (current positions), m
  double radius = 0;              // the fracture radius R (current positions), m
  uint32_t breaking = 0;          // the breaking point (step 2)
  std::vector<uint32_t> removed;  // ascending
  std::vector<uint32_t> exposed;  // the new fracture surface, ascending
  // Rest space (map_fracture_to_rest; fracture_sphere leaves them in current positions): per
  // exposed phyxel the outward unit normal of the crater's wall it is on; the point that
  // moved to the mouth; the tool's axis (the crater's, for the noise's falloff); the
  // breaking point's distance from that centre.
  std::vector<Vec3> exposed_normal;
  Vec3 centre = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();
  double rest_radius = 0;  // m
};

// Per phyxel the phyxels it was torn from (the severed log's torn pairs, both ways).
using TornPartners = std::vector<std::vector<uint32_t>>;

// What fracture_sphere knows of the tears, per phyxel: the phyxels it was torn from, and 1
// where it is torn loose: fewer than half of its pairs to live phyxels are intact (read only
// at the phyxels it looks at).
struct Tears {
  TornPartners partners;
  std::vector<uint8_t> loose;
};

// Pairs (i, j) of the neighbour lists that a cut or a tear severed, keyed by pair_key.
using SeveredKeys = std::unordered_set<uint64_t>;
inline uint64_t pair_key(uint32_t i, uint32_t j) {
  return i < j ? (uint64_t{i} << 32) | j : (uint64_t{j} << 32) | i;
}

// The phyxels a fracture sphere looks at (Aspirator: those near the mouths): ascending ids and
// per id the current position and the largest principal stress (Pa).
struct MouthPhyxels {
  std::vector<uint32_t> ids;
  std::vector<Vec3> x;
  std::vector<double> principal;
};

// Steps 1-3 for one mouth, over the phyxels of `near` (those within reach + shell of the mouth
// at least; the result is as over every phyxel). removed, surface, torn: per phyxel (1:
// removed; 1: on a surface; the tears); shell: delta. A torn partner outside `near` counts at
// the phyxel's own position.
// Returns an event with no removed phyxel when nothing tears. Its rest-space fields are still
// in current positions (centre = mouth): map_fracture_to_rest maps them.
AspirationEvent fracture_sphere(const PhyxelSet& set, const std::vector<uint8_t>& removed,
                                const std::vector<uint8_t>& surface, const Tears& torn,
                                const MouthPhyxels& near, const ToolPose& mouth, double reach,
                                double shell);

// The same over every phyxel: x the current positions, principal the stresses, per phyxel.
AspirationEvent fracture_sphere(const PhyxelSet& set, const std::vector<uint8_t>& removed,
                                const std::vector<uint8_t>& surface, const Tears& torn,
                                const std::vector<Vec3>& x, const std::vector<double>& principal,
                                const ToolPose& mouth, double reach, double shell);

// The event's rest-space fields from the current ones, with the displacement u, the rest
// neighbour lists, the phyxels removed before it and the pairs severed (see the top). Reads u
// of the event's phyxels (removed and exposed) and of their neighbours only.
void map_fracture_to_rest(AspirationEvent& e, const PhyxelSet& set, const NeighbourLists& nbr,
                          const std::vector<Vec3>& u, const std::vector<uint8_t>& removed,
                          const SeveredKeys& severed);

// What the aspirators took, per material of the set (objects' then inclusions', as
// PhyxelSet::materials), and per run.
struct AspirationTotals {
  std::vector<std::string> names;  // of the materials' objects and inclusions
  std::vector<double> initial_mass, removed_mass, initial_volume, removed_volume;  // kg, m^3
  int64_t events = 0;     // aspirations that removed tissue
  double max_radius = 0;  // the largest fracture radius, m
};

// What a checkpoint keeps of an Aspirator (engine/run/checkpoint.h): the phyxels it removed
// (ascending), which phyxels are surface, how much of the solver's severed log it has read and
// the totals' running sums (kept as summed, so a resumed run's totals are bit-identical).
struct AspiratorState {
  uint64_t log_cursor = 0;
  std::vector<uint32_t> removed;
  std::vector<uint8_t> surface;  // per phyxel; empty: no aspirator
  int64_t events = 0;
  double max_radius = 0;                             // m
  std::vector<double> removed_mass, removed_volume;  // per material, kg and m^3
};

// Where an Aspirator's host time went (s): reading the state near the mouths, the fracture
// sphere (steps 1-3), the rest-space map (its displacements read too) and the solver's removal
// of the event's phyxels; per read (one after each tool chunk with a suction tool on).
struct AspirationTimes {
  double read = 0, sphere = 0, rest_map = 0, removal = 0;
  int64_t reads = 0;
};

class Aspirator {
 public:
  Aspirator(const Scene& scene, const PhyxelSet& set);
  // Any suction tool, in a scene where something can tear.
  bool active() const { return active_; }
  // After an advance that ended at time t with the tools at `poses` (one per scene tool): the
  // aspiration of every suction tool on at t, applied to `solver` (Solver::remove_phyxels).
  // rest_space: map each event to rest space (map_fracture_to_rest, its displacements read);
  // off where no one looks at the events' rest-space fields (they stay in current positions).
  std::vector<AspirationEvent> after_advance(Solver& solver, const std::vector<ToolPose>& poses,
                                             double t, bool rest_space = true);
  // Before the advance that ends at time t with the tools at `poses`, where after_advance
  // follows it: the solver may read the mouths' phyxels within that advance
  // (Solver::prefetch_near). Changes no outcome.
  void before_advance(Solver& solver, const std::vector<ToolPose>& poses, double t) const;
  const AspirationTotals& totals() const { return totals_; }
  const AspirationTimes& times() const { return times_; }
  // For checkpoints: the state, and back (before the solver's state is set): the removed
  // phyxels leave `solver` again and the log's first log_cursor pairs (`severed`, the solver's
  // log) are read as after_advance read them. Throws std::invalid_argument on a mismatch.
  AspiratorState state() const;
  void restore(const AspiratorState& state, Solver& solver,
               const std::vector<SeveredPair>& severed);

 private:
  void account(const AspirationEvent& e, const NeighbourLists& nbr);
  void add_torn(const SeveredPair& p);
  // torn_.loose at the torn phyxels of `near`, from the rest lists, removed_ and severed_.
  void refresh_loose(const MouthPhyxels& near, const NeighbourLists& nbr);
  // The counts behind it (live_, intact_), kept as pairs are severed and phyxels removed; built
  // at the first refresh (from the state then) where the rest lists are symmetric.
  void build_counts(const NeighbourLists& nbr);
  void count_severed(uint32_t i, uint32_t j, const NeighbourLists& nbr);
  void count_removed(uint32_t r, const NeighbourLists& nbr);
  void read_severed(Solver& solver);
  Bounds mouth_box(const std::vector<ToolPose>& poses, double t, std::vector<size_t>& on) const;
  // The phyxels in `box` (Solver::read_near), u_ set at them.
  MouthPhyxels read_mouths(Solver& solver, const Bounds& box);
  // u_ at the event's phyxels and their neighbours (Solver::read_displacements).
  void read_event_displacements(Solver& solver, const AspirationEvent& e);

  const Scene* scene_;
  const PhyxelSet* set_;
  bool active_ = false;
  double shell_ = 0;
  std::vector<uint8_t> removed_, surface_;
  Tears torn_;  // loose: as of the last refresh_loose
  // u as last read, valid only where read (the phyxels near the mouths, an event's and their
  // neighbours): what map_fracture_to_rest looks at.
  std::vector<Vec3> u_;
  size_t log_cursor_ = 0;  // of the solver's severed log
  SeveredKeys severed_;    // the log's pairs
  // Per phyxel, of its rest neighbours: those not removed (live_), and of those the pairs not
  // severed (intact_). Valid while counted_.
  std::vector<uint32_t> live_, intact_;
  bool counted_ = false, count_stale_ = true;
  AspirationTotals totals_;
  AspirationTimes times_;
};

}  // namespace phyxel
