#include "app/run_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace phyxel::app {
namespace {

std::string read_all(int fd) {
  std::string text;
  char buffer[64];
  ssize_t n = 0;
  ::lseek(fd, 0, SEEK_SET);
  while ((n = ::read(fd, buffer, sizeof buffer)) > 0 && text.size() < 256)
    text.append(buffer, size_t(n));
  return text;
}

long pid_in(const std::string& text) {
  return std::strtol(text.c_str(), nullptr, 10);
}

bool starts_with(const std::string& s, const char* prefix) {
  return s.rfind(prefix, 0) == 0;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A temporary file of phyxel's writers (engine/run/atomic_file.h names them FILE.tmp).
bool is_phyxel_temp_file(const std::string& name) {
  if (!ends_with(name, ".tmp")) return false;
  const std::string file = name.substr(0, name.size() - 4);
  return (starts_with(file, "points_") && ends_with(file, ".vtp")) ||
         (starts_with(file, "frame_") && ends_with(file, ".png")) || file == "summary.json" ||
         file == "tools.csv" || file == "checkpoint.phx" || ends_with(file, ".mp4");
}

}  // namespace

OutDirLock::OutDirLock(const std::filesystem::path& dir) : file_(dir / kLockFile) {
  // A run that ends unlinks the file before unlocking it: a lock taken on an unlinked file is
  // retried on the new one.
  for (int attempt = 0; attempt < 8; ++attempt) {
    fd_ = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw std::runtime_error("--out " + dir.string() + ": cannot create the lock file " +
                               file_.string() + " (" + std::strerror(errno) +
                               "); check that the folder is writable");
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const long pid = pid_in(read_all(fd_));
      ::close(fd_);
      fd_ = -1;
      throw std::runtime_error(
          "--out " + dir.string() + ": the folder is in use by another run (process " +
          (pid > 0 ? std::to_string(pid) : std::string("unknown")) + ", lock file " +
          file_.string() + "); wait for it to end or choose another --out folder");
    }
    struct stat held {
    }, named{};
    if (::fstat(fd_, &held) == 0 && ::stat(file_.c_str(), &named) == 0 &&
        held.st_ino == named.st_ino && held.st_dev == named.st_dev)
      break;
    ::close(fd_);
    fd_ = -1;
  }
  if (fd_ < 0)
    throw std::runtime_error("--out " + dir.string() + ": cannot lock " + file_.string() +
                             " (other runs keep replacing it)");
  stale_pid_ = pid_in(read_all(fd_));
  const std::string pid = std::to_string(::getpid()) + "\n";
  // The lock holds without the id (a failed write): the id is for messages only.
  const bool written =
      ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) == ssize_t(pid.size());
  (void)written;
}

OutDirLock::~OutDirLock() {
  if (fd_ < 0) return;
  ::unlink(file_.c_str());
  ::close(fd_);
}

std::vector<std::string> remove_stale_temp_files(const std::filesystem::path& dir) {
  std::vector<std::string> removed;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!is_phyxel_temp_file(name)) continue;
    std::error_code remove_ec;
    if (std::filesystem::remove(entry.path(), remove_ec)) removed.push_back(name);
  }
  std::sort(removed.begin(), removed.end());
  return removed;
}

}  // namespace phyxel::app
