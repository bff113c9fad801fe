#include "compute/env.h"

#include <cerrno>
#include <cstdlib>

namespace phyxel::gpu {

bool env_switch(const char* name) {
  const std::string text = env_text(name);
  if (text.empty() || text == "1") return true;
  if (text == "0") return false;
  throw EnvError(std::string(name) + "='" + text +
                 "' is neither 0 (off) nor 1 (on); unset it for the default (on)");
}

std::optional<int64_t> env_number(const char* name, int64_t lo, int64_t hi, const char* unit,
                                  const char* unset) {
  const std::string text = env_text(name);
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long long n = std::strtoll(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE || n < lo || n > hi)
    throw EnvError(std::string(name) + "='" + text + "' is not a whole number of " + unit +
                   " from " + std::to_string(lo) + " to " + std::to_string(hi) + "; unset it for " +
                   unset);
  return n;
}

std::string env_text(const char* name) {
  const char* text = std::getenv(name);
  return text != nullptr ? text : "";
}

}  // namespace phyxel::gpu
