// contact_coloring_kernels.cpp — CPU reference of the contacts' colouring
// on the device (kernels/shared/contact_coloring_params.h): Jones and
// Plassmann, "A Parallel Graph Coloring Heuristic", SIAM J. Sci. Comput.
// 14(3), 1993, one round as two dispatches (claim, decide) over the
// contacts still undecided. Items run in parallel on the CPU too, hence the
// atomics; the result does not depend on their order (see the header).
#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>

#include "contact_coloring_params.h"
#include "cpu/cpu_kernels.h"

namespace sinew::kernels {
namespace {

// The bindings (contact_coloring_params.h).
struct Buffers {
  std::uint32_t* table;
  const std::uint32_t* particles;  // 4 per contact
  const float* x;                  // 4 per particle, w the inverse mass
  std::uint32_t *colour, *lists, *order, *owner, *masks;
};

Buffers buffers_of(std::byte* const* b) {
  const auto u = [&](int k) { return reinterpret_cast<std::uint32_t*>(b[k]); };
  return {u(0), u(1), reinterpret_cast<const float*>(b[2]), u(3), u(4), u(5), u(6), u(7)};
}

std::uint32_t atomic_add(std::uint32_t& word, std::uint32_t value) {
  return std::atomic_ref<std::uint32_t>(word).fetch_add(value, std::memory_order_relaxed);
}

// atomic max (std::atomic_ref has no fetch_max before C++26).
void atomic_max(std::uint32_t& word, std::uint32_t value) {
  std::atomic_ref<std::uint32_t> ref(word);
  std::uint32_t seen = ref.load(std::memory_order_relaxed);
  while (seen < value && !ref.compare_exchange_weak(seen, value, std::memory_order_relaxed)) {
  }
}

bool movable(const Buffers& b, std::uint32_t particle) { return b.x[4 * std::size_t{particle} + 3] > 0.0f; }

void init_step(const ContactColoringParams& p, const Buffers& b, std::uint32_t i) {
  const std::uint32_t c = p.colors + 1;
  const std::uint32_t n = std::min(b.table[2 * c], p.capacity);
  if (i == 0) {
    std::fill(b.table, b.table + 2 * c, 0u);
    b.table[2 * c + 1] = n;
    b.table[2 * c + 2] = 0;
    b.table[2 * c + 3] = 0;
  }
  if (i >= n) return;
  b.colour[i] = SINEW_COLOR_NONE;
  b.lists[i] = i;
  b.order[i] = i;
  for (int k = 0; k < 4; ++k) {
    // Several contacts zero one particle: the same value, in any order.
    const std::uint32_t v = b.particles[4 * std::size_t{i} + k];
    std::atomic_ref<std::uint32_t>(b.owner[v]).store(0u, std::memory_order_relaxed);
    for (std::uint32_t w = 0; w < p.mask_words; ++w)
      std::atomic_ref<std::uint32_t>(b.masks[std::size_t{v} * p.mask_words + w]).store(0u, std::memory_order_relaxed);
  }
}

void table_step(const ContactColoringParams& p, const Buffers& b) {
  const std::uint32_t c = p.colors + 1;
  std::uint32_t sum = 0;
  for (std::uint32_t k = 0; k < c; ++k) {
    b.table[c + k] = sum;
    sum += b.table[k];
  }
}

// Word w of the colours a contact's movable particles' masks hold.
std::uint32_t used_word(const ContactColoringParams& p, const Buffers& b, const std::uint32_t* v, std::uint32_t w) {
  std::uint32_t used = 0;
  for (int q = 0; q < 4; ++q)
    if (movable(b, v[q]))
      used |= std::atomic_ref<std::uint32_t>(b.masks[std::size_t{v[q]} * p.mask_words + w]).load(std::memory_order_relaxed);
  return used;
}

// The lowest colour below the cap none of them holds; p.colors if none.
std::uint32_t lowest_free(const ContactColoringParams& p, const Buffers& b, const std::uint32_t* v) {
  for (std::uint32_t w = 0; w < p.mask_words; ++w) {
    const std::uint32_t k = 32 * w + static_cast<std::uint32_t>(std::countr_one(used_word(p, b, v, w)));
    if (k < std::min(32 * (w + 1), p.colors)) return k;
  }
  return p.colors;
}

// claim, decide or finish for item j of the round's list.
void round_step(const ContactColoringParams& p, const Buffers& b, std::uint32_t j) {
  const std::uint32_t c = p.colors + 1;
  const std::uint32_t m = std::min(b.table[2 * c + 1 + p.list_in], p.capacity);
  if (j >= m) return;
  const std::uint32_t contact = b.lists[std::size_t{p.list_in} * p.capacity + j];
  if (p.step == SINEW_COLOR_STEP_FINISH) {
    b.colour[contact] = p.colors;
    atomic_add(b.table[p.colors], 1);
    atomic_add(b.table[2 * c + 3], 1);
    return;
  }
  const std::uint32_t key = (p.round + 1) << 24 | contact_color_priority(contact);
  const std::uint32_t* v = b.particles + 4 * std::size_t{contact};
  if (p.step == SINEW_COLOR_STEP_CLAIM) {
    // Every colour below the cap taken already (the masks hold the last
    // round's colours): the overflow set now, without waiting for its turn.
    if (lowest_free(p, b, v) == p.colors) {
      b.colour[contact] = p.colors;
      atomic_add(b.table[p.colors], 1);
      return;
    }
    for (int k = 0; k < 4; ++k)
      if (movable(b, v[k])) atomic_max(b.owner[v[k]], key);
    return;
  }
  if (b.colour[contact] == p.colors) return;  // the claims sent it to the overflow set
  bool holds = true;
  for (int k = 0; k < 4; ++k)
    if (movable(b, v[k]) && std::atomic_ref<std::uint32_t>(b.owner[v[k]]).load(std::memory_order_relaxed) != key)
      holds = false;
  if (!holds) {  // a neighbour of higher priority is undecided: the next round
    const std::uint32_t next = 1 - p.list_in;
    const std::uint32_t slot = atomic_add(b.table[2 * c + 1 + next], 1);
    if (slot < p.capacity) b.lists[std::size_t{next} * p.capacity + slot] = contact;
    return;
  }
  const std::uint32_t chosen = lowest_free(p, b, v);
  b.colour[contact] = chosen;
  atomic_add(b.table[chosen], 1);
  if (chosen == p.colors) return;  // the overflow set holds no colour
  for (int k = 0; k < 4; ++k)
    if (movable(b, v[k]))
      std::atomic_ref<std::uint32_t>(b.masks[std::size_t{v[k]} * p.mask_words + chosen / 32])
          .fetch_or(1u << (chosen % 32), std::memory_order_relaxed);
}

}  // namespace

void contact_coloring(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const ContactColoringParams*>(params);
  const Buffers b = buffers_of(bindings);
  for (std::uint32_t i = begin; i < end; ++i) {
    if (p.step == SINEW_COLOR_STEP_INIT)
      init_step(p, b, i);
    else if (p.step == SINEW_COLOR_STEP_TABLE && i == 0)
      table_step(p, b);
    else if (p.step == SINEW_COLOR_STEP_CLAIM || p.step == SINEW_COLOR_STEP_DECIDE || p.step == SINEW_COLOR_STEP_FINISH)
      round_step(p, b, i);
  }
}

}  // namespace sinew::kernels
