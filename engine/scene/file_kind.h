// Why a path named as an input file cannot be read as one: "does not exist", "is a folder",
// "is not a regular file (a device, pipe or socket)". Devices such as /dev/zero would be read
// forever; they are refused before anything is read.
#pragma once

#include <filesystem>
#include <string>

namespace phyxel {

// Empty when `path` is a regular file (or a link to one); else what it is instead.
inline std::string not_a_regular_file(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  switch (status.type()) {
    case std::filesystem::file_type::regular:
      return {};
    case std::filesystem::file_type::not_found:
    case std::filesystem::file_type::none:
      return "does not exist";
    case std::filesystem::file_type::directory:
      return "is a folder, not a regular file";
    case std::filesystem::file_type::character:
    case std::filesystem::file_type::block:
      return "is a device, not a regular file";
    case std::filesystem::file_type::fifo:
      return "is a pipe, not a regular file";
    case std::filesystem::file_type::socket:
      return "is a socket, not a regular file";
    default:
      return ec ? "cannot be read (" + ec.message() + ")" : "is not a regular file";
  }
}

}  // namespace phyxel
