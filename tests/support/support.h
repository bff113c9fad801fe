// Helpers the test areas share: files read whole, the `phyxel` binary run with its stderr kept,
// exit statuses (tests/support/scoped_env.h: environment variables for a scope; scoped_dir.h: a
// folder removed when the scope ends).
#pragma once

#include <exception>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace phyxel::test {

// The `phyxel` binary of this build.
extern const std::string kPhyxel;

// The whole file as it is; empty when it cannot be read.
std::string read_text(const std::filesystem::path& file);
// The file parsed as JSON (throws on a missing file or bad JSON).
nlohmann::json read_json(const std::filesystem::path& file);

// The exit code of a process from std::system's or pclose's status; -1 when it did not exit.
int exit_status(int status);

struct Ran {
  int status;       // exit code (exit_status)
  std::string err;  // its stderr
};
// `phyxel ARGS --quiet` with stdout dropped and stderr written to `err_file`.
Ran run_phyxel(const std::string& args, const std::filesystem::path& err_file);

// The message of the E that `f()` throws, or "no error" when it returns.
template <class E = std::exception, class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace phyxel::test
