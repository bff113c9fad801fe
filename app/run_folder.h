// The output folder of `phyxel run`: one run at a time (a lock file holding the run's process
// id, locked with flock so that a run that died leaves no lock behind), and the temporary files
// of a run that was killed before it could rename them, removed by the next run into the folder.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace phyxel::app {

constexpr const char* kLockFile = ".phyxel.lock";

class OutDirLock {
 public:
  // Locks DIR/.phyxel.lock (creating it) and writes this process's id into it. Throws
  // std::runtime_error naming the folder and the process that holds it when another run does.
  explicit OutDirLock(const std::filesystem::path& dir);
  // Removes the lock file, then unlocks it.
  ~OutDirLock();
  OutDirLock(const OutDirLock&) = delete;
  OutDirLock& operator=(const OutDirLock&) = delete;

  // The process id a lock file left by a run that ended without removing it named (killed, or
  // a second signal), or 0.
  long stale_pid() const { return stale_pid_; }

 private:
  std::filesystem::path file_;
  int fd_ = -1;
  long stale_pid_ = 0;
};

// Removes DIR's temporary files of phyxel's writers (points_*.vtp.tmp, frame_*.png.tmp,
// summary.json.tmp, tools.csv.tmp, checkpoint.phx.tmp, *.mp4.tmp): a run that holds the folder's
// lock writes none before, so they are a killed run's. Returns their names.
std::vector<std::string> remove_stale_temp_files(const std::filesystem::path& dir);

}  // namespace phyxel::app
