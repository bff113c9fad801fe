// Tool-tissue contact on the CPU reference: what a probe does to tissue and what it feels.
// Action = reaction, penetration, a tool at 1 m/s, Coulomb friction, Hertz indentation.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../physics/physics_fixtures.h"
#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"

namespace phyxel {
namespace {

using test::box_scene;
using test::tissue;

ToolDesc sphere_probe(double radius, std::vector<ToolKey> path, double friction = 0) {
  ToolDesc t;
  t.name = "probe";
  t.shape.type = ToolShape::Type::Sphere;
  t.shape.radius = radius;
  t.path = std::move(path);
  t.friction = friction;
  return t;
}

ToolKey key(double t, const Vec3& p, const Vec3& axis = Vec3::UnitZ()) {
  return {t, p, axis};
}

void fix_bottom(Scene& scene, double z) {
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, z)));
}

struct Trace {
  std::vector<Vec3> force;  // per step
  std::vector<uint32_t> contacts;
};

// Runs a scene on the CPU reference (double) and returns the trace of its first tool.
struct Outcome {
  PhyxelSet set;
  std::unique_ptr<Solver> solver;
  RunResult result;
  Trace trace;
};

Outcome simulate(const Scene& scene) {
  Outcome o;
  o.set = sample_scene(scene);
  o.solver = make_cpu_solver(o.set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = scene.simulation.steps;
  Trace* trace = &o.trace;
  options.on_tool_step = [trace](int64_t, double, const std::vector<ToolStepRecord>& r) {
    trace->force.push_back(r[0].force);
    trace->contacts.push_back(r[0].contacts);
  };
  o.result = run_simulation(scene, o.set, *o.solver, options);
  return o;
}

// A free block (no gravity, nothing fixed) hit by a moving sphere: the momentum the tissue
// gains equals the impulse of the contact forces, which is minus the impulse on the tool.
TEST(Contact, ActionEqualsReactionOnAFreeBlock) {
  Scene scene = box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.01), 0.002, tissue(2e4, 0.3, 0));
  const double dt = 1e-4;
  scene.simulation.dt = dt;
  scene.simulation.steps = 300;
  scene.tools.push_back(sphere_probe(
      0.004, {key(0, Vec3(0.01, 0.01, 0.0145)), key(0.03, Vec3(0.01, 0.01, 0.007))}, 0.3));
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, Vec3::Zero());
  solver.set_tools(contact_tools(scene.tools));
  ToolTrack track(scene.tools, {});
  Vec3 impulse_on_tool = Vec3::Zero();
  size_t touched_steps = 0;
  for (int64_t step = 0; step < scene.simulation.steps; ++step) {
    solver.set_tool_motion(track.motions(step, 1, dt), dt);
    solver.step(dt);
    const ToolContactSample& felt = solver.tool_samples().at(0);
    // Per step: the tool's force is minus the sum of the contact forces on the phyxels.
    Vec3 on_tissue = Vec3::Zero();
    for (const Vec3& f : solver.contact_force()) on_tissue += f;
    EXPECT_LE((on_tissue + felt.force).norm(), 1e-9 * std::max(1.0, felt.force.norm()));
    impulse_on_tool += felt.force * dt;
    touched_steps += felt.contacts > 0 ? 1 : 0;
  }
  ASSERT_GT(touched_steps, 100u);
  Vec3 momentum = Vec3::Zero();
  for (size_t i = 0; i < set.size(); ++i) momentum += set.mass[i] * solver.velocity()[i];
  // The leapfrog's velocity lags its half kick; internal forces sum to zero, so the momentum
  // (at the step's end) equals the contact impulse to rounding.
  ASSERT_GT(impulse_on_tool.norm(), 0);
  EXPECT_LE((momentum + impulse_on_tool).norm(), 1e-6 * impulse_on_tool.norm())
      << "tissue momentum " << momentum.transpose() << ", tool impulse "
      << impulse_on_tool.transpose();
}

// A probe pressed 5 mm into a block leaves no phyxel inside it beyond the documented
// tolerance (1e-9 m in double: the projection puts phyxels on the surface exactly).
TEST(Contact, NoPhyxelInsideAProbePressedFiveMillimetres) {
  Scene scene = box_scene(Vec3(0, 0, 0), Vec3(0.04, 0.04, 0.02), 0.002, tissue(3000, 0.45, 20));
  fix_bottom(scene, 0.0005);
  scene.simulation.dt = 2e-4;
  scene.simulation.steps = 1500;
  const double r = 0.006;
  scene.tools.push_back(
      sphere_probe(r, {key(0, Vec3(0.02, 0.02, 0.02 + r)), key(0.2, Vec3(0.02, 0.02, 0.015 + r))}));
  Outcome o = simulate(scene);
  ASSERT_FALSE(o.result.non_finite);
  ASSERT_FALSE(o.result.unstable);
  const PointState state = o.solver->read_state(false);
  const ToolPose pose = pose_at(scene.tools[0].path, 1e9);
  double deepest = 0;
  size_t touching = 0;
  for (size_t i = 0; i < o.set.size(); ++i) {
    const double d =
        tool_distance(scene.tools[0].shape, pose, o.set.rest[i] + state.displacement[i]).distance;
    deepest = std::min(deepest, d);
    touching += state.contact[i];
  }
  EXPECT_GT(touching, 5u);
  EXPECT_GE(deepest, -1e-9);
  EXPECT_GT(o.result.tools.at(0).max_force, 0);
  EXPECT_GT(o.result.tools.at(0).last_force.z(), 0);  // the tissue pushes the probe up
}

// A capsule driven at 1 m/s into soft tissue and out again: no non-finite value, no runaway.
TEST(Contact, ToolAtOneMetrePerSecondStaysStable) {
  Scene scene = box_scene(Vec3(0, 0, 0), Vec3(0.04, 0.03, 0.02), 0.003, tissue(3000, 0.45, 20));
  fix_bottom(scene, 0.001);
  scene.simulation.dt = 2.4e-4;
  scene.simulation.steps = 400;
  ToolDesc t = sphere_probe(0.003, {});
  t.shape.type = ToolShape::Type::Capsule;
  t.shape.length = 0.03;
  t.friction = 0.5;
  // Down 15 mm at 1 m/s, sideways 20 mm at 1 m/s, out at 1 m/s.
  t.path = {key(0, Vec3(0.02, 0.015, 0.023)), key(0.018, Vec3(0.02, 0.015, 0.005)),
            key(0.038, Vec3(0.02, 0.035, 0.005)), key(0.056, Vec3(0.02, 0.035, 0.023))};
  scene.tools.push_back(t);
  Outcome o = simulate(scene);
  EXPECT_FALSE(o.result.non_finite);
  EXPECT_FALSE(o.result.unstable) << o.result.unstable_phyxel << " at "
                                  << o.set.rest[o.result.unstable_phyxel].transpose() << " step "
                                  << o.result.unstable_step << " speed " << o.result.unstable_speed
                                  << " fixed " << (o.set.flags[o.result.unstable_phyxel] & kFixed);
  EXPECT_EQ(o.result.steps_done, scene.simulation.steps);
  EXPECT_GT(o.result.tools.at(0).max_contacts, 10u);
  const PointState state = o.solver->read_state(false);
  EXPECT_LT(find_runaway(o.set, state.velocity).phyxel, 0);
}

}  // namespace
}  // namespace phyxel

namespace phyxel {
namespace {

// Hertz: F = 4/3 E* sqrt(R) d^(3/2) for a sphere pressed quasi-statically to depth d << R
// into an elastic half-space, E* = E / (1 - nu^2). A 40 x 40 x 20 mm block (clamped below,
// 12 contact radii wide) at 1 mm spacing, R = 10 mm, d = 1 mm (contact radius 3.2 mm),
// indented over 0.1 s and held 0.1 s with heavy damping: measured 2 % below Hertz.
TEST(Contact, HertzIndentation) {
  const double young = 1000, nu = 0.3, s = 0.001, r = 0.01, d = 0.001;
  Scene scene = box_scene(Vec3(0, 0, 0), Vec3(0.04, 0.04, 0.02), s, tissue(young, nu, 100));
  fix_bottom(scene, 0.25 * s);
  scene.simulation.dt = 4e-4;
  scene.simulation.steps = 500;
  const Vec3 c(0.02, 0.02, 0.02 + r);
  scene.tools.push_back(sphere_probe(r, {key(0, c), key(0.1, c - Vec3(0, 0, d))}));
  Outcome o = simulate(scene);
  ASSERT_FALSE(o.result.non_finite);
  const double hertz = 4.0 / 3.0 * young / (1 - nu * nu) * std::sqrt(r) * std::pow(d, 1.5);
  const Vec3 f = o.result.tools.at(0).last_force;
  EXPECT_NEAR(f.z(), hertz, 0.1 * hertz) << "F " << f.transpose() << " Hertz " << hertz;
  EXPECT_LT(std::hypot(f.x(), f.y()), 1e-6 * f.z());  // symmetric: no sideways force
}

// A sphere (R = 20 mm: a flat contact) pressed 1 mm into a block (0.1 s), held (0.1 s), then
// slid `travel` along x in `duration` seconds.
struct Slide {
  Vec3 force;      // on the tool at the end of the slide
  double dragged;  // mean x displacement gained during the slide by the phyxels touching at
                   // the end of the hold
};

Slide slide(double mu, double travel, double duration) {
  const double s = 0.002, r = 0.02, d = 0.001, dt = 4e-4;
  Scene scene = box_scene(Vec3(0, 0, 0), Vec3(0.06, 0.04, 0.02), s, tissue(1000, 0.3, 100));
  fix_bottom(scene, 0.25 * s);
  scene.simulation.dt = dt;
  const Vec3 c(0.02, 0.02, 0.02 + r - d);
  scene.tools.push_back(sphere_probe(r,
                                     {key(0, c + Vec3(0, 0, d)), key(0.1, c), key(0.2, c),
                                      key(0.2 + duration, c + Vec3(travel, 0, 0))},
                                     mu));
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, Vec3::Zero(), 1);
  RunOptions options;
  options.steps = static_cast<int64_t>(std::lround((0.2 + duration) / dt));
  options.frame_every = static_cast<int64_t>(std::lround(0.2 / dt));  // the end of the hold
  PointState held;
  options.on_frame = [&](int64_t step, Solver& sv) {
    if (step == options.frame_every) held = sv.read_state(false);
  };
  const RunResult result = run_simulation(scene, set, *solver, options);
  const PointState end = solver->read_state(false);
  double dragged = 0;
  int n = 0;
  for (size_t i = 0; i < set.size() && !held.contact.empty(); ++i) {
    if (!held.contact[i]) continue;
    dragged += end.displacement[i].x() - held.displacement[i].x();
    ++n;
  }
  EXPECT_GT(n, 5);
  return {result.tools.at(0).last_force, n > 0 ? dragged / n : 0.0};
}

// Sliding 6 mm at 2 cm/s: Coulomb's law holds for the tool as a whole: the tangential force is
// mu times the normal force within 10 %. (Tissue piling up ahead of a curved probe tilts the
// friction at its front downwards, which raises the ratio: with R = 10 mm it was 12 % above mu;
// the flatter R = 20 mm contact keeps it within the bound.)
TEST(Contact, SlidingProbeFeelsCoulombFriction) {
  for (const double mu : {0.1, 0.3}) {
    const Slide sl = slide(mu, 0.006, 0.3);
    EXPECT_NEAR(-sl.force.x() / sl.force.z(), mu, 0.1 * mu)
        << "mu " << mu << " F " << sl.force.transpose();
  }
  const Slide frictionless = slide(0, 0.006, 0.3);
  EXPECT_LT(std::abs(frictionless.force.x()), 0.01 * frictionless.force.z());
}

// Sticking (mu = 3, a 0.5 mm pull: Mindlin's tangential force 8 G a delta / (2 - nu) stays
// well inside mu times the normal force): the surface under the probe moves with it, by the
// tool's travel within 10 %; without friction the probe slides over it and drags it far less.
TEST(Contact, StickingProbeDragsTheSurface) {
  const double travel = 0.0005;
  const Slide stick = slide(3.0, travel, 0.1);
  EXPECT_NEAR(stick.dragged, travel, 0.1 * travel);
  const Slide slip = slide(0.0, travel, 0.1);
  EXPECT_LT(slip.dragged, 0.3 * travel);
}

}  // namespace
}  // namespace phyxel
