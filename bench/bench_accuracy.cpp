// phyxel bench --accuracy: run time against error on the validation scenes, swept over
// resolution, time step and device; CSV, JSON and a gnuplot Pareto plot.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "bench/benches.h"
#include "compute/gpu_solver.h"
#include "engine/run/validation.h"

namespace phyxel::bench {
namespace {

constexpr const char* kHelp =
    "usage: phyxel bench --accuracy [options]\n"
    "\n"
    "Runs the validation scenes of scenes/validation (cantilever vs CalculiX, uniaxial bar and\n"
    "wave speed vs closed form) for each spacing scale, time-step fraction and device, and\n"
    "reports run time against relative error.\n"
    "\n"
    "options:\n"
    "  --cases LIST        cantilever_small,cantilever_large,cantilever_slit,uniaxial_bar,\n"
    "                      wave_bar (default all)\n"
    "  --spacings LIST     spacing scales relative to the scene's (default 2,1.333333,1)\n"
    "  --dt LIST           fractions of the stable step (default 1,0.5)\n"
    "  --device LIST       cpu and/or gpu, gpu:N or a GPU name (default cpu)\n"
    "  --threads N         CPU threads (default all cores)\n"
    "  --source DIR        repository root holding scenes/validation (default .)\n"
    "  --out DIR           writes accuracy.csv, accuracy.json, accuracy.png (default bench-out)";

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::vector<double> numbers(const std::string& text, const std::string& option) {
  std::vector<double> out;
  for (const std::string& item : split(text)) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (*end != '\0' || !(v > 0) || !std::isfinite(v))
      throw UsageError("phyxel bench: " + option + " " + text + ": expected positive numbers");
    out.push_back(v);
  }
  return out;
}

// Least-squares slope of log(error) against log(spacing): the observed convergence order.
double convergence_order(const std::vector<ValidationRun>& runs) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const ValidationRun& r : runs) {
    if (!(r.error > 0)) continue;
    const double x = std::log(r.spacing), y = std::log(r.error);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  if (n < 2) return std::nan("");
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void write_plot(const std::filesystem::path& dir, const std::vector<ValidationRun>& rows) {
  std::map<std::string, std::vector<const ValidationRun*>> series;
  for (const ValidationRun& r : rows) series[r.case_name + " " + r.device].push_back(&r);
  std::ofstream data(dir / "accuracy.dat");
  std::string plot;
  int index = 0;
  for (const auto& [name, runs] : series) {
    data << "# " << name << "\n";
    for (const ValidationRun* r : runs) data << r->wall_seconds << " " << r->error << "\n";
    data << "\n\n";
    plot += std::string(plot.empty() ? "plot " : ", ") + "'accuracy.dat' index " +
            std::to_string(index++) + " with linespoints title '" + name + "'";
  }
  data.close();
  std::ofstream gp(dir / "accuracy.gp");
  gp << "set terminal pngcairo size 900,600\nset output 'accuracy.png'\n"
     << "set logscale xy\nset xlabel 'run time (s)'\nset ylabel 'relative error'\n"
     << "set termoption noenhanced\nset key below\nset grid\n"
     << plot << "\n";
  gp.close();
  const std::string cmd = "cd '" + dir.string() + "' && gnuplot accuracy.gp 2>&1";
  if (std::system(cmd.c_str()) != 0)
    std::fprintf(stderr,
                 "phyxel bench: gnuplot failed or is missing (install gnuplot-nox); "
                 "the data is in %s\n",
                 (dir / "accuracy.dat").c_str());
}

// The solver factory for a device name: the CPU reference with `threads`, or (gpu, gpu:N, a
// name) the float32 GPU solver, one context per run.
SolverFactory device_factory(const std::string& device, int threads) {
  if (device == "cpu")
    return
        [threads](const PhyxelSet& set, const Vec3& g) { return make_cpu_solver(set, g, threads); };
  return [device](const PhyxelSet& set, const Vec3& g) {
    gpu::ContextOptions context;
    context.device = device;
    return make_gpu_solver(set, g, context);
  };
}

}  // namespace

int bench_accuracy(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--accuracy");
  if (opts.flag("--help")) {
    std::puts(kHelp);
    return 0;
  }
  const auto wanted = split(opts.value(
      "--cases", "cantilever_small,cantilever_large,cantilever_slit,uniaxial_bar,wave_bar"));
  const auto spacings = numbers(opts.value("--spacings", "2,1.333333,1"), "--spacings");
  const auto fractions = numbers(opts.value("--dt", "1,0.5"), "--dt");
  const auto devices = split(opts.value("--device", "cpu"));
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::filesystem::path source = opts.value("--source", ".");
  const std::filesystem::path out = opts.value("--out", "bench-out");
  opts.finish();
  for (double f : fractions)
    if (f > 1) throw UsageError("phyxel bench: --dt fractions above 1 would be substepped");
  std::filesystem::create_directories(out);

  std::vector<ValidationRun> rows;
  // Rewritten after every row, so a run cut short still leaves its data.
  auto write_tables = [&] {
    nlohmann::json json = nlohmann::json::array();
    std::ofstream csv(out / "accuracy.csv");
    csv << "case,device,spacing,dt_fraction,dt,phyxels,steps,wall_seconds,value,reference,"
           "rel_error,finite\n";
    for (const ValidationRun& r : rows) {
      csv << r.case_name << ",\"" << r.device << "\"," << r.spacing << "," << r.dt_fraction << ","
          << r.dt << "," << r.phyxels << "," << r.steps << "," << r.wall_seconds << "," << r.value
          << "," << r.reference << "," << r.error << "," << (r.finite ? 1 : 0) << "\n";
      json.push_back({{"case", r.case_name},
                      {"device", r.device},
                      {"spacing", r.spacing},
                      {"dt_fraction", r.dt_fraction},
                      {"dt", r.dt},
                      {"phyxels", r.phyxels},
                      {"steps", r.steps},
                      {"wall_seconds", r.wall_seconds},
                      {"value", r.value},
                      {"reference", r.reference},
                      {"rel_error", r.error},
                      {"finite", r.finite}});
    }
    std::ofstream(out / "accuracy.json") << json.dump(2) << "\n";
  };
  std::printf("%-17s %-30s %9s %7s %8s %7s %9s %13s %13s %10s\n", "case", "device", "spacing",
              "dt/dts", "phyxels", "steps", "wall s", "value", "reference", "rel error");
  for (const ValidationCase& c : validation_cases(source)) {
    if (std::find(wanted.begin(), wanted.end(), c.name) == wanted.end()) continue;
    for (const std::string& device : devices) {
      const SolverFactory factory = device_factory(device, threads);
      for (double scale : spacings) {
        for (double fraction : fractions) {
          ValidationRun r;
          try {
            r = run_validation(c, scale, fraction, factory);
          } catch (const std::invalid_argument& e) {  // a case this solver refuses
            std::printf("%-17s %-30s skipped: %s\n", c.name.c_str(), device.c_str(), e.what());
            continue;
          }
          std::printf("%-17s %-30s %9.5f %7.3f %8zu %7lld %9.3f %13.6g %13.6g %10.3e%s\n",
                      r.case_name.c_str(), r.device.c_str(), r.spacing, r.dt_fraction, r.phyxels,
                      static_cast<long long>(r.steps), r.wall_seconds, r.value, r.reference,
                      r.error, r.finite ? "" : "  NON-FINITE");
          std::fflush(stdout);
          rows.push_back(r);
          write_tables();
        }
      }
    }
  }

  // Observed convergence order per case and device, at the smallest time step.
  std::map<std::string, std::vector<ValidationRun>> by_series;
  const double smallest = *std::min_element(fractions.begin(), fractions.end());
  for (const ValidationRun& r : rows)
    if (r.dt_fraction == smallest) by_series[r.case_name + " " + r.device].push_back(r);
  for (const auto& [name, runs] : by_series)
    std::printf("convergence order (error ~ spacing^p) %-45s p = %.2f\n", name.c_str(),
                convergence_order(runs));
  write_plot(out, rows);
  std::printf("wrote %s, %s, %s\n", (out / "accuracy.csv").c_str(), (out / "accuracy.json").c_str(),
              (out / "accuracy.png").c_str());
  return 0;
}

}  // namespace phyxel::bench
