#include "engine/run/tool_trace.h"

#include <cstdio>
#include <stdexcept>

namespace phyxel {

ToolTraceWriter::ToolTraceWriter(const std::filesystem::path& file,
                                 const std::vector<ToolDesc>& tools)
    : out_(file) {
  for (const ToolDesc& t : tools) names_.push_back(t.name);
  out_.append("step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts\n");
}

void ToolTraceWriter::write(int64_t step, double t, const std::vector<ToolStepRecord>& records) {
  char row[512];
  for (size_t k = 0; k < records.size() && k < names_.size(); ++k) {
    const ToolStepRecord& r = records[k];
    std::snprintf(row, sizeof row, "%lld,%.9g,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%u\n",
                  static_cast<long long>(step), t, names_[k].c_str(), r.pose.position.x(),
                  r.pose.position.y(), r.pose.position.z(), r.pose.axis.x(), r.pose.axis.y(),
                  r.pose.axis.z(), r.force.x(), r.force.y(), r.force.z(), r.contacts);
    out_.append(row);
  }
}

void ToolTraceWriter::close() {
  out_.commit();
}

}  // namespace phyxel
