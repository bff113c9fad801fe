// The aspirator (engine/solver/suction.h, aspiration.h; docs/suction.md) on the CPU reference:
// its pull law (toward the mouth, within reach ahead of it, adding up to F = pressure x mouth
// area along the axis over a full half ball); the fracture sphere of the paper's hybrid tearing
// on a synthetic set; a block under suction below its tear stress deforms and lets go without
// losing anything; above it, pieces are aspirated, removed + remaining mass and volume equal the
// initial ones, and every value stays finite through repeated aspiration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "engine/run/checkpoint.h"
#include "engine/run/run_schedule.h"
#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "engine/solver/suction.h"
#include "engine/surgery/aspiration.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

ContactTool aspirator(double radius, double pressure, double reach) {
  ContactTool t;
  t.shape.type = ToolShape::Type::Capsule;
  t.shape.radius = radius;
  t.shape.length = 0.05;
  t.suction.pressure = pressure;
  t.suction.reach = reach;
  return t;
}

TEST(SuctionPull, PullsTowardTheMouthWithinReachAheadOfIt) {
  const ContactTool tool = aspirator(0.002, 2e4, 0.005);
  const ToolPose mouth{Vec3(0, 0, 0.01), Vec3::UnitZ()};
  const double v = 1e-9;
  const Vec3 ahead = suction_pull<double>(tool, mouth, Vec3(0.001, 0, 0.008), v);
  const Vec3 dir = (mouth.position - Vec3(0.001, 0, 0.008)).normalized();
  EXPECT_NEAR(ahead.normalized().dot(dir), 1.0, 1e-12);
  EXPECT_NEAR(ahead.norm(), suction_pull_density(tool) * v, 1e-15);
  EXPECT_EQ(suction_pull<double>(tool, mouth, Vec3(0, 0, 0.012), v), Vec3::Zero());  // behind
  EXPECT_EQ(suction_pull<double>(tool, mouth, Vec3(0, 0, 0.004), v), Vec3::Zero());  // beyond
  EXPECT_EQ(suction_pull<double>(tool, mouth, mouth.position, v), Vec3::Zero());     // at it
  ContactTool off = tool;
  off.suction.pressure = 0;
  EXPECT_EQ(suction_pull<double>(off, mouth, Vec3(0, 0, 0.008), v), Vec3::Zero());
  // A half ball full of tissue: the pulls' vector sum is pressure x mouth area along the axis,
  // the force on the mouth (until 2026-11-26 it was half that: their magnitudes added up to it).
  const double h = 2e-4;
  Vec3 sum = Vec3::Zero();
  for (double x = -0.005; x <= 0.005; x += h)
    for (double y = -0.005; y <= 0.005; y += h)
      for (double z = 0.01 - 0.005; z <= 0.01; z += h)
        sum += suction_pull<double>(tool, mouth, Vec3(x, y, z), h * h * h);
  const double force = 2e4 * std::numbers::pi * 0.002 * 0.002;
  EXPECT_NEAR(sum.z(), force, 0.03 * force);
  EXPECT_NEAR(std::hypot(sum.x(), sum.y()), 0, 1e-3 * force);
}

TEST(Suction, BelowTheTearStressDeformsAndLetsGoWithoutRemovingAnything) {
  const Scene scene = parse_scene(test::suction_block_json(1e6), "block.json");
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  RunOptions options;
  options.steps = 150;  // the suction's 0.15 s
  RunResult during = run_simulation(scene, set, *solver, options);
  ASSERT_TRUE(during.aspirating);
  const PointState mid = solver->read_state(false);
  double lifted = 0;  // the top under the mouth rises toward it
  for (size_t i = 0; i < set.size(); ++i)
    if ((set.rest[i] - Vec3(0.01, 0.01, 0.01)).norm() < 1e-9) lifted = mid.displacement[i].z();
  EXPECT_GT(lifted, 2e-4) << "the tissue under the mouth did not rise";
  EXPECT_GT(during.tools[0].max_force, 0.01);  // the tube feels the tissue it holds
  EXPECT_EQ(during.aspiration.events, 0);
  // Off: the block relaxes back (the continuation of the same solver, suction off).
  Scene off = scene;
  off.tools[0].suction.until = 1e-6;
  options.steps = 300;
  run_simulation(off, set, *solver, options);
  const PointState end = solver->read_state(false);
  double largest = 0;
  for (const Vec3& u : end.displacement) largest = std::max(largest, u.norm());
  EXPECT_LT(largest, 0.1 * lifted) << "the tissue did not let go";
  for (const double m : during.aspiration.removed_mass) EXPECT_EQ(m, 0.0);
}

TEST(Suction, AboveTheTearStressAspiratesAndAccountsMassAndVolumeExactly) {
  const Scene scene = parse_scene(test::suction_block_json(1000, true), "block.json");
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  std::vector<uint32_t> removed;
  size_t exposing = 0;  // events that exposed a fracture surface
  RunOptions options;
  options.steps = 300;
  options.on_aspiration = [&](const AspirationEvent& e) {
    EXPECT_GT(e.radius, 0);
    EXPECT_LE(e.radius, 0.005 + 1e-12);
    exposing += !e.exposed.empty();
    removed.insert(removed.end(), e.removed.begin(), e.removed.end());
  };
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_GE(r.aspiration.events, 2) << "expected repeated aspiration";
  ASSERT_FALSE(removed.empty());
  EXPECT_GT(exposing, 0u);
  EXPECT_EQ(solver->first_non_finite(), -1);
  // Exactly the removed phyxels' mass and volume; with what remains, the initial.
  double mass = 0, volume = 0, remaining_mass = 0, remaining_volume = 0;
  std::vector<uint8_t> gone(set.size(), 0);
  for (const uint32_t i : removed) {
    EXPECT_EQ(gone[i], 0) << "phyxel " << i << " removed twice";
    gone[i] = 1;
    mass += set.mass[i];
    volume += set.volume[i];
  }
  for (size_t i = 0; i < set.size(); ++i)
    if (!gone[i]) {
      remaining_mass += set.mass[i];
      remaining_volume += set.volume[i];
    }
  EXPECT_DOUBLE_EQ(r.aspiration.removed_mass[0], mass);
  EXPECT_DOUBLE_EQ(r.aspiration.removed_volume[0], volume);
  EXPECT_NEAR(r.aspiration.removed_mass[0] + remaining_mass, r.aspiration.initial_mass[0],
              1e-12 * r.aspiration.initial_mass[0]);
  EXPECT_NEAR(r.aspiration.removed_volume[0] + remaining_volume, r.aspiration.initial_volume[0],
              1e-12 * r.aspiration.initial_volume[0]);
  // Only tissue near the mouth went: nothing fixed, nothing beyond the reach's sphere.
  for (const uint32_t i : removed) {
    EXPECT_FALSE(set.flags[i] & kFixed);
    EXPECT_LT((set.rest[i] - Vec3(0.01, 0.01, 0.0117)).norm(), 0.012) << i;
  }
  RecordProperty("aspirated_mass_g", std::to_string(1e3 * mass));
}

// The aspirator acts at the end of each tool chunk, on a grid from step 0: frames, point
// outputs and their splits of the advances change nothing of what is aspirated or where the
// tissue ends up.
// The flow's factor (suction.h): the whole pull at rest relative to the tool, none at the flow's
// speed toward the tip, the whole pull moving away, and no kick past the flow's speed.
TEST(SuctionPull, TheFlowScalesThePullBySpeedTowardTheTip) {
  Suction s;
  s.flow_speed = 0.5;
  const Vec3 to_tip = Vec3::UnitZ();
  EXPECT_EQ(suction_flow_factor<double>(s, to_tip, Vec3::Zero(), 0.1), 1.0);
  EXPECT_DOUBLE_EQ(suction_flow_factor<double>(s, to_tip, Vec3(0.3, 0, 0.25), 0.1), 0.5);
  EXPECT_EQ(suction_flow_factor<double>(s, to_tip, Vec3(0, 0, 0.5), 0.1), 0.0);
  EXPECT_EQ(suction_flow_factor<double>(s, to_tip, Vec3(0, 0, 2), 0.1), 0.0);
  EXPECT_EQ(suction_flow_factor<double>(s, to_tip, Vec3(0, 0, -2), 0.1), 1.0);
  // A kick of 2 m/s from rest is cut to the flow's 0.5 m/s.
  EXPECT_DOUBLE_EQ(2 * suction_flow_factor<double>(s, to_tip, Vec3::Zero(), 2.0), 0.5);
}

// The largest speed toward the mouth of the phyxels in its reach.
double fastest_into_mouth(const Scene& scene, const PhyxelSet& set, const PointState& state) {
  const Vec3 tip = scene.tools[0].path[0].position;
  double fastest = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 r = tip - (set.rest[i] + state.displacement[i]);
    if (r.norm() > scene.tools[0].suction.reach || !(r.norm() > 0)) continue;
    fastest = std::max(fastest, state.velocity[i].dot(r.normalized()));
  }
  return fastest;
}

// Tissue that no longer holds together (a block of 1 Pa, its fragments all but free) is drawn
// into the mouth no faster than the flow, whose speed bounds w even where one substep's whole
// pull (1.08 m/s here) would pass it; without the bound (a flow of 100 m/s) the same pull takes
// it past 1 m/s within two steps. Until 2026-11-26 nothing bounded it, and fragments torn at the
// mouth outran the tissue's sound speed (the brain at --refine 2 stopped as unstable).
TEST(Suction, FragmentsAreDrawnInNoFasterThanTheFlow) {
  Scene scene = parse_scene(test::suction_block_json(1e6), "block.json");
  scene.objects[0].material.young = 1;
  scene.objects[0].material.damping = 0;
  for (const double flow : {0.2, 100.0}) {
    scene.tools[0].suction.flow_speed = flow;
    const PhyxelSet set = sample_scene(scene);
    const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
    double fastest = 0;
    test::advance_tools_in_chunks(*solver, scene, set, 20, 2, [&](const auto&) {
      fastest = std::max(fastest, fastest_into_mouth(scene, set, solver->read_state(false)));
    });
    if (flow < 1)
      EXPECT_LE(fastest, flow * 1.001);  // the 1 Pa of elasticity adds a little
    else
      EXPECT_GT(fastest, 1.0);
    std::printf("[ suction  ] flow %g m/s: fragments into the mouth at up to %.4g m/s\n", flow,
                fastest);
  }
}

TEST(Suction, FramesAndOutputsChangeNothingThatIsAspirated) {
  const Scene scene = parse_scene(test::suction_block_json(1000, true), "block.json");
  const PhyxelSet set = sample_scene(scene);
  // listen: an on_aspiration callback (without one, no event is mapped to rest space).
  auto run = [&](int64_t frame_every, bool listen = true) {
    const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
    RunOptions options;
    options.steps = 300;
    int frames = 0;
    if (frame_every > 0) {
      options.frame_every = frame_every;
      options.on_frame = [&](int64_t, Solver&) { ++frames; };
    }
    std::vector<uint32_t> removed;
    if (listen)
      options.on_aspiration = [&](const AspirationEvent& e) {
        removed.insert(removed.end(), e.removed.begin(), e.removed.end());
      };
    const RunResult r = run_simulation(scene, set, *solver, options);
    EXPECT_EQ(frames > 0, frame_every > 0);
    return std::make_tuple(r.aspiration.events, removed, solver->read_state(false).displacement);
  };
  const auto [events, removed, u] = run(0);
  ASSERT_GE(events, 2);
  {
    SCOPED_TRACE("no listener");
    const auto [e, r, v] = run(0, false);
    EXPECT_EQ(e, events);
    EXPECT_EQ(v, u);
  }
  for (const int64_t every : {7, 45}) {  // neither divides the tool chunk nor is a multiple
    SCOPED_TRACE(every);
    const auto [e, r, v] = run(every);
    EXPECT_EQ(e, events);
    EXPECT_EQ(r, removed);
    ASSERT_EQ(v.size(), u.size());
    for (size_t i = 0; i < u.size(); ++i) ASSERT_EQ(v[i], u[i]) << "phyxel " << i;
  }
}

// A checkpoint holds what the aspirator took (removed phyxels, surface, totals): a run stopped
// on the tool chunks' grid and resumed ends bit-identical to the uninterrupted one, with
// aspirations before and after the checkpoint.
TEST(Suction, AnAspiratingRunResumesBitIdentically) {
  const Scene scene = parse_scene(test::suction_block_json(1000, true), "block.json");
  const PhyxelSet set = sample_scene(scene);
  const TimeStepPlan plan = plan_time_step(scene, set);
  const int64_t chunk =
      tool_chunk_steps(scene, RunOptions{}, set.size(), plan.substeps, plan.dt_requested);
  const int64_t stop = chunk * (150 / chunk), total = 300;
  const fs::path dir = test::test_output_dir("suction_checkpoint");
  auto run = [&](const std::string& name, int64_t steps, const Checkpoint* from) {
    const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
    RunOptions options;
    options.steps = steps;
    options.out_dir = dir / name;
    fs::create_directories(options.out_dir);
    options.checkpoint_every = stop;
    options.resume = from;
    options.scene_hash = 0;  // a scene from text
    const RunResult r = run_simulation(scene, set, *solver, options);
    return std::make_tuple(r.aspiration, solver->read_state(false));
  };
  const auto [full, full_state] = run("full", total, nullptr);
  const auto [part, part_state] = run("part", stop, nullptr);
  const Checkpoint at_stop = read_checkpoint(dir / "part" / kCheckpointFile);
  EXPECT_FALSE(at_stop.aspiration.removed.empty());
  const auto [resumed, state] = run("part", total, &at_stop);
  ASSERT_GT(part.events, 0);
  ASSERT_GT(full.events, part.events);
  EXPECT_EQ(resumed.events, full.events);
  EXPECT_EQ(resumed.removed_mass, full.removed_mass);
  EXPECT_EQ(resumed.max_radius, full.max_radius);
  ASSERT_EQ(state.displacement.size(), full_state.displacement.size());
  for (size_t i = 0; i < state.displacement.size(); ++i) {
    ASSERT_EQ(state.displacement[i], full_state.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(state.velocity[i], full_state.velocity[i]) << "phyxel " << i;
  }
}

// A line of phyxels along -z below a mouth at the origin: the fracture sphere by hand.
TEST(FractureSphere, TheFarthestOverstressedSurfacePhyxelSetsTheRadius) {
  PhyxelSet set;
  Material m = test::tissue(1e4);
  m.tear_stress = 100;
  set.materials = {m};
  const int n = 10;
  for (int k = 0; k < n; ++k) {
    set.rest.push_back(Vec3(0, 0, -0.001 * (k + 1)));
    set.mass.push_back(1e-6);
    set.volume.push_back(1e-9);
    set.material.push_back(0);
    set.object.push_back(0);
    set.flags.push_back(kSurface);
  }
  const ToolPose mouth{Vec3::Zero(), Vec3::UnitZ()};
  std::vector<uint8_t> removed(n, 0), surface(n, 1);
  Tears torn{TornPartners(n), std::vector<uint8_t>(n, 0)};
  std::vector<double> principal(n, 50);
  principal[0] = principal[2] = 150;  // overstressed at 1 and 3 mm
  const std::vector<Vec3> x = set.rest;
  AspirationEvent e =
      fracture_sphere(set, removed, surface, torn, x, principal, mouth, 0.005, 0.0015);
  EXPECT_DOUBLE_EQ(e.radius, 0.003);
  EXPECT_EQ(e.removed, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(e.exposed, (std::vector<uint32_t>{3}));  // 4 mm: within R + delta
  // Overstressed beyond the reach, or only inside the tissue (not on a surface): nothing.
  principal.assign(n, 50);
  principal[7] = 150;
  EXPECT_TRUE(fracture_sphere(set, removed, surface, torn, x, principal, mouth, 0.005, 0.0015)
                  .removed.empty());
  principal[7] = 50;
  principal[1] = 150;
  surface[1] = 0;
  EXPECT_TRUE(fracture_sphere(set, removed, surface, torn, x, principal, mouth, 0.005, 0.0015)
                  .removed.empty());
  // A crack has failed whatever the stress now: 2 and 3 mm torn apart, R = 2.5 mm (the
  // crack, not the far phyxel); torn loose, 3 mm counts at its own position.
  principal[1] = 50;
  torn.partners[1] = {2};
  torn.partners[2] = {1};
  e = fracture_sphere(set, removed, surface, torn, x, principal, mouth, 0.005, 0.0015);
  EXPECT_NEAR(e.radius, 0.0025, 1e-15);
  EXPECT_EQ(e.removed, (std::vector<uint32_t>{0, 1}));
  torn.loose[2] = 1;
  e = fracture_sphere(set, removed, surface, torn, x, principal, mouth, 0.005, 0.0015);
  EXPECT_DOUBLE_EQ(e.radius, 0.003);
  EXPECT_EQ(e.removed, (std::vector<uint32_t>{0, 1, 2}));
  torn = Tears{TornPartners(n), std::vector<uint8_t>(n, 0)};
  // Behind the mouth nothing is in reach.
  const ToolPose turned{Vec3::Zero(), -Vec3::UnitZ()};
  surface.assign(n, 1);
  EXPECT_TRUE(fracture_sphere(set, removed, surface, torn, x, principal, turned, 0.005, 0.0015)
                  .removed.empty());
}

}  // namespace
}  // namespace phyxel
