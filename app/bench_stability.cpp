// phyxel bench --stability: long soaks on the CPU in double and float, reporting energy drift,
// the largest speed, the first non-finite value, and float-against-double drift.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/bench_extras.h"
#include "app/options.h"
#include "engine/shape.h"
#include "engine/simulation.h"

namespace phyxel::app {
namespace {

struct Soak {
  std::string name;
  Scene scene;
  double dt_fraction;
  Eigen::Matrix3d initial_gradient = Eigen::Matrix3d::Zero();  // u0 = G x0
};

struct SoakResult {
  double energy_drift = 0;  // max |E(t) - E(0)| / |E(0)| (J when E(0) = 0)
  double max_speed = 0;
  int64_t non_finite_step = -1;
  long non_finite_phyxel = -1;
  double seconds = 0;
  std::vector<Vec3> final_u;
};

Scene free_cube() {
  Scene s;
  s.simulation.dt = 1;
  ObjectDesc o;
  o.name = "cube";
  o.shape.type = Shape::Type::Box;
  o.shape.min = Vec3::Zero();
  o.shape.max = Vec3::Constant(0.02);
  o.spacing = 0.0025;
  o.support_radius = 0.005;
  o.material = {1e5, 0.45, 1000, 0, std::nullopt, 0.05};
  s.objects.push_back(o);
  return s;
}

SoakResult soak(const Soak& c, bool single, int64_t steps, int threads) {
  const PhyxelSet set = sample_scene(c.scene);
  const double dt = c.dt_fraction * plan_time_step(c.scene, set).dt_stable;
  SoakResult r;
  const auto t0 = std::chrono::steady_clock::now();
  // The soak starts from a deformed state u0 = G x0, which the Solver interface cannot set, so
  // it drives the CPU solver types directly.
  std::unique_ptr<CpuSolver<double>> d;
  std::unique_ptr<CpuSolver<float>> f;
  if (single)
    f = std::make_unique<CpuSolver<float>>(set, c.scene.simulation.gravity);
  else
    d = std::make_unique<CpuSolver<double>>(set, c.scene.simulation.gravity);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 u = c.initial_gradient * set.rest[i];
    if (single)
      f->displacement()[i] = u.cast<float>();
    else
      d->displacement()[i] = u;
  }
  if (single)
    f->set_threads(threads), f->compute_forces();
  else
    d->set_threads(threads), d->compute_forces();
  auto energy = [&] { return single ? f->energies().total() : d->energies().total(); };
  const double e0 = energy();
  for (int64_t k = 1; k <= steps; ++k) {
    if (single)
      f->step(float(dt));
    else
      d->step(dt);
    if (k % 100 != 0 && k != steps) continue;
    const long bad = single ? f->first_non_finite() : d->first_non_finite();
    if (bad >= 0) {
      r.non_finite_step = k;
      r.non_finite_phyxel = bad;
      break;
    }
    for (size_t i = 0; i < set.size(); ++i)
      r.max_speed =
          std::max(r.max_speed, single ? double(f->velocity()[i].norm()) : d->velocity()[i].norm());
    if (k % 1000 == 0 || k == steps)
      r.energy_drift = e0 != 0 ? std::max(r.energy_drift, std::abs(energy() - e0) / std::abs(e0))
                               : std::abs(energy());
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.final_u.resize(set.size());
  for (size_t i = 0; i < set.size(); ++i)
    r.final_u[i] = single ? Vec3(f->displacement()[i].cast<double>()) : d->displacement()[i];
  return r;
}

}  // namespace

int bench_stability(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--stability");
  const int64_t steps = opts.integer("--steps", 100000, 1, int64_t(1) << 40);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string json_file = opts.value("--json", "");
  opts.finish();

  std::vector<Soak> soaks;
  const Eigen::Matrix3d stretch = Eigen::Vector3d(0.2, -0.05, 0.05).asDiagonal();
  soaks.push_back({"free cube, 20 % stretch, nu 0.45, dt 0.5x bound", free_cube(), 0.5, stretch});
  soaks.push_back({"free cube, 20 % stretch, nu 0.45, dt 1.0x bound", free_cube(), 1.0, stretch});
  // Damped and loaded: float and double must stay together here (undamped large vibration is
  // sensitive to rounding like any two nearby trajectories of a nonlinear system).
  soaks.push_back({"demo beam (scenes/beam.json), gravity, damped", load_scene("scenes/beam.json"),
                   1.0, Eigen::Matrix3d::Zero()});
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-48s %-7s %10s %12s %11s %22s %9s\n", "soak", "real", "steps", "energy drift",
              "max speed", "first non-finite", "wall s");
  for (const Soak& c : soaks) {
    const SoakResult d = soak(c, false, steps, threads);
    const SoakResult f = soak(c, true, steps, threads);
    double diff = 0;
    const Eigen::AlignedBox3d box = shape_bounds(c.scene.objects[0].shape);
    const double extent = box.sizes().maxCoeff();
    for (size_t i = 0; i < d.final_u.size(); ++i)
      diff = std::max(diff, (d.final_u[i] - f.final_u[i]).norm());
    for (const auto& [label, r] :
         {std::pair<const char*, const SoakResult&>{"double", d}, {"float", f}}) {
      char bad[64] = "none";
      if (r.non_finite_step >= 0)
        std::snprintf(bad, sizeof bad, "step %lld phyxel %ld",
                      static_cast<long long>(r.non_finite_step), r.non_finite_phyxel);
      std::printf("%-48s %-7s %10lld %12.3e %11.4g %22s %9.2f\n", c.name.c_str(), label,
                  static_cast<long long>(steps), r.energy_drift, r.max_speed, bad, r.seconds);
      rows.push_back({{"soak", c.name},
                      {"real", label},
                      {"steps", steps},
                      {"energy_drift", r.energy_drift},
                      {"max_speed", r.max_speed},
                      {"non_finite_step", r.non_finite_step},
                      {"non_finite_phyxel", r.non_finite_phyxel},
                      {"wall_seconds", r.seconds}});
    }
    std::printf(
        "  float vs double after %lld steps: max |u_f - u_d| = %.3e m (%.3e of the extent)\n",
        static_cast<long long>(steps), diff, diff / extent);
    rows.back()["float_vs_double_max_u"] = diff;
  }
  if (!json_file.empty()) std::ofstream(json_file) << rows.dump(2) << "\n";
  return 0;
}

}  // namespace phyxel::app
