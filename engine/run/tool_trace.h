// DIR/tools.csv of a run with tools: one row per step and tool,
//   step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts,cut_force,theta,f_l,f_p,depth,f_cx,f_cy,f_cz
// (the tip position and axis at the end of the step, the mean force on the tool over the
// step's substeps in N, the phyxels in contact at its last substep; a scalpel's cutting force
// of eqs 21-26, ToolStepRecord::cut, zeros for other tools). Written to tools.csv.tmp
// and renamed at close(), or when the writer is destroyed without close() (a run stopped by
// an error keeps the rows of the steps it did); a failed write removes tools.csv.tmp. A run
// with checkpoints writes it in place instead (flush() before each checkpoint), so that the
// file holds every row up to the latest checkpoint, and a resumed run cuts it back to the
// checkpoint's step and appends.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "engine/run/atomic_file.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {

class ToolTraceWriter {
 public:
  // The file (tools.csv.tmp unless in_place) is created, with its header, at the first
  // write(), flush() or close(): until then the folder is as it was. Throws std::runtime_error
  // naming the file. resume_after >= 0 (a resumed run): keeps the header and the rows of steps
  // up to resume_after of the existing file (checked here) and appends after them.
  ToolTraceWriter(const std::filesystem::path& file, const std::vector<ToolDesc>& tools,
                  int64_t resume_after = -1, bool in_place = false);
  ~ToolTraceWriter();
  // One row per tool. Throws std::runtime_error naming the file when the write fails (a full
  // disk; tools.csv.tmp is removed).
  void write(int64_t step, double t, const std::vector<ToolStepRecord>& records);
  // In place: writes the buffered rows out (before a checkpoint). Atomic: nothing.
  void flush();
  // Atomic: writes the rest and renames tools.csv.tmp to tools.csv. In place: closes the file.
  // Throws like write().
  void close();

 private:
  void open();

  std::filesystem::path file_;
  bool in_place_ = false;
  bool opened_ = false;
  std::optional<uintmax_t> kept_;  // a resumed run: the bytes of the file it keeps
  std::vector<std::string> names_;
  std::optional<AtomicFileWriter> atomic_;
  std::ofstream out_;
};

}  // namespace phyxel
