// The PHYXEL_* environment variables, parsed in one place: switches ("0" turns one off), whole
// numbers in a range, and text. A value a variable does not take is an EnvError of one line
// naming the variable, the value and what it takes. A leaf: no Vulkan, no other project header.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace phyxel::gpu {

class EnvError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A switch, on by default: unset, empty or "1" is on, "0" is off; any other value throws.
bool env_switch(const char* name);

// A whole number from `lo` to `hi` counting `unit` ("seconds"); nullopt when unset or empty.
// Any other value throws "NAME='VALUE' is not a whole number of UNIT from LO to HI; unset it
// for UNSET" (`unset`: what the variable's absence means, e.g. "the default (120)").
std::optional<int64_t> env_number(const char* name, int64_t lo, int64_t hi, const char* unit,
                                  const char* unset);

// The text; empty when unset.
std::string env_text(const char* name);

}  // namespace phyxel::gpu
