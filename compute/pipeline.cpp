#include "compute/pipeline.h"

#include <array>
#include <atomic>
#include <stdexcept>
#include <utility>
#include <vector>

namespace phyxel::gpu {
namespace {

// The last serial given to a pipeline (Pipeline::serial).
std::atomic<uint64_t> last_pipeline_serial{0};

// The layout the code declares: `storage_buffers` at set 0, then the caller's set 1.
std::vector<SpirvBinding> declared_bindings(uint32_t storage_buffers, const CallerSet& set1) {
  std::vector<SpirvBinding> out;
  for (uint32_t i = 0; i < storage_buffers; ++i)
    out.push_back({0, i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, ""});
  for (const VkDescriptorSetLayoutBinding& b : set1.bindings)
    out.push_back({1, b.binding, b.descriptorType, b.descriptorCount, ""});
  return out;
}

}  // namespace

std::array<uint32_t, 3> group_counts(uint32_t elements, uint32_t workgroup_size,
                                     const std::array<uint32_t, 3>& max_groups) {
  if (elements == 0) return {0, 0, 0};
  const uint64_t groups = (uint64_t{elements} + workgroup_size - 1) / workgroup_size;
  if (groups <= max_groups[0]) return {static_cast<uint32_t>(groups), 1, 1};
  const uint64_t rows = (groups + max_groups[0] - 1) / max_groups[0];
  if (rows > max_groups[1]) {
    throw VulkanError("a dispatch of " + std::to_string(elements) +
                      " invocations exceeds the device's workgroup-count limits");
  }
  return {max_groups[0], static_cast<uint32_t>(rows), 1};
}

Pipeline::Pipeline(Context& ctx, const ShaderCode& code, uint32_t bindings,
                   uint32_t push_constant_size, const CallerSet& set1,
                   const std::vector<uint32_t>& specialization)
    : ctx_(&ctx), bindings_(bindings), push_size_(push_constant_size), name_(code.name) {
  const DeviceInfo& info = ctx.info();
  workgroup_ = spirv_workgroup_size(code);
  if ((set1.layout == VK_NULL_HANDLE) != set1.bindings.empty()) {
    throw std::logic_error("shader '" + name_ +
                           "': a caller's set 1 needs its layout and bindings");
  }
  shader_bindings_ = spirv_bindings(code);
  check_bindings(code, shader_bindings_, declared_bindings(bindings, set1));
  const uint64_t invocations = uint64_t{workgroup_[0]} * workgroup_[1] * workgroup_[2];
  if (invocations > info.max_workgroup_invocations || workgroup_[0] > info.max_workgroup_size[0] ||
      workgroup_[1] > info.max_workgroup_size[1] || workgroup_[2] > info.max_workgroup_size[2]) {
    throw VulkanError("shader '" + name_ + "': workgroup of " + std::to_string(invocations) +
                      " invocations exceeds the limits of " + info.name);
  }
  if (push_constant_size % 4 != 0 || push_constant_size > info.max_push_constants_size) {
    throw VulkanError("shader '" + name_ + "': " + std::to_string(push_constant_size) +
                      " bytes of push constants (a multiple of 4, at most " +
                      std::to_string(info.max_push_constants_size) + " on " + info.name + ")");
  }
  if (ctx.pushes_descriptors() && bindings > info.max_push_descriptors) {
    throw VulkanError("shader '" + name_ + "': " + std::to_string(bindings) +
                      " bindings exceed maxPushDescriptors (" +
                      std::to_string(info.max_push_descriptors) + ")");
  }
  const DeviceFunctions& fn = ctx.fn();
  VkShaderModule module = VK_NULL_HANDLE;
  try {
    std::vector<VkDescriptorSetLayoutBinding> slots(bindings);
    for (uint32_t i = 0; i < bindings; ++i) {
      slots[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    }
    auto set = vk_struct<VkDescriptorSetLayoutCreateInfo>(
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    if (ctx.pushes_descriptors()) {
      set.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    }
    set.bindingCount = bindings;
    set.pBindings = slots.data();
    VK_CHECK(fn.vkCreateDescriptorSetLayout(ctx.device(), &set, nullptr, &set_layout_));

    const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_size};
    auto layout =
        vk_struct<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    const std::array<VkDescriptorSetLayout, 2> sets = {set_layout_, set1.layout};
    layout.setLayoutCount = set1.layout != VK_NULL_HANDLE ? 2 : 1;
    layout.pSetLayouts = sets.data();
    layout.pushConstantRangeCount = push_constant_size > 0 ? 1 : 0;
    layout.pPushConstantRanges = &range;
    VK_CHECK(fn.vkCreatePipelineLayout(ctx.device(), &layout, nullptr, &layout_));

    auto shader = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    shader.codeSize = code.bytes;
    shader.pCode = code.words;
    VK_CHECK(fn.vkCreateShaderModule(ctx.device(), &shader, nullptr, &module));

    auto create =
        vk_struct<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    create.stage = vk_struct<VkPipelineShaderStageCreateInfo>(
        VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO);
    create.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    create.stage.module = module;
    create.stage.pName = "main";
    std::vector<VkSpecializationMapEntry> entries(specialization.size());
    for (uint32_t k = 0; k < entries.size(); ++k)
      entries[k] = {k, k * uint32_t{sizeof(uint32_t)}, sizeof(uint32_t)};
    VkSpecializationInfo spec{};
    spec.mapEntryCount = static_cast<uint32_t>(entries.size());
    spec.pMapEntries = entries.data();
    spec.dataSize = specialization.size() * sizeof(uint32_t);
    spec.pData = specialization.data();
    if (!specialization.empty()) create.stage.pSpecializationInfo = &spec;
    create.layout = layout_;
    VK_CHECK(
        fn.vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &create, nullptr, &pipeline_));
    fn.vkDestroyShaderModule(ctx.device(), module, nullptr);
    ctx.set_name(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<uint64_t>(pipeline_), name_);
    ctx.set_name(VK_OBJECT_TYPE_PIPELINE_LAYOUT, reinterpret_cast<uint64_t>(layout_), name_);
    serial_ = ++last_pipeline_serial;
  } catch (...) {
    if (module != VK_NULL_HANDLE) fn.vkDestroyShaderModule(ctx.device(), module, nullptr);
    reset();
    throw;
  }
}

Pipeline::~Pipeline() {
  reset();
}

Pipeline::Pipeline(Pipeline&& other) noexcept {
  *this = std::move(other);
}

Pipeline& Pipeline::operator=(Pipeline&& other) noexcept {
  if (this != &other) {
    reset();
    ctx_ = std::exchange(other.ctx_, nullptr);
    pipeline_ = std::exchange(other.pipeline_, VK_NULL_HANDLE);
    layout_ = std::exchange(other.layout_, VK_NULL_HANDLE);
    set_layout_ = std::exchange(other.set_layout_, VK_NULL_HANDLE);
    bindings_ = other.bindings_;
    push_size_ = other.push_size_;
    workgroup_ = other.workgroup_;
    name_ = std::move(other.name_);
    shader_bindings_ = std::move(other.shader_bindings_);
    serial_ = std::exchange(other.serial_, 0);
  }
  return *this;
}

void Pipeline::destroy() {
  const DeviceFunctions& fn = ctx_->fn();
  if (pipeline_ != VK_NULL_HANDLE) fn.vkDestroyPipeline(ctx_->device(), pipeline_, nullptr);
  if (layout_ != VK_NULL_HANDLE) fn.vkDestroyPipelineLayout(ctx_->device(), layout_, nullptr);
  if (set_layout_ != VK_NULL_HANDLE) {
    fn.vkDestroyDescriptorSetLayout(ctx_->device(), set_layout_, nullptr);
  }
}

void Pipeline::reset() {
  if (ctx_ == nullptr) return;
  if (!ctx_->abandoned()) destroy();  // else unfinished work may still run it: leak it
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
  serial_ = 0;
  ctx_ = nullptr;
}

namespace detail {
namespace {

// The descriptor of binding `index`, after checking the buffer's block name (when the list is
// `named`), size, offset and range.
VkDescriptorBufferInfo checked_buffer(const Pipeline& pipeline, const DeviceInfo& info,
                                      const BufferRef& b, uint32_t index, bool named) {
  // The error's text is only built for an error.
  const auto which = [&] {
    return "dispatch of '" + pipeline.name() + "': binding " + std::to_string(index) + " ('" +
           b.buffer->name() + "')";
  };
  if ((b.block != nullptr) != named) {
    throw std::logic_error(which() + (named ? " has no block name" : " has one") +
                           ": name every buffer of the list or none");
  }
  const std::string& block = pipeline.shader_bindings()[index].name;
  if (named && block != b.block) {
    throw std::logic_error(which() + " is listed as '" + b.block + "', but the shader's binding " +
                           std::to_string(index) + " is '" + block + "'");
  }
  if (!*b.buffer) throw std::logic_error(which() + " is an empty buffer");
  const VkDeviceSize size = b.buffer->size();
  const VkDeviceSize range =
      b.range == VK_WHOLE_SIZE ? (size > b.offset ? size - b.offset : 0) : b.range;
  if (b.offset > size || range > size - b.offset) {
    throw std::logic_error(which() + " runs past the end of the buffer");
  }
  if (b.offset % info.min_storage_buffer_offset_alignment != 0) {
    throw std::logic_error(which() + ": offset " + std::to_string(b.offset) +
                           " is not a multiple of minStorageBufferOffsetAlignment (" +
                           std::to_string(info.min_storage_buffer_offset_alignment) + ")");
  }
  if (range > info.max_storage_buffer_range) {
    throw std::logic_error(which() + ": " + std::to_string(range) +
                           " bytes exceed maxStorageBufferRange (" +
                           std::to_string(info.max_storage_buffer_range) + "); bind it in pieces");
  }
  return {b.buffer->handle(), b.offset, b.range};
}

using BufferInfos = std::array<VkDescriptorBufferInfo, kMaxDispatchBindings>;

// Every buffer of the list checked (checked_buffer), their descriptors into `infos`.
void check_buffers(const Pipeline& pipeline, const DeviceInfo& info,
                   std::initializer_list<BufferRef> bindings, BufferInfos& infos) {
  const bool named = bindings.size() > 0 && bindings.begin()->block != nullptr;
  uint32_t count = 0;
  for (const BufferRef& b : bindings) {
    infos[count] = checked_buffer(pipeline, info, b, count, named);
    ++count;
  }
}

// The checks of a dispatch that do not look at its buffers; the group counts.
std::array<uint32_t, 3> checked_groups(Recorder& rec, const Pipeline& pipeline, size_t push_size,
                                       size_t buffers, uint32_t elements) {
  const std::string& name = pipeline.name();
  if (pipeline.handle() == VK_NULL_HANDLE) {
    throw std::logic_error("dispatch of an empty Pipeline");
  }
  if (!rec.recording()) {
    throw std::logic_error("dispatch of '" + name + "' into a submitted Recorder (wait() first)");
  }
  if (push_size != pipeline.push_constant_size()) {
    throw std::logic_error("dispatch of '" + name + "': push constants of " +
                           std::to_string(push_size) + " bytes, but the pipeline declares " +
                           std::to_string(pipeline.push_constant_size()));
  }
  if (buffers != pipeline.bindings()) {
    throw std::logic_error("dispatch of '" + name + "': " + std::to_string(buffers) +
                           " buffers, but the pipeline declares " +
                           std::to_string(pipeline.bindings()) + " bindings");
  }
  if (buffers > kMaxDispatchBindings)
    throw std::logic_error("dispatch of '" + name + "': more than " +
                           std::to_string(kMaxDispatchBindings) + " bindings");
  const std::array<uint32_t, 3>& wg = pipeline.workgroup_size();
  if (wg[1] != 1 || wg[2] != 1) {
    throw std::logic_error("dispatch of '" + name + "': dispatch() is for 1D workgroups");
  }
  return group_counts(elements, wg[0], rec.context().info().max_workgroup_count);
}

// Writes `count` storage-buffer descriptors into `set` (bindings 0..count-1), or pushes them
// (set VK_NULL_HANDLE).
void write_buffers(Recorder& rec, const Pipeline& pipeline, VkDescriptorSet set,
                   const BufferInfos& infos, uint32_t count) {
  std::array<VkWriteDescriptorSet, kMaxDispatchBindings> writes{};
  for (uint32_t i = 0; i < count; ++i) {
    writes[i] = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
    writes[i].dstSet = set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  Context& ctx = rec.context();
  if (set == VK_NULL_HANDLE) {
    ctx.fn().vkCmdPushDescriptorSetKHR(rec.cmd(), VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(),
                                       0, count, writes.data());
  } else {
    ctx.fn().vkUpdateDescriptorSets(ctx.device(), count, writes.data(), 0, nullptr);
  }
}

bool same_blocks(const DescriptorSetCache::Entry& entry, std::initializer_list<BufferRef> list) {
  size_t i = 0;
  for (const BufferRef& b : list)
    if (entry.blocks[i++] != b.block) return false;
  return true;
}

// The recorder's set for this pipeline and binding list. A list met before with the same block
// names (as pointers) was checked then: the key holds all that the checks read (each buffer's
// serial fixes its size); any other is checked, and a new key's set written.
VkDescriptorSet cached_set(Recorder& rec, const Pipeline& pipeline,
                           std::initializer_list<BufferRef> bindings) {
  DescriptorKey key(pipeline.serial());
  for (const BufferRef& b : bindings) {
    key.add(b.buffer->serial());
    key.add(b.offset);
    key.add(b.range);
  }
  DescriptorSetCache& cache = rec.descriptor_cache();
  DescriptorSetCache::Entry* entry = cache.find(key);
  if (entry != nullptr && same_blocks(*entry, bindings)) return entry->set;
  BufferInfos infos{};
  check_buffers(pipeline, rec.context().info(), bindings, infos);
  if (entry == nullptr) {
    entry = &cache.insert(key, pipeline.set_layout());
    write_buffers(rec, pipeline, entry->set, infos, static_cast<uint32_t>(bindings.size()));
  }
  entry->blocks.clear();
  for (const BufferRef& b : bindings) entry->blocks.push_back(b.block);
  return entry->set;
}

}  // namespace

void record_dispatch(Recorder& rec, const Pipeline& pipeline, const void* push, size_t push_size,
                     std::initializer_list<BufferRef> bindings, uint32_t elements,
                     const Buffer* indirect, VkDeviceSize indirect_offset) {
  const std::array<uint32_t, 3> groups =
      checked_groups(rec, pipeline, push_size, bindings.size(), elements);
  Context& ctx = rec.context();
  const auto count = static_cast<uint32_t>(bindings.size());
  // Up to kMaxDispatchBindings on the stack: the host work of recording is what limits small
  // scenes (no allocation per dispatch).
  BufferInfos infos{};
  VkDescriptorSet set = VK_NULL_HANDLE;
  if (count > 0 && ctx.descriptor_cache())
    set = cached_set(rec, pipeline, bindings);
  else
    check_buffers(pipeline, ctx.info(), bindings, infos);
  if (indirect != nullptr && (!*indirect || indirect_offset % 4 != 0 ||
                              indirect_offset + 3 * sizeof(uint32_t) > indirect->size()))
    throw std::logic_error("dispatch of '" + pipeline.name() +
                           "': the indirect arguments are not in '" +
                           (*indirect ? indirect->name() : std::string("an empty buffer")) + "'");
  if (elements == 0 && indirect == nullptr) return;

  const DeviceFunctions& fn = ctx.fn();
  const VkCommandBuffer cmd = rec.cmd();
  fn.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.handle());
  if (count > 0 && !ctx.pushes_descriptors()) {
    if (set == VK_NULL_HANDLE) {  // neither cached nor pushed: a set for this dispatch
      set = rec.allocate_descriptor_set(pipeline.set_layout());
      write_buffers(rec, pipeline, set, infos, count);
    }
    fn.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(), 0, 1, &set,
                               0, nullptr);
  } else if (count > 0) {
    write_buffers(rec, pipeline, VK_NULL_HANDLE, infos, count);
  }
  if (push_size > 0) {
    fn.vkCmdPushConstants(cmd, pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                          static_cast<uint32_t>(push_size), push);
  }
  if (indirect != nullptr)
    fn.vkCmdDispatchIndirect(cmd, indirect->handle(), indirect_offset);
  else
    fn.vkCmdDispatch(cmd, groups[0], groups[1], groups[2]);
  rec.count_dispatch();
}

}  // namespace detail
}  // namespace phyxel::gpu
