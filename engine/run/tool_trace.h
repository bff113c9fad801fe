// DIR/tools.csv of a run with tools: one row per step and tool,
//   step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts
// (the tip position and axis at the end of the step, the mean force on the tool over the
// step's substeps in N, the phyxels in contact at its last substep). Written to tools.csv.tmp
// and renamed at close(), or when the writer is destroyed without close() (a run stopped by
// an error keeps the rows of the steps it did); a failed write removes tools.csv.tmp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/run/atomic_file.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {

class ToolTraceWriter {
 public:
  // Creates tools.csv.tmp and buffers the header. Throws std::runtime_error naming the file.
  ToolTraceWriter(const std::filesystem::path& file, const std::vector<ToolDesc>& tools);
  // One row per tool. Throws std::runtime_error naming the file when the write fails (a full
  // disk), after removing tools.csv.tmp.
  void write(int64_t step, double t, const std::vector<ToolStepRecord>& records);
  // Writes the rest and renames tools.csv.tmp to tools.csv; throws like write().
  void close();

 private:
  std::vector<std::string> names_;
  AtomicFileWriter out_;
};

}  // namespace phyxel
