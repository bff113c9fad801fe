#include "app/options.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace phyxel::app {
namespace {

std::string short_number(double v) {  // %g: "1", "0.5", "1e+03"
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

}  // namespace

OptionParser::OptionParser(std::string command, const Args& args) : command_(std::move(command)) {
  for (const std::string& a : args) {
    const size_t eq = a.find('=');
    if (a.rfind("--", 0) == 0 && eq != std::string::npos) {
      args_.push_back(a.substr(0, eq));
      args_.push_back(a.substr(eq + 1));
    } else {
      args_.push_back(a);
    }
  }
  used_.assign(args_.size(), false);
}

bool OptionParser::flag(const std::string& name) {
  known_.insert(name);
  bool found = false;
  for (size_t i = 0; i < args_.size(); ++i)
    if (!used_[i] && args_[i] == name) used_[i] = found = true;
  return found;
}

std::string OptionParser::value(const std::string& name, const std::string& fallback) {
  known_.insert(name);
  std::string result = fallback;
  for (size_t i = 0; i < args_.size(); ++i) {
    if (used_[i] || args_[i] != name) continue;
    if (i + 1 >= args_.size())
      throw UsageError("phyxel " + command_ + ": " + name + " needs a value");
    used_[i] = used_[i + 1] = true;
    result = args_[i + 1];
  }
  return result;
}

int64_t OptionParser::integer(const std::string& name, int64_t fallback, int64_t min, int64_t max) {
  const std::string text = value(name, "");
  if (text.empty()) return fallback;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (*end != '\0' || v < min || v > max)
    throw UsageError("phyxel " + command_ + ": " + name + " " + text +
                     ": expected an integer from " + std::to_string(min) + " to " +
                     std::to_string(max));
  return v;
}

double OptionParser::number(const std::string& name, double fallback, double min, double max) {
  const std::string text = value(name, "");
  if (text.empty()) return fallback;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (*end != '\0' || !std::isfinite(v) || v < min || v > max)
    throw UsageError("phyxel " + command_ + ": " + name + " " + text + ": expected a number from " +
                     short_number(min) + " to " + short_number(max));
  return v;
}

std::vector<std::string> OptionParser::finish() {
  std::vector<std::string> positional;
  for (size_t i = 0; i < args_.size(); ++i) {
    if (used_[i]) continue;
    if (args_[i].rfind("--", 0) == 0) {
      std::string known;
      for (const std::string& k : known_) known += (known.empty() ? "" : ", ") + k;
      throw UsageError("phyxel " + command_ + ": unknown option " + args_[i] +
                       " (allowed: " + known + ")");
    }
    positional.push_back(args_[i]);
  }
  return positional;
}

}  // namespace phyxel::app
