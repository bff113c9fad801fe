#include "tests/support/support.h"

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace phyxel::test {

const std::string kPhyxel = PHYXEL_BINARY_DIR "/app/phyxel";

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

nlohmann::json read_json(const std::filesystem::path& file) {
  return nlohmann::json::parse(read_text(file));
}

int exit_status(int status) {
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

Ran run_phyxel(const std::string& args, const std::filesystem::path& err_file) {
  const std::string cmd = kPhyxel + " " + args + " --quiet 2>" + err_file.string() + " >/dev/null";
  const int status = std::system(cmd.c_str());
  return {exit_status(status), read_text(err_file)};
}

}  // namespace phyxel::test
