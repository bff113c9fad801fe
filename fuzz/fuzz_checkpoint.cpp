// libFuzzer target: the checkpoint reader on arbitrary bytes (scripts/fuzz.sh). Every problem
// with the input must be a CheckpointError; anything else escapes and libFuzzer reports it.
// Most mutations fail the checksum, so the target also parses the input with its checksum
// recomputed, which reaches the sections' parsing.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "engine/run/checkpoint.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    phyxel::parse_checkpoint(bytes, "fuzz.phx");
  } catch (const phyxel::CheckpointError&) {
  }
  uint64_t length = 0;
  if (bytes.size() >= 24 + 8) {
    std::memcpy(&length, bytes.data() + 16, sizeof length);
    if (length == bytes.size()) {
      const uint64_t sum = phyxel::fnv1a64(bytes.data(), length - 8);
      std::memcpy(bytes.data() + length - 8, &sum, sizeof sum);
      try {
        phyxel::parse_checkpoint(bytes, "fuzz.phx");
      } catch (const phyxel::CheckpointError&) {
      }
    }
  }
  return 0;
}
