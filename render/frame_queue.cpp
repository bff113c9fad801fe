#include "render/frame_queue.h"

#include <exception>
#include <utility>

namespace phyxel::render {

void FrameQueue::Slots::release(uint32_t slot) {
  {
    std::lock_guard lock(mutex);
    busy[slot] = false;
  }
  freed.notify_all();
}

struct FrameQueue::SlotLease {
  std::shared_ptr<Slots> slots;
  uint32_t slot;
  SlotLease(std::shared_ptr<Slots> s, uint32_t k) : slots(std::move(s)), slot(k) {}
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
  ~SlotLease() { slots->release(slot); }
};

FrameQueue::FrameQueue(gpu::Context& ctx, SplatRenderer& renderer, FrameSink& sink)
    : renderer_(&renderer), sink_(&sink) {
  for (uint32_t k = 0; k < recorders_.size(); ++k)
    recorders_[k] = std::make_unique<gpu::Recorder>(ctx, "frame " + std::to_string(k));
}

FrameQueue::~FrameQueue() {
  try {
    drain();
  } catch (const std::exception&) {  // NOLINT(bugprone-empty-catch): a destructor stays quiet
  }
}

void FrameQueue::drain() {
  if (!pending_) return;
  const Pending frame = std::move(*pending_);
  pending_.reset();
  try {
    recorders_[frame.slot]->wait();
  } catch (...) {
    slots_->release(frame.slot);
    throw;
  }
  auto lease = std::make_shared<SlotLease>(slots_, frame.slot);
  SplatRenderer* renderer = renderer_;
  const uint32_t slot = frame.slot;
  sink_->push(
      frame.name, [renderer, slot, lease] { return renderer->read_frame(slot); },
      frame.video_index);
}

void FrameQueue::submit(const RenderInputs& inputs, const FrameSetup& setup, std::string name,
                        int64_t video_index) {
  drain();
  const uint32_t slot = next_;
  next_ = (next_ + 1) % SplatRenderer::kReadbackSlots;
  {
    // The sink copies frames in order: the slot's last frame is at most one behind.
    std::unique_lock lock(slots_->mutex);
    slots_->freed.wait(lock, [&] { return !slots_->busy[slot]; });
    slots_->busy[slot] = true;
  }
  try {
    gpu::Recorder& rec = *recorders_[slot];
    renderer_->record(rec, inputs, setup, nullptr, slot);
    rec.submit();
  } catch (...) {
    slots_->release(slot);
    throw;
  }
  pending_ = Pending{slot, std::move(name), video_index};
}

}  // namespace phyxel::render
