// A single-writer sequence lock over N doubles: the writer never waits, a reader either gets a
// consistent copy or learns that the writer was in the middle of a write. Every shared word is
// an atomic, so there is no data race in the C++ sense (the payload words are relaxed atomics
// ordered by the fences around the sequence counter, Boehm 2012, "Can seqlocks get along with
// programming language memory models?").
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace phyxel {

template <size_t N>
class Seqlock {
 public:
  using Payload = std::array<double, N>;

  // One writer thread only.
  void write(const Payload& value) {
    const uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    for (size_t i = 0; i < N; ++i) words_[i].store(value[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  // One attempt: true and `out` consistent, or false (a write overlapped; `out` is garbage).
  bool try_read(Payload& out) const {
    const uint64_t s1 = seq_.load(std::memory_order_acquire);
    if (s1 & 1) return false;
    for (size_t i = 0; i < N; ++i) out[i] = words_[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    return seq_.load(std::memory_order_relaxed) == s1;
  }

  // Retries until consistent: a write takes nanoseconds, so this returns at once in practice.
  Payload read() const {
    Payload out;
    while (!try_read(out)) {
    }
    return out;
  }

  // How many writes have completed.
  uint64_t writes() const { return seq_.load(std::memory_order_acquire) / 2; }

 private:
  std::atomic<uint64_t> seq_{0};
  std::array<std::atomic<double>, N> words_{};
};

// Two seqlocked slots and the index of the newest: the writer fills the older slot, then
// flips the index, so a reader reading the newest slot is overlapped only if the writer
// published twice during that read. read_newest() makes a bounded number of attempts and never
// waits: on failure the caller keeps what it had.
template <size_t N>
class DoubleBuffer {
 public:
  using Payload = typename Seqlock<N>::Payload;

  void publish(const Payload& value) {
    const int next = 1 - newest_.load(std::memory_order_relaxed);
    slots_[next].write(value);
    newest_.store(next, std::memory_order_release);
    count_.fetch_add(1, std::memory_order_release);
  }

  bool read_newest(Payload& out) const {
    for (int attempt = 0; attempt < 4; ++attempt) {
      if (slots_[newest_.load(std::memory_order_acquire)].try_read(out)) return true;
    }
    return false;
  }

  uint64_t published() const { return count_.load(std::memory_order_acquire); }

 private:
  std::array<Seqlock<N>, 2> slots_;
  std::atomic<int> newest_{0};
  std::atomic<uint64_t> count_{0};
};

}  // namespace phyxel
