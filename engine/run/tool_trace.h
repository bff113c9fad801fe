// DIR/tools.csv of a run with tools: one row per step and tool,
//   step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts
// (the tip position and axis at the end of the step, the mean force on the tool over the
// step's substeps in N, the phyxels in contact at its last substep).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "engine/surgery/tool_track.h"

namespace phyxel {

class ToolTraceWriter {
 public:
  // Creates the file and writes the header. Throws std::runtime_error naming the file.
  // resume_after >= 0 (a resumed run): keeps the header and the rows of steps up to
  // resume_after of the existing file and appends after them.
  ToolTraceWriter(const std::filesystem::path& file, const std::vector<ToolDesc>& tools,
                  int64_t resume_after = -1);
  // One row per tool. Throws std::runtime_error when the write fails (a full disk).
  void write(int64_t step, double t, const std::vector<ToolStepRecord>& records);
  // Writes the buffered rows out (before a checkpoint: the file then holds every row up to it).
  void flush();
  void close();

 private:
  std::filesystem::path file_;
  std::vector<std::string> names_;
  std::ofstream out_;
};

}  // namespace phyxel
