// Private to the scene reader (scene_json*.cpp): a JSON value together with its path in the
// document ("objects[0].material.poisson"), with accessors that check types, ranges and
// unknown keys. Every failure throws SceneError with one line:
//   FILE: JSON.PATH: problem; what is allowed
#pragma once

#include <cstdint>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/scene.h"

namespace phyxel::json_reader {

// The allowed interval of a number, printed like "-1 < poisson < 0.5" or "0 < courant <= 1".
struct Limits {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_inclusive = false;
  bool hi_inclusive = false;

  static Limits any() { return {}; }
  static Limits above(double lo) { return {lo, Limits{}.hi, false, false}; }
  static Limits at_least(double lo) { return {lo, Limits{}.hi, true, false}; }
  static Limits open(double lo, double hi) { return {lo, hi, false, false}; }
  static Limits above_up_to(double lo, double hi) { return {lo, hi, false, true}; }

  bool contains(double x) const;
  // "0 < young", "-1 < poisson < 0.5", "any finite number"; `name` is the quantity.
  std::string describe(std::string_view name) const;
};

// Shortest form that reads back to the same double ("0.5", "1e-05", "20000").
std::string format_number(double x);
// Six significant digits, for derived values ("0.00353553").
std::string format_approx(double x);

// Deepest nesting of arrays and objects a document may have: scene files need fewer than 10
// levels; the limit keeps messages and memory small for hostile or broken files.
constexpr size_t kMaxNesting = 64;
// Paths in messages keep their first and last kPathEndSegments segments, with the count of
// those left out between ("a.b.c...(199994 more levels)...[0][0][0]"), and at most
// kMaxPathSegmentChars characters of each segment (a key can be long).
constexpr size_t kPathEndSegments = 3;
constexpr size_t kMaxPathSegmentChars = 40;
std::string shorten_path(std::string_view path);

// Throws SceneError("FILE: PATH: problem; allowed"). PATH is shortened by shorten_path. An empty
// path reads "(top level)". Line breaks in any part are replaced so that the message stays on one
// line.
[[noreturn]] void fail(const std::string& file, std::string_view path, std::string_view problem,
                       std::string_view allowed);

// Parses JSON text. Syntax errors and number overflows become SceneError naming the line and
// column nlohmann reports and the path of the value being read; a key repeated in one object
// is an error too (nlohmann would silently keep the last).
nlohmann::json parse_document(const std::string& text, const std::string& file);

class Node {
 public:
  Node(const nlohmann::json& value, std::string path, const std::string& file)
      : value_(&value), path_(std::move(path)), file_(&file) {}

  const nlohmann::json& value() const { return *value_; }
  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  // The last component of the path: "poisson", "radii[1]"; used to name the quantity.
  std::string leaf() const;
  [[noreturn]] void fail(std::string_view problem, std::string_view allowed) const {
    json_reader::fail(*file_, path_, problem, allowed);
  }

  // This node must be an object whose keys are all in `allowed` (unknown keys are typos).
  // `expected` says what the object is, for the wrong-type message.
  void expect_object(std::string_view expected,
                     std::initializer_list<std::string_view> allowed) const;
  std::optional<Node> find(std::string_view key) const;
  // A required member; when absent, fails saying what is `expected` there.
  Node at(std::string_view key, std::string_view expected) const;
  // This node must be an array; `expected` describes it for the wrong-type message.
  std::vector<Node> elements(std::string_view expected) const;

  double number(const Limits& limits, std::string_view unit = {}) const;
  int64_t integer(const Limits& limits) const;
  std::string text() const;  // a non-empty string
  std::string choice(std::initializer_list<std::string_view> options) const;
  // An array of exactly three numbers, each within `limits`.
  Vec3 vec3(const Limits& limits, std::string_view unit = {}) const;

  // Members of an object node: required, or optional with a fallback.
  double number(std::string_view key, const Limits& limits, std::string_view unit) const;
  double number_or(std::string_view key, double fallback, const Limits& limits,
                   std::string_view unit) const;
  int64_t integer(std::string_view key, const Limits& limits) const;
  int64_t integer_or(std::string_view key, int64_t fallback, const Limits& limits) const;
  Vec3 vec3(std::string_view key, const Limits& limits, std::string_view unit) const;
  Vec3 vec3_or(std::string_view key, const Vec3& fallback, const Limits& limits,
               std::string_view unit) const;

 private:
  std::string child_path(std::string_view key) const;
  [[noreturn]] void fail_type(std::string_view expected, std::string_view allowed) const;

  const nlohmann::json* value_;
  std::string path_;
  const std::string* file_;
};

// "allowed 0 < young, in Pa": the allowed-part of a message about a number.
std::string allowed_number(std::string_view name, const Limits& limits, std::string_view unit);

}  // namespace phyxel::json_reader
