#include "engine/run/tool_trace.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

namespace phyxel {

namespace {

// The length of the part of `file` a resumed run keeps: the header and the rows of steps up to
// `last_step` (rows past it were written after the checkpoint by a run that then stopped).
uintmax_t kept_length(const std::filesystem::path& file, int64_t last_step) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw std::runtime_error("cannot read " + file.string() +
                             " to continue it; the checkpointed run's tools.csv is missing");
  std::string line;
  uintmax_t kept = 0;
  long long last = 0;  // the step of the last row kept
  bool header = true;
  while (std::getline(in, line)) {
    if (!header) {
      char* end = nullptr;
      const long long step = std::strtoll(line.c_str(), &end, 10);
      if (end == line.c_str() || *end != ',')
        throw std::runtime_error(file.string() + ": a row without a step number (\"" +
                                 line.substr(0, 40) + "\"); cannot continue it");
      if (step > last_step) break;
      last = step;
    }
    kept += line.size() + 1;
    header = false;
  }
  if (header || last < last_step)
    throw std::runtime_error(file.string() + ": ends before step " + std::to_string(last_step) +
                             " of the checkpoint; cannot continue it");
  in.clear();
  in.seekg(0, std::ios::end);
  return std::min<uintmax_t>(kept, static_cast<uintmax_t>(in.tellg()));
}

}  // namespace

ToolTraceWriter::ToolTraceWriter(const std::filesystem::path& file,
                                 const std::vector<ToolDesc>& tools, int64_t resume_after,
                                 bool in_place)
    : file_(file), in_place_(in_place) {
  for (const ToolDesc& t : tools) names_.push_back(t.name);
  // Checked now, applied at the first row: a run that fails before its first step leaves the
  // earlier tools.csv as it was.
  if (resume_after >= 0) kept_ = kept_length(file, resume_after);
}

ToolTraceWriter::~ToolTraceWriter() = default;

void ToolTraceWriter::open() {
  if (opened_) return;
  opened_ = true;
  const char* header =
      "step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts,cut_force,theta,f_l,f_p,depth,f_cx,f_cy,"
      "f_cz\n";
  if (kept_) {
    // Appended to: cut back to the checkpoint's step, then the rows after it follow.
    std::error_code ec;
    std::filesystem::resize_file(file_, *kept_, ec);
    if (ec)
      throw std::runtime_error("cannot continue " + file_.string() + " (" + ec.message() + ")");
    out_.open(file_, std::ios::app);
  } else if (in_place_) {
    out_.open(file_);
    out_ << header;
  } else {
    atomic_.emplace(file_);
    atomic_->append(header);
    return;
  }
  if (!out_)
    throw std::runtime_error("cannot write " + file_.string() + "; check the output folder");
}

namespace {

// Appends `v` as printf's %.{precision}g writes it (std::to_chars' general format is defined
// so), and a comma: a row of tools.csv is written every step and tool, and snprintf's format
// parsing for 20 numbers cost microseconds per row.
char* put(char* at, char* end, double v, int precision) {
  at = std::to_chars(at, end, v, std::chars_format::general, precision).ptr;
  *at++ = ',';
  return at;
}
char* put(char* at, char* end, long long v) {
  at = std::to_chars(at, end, v).ptr;
  *at++ = ',';
  return at;
}

}  // namespace

void ToolTraceWriter::write(int64_t step, double t, const std::vector<ToolStepRecord>& records) {
  open();
  // At most 21 fields of at most 24 characters each, and the tool's name.
  std::string row;
  for (size_t k = 0; k < records.size() && k < names_.size(); ++k) {
    const ToolStepRecord& r = records[k];
    const CutFeedback& c = r.cut;
    row.resize(names_[k].size() + 600);
    char* const begin = row.data();
    char* const end = begin + row.size();
    char* at = put(begin, end, static_cast<long long>(step));
    at = put(at, end, t, 9);
    at = std::copy(names_[k].begin(), names_[k].end(), at);
    *at++ = ',';
    for (double v : {r.pose.position.x(), r.pose.position.y(), r.pose.position.z(), r.pose.axis.x(),
                     r.pose.axis.y(), r.pose.axis.z(), r.force.x(), r.force.y(), r.force.z()})
      at = put(at, end, v, 9);
    at = put(at, end, static_cast<long long>(r.contacts));
    for (double v : {c.cut_force, c.theta, c.in_plane, c.normal, c.depth, c.friction.x(),
                     c.friction.y(), c.friction.z()})
      at = put(at, end, v, 6);
    at[-1] = '\n';
    row.resize(static_cast<size_t>(at - begin));
    if (atomic_)
      atomic_->append(row);
    else
      out_ << row;
  }
  if (!atomic_ && !out_)
    throw std::runtime_error("cannot write " + file_.string() + " (disk full?); the run stopped");
}

void ToolTraceWriter::flush() {
  open();
  if (atomic_) return;  // whole at close(); a checkpointed run writes in place
  out_.flush();
  if (!out_)
    throw std::runtime_error("cannot write " + file_.string() + " (disk full?); the run stopped");
}

void ToolTraceWriter::close() {
  open();
  if (atomic_) {
    atomic_->commit();
    return;
  }
  out_.close();
  if (out_.fail()) throw std::runtime_error("cannot finish " + file_.string() + " (disk full?)");
}

}  // namespace phyxel
