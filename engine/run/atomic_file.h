// Output files that are either whole or absent: the bytes go to FILE.tmp, which is renamed
// over FILE once everything is written. A failed write (a full disk, a file size limit)
// removes FILE.tmp and throws std::runtime_error naming FILE and the cause, so that a run
// stopped by a full disk leaves no *.tmp behind and every file it wrote before stays whole.
// Used by every writer of a run: points_NNNNNN.vtp, summary.json, frame_NNNNNN.png, tools.csv.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace phyxel {

class AtomicFileWriter {
 public:
  // Creates FILE.tmp (truncating a stale one). Throws std::runtime_error naming FILE.
  explicit AtomicFileWriter(std::filesystem::path file);
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  // Commits what was appended when still open, without throwing; removes FILE.tmp when that
  // fails.
  ~AtomicFileWriter();

  // Buffers `bytes`, writing to FILE.tmp when the buffer is large. Throws on a failed write,
  // after removing FILE.tmp.
  void append(std::string_view bytes);
  // Writes what is buffered, closes FILE.tmp and renames it to FILE. Throws on failure, after
  // removing FILE.tmp.
  void commit();
  // Closes and removes FILE.tmp; FILE is left as it was.
  void abandon() noexcept;

  const std::filesystem::path& file() const { return file_; }
  std::filesystem::path temp_file() const;

 private:
  void flush();
  [[noreturn]] void fail(const std::string& doing, int error);

  std::filesystem::path file_;
  std::string buffer_;
  int fd_ = -1;
};

// FILE's whole content, atomically (AtomicFileWriter).
void write_file_atomically(const std::filesystem::path& file, std::string_view bytes);

// "cannot write FILE: the disk is full (No space left on device); ..." for errno `error`.
std::string write_failure_message(const std::filesystem::path& file, const std::string& doing,
                                  int error);

}  // namespace phyxel
