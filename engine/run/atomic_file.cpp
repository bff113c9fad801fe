#include "engine/run/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace phyxel {
namespace {

constexpr size_t kBufferBytes = size_t(1) << 16;

}  // namespace

std::string write_failure_message(const std::filesystem::path& file, const std::string& doing,
                                  int error) {
  std::string cause;
  if (error == ENOSPC || error == EDQUOT)
    cause = "the disk is full (" + std::string(std::strerror(error)) +
            "); free space in the output folder or choose another --out folder";
  else if (error == EFBIG)
    cause = "the file size limit was reached (" + std::string(std::strerror(error)) +
            "); raise the limit (ulimit -f) or write less output";
  else
    cause = "the write failed (" + std::string(std::strerror(error)) +
            "); check that the output folder is writable and has space";
  return "cannot " + doing + " " + file.string() + ": " + cause + "; no partial file was left";
}

AtomicFileWriter::AtomicFileWriter(std::filesystem::path file) : file_(std::move(file)) {
  fd_ = ::open(temp_file().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int error = errno;
    throw std::runtime_error(write_failure_message(file_, "create", error));
  }
}

AtomicFileWriter::~AtomicFileWriter() {
  if (fd_ < 0) return;
  try {
    commit();
  } catch (const std::exception&) {
    // commit() has removed the temporary file; a destructor cannot report more.
  }
}

std::filesystem::path AtomicFileWriter::temp_file() const {
  std::filesystem::path tmp = file_;
  tmp += ".tmp";
  return tmp;
}

void AtomicFileWriter::append(std::string_view bytes) {
  if (fd_ < 0) throw std::logic_error("AtomicFileWriter: append after commit or abandon");
  buffer_.append(bytes);
  if (buffer_.size() >= kBufferBytes) flush();
}

void AtomicFileWriter::flush() {
  size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("write", n < 0 ? errno : ENOSPC);
    done += static_cast<size_t>(n);
  }
  buffer_.clear();
}

void AtomicFileWriter::commit() {
  if (fd_ < 0) throw std::logic_error("AtomicFileWriter: commit after commit or abandon");
  flush();
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) {
    const int error = errno;
    std::error_code ec;
    std::filesystem::remove(temp_file(), ec);
    throw std::runtime_error(write_failure_message(file_, "write", error));
  }
  std::error_code ec;
  std::filesystem::rename(temp_file(), file_, ec);
  if (ec) {
    std::filesystem::remove(temp_file(), ec);
    throw std::runtime_error("cannot rename " + temp_file().string() + " to " + file_.string() +
                             ": " + ec.message() + "; no partial file was left");
  }
}

void AtomicFileWriter::abandon() noexcept {
  if (fd_ < 0) return;
  ::close(std::exchange(fd_, -1));
  std::error_code ec;
  std::filesystem::remove(temp_file(), ec);
  buffer_.clear();
}

void AtomicFileWriter::fail(const std::string& doing, int error) {
  abandon();
  throw std::runtime_error(write_failure_message(file_, doing, error));
}

void write_file_atomically(const std::filesystem::path& file, std::string_view bytes) {
  AtomicFileWriter writer(file);
  writer.append(bytes);
  writer.commit();
}

}  // namespace phyxel
