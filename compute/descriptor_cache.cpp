#include "compute/descriptor_cache.h"

#include <algorithm>

namespace phyxel::gpu {
namespace {

constexpr uint32_t kSetsPerPool = 256;
constexpr uint32_t kBuffersPerPool = kSetsPerPool * 8;

}  // namespace

DescriptorPools::~DescriptorPools() {
  if (ctx_->abandoned()) return;  // unfinished work may read the sets
  for (VkDescriptorPool p : pools_) ctx_->fn().vkDestroyDescriptorPool(ctx_->device(), p, nullptr);
}

VkDescriptorSet DescriptorPools::allocate(VkDescriptorSetLayout layout) {
  const DeviceFunctions& fn = ctx_->fn();
  while (true) {
    if (in_use_ == pools_.size()) {
      VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBuffersPerPool};
      auto info =
          vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
      info.maxSets = kSetsPerPool;
      info.poolSizeCount = 1;
      info.pPoolSizes = &size;
      VkDescriptorPool pool = VK_NULL_HANDLE;
      VK_CHECK(fn.vkCreateDescriptorPool(ctx_->device(), &info, nullptr, &pool));
      pools_.push_back(pool);
    }
    auto alloc =
        vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
    alloc.descriptorPool = pools_[in_use_];
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    const VkResult result = fn.vkAllocateDescriptorSets(ctx_->device(), &alloc, &set);
    if (result == VK_SUCCESS) return set;
    if (result != VK_ERROR_OUT_OF_POOL_MEMORY && result != VK_ERROR_FRAGMENTED_POOL) {
      VK_CHECK(result);
    }
    ++in_use_;  // this pool is full: move on to the next (or a new one)
  }
}

void DescriptorPools::reset() {
  for (VkDescriptorPool p : pools_)
    VK_CHECK(ctx_->fn().vkResetDescriptorPool(ctx_->device(), p, 0));
  in_use_ = 0;
}

DescriptorSetCache::Entry* DescriptorSetCache::find(const DescriptorKey& key) {
  const auto [first, last] = index_.equal_range(key.hash);
  for (auto it = first; it != last; ++it) {
    Entry& e = entries_[it->second];
    if (e.key.size() == key.size && std::equal(e.key.begin(), e.key.end(), key.words.begin()))
      return &e;
  }
  return nullptr;
}

DescriptorSetCache::Entry& DescriptorSetCache::insert(const DescriptorKey& key,
                                                      VkDescriptorSetLayout layout) {
  Entry e;
  e.set = pools_.allocate(layout);
  e.key.assign(key.words.begin(), key.words.begin() + key.size);
  index_.emplace(key.hash, entries_.size());
  entries_.push_back(std::move(e));
  return entries_.back();
}

void DescriptorSetCache::trim(size_t bound) {
  if (entries_.size() <= bound) return;
  pools_.reset();
  index_.clear();
  entries_.clear();
}

}  // namespace phyxel::gpu
