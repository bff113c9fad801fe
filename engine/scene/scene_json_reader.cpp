// The checked JSON reader behind the scene loader (see json_reader.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "engine/scene/json_reader.h"

namespace phyxel::json_reader {

using nlohmann::json;

bool Limits::contains(double x) const {
  const bool lo_ok = lo_inclusive ? x >= lo : x > lo;
  const bool hi_ok = hi_inclusive ? x <= hi : x < hi;
  return lo_ok && hi_ok;
}

std::string Limits::describe(std::string_view name) const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  const std::string n(name);
  if (has_lo && has_hi) {
    return format_number(lo) + (lo_inclusive ? " <= " : " < ") + n +
           (hi_inclusive ? " <= " : " < ") + format_number(hi);
  }
  if (has_lo) return n + (lo_inclusive ? " >= " : " > ") + format_number(lo);
  if (has_hi) return n + (hi_inclusive ? " <= " : " < ") + format_number(hi);
  return "any finite number";
}

std::string format_number(double x) {
  // The shortest %g form that reads back exactly, in fixed notation for whole numbers of up
  // to 17 digits: "0.0005", "1e-05", "20000", "-5000".
  const int digits_before_point =
      (x != 0 && std::isfinite(x)) ? int(std::floor(std::log10(std::abs(x)))) + 1 : 1;
  char buf[64];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", std::clamp(digits_before_point, precision, 17), x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

std::string format_approx(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string allowed_number(std::string_view name, const Limits& limits, std::string_view unit) {
  std::string s = "allowed " + limits.describe(name);
  if (!unit.empty()) s += " (" + std::string(unit) + ")";
  return s;
}

namespace {
// At most kMaxPathSegmentChars characters of a key or path segment.
std::string clip(std::string_view segment) {
  return segment.size() <= kMaxPathSegmentChars
             ? std::string(segment)
             : std::string(segment.substr(0, kMaxPathSegmentChars)) + "...";
}
}  // namespace

std::string shorten_path(std::string_view path) {
  // Segments start at '.' or '[': "objects", ".material", "[0]".
  std::vector<std::string_view> segments;
  size_t start = 0;
  for (size_t i = 1; i <= path.size(); ++i) {
    if (i == path.size() || path[i] == '.' || path[i] == '[') {
      segments.push_back(path.substr(start, i - start));
      start = i;
    }
  }
  std::string out;
  if (segments.size() <= 2 * kPathEndSegments + 1) {
    for (std::string_view segment : segments) out += clip(segment);
    return out;
  }
  for (size_t i = 0; i < kPathEndSegments; ++i) out += clip(segments[i]);
  out += "...(" + std::to_string(segments.size() - 2 * kPathEndSegments) + " more levels)...";
  for (size_t i = segments.size() - kPathEndSegments; i < segments.size(); ++i)
    out += clip(segments[i]);
  return out;
}

void fail(const std::string& file, std::string_view path, std::string_view problem,
          std::string_view allowed) {
  std::string msg = file + ": " + (path.empty() ? std::string("(top level)") : shorten_path(path)) +
                    ": " + std::string(problem) + "; " + std::string(allowed);
  std::replace_if(
      msg.begin(), msg.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  throw SceneError(msg);
}

namespace {

// What a JSON value is, for "expected X, got Y" messages.
std::string describe_value(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return v.get<bool>() ? "true" : "false";
    case json::value_t::string: {
      std::string s = v.get<std::string>();
      if (s.size() > 40) s = s.substr(0, 40) + "...";
      return "string \"" + s + "\"";
    }
    case json::value_t::array:
      return "an array of " + std::to_string(v.size()) + " elements";
    case json::value_t::object:
      return "an object";
    default:
      return "number " + v.dump();
  }
}

std::string join(std::initializer_list<std::string_view> items) {
  std::string s;
  for (std::string_view item : items) s += (s.empty() ? "" : ", ") + std::string(item);
  return s;
}

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// " (did you mean "young"?)" when one option is a likely typo of `word`.
std::string suggestion(std::string_view word, std::initializer_list<std::string_view> options) {
  std::string_view best;
  size_t best_distance = 3;
  for (std::string_view option : options) {
    const size_t d = edit_distance(word, option);
    if (d < best_distance && d < option.size()) best = option, best_distance = d;
  }
  return best.empty() ? std::string() : " (did you mean \"" + std::string(best) + "\"?)";
}

// Follows the parser's events to know the path of the value being read, and rejects keys
// that appear twice in one object.
class PathTracker {
 public:
  explicit PathTracker(const std::string& file) : file_(file) {}

  bool on_event(json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        if (frames_.size() >= kMaxNesting) {
          fail(file_, path(),
               "the document nests arrays and objects more than " + std::to_string(kMaxNesting) +
                   " levels deep",
               "allowed at most " + std::to_string(kMaxNesting) +
                   " levels of nesting (a scene file needs fewer than 10)");
        }
        frames_.push_back({event == json::parse_event_t::array_start, {}, 0, {}});
        break;
      case json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second) {
          fail(file_, path(), "duplicate key \"" + clip(top.key) + "\"",
               "each key may appear only once in an object");
        }
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames_.pop_back();
        next_element();
        break;
      case json::parse_event_t::value:
        next_element();
        break;
    }
    return true;
  }

  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.array) {
        p += '[';
        p += std::to_string(f.index);
        p += ']';
      } else if (!f.key.empty()) {
        if (!p.empty()) p += '.';
        p += f.key;
      }
    }
    return p;
  }

 private:
  struct Frame {
    bool array;
    std::string key;
    size_t index;
    std::set<std::string> keys;
  };

  void next_element() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }

  const std::string& file_;
  std::vector<Frame> frames_;
};

// nlohmann's what() without its "[json.exception.parse_error.101] " prefix.
std::string without_prefix(const char* what) {
  std::string s = what;
  if (!s.empty() && s[0] == '[') {
    const size_t end = s.find("] ");
    if (end != std::string::npos) s.erase(0, end + 2);
  }
  return s;
}

}  // namespace

json parse_document(const std::string& text, const std::string& file) {
  PathTracker tracker(file);
  try {
    return json::parse(text, [&tracker](int, json::parse_event_t event, json& parsed) {
      return tracker.on_event(event, parsed);
    });
  } catch (const json::parse_error& e) {
    fail(file, tracker.path(), "invalid JSON, " + without_prefix(e.what()),
         "allowed standard JSON: double-quoted keys and strings, commas between items, no "
         "trailing commas, no comments");
  } catch (const json::out_of_range& e) {
    fail(file, tracker.path(), without_prefix(e.what()) + ", not a finite number",
         "allowed finite numbers, magnitude below 1.7e308");
  } catch (const json::exception& e) {
    fail(file, tracker.path(), "invalid JSON, " + without_prefix(e.what()),
         "allowed standard JSON");
  }
}

std::string Node::leaf() const {
  if (path_.empty()) return "value";
  const size_t dot = path_.rfind('.');
  return dot == std::string::npos ? path_ : path_.substr(dot + 1);
}

std::string Node::child_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

void Node::fail_type(std::string_view expected, std::string_view allowed) const {
  fail("expected " + std::string(expected) + ", got " + describe_value(*value_), allowed);
}

void Node::expect_object(std::string_view expected,
                         std::initializer_list<std::string_view> allowed) const {
  const std::string where = path_.empty() ? "at the top level" : "in " + shorten_path(path_);
  const std::string allowed_keys = "allowed keys " + where + ": " + join(allowed);
  if (!value_->is_object()) fail_type(expected, allowed_keys);
  for (const auto& item : value_->items()) {
    const std::string& key = item.key();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      json_reader::fail(*file_, child_path(key),
                        "unknown key \"" + clip(key) + "\"" + suggestion(key, allowed),
                        allowed_keys);
    }
  }
}

std::optional<Node> Node::find(std::string_view key) const {
  const auto it = value_->find(key);
  if (it == value_->end()) return std::nullopt;
  return Node(*it, child_path(key), *file_);
}

Node Node::at(std::string_view key, std::string_view expected) const {
  std::optional<Node> child = find(key);
  if (!child) {
    json_reader::fail(*file_, child_path(key), "missing required key \"" + std::string(key) + "\"",
                      "add it: " + std::string(expected));
  }
  return *child;
}

std::vector<Node> Node::elements(std::string_view expected) const {
  if (!value_->is_array()) fail_type(expected, "allowed " + std::string(expected));
  std::vector<Node> out;
  for (size_t i = 0; i < value_->size(); ++i) {
    out.emplace_back((*value_)[i], path_ + "[" + std::to_string(i) + "]", *file_);
  }
  return out;
}

double Node::number(const Limits& limits, std::string_view unit) const {
  const std::string allowed = allowed_number(leaf(), limits, unit);
  if (!value_->is_number()) fail_type("a number", allowed);
  const double x = value_->get<double>();
  if (!std::isfinite(x)) fail(format_number(x) + " is not a finite number", allowed);
  if (!limits.contains(x)) fail(format_number(x) + " is out of range", allowed);
  return x;
}

int64_t Node::integer(const Limits& limits) const {
  const std::string allowed = allowed_number(leaf(), limits, "a whole number");
  if (!value_->is_number()) fail_type("a whole number", allowed);
  int64_t n = 0;
  if (value_->is_number_unsigned()) {
    const uint64_t u = value_->get<uint64_t>();
    if (u > static_cast<uint64_t>(INT64_MAX)) fail(value_->dump() + " is too large", allowed);
    n = static_cast<int64_t>(u);
  } else if (value_->is_number_integer()) {
    n = value_->get<int64_t>();
  } else {
    const double x = value_->get<double>();
    if (x != std::trunc(x)) fail(format_number(x) + " is not a whole number", allowed);
    if (!(std::abs(x) < 9.2e18)) fail(format_number(x) + " is too large", allowed);
    n = static_cast<int64_t>(x);
  }
  if (!limits.contains(static_cast<double>(n)))
    fail(std::to_string(n) + " is out of range", allowed);
  return n;
}

std::string Node::text() const {
  if (!value_->is_string()) fail_type("a string", "allowed a non-empty string");
  std::string s = value_->get<std::string>();
  if (s.empty()) fail("empty string", "allowed a non-empty string");
  return s;
}

std::string Node::choice(std::initializer_list<std::string_view> options) const {
  const std::string allowed = "allowed " + join(options);
  if (!value_->is_string()) fail_type("a string", allowed);
  std::string s = value_->get<std::string>();
  if (std::find(options.begin(), options.end(), s) == options.end()) {
    fail("unknown value \"" + s + "\"" + suggestion(s, options), allowed);
  }
  return s;
}

Vec3 Node::vec3(const Limits& limits, std::string_view unit) const {
  const bool bounded = std::isfinite(limits.lo) || std::isfinite(limits.hi);
  std::string allowed = bounded ? "allowed [x, y, z] with " + limits.describe("each component")
                                : std::string("allowed [x, y, z] of finite numbers");
  if (!unit.empty()) allowed += " (" + std::string(unit) + ")";
  if (!value_->is_array() || value_->size() != 3) fail_type("an array of 3 numbers", allowed);
  Vec3 v;
  for (int i = 0; i < 3; ++i) {
    v[i] = Node((*value_)[i], path_ + "[" + std::to_string(i) + "]", *file_).number(limits, unit);
  }
  return v;
}

double Node::number(std::string_view key, const Limits& limits, std::string_view unit) const {
  const std::string expected = "a number, " + allowed_number(key, limits, unit);
  return at(key, expected).number(limits, unit);
}

double Node::number_or(std::string_view key, double fallback, const Limits& limits,
                       std::string_view unit) const {
  const std::optional<Node> child = find(key);
  return child ? child->number(limits, unit) : fallback;
}

int64_t Node::integer(std::string_view key, const Limits& limits) const {
  const std::string expected = "a whole number, " + allowed_number(key, limits, "");
  return at(key, expected).integer(limits);
}

int64_t Node::integer_or(std::string_view key, int64_t fallback, const Limits& limits) const {
  const std::optional<Node> child = find(key);
  return child ? child->integer(limits) : fallback;
}

Vec3 Node::vec3(std::string_view key, const Limits& limits, std::string_view unit) const {
  const std::string expected = "an array [x, y, z] of numbers (" + std::string(unit) + ")";
  return at(key, expected).vec3(limits, unit);
}

Vec3 Node::vec3_or(std::string_view key, const Vec3& fallback, const Limits& limits,
                   std::string_view unit) const {
  const std::optional<Node> child = find(key);
  return child ? child->vec3(limits, unit) : fallback;
}

}  // namespace phyxel::json_reader
