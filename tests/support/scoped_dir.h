// A folder for the scope of a test: made fresh, removed when the scope ends, whether the test
// passed, failed an assertion or threw (nothing of it left in /tmp or the test output).
#pragma once

#include <filesystem>
#include <system_error>
#include <utility>

namespace phyxel::test {

class ScopedDir {
 public:
  explicit ScopedDir(std::filesystem::path path) : path_(std::move(path)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScopedDir() {
    std::error_code ignored;  // a destructor does not throw; what is left is only litter
    std::filesystem::remove_all(path_, ignored);
  }
  ScopedDir(const ScopedDir&) = delete;
  ScopedDir& operator=(const ScopedDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace phyxel::test
