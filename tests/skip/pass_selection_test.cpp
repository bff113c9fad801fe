// Skipping what a scene does not need: fixed-only regions cost nothing, sleeping objects are
// skipped until a load reaches them, and --no-skip gives the same result within round-off.
#include <gtest/gtest.h>

#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

// A soft block whose lower half is clamped (a fixed-only region), sagging under gravity.
Scene clamped_block() {
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.03), 0.0025, test::tissue(2e4, 0.3, 150));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0151)));
  return scene;
}

RunResult run(Scene scene, int64_t steps, bool select, std::vector<Vec3>* u,
              Solver** keep = nullptr) {
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  static std::unique_ptr<Solver> last;
  last = make_cpu_solver(set, scene.simulation.gravity, 1);
  RunOptions options;
  options.steps = steps;
  options.pass_selection = select;
  const RunResult r = run_simulation(scene, set, *last, options);
  if (u) *u = last->read_state(false).displacement;
  if (keep) *keep = last.get();
  return r;
}

double max_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

double max_norm(const std::vector<Vec3>& a) {
  double d = 0;
  for (const Vec3& x : a) d = std::max(d, x.norm());
  return d;
}

TEST(PassSelection, FixedOnlyRegionsAreSkipped) {
  const Scene scene = clamped_block();
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  size_t fixed = 0;
  for (uint32_t f : set.flags) fixed += (f & kFixed) ? 1 : 0;
  EXPECT_EQ(solver.force_pass_size(), set.size() - fixed);
  // The stress pass keeps one layer of fixed neighbours; deeper fixed phyxels are skipped.
  EXPECT_LT(solver.stress_pass_size(), set.size());
  EXPECT_GT(solver.stress_pass_size(), solver.force_pass_size());
  solver.set_pass_selection(false);
  EXPECT_EQ(solver.force_pass_size(), set.size());
  EXPECT_EQ(solver.stress_pass_size(), set.size());
}

TEST(PassSelection, NoSkipGivesTheSameResult) {
  std::vector<Vec3> skipped, full;
  run(clamped_block(), 600, true, &skipped);
  run(clamped_block(), 600, false, &full);
  ASSERT_GT(max_norm(full), 0);
  EXPECT_LE(max_difference(skipped, full), 1e-12 * max_norm(full));
}

Scene sleepy_block() {
  Scene scene = clamped_block();
  scene.simulation.sleep = {true, 1e-12, 200};
  // A push on the top face that switches on later, after the block has come to rest.
  Load push;
  push.region = test::box_shape(Vec3(-1, -1, 0.0299), Vec3(1, 1, 1));
  push.force = Vec3(0.002, 0, 0);
  push.from = 0.15;
  scene.objects[0].loads.push_back(push);
  return scene;
}

TEST(Sleeping, RestingObjectSleepsAndWakesWhenALoadReachesIt) {
  Scene scene = sleepy_block();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const int64_t load_step = static_cast<int64_t>(std::ceil(0.15 / dt));
  // Up to just before the load: it must have fallen asleep.
  std::vector<Vec3> before;
  const RunResult early = run(scene, load_step - 1, true, &before);
  EXPECT_GE(early.sleeps, 1);
  EXPECT_EQ(early.wakes, 0);
  // Past the load: it wakes and moves sideways.
  std::vector<Vec3> after;
  const RunResult late = run(scene, load_step + 3000, true, &after);
  EXPECT_GE(late.wakes, 1);
  EXPECT_EQ(late.load_changes, 1);
  double sideways = 0;
  for (const Vec3& u : after) sideways = std::max(sideways, u.x());
  EXPECT_GT(sideways, 1e-5);
}

TEST(Sleeping, ChangesResultsOnlyBelowItsRestBound) {
  // With and without sleeping, the block ends at the same equilibrium under the push, to
  // within what the discarded motion (kinetic energy < 1e-12 J) can account for.
  std::vector<Vec3> slept, awake;
  Scene scene = sleepy_block();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const int64_t steps = static_cast<int64_t>(std::ceil(0.15 / dt)) + 6000;
  const RunResult a = run(scene, steps, true, &slept);
  const RunResult b = run(scene, steps, false, &awake);
  EXPECT_GE(a.sleeps, 1);
  EXPECT_EQ(b.sleeps, 0);
  EXPECT_LT(max_difference(slept, awake), 1e-3 * max_norm(awake));
}

// Forwards to a solver and counts what the run loop reads back.
class CountingSolver final : public Solver {
 public:
  explicit CountingSolver(std::unique_ptr<Solver> inner) : inner_(std::move(inner)) {}
  std::string device() const override { return inner_->device(); }
  void advance(int64_t substeps, double dt) override { inner_->advance(substeps, dt); }
  Energies energies() override { return inner_->energies(); }
  long first_non_finite() override { return inner_->first_non_finite(); }
  PointState read_state(bool with_stress) override {
    ++reads;
    return inner_->read_state(with_stress);
  }
  size_t regularised_count() const override { return inner_->regularised_count(); }
  const NeighbourLists& neighbours() const override { return inner_->neighbours(); }
  std::pair<double, double> max_norms() override { return inner_->max_norms(); }
  std::vector<ObjectMotion> object_motion(const PhyxelSet& set) override {
    ++motions;
    return inner_->object_motion(set);
  }
  void set_state(const std::vector<Vec3>& u, const std::vector<Vec3>& v) override {
    inner_->set_state(u, v);
  }
  // The inner solver's facets: what they do is not counted.
  PassSelection* pass_selection() override { return inner_->pass_selection(); }
  LoadChanges* load_changes() override { return inner_->load_changes(); }
  Tools* tools() override { return inner_->tools(); }

  int reads = 0, motions = 0;

 private:
  std::unique_ptr<Solver> inner_;
};

// The sleep and rest checks read per-object reductions, not the state: without tools nothing
// is read back before the end, with a tool the state once per object that falls asleep (where it
// sleeps, for waking it when the tool comes near). The decisions are those of the uncounted run.
TEST(Sleeping, ChecksReadTheStateBackOnlyWhereAnObjectFallsAsleepNearTools) {
  for (const bool with_tool : {false, true}) {
    Scene scene = sleepy_block();
    scene.simulation.until_rest = {true, 1e-30, 100000};  // decided at every check, never met
    if (with_tool) {
      ToolDesc probe;  // far above the block, still
      probe.name = "probe";
      probe.shape.radius = 0.002;
      probe.path = {{0.0, Vec3(0, 0, 0.5), Vec3::UnitZ()}};
      scene.tools.push_back(probe);
    }
    const PhyxelSet set = sample_scene(scene);
    scene.simulation.dt = plan_time_step(scene, set).dt_stable;
    RunOptions options;
    options.steps = static_cast<int64_t>(std::ceil(0.15 / scene.simulation.dt)) + 3000;
    options.pass_selection = true;
    CountingSolver counted(make_cpu_solver(set, scene.simulation.gravity, 1));
    const RunResult a = run_simulation(scene, set, counted, options);
    const std::unique_ptr<Solver> plain = make_cpu_solver(set, scene.simulation.gravity, 1);
    const RunResult b = run_simulation(scene, set, *plain, options);
    EXPECT_GE(a.sleeps, 1);
    EXPECT_EQ(a.sleeps, b.sleeps);
    EXPECT_EQ(a.wakes, b.wakes);
    EXPECT_EQ(a.steps_done, b.steps_done);
    EXPECT_GE(counted.motions, options.steps / 100);
    // And once at the end, for the summary's largest displacement.
    EXPECT_EQ(counted.reads, (with_tool ? a.sleeps : 0) + 1) << (with_tool ? "with" : "without");
    const PointState sa = counted.read_state(false), sb = plain->read_state(false);
    EXPECT_EQ(max_difference(sa.displacement, sb.displacement), 0.0);
  }
}

}  // namespace
}  // namespace phyxel
