// Descriptor sets of storage buffers for dispatch(): the pools a Recorder allocates them from,
// and the cache of sets it keeps across submissions (ContextOptions::descriptor_cache), keyed
// by the pipeline and the exact binding list: each buffer's serial (never a VkBuffer handle,
// whose value a later buffer may reuse), offset and range. A set is written once, on the
// first dispatch of its key, and only bound after; docs/decisions.md, "Cached descriptor sets".
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "compute/context.h"

namespace phyxel::gpu {

// Pools of storage-buffer descriptor sets, created as needed.
class DescriptorPools {
 public:
  explicit DescriptorPools(Context& ctx) : ctx_(&ctx) {}
  ~DescriptorPools();
  DescriptorPools(const DescriptorPools&) = delete;
  DescriptorPools& operator=(const DescriptorPools&) = delete;

  VkDescriptorSet allocate(VkDescriptorSetLayout layout);
  // Frees every set: only when no command buffer that binds one is pending.
  void reset();
  // Forgets the pools without destroying them (a hung device may still use them).
  void abandon() { pools_.clear(); }

 private:
  Context* ctx_;
  std::vector<VkDescriptorPool> pools_;
  size_t in_use_ = 0;
};

// The most buffers one dispatch binds (solver_force_tear's 29; maxPushDescriptors is 32 or more).
constexpr size_t kMaxDispatchBindings = 29;

// A dispatch's set 0 as the cache's key: the pipeline's serial, then per buffer its serial,
// offset and range.
struct DescriptorKey {
  std::array<uint64_t, 1 + 3 * kMaxDispatchBindings> words{};
  uint32_t size = 0;  // words used
  uint64_t hash = 0xcbf29ce484222325ull;

  explicit DescriptorKey(uint64_t pipeline_serial) { add(pipeline_serial); }
  void add(uint64_t word) {
    words[size++] = word;
    // FNV-1a over whole words.
    hash = (hash ^ word) * 0x100000001b3ull;
  }
};

class DescriptorSetCache {
 public:
  struct Entry {
    std::vector<uint64_t> key;
    // The block names the binding list was checked with (dispatch() checks a list whose names
    // differ by pointer again).
    std::vector<const char*> blocks;
    VkDescriptorSet set = VK_NULL_HANDLE;
  };

  explicit DescriptorSetCache(Context& ctx) : pools_(ctx) {}

  // The entry of `key`, or null.
  Entry* find(const DescriptorKey& key);
  // A new entry for `key` with a set of `layout`, for the caller to write (it is not bound by
  // any command yet).
  Entry& insert(const DescriptorKey& key, VkDescriptorSetLayout layout);
  size_t size() const { return entries_.size(); }
  // Drops every set when more than `bound` are kept: only when no command buffer that binds
  // one is pending (Recorder::wait). Sets of destroyed buffers are never bound again (their
  // serials never recur) but stay until then.
  void trim(size_t bound);
  void abandon() { pools_.abandon(); }

 private:
  DescriptorPools pools_;
  std::unordered_multimap<uint64_t, size_t> index_;  // key hash -> entries_
  std::vector<Entry> entries_;
};

}  // namespace phyxel::gpu
