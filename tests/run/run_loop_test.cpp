// The run loop: time-step plan, rest detection, non-finite detection, output schedule, stop
// requests, and thread-count independence of the CPU solver.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <sstream>
#include <utility>

#include "engine/run/run_loop.h"
#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

Scene cube_scene() {
  return test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.0025, test::tissue(1e5, 0.3, 50));
}

TEST(TimeStepPlan, SubstepsWhenTheRequestedStepIsUnstable) {
  Scene scene = cube_scene();
  const PhyxelSet set = sample_scene(scene);
  const double cp = p_wave_speed(scene.objects[0].material);
  const double bound = 0.5 * 0.0025 / cp;
  scene.simulation.dt = 0.5 * bound;
  TimeStepPlan plan = plan_time_step(scene, set);
  EXPECT_NEAR(plan.dt_stable, bound, 1e-15);
  EXPECT_EQ(plan.substeps, 1);
  EXPECT_EQ(plan.dt_used, scene.simulation.dt);
  EXPECT_TRUE(plan.reason.empty());
  scene.simulation.dt = 2.5 * bound;
  plan = plan_time_step(scene, set);
  EXPECT_EQ(plan.substeps, 3);
  EXPECT_NEAR(plan.dt_used, 2.5 * bound / 3, 1e-15);
  EXPECT_NE(plan.reason.find("3 substeps"), std::string::npos) << plan.reason;
  EXPECT_NE(plan.reason.find("stable step"), std::string::npos) << plan.reason;
}

TEST(CpuSolver, ResultsDoNotDependOnTheThreadCount) {
  // Large enough (2601 phyxels) for the solver to really use two threads.
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.04, 0.04, 0.02), 0.0025, test::tissue(1e5, 0.3, 50));
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001)));
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  CpuSolver<double> one(set, Vec3(0, 0, -9.81)), two(set, Vec3(0, 0, -9.81));
  one.set_threads(1);
  two.set_threads(2);
  ASSERT_GE(set.size(), 2048u);
  for (int k = 0; k < 50; ++k) {
    one.step(dt);
    two.step(dt);
  }
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(one.displacement()[i], two.displacement()[i]) << "phyxel " << i;
    ASSERT_EQ(one.velocity()[i], two.velocity()[i]) << "phyxel " << i;
  }
}

TEST(RunLoop, StopsAtRestAndWritesTheLastPoints) {
  Scene scene = cube_scene();  // no load: it is at rest from the start
  scene.simulation.steps = 100000;
  scene.simulation.until_rest = {true, 1e-12, 300};
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = scene.simulation.steps;
  options.out_dir = test::test_output_dir("run_rest");
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_TRUE(r.stopped_at_rest);
  EXPECT_GE(r.steps_done, 300);
  EXPECT_LE(r.steps_done, 400);
  ASSERT_EQ(r.outputs.size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(options.out_dir / r.outputs[0]));
}

TEST(RunLoop, MovingObjectIsNotAtRestAndOutputsFollowTheSchedule) {
  Scene scene = cube_scene();
  scene.simulation.gravity = Vec3(0, 0, -9.81);  // free fall: never at rest
  scene.objects[0].material.damping = 0;
  scene.simulation.steps = 250;
  scene.simulation.until_rest = {true, 1e-12, 50};
  scene.output.every = 100;
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = scene.simulation.steps;
  options.out_dir = test::test_output_dir("run_schedule");
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_FALSE(r.stopped_at_rest);
  EXPECT_EQ(r.steps_done, 250);
  const std::vector<std::string> expected = {"points_000100.vtp", "points_000200.vtp",
                                             "points_000250.vtp"};
  EXPECT_EQ(r.outputs, expected);
  // Free fall: every phyxel has fallen g t^2 / 2.
  const double t = 250 * scene.simulation.dt;
  EXPECT_NEAR(r.max_displacement, 0.5 * 9.81 * t * t, 1e-9);
}

// A solver whose state turns non-finite after a given number of substeps.
class FailingSolver final : public Solver {
 public:
  FailingSolver(int64_t fail_after, size_t phyxels)
      : fail_after_(fail_after), u_(phyxels, Vec3::Zero()), v_(phyxels, Vec3::Zero()) {}
  std::string device() const override { return "test"; }
  void advance(int64_t substeps, double) override { done_ += substeps; }
  Energies energies() override { return {}; }
  long first_non_finite() override { return done_ >= fail_after_ ? 7 : -1; }
  PointState read_state(bool) override { return {u_, v_, {}, {}, {}}; }
  void set_state(const std::vector<Vec3>& u, const std::vector<Vec3>& v) override {
    u_ = u;
    v_ = v;
  }
  size_t regularised_count() const override { return 0; }
  const NeighbourLists& neighbours() const override { return nbr_; }

 private:
  int64_t fail_after_, done_ = 0;
  std::vector<Vec3> u_, v_;
  NeighbourLists nbr_;
};

// A solver without a facet has none: the base gives nullptr for each.
TEST(SolverFacets, ASolverWithoutAFacetGivesNullptr) {
  FailingSolver bare(1, 8);
  EXPECT_EQ(bare.pass_selection(), nullptr);
  EXPECT_EQ(bare.load_changes(), nullptr);
  EXPECT_EQ(bare.tools(), nullptr);
  EXPECT_EQ(bare.principal_stress(), nullptr);
  EXPECT_EQ(bare.tearing(), nullptr);
  EXPECT_EQ(bare.removal(), nullptr);
  EXPECT_EQ(bare.cutting(), nullptr);
  EXPECT_THROW(need(bare.cutting(), bare, "sever pairs"), std::logic_error);
  const Scene scene = cube_scene();
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  EXPECT_NE(cpu->pass_selection(), nullptr);
  EXPECT_NE(cpu->load_changes(), nullptr);
  EXPECT_NE(cpu->tools(), nullptr);
  EXPECT_NE(cpu->principal_stress(), nullptr);
  EXPECT_NE(cpu->tearing(), nullptr);
  EXPECT_NE(cpu->removal(), nullptr);
  EXPECT_NE(cpu->cutting(), nullptr);
  // Without cutting, every pair is joined and nothing is severed.
  EXPECT_EQ(severed_pair_count(bare), 0u);
  EXPECT_EQ(alive_pairs(*cpu), std::vector<uint8_t>(cpu->neighbours().index.size(), 1));
}

// The CPU solver with one of its facets hidden, as a solver without that ability.
class HidingSolver final : public Solver {
 public:
  HidingSolver(std::unique_ptr<Solver> inner, std::string hidden)
      : inner_(std::move(inner)), hidden_(std::move(hidden)) {}
  std::string device() const override { return "test (no " + hidden_ + ")"; }
  void advance(int64_t substeps, double dt) override { inner_->advance(substeps, dt); }
  Energies energies() override { return inner_->energies(); }
  long first_non_finite() override { return inner_->first_non_finite(); }
  PointState read_state(bool with_stress) override { return inner_->read_state(with_stress); }
  void set_state(const std::vector<Vec3>& u, const std::vector<Vec3>& v) override {
    inner_->set_state(u, v);
  }
  size_t regularised_count() const override { return inner_->regularised_count(); }
  const NeighbourLists& neighbours() const override { return inner_->neighbours(); }
  PassSelection* pass_selection() override {
    return shown("pass selection", inner_->pass_selection());
  }
  LoadChanges* load_changes() override { return shown("load changes", inner_->load_changes()); }
  Tools* tools() override { return shown("tools", inner_->tools()); }
  PrincipalStress* principal_stress() override {
    return shown("principal stress", inner_->principal_stress());
  }
  Tearing* tearing() override { return shown("tearing", inner_->tearing()); }
  Removal* removal() override { return shown("removal", inner_->removal()); }
  Cutting* cutting() override { return shown("cutting", inner_->cutting()); }

 private:
  template <class Facet>
  Facet* shown(const std::string& name, Facet* facet) const {
    return name == hidden_ ? nullptr : facet;
  }
  std::unique_ptr<Solver> inner_;
  std::string hidden_;
};

// A scene that needs an ability the solver lacks is refused before the run, with one line
// naming the scene file, what needs it and which device to use; with the facet it starts.
TEST(RunLoop, RefusesASceneNeedingAnAbsentFacet) {
  struct Case {
    std::string facet;
    std::function<void(Scene&)> needs_it;
    std::string message;  // after "<file>: "
  };
  ToolDesc probe;
  probe.name = "probe";
  probe.shape.radius = 0.002;
  probe.path = {{0.0, Vec3(0, 0, 0.5), Vec3::UnitZ()}};
  const std::vector<Case> cases = {
      {"tearing", [](Scene& s) { s.objects[0].material.tear_stress = 1e4; },
       "a material has tear_stress, which test (no tearing) cannot evaluate; use --device cpu"},
      {"load changes",
       [](Scene& s) {
         s.objects[0].loads.push_back({test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 1)),
                                       Vec3(0, 0, -1e-3), 0, 10 * s.simulation.dt});
       },
       "loads with from/until switch during the run, which test (no load changes) cannot do; "
       "use --device cpu"},
      {"removal",
       [probe](Scene& s) {
         s.objects[0].material.tear_stress = 1e4;
         ToolDesc suction = probe;
         suction.type = ToolDesc::Type::Suction;
         suction.suction.pressure = 1e4;
         suction.suction.reach = 0.003;
         s.tools.push_back(suction);
       },
       "a suction tool aspirates tissue, which test (no removal) cannot remove; use --device cpu "
       "or gpu"},
      {"tools", [probe](Scene& s) { s.tools.push_back(probe); },
       "the scene has tools, which test (no tools) cannot simulate; use --device cpu"},
  };
  for (const Case& c : cases) {
    Scene scene = cube_scene();
    scene.file = "facets.json";
    const PhyxelSet plain = sample_scene(scene);
    scene.simulation.dt = plan_time_step(scene, plain).dt_stable;
    c.needs_it(scene);
    const PhyxelSet set = sample_scene(scene);
    RunOptions options;
    options.steps = 100;
    HidingSolver without(make_cpu_solver(set, scene.simulation.gravity, 1), c.facet);
    try {
      RunLoop loop(scene, set, without, options);
      ADD_FAILURE() << c.facet << ": not refused";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "facets.json: " + c.message);
    }
    HidingSolver with(make_cpu_solver(set, scene.simulation.gravity, 1), "none");
    EXPECT_NO_THROW({ RunLoop loop(scene, set, with, options); }) << c.facet;
  }
}

TEST(RunLoop, StopsCleanlyAtTheFirstNonFiniteCheck) {
  Scene scene = cube_scene();
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  FailingSolver solver(250, set.size());
  RunOptions options;
  options.steps = 1000;
  const RunResult r = run_simulation(scene, set, solver, options);
  EXPECT_TRUE(r.non_finite);
  EXPECT_EQ(r.non_finite_step, 300);  // checked every 100 steps
  EXPECT_EQ(r.non_finite_phyxel, 7);
  EXPECT_EQ(r.steps_done, 300);
  EXPECT_TRUE(r.outputs.empty());  // no file with NaN in it
}

// A stop can be requested: the advances are cut short (here to one step each), and the states
// are those of a run that cannot be stopped, bit for bit.
TEST(RunLoop, StoppableRunSplitsAdvancesExactly) {
  Scene scene = cube_scene();
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001)));
  scene.simulation.steps = 120;
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = 2.5 * plan_time_step(scene, set).dt_stable;  // 3 substeps per step
  RunOptions plain;
  plain.steps = scene.simulation.steps;
  RunOptions stoppable = plain;
  int polls = 0;
  stoppable.stop_requested = [&polls] { return ++polls < 0; };
  stoppable.stop_poll_seconds = 0;  // every advance one step
  auto a = make_cpu_solver(set, scene.simulation.gravity, 1);
  auto b = make_cpu_solver(set, scene.simulation.gravity, 1);
  const RunResult ra = run_simulation(scene, set, *a, plain);
  const RunResult rb = run_simulation(scene, set, *b, stoppable);
  // One advance per step, each taken as longer than a poll (stop_poll_seconds 0): the stop is
  // asked about after each of its first two substeps and after each step but the last.
  EXPECT_EQ(polls, 120 * 2 + 119);
  EXPECT_FALSE(rb.stopped);
  EXPECT_EQ(ra.steps_done, rb.steps_done);
  const PointState sa = a->read_state(false), sb = b->read_state(false);
  ASSERT_GT(ra.max_displacement, 0);
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(sa.displacement[i], sb.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(sa.velocity[i], sb.velocity[i]) << "phyxel " << i;
  }
}

// The cube falling, its dt 2.5 stable steps: 3 substeps per step.
std::pair<Scene, PhyxelSet> three_substep_cube() {
  Scene scene = cube_scene();
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = 2.5 * plan_time_step(scene, set).dt_stable;
  return {std::move(scene), std::move(set)};
}

// A step slower than a poll is polled between its substeps (a large scene on a slow device has
// steps of seconds with few substeps): the stop ends it after its first substep and puts the
// solver back to the step's start.
TEST(RunLoop, AStopIsSeenInsideASlowStepOfFewSubsteps) {
  const auto [scene, set] = three_substep_cube();
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = 10;
  int polls = 0;
  options.stop_requested = [&polls] { return ++polls >= 1; };
  options.stop_poll_seconds = 0;  // every step slower than a poll
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(polls, 2);  // after the first substep, then the loop's own look at the stop
  EXPECT_EQ(r.steps_done, 0);
  for (const Vec3& u : solver->read_state(false).displacement) ASSERT_EQ(u, Vec3::Zero());
}

// Steps measured faster than a poll go whole: only the first, not yet timed, is split.
TEST(RunLoop, FastStepsAreNotSplitOnceTimed) {
  const auto [scene, set] = three_substep_cube();
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = 120;
  int polls = 0;
  options.stop_requested = [&polls] { return ++polls < 0; };
  options.stop_poll_seconds = 1e9;
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_EQ(r.steps_done, 120);
  // Two polls inside the first step, then advances of 4, 16, 64 and 35 steps polled between.
  EXPECT_EQ(polls, 2 + 4);
}

TEST(RunLoop, StopRequestEndsTheRunWithTheLastStateAndFrame) {
  Scene scene = cube_scene();
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.output.every = 1000;
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = 1000000;
  options.out_dir = test::test_output_dir("run_stop");
  options.frame_every = 100000;
  std::vector<int64_t> frames;
  options.on_frame = [&frames](int64_t step, Solver&) { frames.push_back(step); };
  int polls = 0;
  options.stop_requested = [&polls] { return ++polls >= 5; };
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(polls, 5);
  EXPECT_GT(r.steps_done, 0);
  EXPECT_LT(r.steps_done, 1000);  // the first advances are a step, then at most 4x the last
  ASSERT_EQ(r.outputs.size(), 1u);
  char last[64];
  std::snprintf(last, sizeof last, "points_%06lld.vtp", static_cast<long long>(r.steps_done));
  EXPECT_EQ(r.outputs.back(), last);
  EXPECT_TRUE(std::filesystem::exists(options.out_dir / last));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames.back(), r.steps_done);
}

}  // namespace
}  // namespace phyxel
