#include "render/frame_queue.h"

#include <exception>
#include <utility>

namespace phyxel::render {
namespace {

// Frees a read-back slot when the last copy of the sink's job that holds it is destroyed: after
// the copy ran, or unrun when the sink dropped the frame after a failure.
struct SlotLease {
  SlotLease(std::shared_ptr<void> s, std::mutex* m, std::condition_variable* f, bool* b)
      : slots(std::move(s)), mutex(m), freed(f), busy(b) {}
  std::shared_ptr<void> slots;
  std::mutex* mutex;
  std::condition_variable* freed;
  bool* busy;
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
  ~SlotLease() {
    {
      std::lock_guard lock(*mutex);
      *busy = false;
    }
    freed->notify_all();
  }
};

}  // namespace

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
    std::lock_guard lock(slots_->mutex);
    slots_->busy[frame.slot] = false;
    throw;
  }
  Slots& s = *slots_;
  auto lease =
      std::shared_ptr<SlotLease>(new SlotLease{slots_, &s.mutex, &s.freed, &s.busy[frame.slot]});
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
    std::lock_guard lock(slots_->mutex);
    slots_->busy[slot] = false;
    throw;
  }
  pending_ = Pending{slot, std::move(name), video_index};
}

}  // namespace phyxel::render
