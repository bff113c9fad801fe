// `phyxel bench`: picks the benchmark its option names.
#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "bench/benches.h"

namespace phyxel::bench {

int bench_command(const Args& args) {
  const auto has = [&](const char* flag) {
    return std::find(args.begin(), args.end(), flag) != args.end();
  };
  if (has("--skips")) return bench_skips(args);
  if (has("--stability")) return bench_stability(args);
  if (has("--render")) return bench_render_command(args);
  if (has("--haptics")) return bench_haptics(args);
  if (has("--cutting")) return bench_cutting(args);
  if (has("--tearing")) return bench_tearing(args);
  if (has("--sampling")) return bench_sampling(args);
  if (has("--surgery")) return bench_surgery(args);
  if (has("--accuracy")) return bench_accuracy(args);
  return bench_scale(args);
}

void write_json_file(const std::filesystem::path& file, const nlohmann::json& json) {
  if (file.empty()) return;
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  std::ofstream out(file);
  out << json.dump(2) << "\n";
  if (!out) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace phyxel::bench
