// sinew/haptics/seqlock_channel.h — a lock-free, double-buffered seqlock: one
// writer publishes fixed-size values, any number of readers take the newest.
// Header-only and free of the rest of sinew, so the ThreadSanitizer test
// builds it alone.
//
// Algorithm: the sequence lock (Lameter, "Effective synchronization on Linux/
// NUMA systems", 2005) in the form that is correct under the C++ memory
// model: H.-J. Boehm, "Can seqlocks get along with programming language
// memory models?", MSPC 2012, section 5 (the fence-based version):
//   writer: seq.store(odd, relaxed); atomic_thread_fence(release);
//           payload words stored relaxed; seq.store(even, release)
//   reader: s0 = seq.load(acquire); payload words loaded relaxed;
//           atomic_thread_fence(acquire); s1 = seq.load(relaxed);
//           the copy is whole iff s0 == s1 and s0 is even.
// The payload lives in std::atomic<std::uint64_t> words, so a concurrent
// write and read are not a data race in the C++ sense (no undefined
// behaviour, nothing for ThreadSanitizer to report, no annotations): a read
// that overlapped a write is detected by the sequence and thrown away.
//
// Double buffering: two slots, each with its own sequence. Publication n goes
// to slot n % 2, then `published` becomes n. A reader copies the slot of the
// newest publication, which the writer leaves alone until it has completed
// the *next* publication; a read is retried only when the writer completed
// two publications during one copy (a few hundred ns), never for a lock.
//
// Why a seqlock rather than an atomic-index triple buffer: any number of
// readers (the haptic thread, a viewer, telemetry), where a triple buffer
// serves one; readers never write shared memory (no cache-line ping-pong
// with the writer); and every shared byte is an atomic, so the channel is
// TSan-clean by construction. Progress: the writer is wait-free (a fixed
// number of stores, never waits); a reader is lock-free (it retries only
// when the writer made progress) and try_read bounds its attempts, so a
// reader in a real-time loop can never be held up.
#pragma once

#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace sinew::haptics {

/// One writer, many readers, newest value wins. T must be trivially
/// copyable, a multiple of 8 bytes and at most 8-byte aligned (a struct of
/// doubles and 64-bit integers). Not copyable or movable (threads hold
/// references to it).
template <class T>
class SeqlockChannel {
  static_assert(std::is_trivially_copyable_v<T>, "SeqlockChannel payloads are copied word by word");
  static_assert(sizeof(T) % sizeof(std::uint64_t) == 0, "pad the payload to a multiple of 8 bytes");
  static_assert(alignof(T) <= alignof(std::uint64_t), "payload alignment above 8 bytes is not supported");
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free, "needs lock-free 64-bit atomics");

 public:
  static constexpr std::size_t kWords = sizeof(T) / sizeof(std::uint64_t);
  using Words = std::array<std::uint64_t, kWords>;

  SeqlockChannel() = default;
  SeqlockChannel(const SeqlockChannel&) = delete;
  SeqlockChannel& operator=(const SeqlockChannel&) = delete;

  /// Publishes `value` (writer thread only: one writer at a time). Wait-free:
  /// a fixed number of atomic stores, no allocation, never blocks.
  /// [in] value: copied whole; readers see it or a newer value, never a mix.
  void publish(const T& value) noexcept {
    const auto words = std::bit_cast<Words>(value);
    const std::uint64_t n = writes_ + 1;
    Slot& slot = slots_[n & 1u];
    slot.seq.store(2 * n - 1, std::memory_order_relaxed);  // odd: being written
    std::atomic_thread_fence(std::memory_order_release);   // orders the odd store before the payload stores
    for (std::size_t i = 0; i < kWords; ++i) slot.words[i].store(words[i], std::memory_order_relaxed);
    slot.seq.store(2 * n, std::memory_order_release);      // even: whole
    published_.store(n, std::memory_order_release);
    writes_ = n;
  }

  /// Copies the newest published value into `out` (any thread; never
  /// blocks the writer or waits for it). Lock-free with at most
  /// `max_attempts` copies: false when nothing was published yet, or when
  /// every attempt overlapped two publications (then `out` is unchanged).
  /// [out] out: a whole value; [out] version: its publication number (1, 2, ...),
  /// never smaller than one an earlier read of this thread returned.
  bool try_read(T& out, unsigned max_attempts = 8, std::uint64_t* version = nullptr) const noexcept {
    for (unsigned attempt = 0; attempt < max_attempts; ++attempt) {
      const std::uint64_t n = published_.load(std::memory_order_acquire);
      if (n == 0) return false;
      const Slot& slot = slots_[n & 1u];
      const std::uint64_t s0 = slot.seq.load(std::memory_order_acquire);
      // The slot must still hold publication n itself. Taking a newer one
      // found there (n + 2, the writer lapped us) could hand out n + 2 and,
      // on the next read, n + 1 (published_ is stored after the slot), so
      // versions would go backwards; retry instead. Odd: being rewritten.
      if (s0 != 2 * n) continue;
      Words words;
      for (std::size_t i = 0; i < kWords; ++i) words[i] = slot.words[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);  // orders the payload loads before the re-check
      if (slot.seq.load(std::memory_order_relaxed) != s0) continue;  // overlapped a write: discard
      out = std::bit_cast<T>(words);
      if (version) *version = s0 / 2;
      return true;
    }
    return false;
  }

  /// Publications completed so far (any thread).
  [[nodiscard]] std::uint64_t published() const noexcept { return published_.load(std::memory_order_acquire); }

 private:
  struct alignas(64) Slot {
    std::atomic<std::uint64_t> seq{0};
    std::array<std::atomic<std::uint64_t>, kWords> words{};
  };
  alignas(64) std::atomic<std::uint64_t> published_{0};
  std::uint64_t writes_ = 0;  // the writer's own count (touched by the writer thread only)
  Slot slots_[2];
};

}  // namespace sinew::haptics
