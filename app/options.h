// A small command-line option parser: "--name value" / "--name=value" options, flags and
// positional arguments; unknown options are errors that name the command.
#pragma once

#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/commands.h"

namespace phyxel::app {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class OptionParser {
 public:
  OptionParser(std::string command, const Args& args);
  bool flag(const std::string& name);
  std::string value(const std::string& name, const std::string& fallback);
  int64_t integer(const std::string& name, int64_t fallback, int64_t min, int64_t max);
  double number(const std::string& name, double fallback, double min, double max);
  // Every option must have been asked for; returns the positional arguments.
  std::vector<std::string> finish();

 private:
  std::string command_;
  std::vector<std::string> args_;
  std::vector<bool> used_;
  std::set<std::string> known_;
};

}  // namespace phyxel::app
