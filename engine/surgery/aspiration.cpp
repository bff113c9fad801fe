#include "engine/surgery/aspiration.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "engine/solver/mls_gradient.h"
#include "engine/solver/solver.h"
#include "engine/solver/suction.h"

namespace phyxel {
namespace {

// Adds the time since `mark` to `into` and moves the mark.
void lap(double& into, std::chrono::steady_clock::time_point& mark) {
  const auto now = std::chrono::steady_clock::now();
  into += std::chrono::duration<double>(now - mark).count();
  mark = now;
}

double tear_stress_of(const PhyxelSet& set, uint32_t i) {
  return set.materials[set.material[i]].tear_stress.value_or(0.0);
}

}  // namespace

AspirationEvent fracture_sphere(const PhyxelSet& set, const std::vector<uint8_t>& removed,
                                const std::vector<uint8_t>& surface, const Tears& torn,
                                const MouthPhyxels& near, const ToolPose& mouth, double reach,
                                double shell) {
  const size_t n = set.size();
  const size_t m = near.ids.size();
  if (removed.size() != n || surface.size() != n || torn.partners.size() != n ||
      torn.loose.size() != n || near.x.size() != m || near.principal.size() != m)
    throw std::invalid_argument("fracture_sphere: per-phyxel arrays of different sizes");
  AspirationEvent e;
  e.mouth = e.centre = mouth.position;
  e.axis = mouth.axis;
  auto takes = [&](uint32_t i) {
    return !removed[i] && !(set.flags[i] & kFixed) && tear_stress_of(set, i) > 0;
  };
  auto position = [&](uint32_t j, const Vec3& otherwise) {  // near.ids is ascending
    const auto it = std::lower_bound(near.ids.begin(), near.ids.end(), j);
    return it != near.ids.end() && *it == j ? near.x[size_t(it - near.ids.begin())] : otherwise;
  };
  // Steps 1 and 2: the farthest failure point in reach: an overstressed surface phyxel or one
  // torn loose, at the phyxel; the crack of a torn pair, at the pair's midpoint (the log's
  // t = 0.5) between two live phyxels.
  double radius = -1;
  auto candidate = [&](uint32_t i, const Vec3& at) {
    const double d = (at - mouth.position).norm();
    if (d > radius && in_suction_reach(mouth, reach, at)) {
      radius = d;
      e.breaking = i;
    }
  };
  for (size_t k = 0; k < m; ++k) {
    const uint32_t i = near.ids[k];
    if (!takes(i)) continue;
    if ((surface[i] && near.principal[k] >= tear_stress_of(set, i)) || torn.loose[i])
      candidate(i, near.x[k]);
    for (const uint32_t j : torn.partners[i])
      if (!removed[j]) candidate(i, 0.5 * (near.x[k] + position(j, near.x[k])));
  }
  if (radius < 0) return e;
  e.radius = e.rest_radius = radius;
  // Step 3: inside the sphere aspirated, the shell outside it exposed.
  for (size_t k = 0; k < m; ++k) {
    const uint32_t i = near.ids[k];
    if (removed[i]) continue;
    const double d = (near.x[k] - mouth.position).norm();
    if (d <= radius && takes(i))
      e.removed.push_back(i);
    else if (d > radius && d <= radius + shell && !(set.flags[i] & kFixed)) {
      e.exposed.push_back(i);
      e.exposed_normal.push_back((mouth.position - near.x[k]) / d);
    }
  }
  return e;
}

AspirationEvent fracture_sphere(const PhyxelSet& set, const std::vector<uint8_t>& removed,
                                const std::vector<uint8_t>& surface, const Tears& torn,
                                const std::vector<Vec3>& x, const std::vector<double>& principal,
                                const ToolPose& mouth, double reach, double shell) {
  if (x.size() != set.size() || principal.size() != set.size())
    throw std::invalid_argument("fracture_sphere: per-phyxel arrays of different sizes");
  MouthPhyxels all;
  all.ids.resize(set.size());
  for (size_t i = 0; i < all.ids.size(); ++i) all.ids[i] = static_cast<uint32_t>(i);
  all.x = x;
  all.principal = principal;
  return fracture_sphere(set, removed, surface, torn, all, mouth, reach, shell);
}

void map_fracture_to_rest(AspirationEvent& e, const PhyxelSet& set, const NeighbourLists& nbr,
                          const std::vector<Vec3>& u, const std::vector<uint8_t>& removed,
                          const SeveredKeys& severed) {
  if (e.removed.empty()) return;
  auto going = [&](uint32_t j) {  // e.removed is ascending
    return std::binary_search(e.removed.begin(), e.removed.end(), j);
  };
  auto deformation = [&](uint32_t i, bool after) {
    const double h = set.objects[set.object[i]].support_radius;
    return mls_deformation(set.rest, nbr, u, i, h, [&](uint32_t, uint32_t j) {
      return !removed[j] && !(after && going(j)) && !severed.count(pair_key(i, j));
    });
  };
  // The centre and axis: each aspirated phyxel's first-order preimage of the mouth,
  // x0_k + F_k^-1 (c - x_k), and F_k^-1 a, mass-weighted (exact for an affine motion). A
  // crushed or inverted phyxel (det F < 0.1) has no useful F^-1: it counts with F = I.
  Vec3 centre = Vec3::Zero(), axis = Vec3::Zero();
  double mass = 0;
  for (const uint32_t k : e.removed) {
    const Eigen::Matrix3d f = deformation(k, false).f;
    const Eigen::Matrix3d f_inv =
        f.determinant() >= 0.1 ? Eigen::Matrix3d(f.inverse()) : Eigen::Matrix3d::Identity();
    centre += set.mass[k] * (set.rest[k] + f_inv * (e.mouth - set.rest[k] - u[k]));
    axis += set.mass[k] * (f_inv * e.axis);
    mass += set.mass[k];
  }
  if (mass > 0) e.centre = centre / mass;
  if (axis.norm() > 0) e.axis = axis.normalized();
  e.rest_radius = (set.rest[e.breaking] - e.centre).norm();
  // The wall's normals as the deform pass will carry them, with the aspirated phyxels gone.
  for (size_t k = 0; k < e.exposed.size(); ++k) {
    const Vec3 n0 = deformation(e.exposed[k], true).f.transpose() * e.exposed_normal[k];
    if (n0.norm() > 0) e.exposed_normal[k] = n0.normalized();
  }
}

Aspirator::Aspirator(const Scene& scene, const PhyxelSet& set)
    : scene_(&scene),
      set_(&set),
      removed_(set.size(), 0),
      surface_(set.size(), 0),
      torn_{TornPartners(set.size()), std::vector<uint8_t>(set.size(), 0)} {
  bool suction = false;
  for (const ToolDesc& t : scene.tools) suction = suction || t.suction.sucks();
  active_ = suction && scene.tearing_possible();
  for (const ObjectRange& o : set.objects) shell_ = std::max(shell_, o.spacing);
  if (active_) u_.assign(set.size(), Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i) {
    removed_[i] = (set.flags[i] & kRemoved) != 0;
    surface_[i] = (set.flags[i] & kSurface) != 0;
  }
  const size_t m = set.materials.size();
  totals_.initial_mass.assign(m, 0);
  totals_.removed_mass.assign(m, 0);
  totals_.initial_volume.assign(m, 0);
  totals_.removed_volume.assign(m, 0);
  for (const ObjectDesc& o : scene.objects) totals_.names.push_back(o.name);
  for (const ObjectDesc& o : scene.objects)
    for (const Inclusion& inc : o.inclusions) totals_.names.push_back(inc.name);
  totals_.names.resize(m);
  for (size_t i = 0; i < set.size(); ++i) {
    if (removed_[i]) continue;
    totals_.initial_mass[set.material[i]] += set.mass[i];
    totals_.initial_volume[set.material[i]] += set.volume[i];
  }
}

void Aspirator::account(const AspirationEvent& e, const NeighbourLists& nbr) {
  for (const uint32_t i : e.removed) {
    if (counted_ && !removed_[i]) count_removed(i, nbr);
    removed_[i] = 1;
    totals_.removed_mass[set_->material[i]] += set_->mass[i];
    totals_.removed_volume[set_->material[i]] += set_->volume[i];
  }
  for (const uint32_t i : e.exposed) surface_[i] = 1;
  if (!e.removed.empty()) {
    ++totals_.events;
    totals_.max_radius = std::max(totals_.max_radius, e.radius);
  }
}

void Aspirator::add_torn(const SeveredPair& p) {
  torn_.partners[p.i].push_back(p.j);
  torn_.partners[p.j].push_back(p.i);
}

// The live and intact counts once (O(pairs)), then per severed pair and removed phyxel: a
// refresh is O(near) with no look-up in severed_. Rows are symmetric (find_rest_neighbours:
// one support radius per object), so the phyxels that have r as a neighbour are r's own.
void Aspirator::build_counts(const NeighbourLists& nbr) {
  count_stale_ = false;
  counted_ = false;
  const size_t n = removed_.size();
  if (nbr.offset.size() != n + 1) return;
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t s = nbr.offset[i]; s < nbr.offset[i + 1]; ++s)
      if (nbr.slot(nbr.index[s], i) == NeighbourLists::kNoSlot) return;  // not symmetric
  live_.assign(n, 0);
  for (size_t i = 0; i < n; ++i)
    for (uint32_t s = nbr.offset[i]; s < nbr.offset[i + 1]; ++s)
      live_[i] += !removed_[nbr.index[s]];
  intact_ = live_;
  counted_ = true;
  for (const uint64_t key : severed_) count_severed(uint32_t(key >> 32), uint32_t(key), nbr);
}

// The pair (i, j) was just severed.
void Aspirator::count_severed(uint32_t i, uint32_t j, const NeighbourLists& nbr) {
  if (nbr.slot(i, j) == NeighbourLists::kNoSlot) return;
  intact_[i] -= !removed_[j];
  intact_[j] -= !removed_[i];
}

// r is about to be removed.
void Aspirator::count_removed(uint32_t r, const NeighbourLists& nbr) {
  for (uint32_t s = nbr.offset[r]; s < nbr.offset[r + 1]; ++s) {
    const uint32_t j = nbr.index[s];
    --live_[j];
    intact_[j] -= !severed_.count(pair_key(j, r));
  }
}

void Aspirator::refresh_loose(const MouthPhyxels& near, const NeighbourLists& nbr) {
  if (count_stale_) build_counts(nbr);
  for (const uint32_t i : near.ids) {
    if (torn_.partners[i].empty() || removed_[i]) continue;
    if (counted_) {
      torn_.loose[i] = 2 * intact_[i] < live_[i];
      continue;
    }
    int live = 0, intact = 0;
    for (uint32_t s = nbr.offset[i]; s < nbr.offset[i + 1]; ++s) {
      const uint32_t j = nbr.index[s];
      live += !removed_[j];
      intact += !removed_[j] && !severed_.count(pair_key(i, j));
    }
    torn_.loose[i] = 2 * intact < live;
  }
}

void Aspirator::read_severed(Solver& solver) {
  // What tore or was cut since the last aspiration: torn pairs are cracks (failures), and every
  // severed pair opened a face (a surface).
  Cutting* cut = solver.cutting();
  if (!cut || cut->severed_pairs() <= log_cursor_) return;
  for (const SeveredPair& p : cut->severed_since(log_cursor_)) {
    surface_[p.i] = surface_[p.j] = 1;
    if (p.torn) add_torn(p);
    if (severed_.insert(pair_key(p.i, p.j)).second && counted_)
      count_severed(p.i, p.j, solver.neighbours());
  }
  log_cursor_ = cut->severed_pairs();
}

MouthPhyxels Aspirator::read_mouths(Solver& solver, const Bounds& box) {
  NearState state = solver.read_near(*set_, box);
  if (state.principal.size() != state.ids.size())
    throw std::logic_error(solver.device() + " gave no principal stresses for aspiration");
  MouthPhyxels near;
  near.x.resize(state.ids.size());
  for (size_t k = 0; k < state.ids.size(); ++k) {
    const uint32_t i = state.ids[k];
    u_[i] = state.displacement[k];
    near.x[k] = set_->rest[i] + state.displacement[k];
  }
  near.ids = std::move(state.ids);
  near.principal = std::move(state.principal);
  return near;
}

void Aspirator::read_event_displacements(Solver& solver, const AspirationEvent& e) {
  // map_fracture_to_rest's F of the removed and exposed phyxels reads u of their neighbours.
  const NeighbourLists& nbr = solver.neighbours();
  std::vector<uint32_t> ids;
  for (const std::vector<uint32_t>* list : {&e.removed, &e.exposed})
    for (const uint32_t i : *list) {
      ids.push_back(i);
      ids.insert(ids.end(), nbr.index.begin() + nbr.offset[i],
                 nbr.index.begin() + nbr.offset[i + 1]);
    }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  const std::vector<Vec3> u = solver.read_displacements(ids);
  for (size_t k = 0; k < ids.size(); ++k) u_[ids[k]] = u[k];
}

// The suction tools on at t (into `on`), and a box around their mouths holding every phyxel
// that fracture_sphere looks at (within reach + shell), with a margin for the solver's float
// test.
Bounds Aspirator::mouth_box(const std::vector<ToolPose>& poses, double t,
                            std::vector<size_t>& on) const {
  Bounds box;
  for (size_t k = 0; k < scene_->tools.size() && k < poses.size(); ++k) {
    const Suction& s = scene_->tools[k].suction;
    const bool haptic = scene_->tools[k].control == ToolDesc::Control::Haptic;
    if (!s.sucks() || !(haptic || s.on_at(scene_->tools[k].cycle_time(t)))) continue;
    on.push_back(k);
    const Vec3 r = Vec3::Constant(1.01 * (s.reach + shell_) + 1e-6);
    box.extend(Bounds{poses[k].position - r, poses[k].position + r});
  }
  return box;
}

void Aspirator::before_advance(Solver& solver, const std::vector<ToolPose>& poses, double t) const {
  if (!active_) return;
  std::vector<size_t> on;
  const Bounds box = mouth_box(poses, t, on);
  if (!on.empty()) solver.prefetch_near(box);
}

std::vector<AspirationEvent> Aspirator::after_advance(Solver& solver,
                                                      const std::vector<ToolPose>& poses, double t,
                                                      bool rest_space) {
  std::vector<AspirationEvent> events;
  if (!active_) return events;
  read_severed(solver);
  std::vector<size_t> on;
  const Bounds box = mouth_box(poses, t, on);
  if (on.empty()) return events;
  auto mark = std::chrono::steady_clock::now();
  const MouthPhyxels near = read_mouths(solver, box);  // one read for every tool
  ++times_.reads;
  lap(times_.read, mark);
  refresh_loose(near, solver.neighbours());
  for (const size_t k : on) {
    AspirationEvent e = fracture_sphere(*set_, removed_, surface_, torn_, near, poses[k],
                                        scene_->tools[k].suction.reach, shell_);
    lap(times_.sphere, mark);
    if (e.removed.empty()) continue;
    if (rest_space) {
      read_event_displacements(solver, e);
      map_fracture_to_rest(e, *set_, solver.neighbours(), u_, removed_, severed_);
    }
    lap(times_.rest_map, mark);
    e.tool = k;
    e.time = t;
    need(solver.removal(), solver, "remove phyxels").remove_phyxels(e.removed);
    account(e, solver.neighbours());
    lap(times_.removal, mark);
    events.push_back(std::move(e));
  }
  return events;
}

AspiratorState Aspirator::state() const {
  AspiratorState s;
  if (!active_) return s;
  s.log_cursor = log_cursor_;
  for (size_t i = 0; i < removed_.size(); ++i)
    if (removed_[i] && !(set_->flags[i] & kRemoved)) s.removed.push_back(uint32_t(i));
  s.surface = surface_;
  s.events = totals_.events;
  s.max_radius = totals_.max_radius;
  s.removed_mass = totals_.removed_mass;
  s.removed_volume = totals_.removed_volume;
  return s;
}

void Aspirator::restore(const AspiratorState& s, Solver& solver,
                        const std::vector<SeveredPair>& severed) {
  if (!active_ && s.surface.empty()) return;
  const size_t m = totals_.removed_mass.size();
  if (!active_ || s.surface.size() != surface_.size() || s.log_cursor > severed.size() ||
      s.removed_mass.size() != m || s.removed_volume.size() != m)
    throw std::invalid_argument("its aspiration state does not fit this scene");
  for (const uint32_t i : s.removed)
    if (i >= removed_.size() || removed_[i])
      throw std::invalid_argument("its aspirated phyxels do not fit this scene");
  for (const uint32_t i : s.removed) removed_[i] = 1;
  count_stale_ = true;  // counted again from this state at the next refresh
  surface_ = s.surface;
  for (size_t k = 0; k < s.log_cursor; ++k) {
    const SeveredPair& p = severed[k];
    if (p.torn) add_torn(p);
    severed_.insert(pair_key(p.i, p.j));
  }
  log_cursor_ = s.log_cursor;
  totals_.events = s.events;
  totals_.max_radius = s.max_radius;
  totals_.removed_mass = s.removed_mass;
  totals_.removed_volume = s.removed_volume;
  if (!s.removed.empty())
    need(solver.removal(), solver, "remove phyxels").remove_phyxels(s.removed);
}

}  // namespace phyxel
