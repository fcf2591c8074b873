// device_contact_coloring.cpp — the contacts' colouring as a program (see
// device_contact_coloring.h; Jones and Plassmann, SIAM J. Sci. Comput.
// 14(3), 1993).
#include "coloring/device_contact_coloring.h"

#include <algorithm>
#include <bit>
#include <initializer_list>
#include <string>

#include "contact_coloring_params.h"
#include "program/primitives.h"

namespace sinew {

Result<DeviceContactColoring> make_device_contact_coloring(Device& device, std::uint32_t capacity,
                                                           std::uint32_t particles, std::uint32_t colors,
                                                           std::uint32_t rounds) {
  const auto bad = [](const std::string& what) { return Error(ErrorCode::bad_parameter, "contact colouring: " + what); };
  if (capacity < 1 || capacity > SINEW_COLOR_MAX_CONTACTS)
    return bad("a capacity of " + std::to_string(capacity) + " contacts, outside [1, 2^24]");
  if (particles < 1) return bad("no particles");
  if (colors < 1 || colors > SINEW_COLOR_MAX_COLORS)
    return bad("a cap of " + std::to_string(colors) + " colours, outside [1, " +
               std::to_string(SINEW_COLOR_MAX_COLORS) + "]");
  if (rounds < 1 || rounds > SINEW_COLOR_MAX_ROUNDS)
    return bad(std::to_string(rounds) + " rounds, outside [1, " + std::to_string(SINEW_COLOR_MAX_ROUNDS) + "]");
  DeviceContactColoring c;
  c.capacity = capacity;
  c.particles = particles;
  c.colors = colors;
  c.rounds = rounds;
  const std::size_t n = capacity;
  const std::uint32_t mask_words = (colors + 31) / 32;
  const struct {
    BufferHandle* handle;
    std::size_t words;
    const char* label;
  } buffers[] = {
      {&c.table, c.table_words(), "contact colouring table"},
      {&c.order, n, "contact colouring order"},
      {&c.colour, n, "contact colours"},
      {&c.lists, 2 * n, "contact colouring rounds' lists"},
      {&c.owner, particles, "contact colouring owners"},
      {&c.masks, std::size_t{particles} * mask_words, "contact colouring masks"},
      {&c.colour_tmp, n, "contact colours (sort)"},
      {&c.order_tmp, n, "contact colouring order (sort)"},
      {&c.scratch, radix_sort_scratch_words(capacity), "contact colouring sort scratch"},
  };
  for (const auto& buffer : buffers) {
    auto made = device.create_buffer(buffer.words * 4, buffer.label);
    if (!made) return made.error();
    *buffer.handle = *made;
  }
  return c;
}

Status destroy_device_contact_coloring(Device& device, DeviceContactColoring& c) {
  for (BufferHandle* h : {&c.table, &c.order, &c.colour, &c.lists, &c.owner, &c.masks, &c.colour_tmp, &c.order_tmp,
                          &c.scratch})
    if (h->valid()) {
      if (Status s = device.destroy_buffer(*h); !s) return s;
      *h = {};
    }
  return {};
}

void append_device_contact_coloring(FrameProgram& program, const DeviceContactColoring& c, BufferHandle contacts,
                                    BufferHandle positions) {
  kernels::ContactColoringParams p{};
  p.capacity = c.capacity;
  p.colors = c.colors;
  p.mask_words = (c.colors + 31) / 32;
  program.counter("contacts to colour", c.table, c.count_word(), c.capacity);
  const std::uint32_t lists[2] = {
      program.counter("contacts undecided in a colouring round (list a)", c.table, c.count_word() + 1, c.capacity),
      program.counter("contacts undecided in a colouring round (list b)", c.table, c.count_word() + 2, c.capacity)};
  // The overflow set is solved by one invocation's loop, and lavapipe
  // breaks every loop of an invocation after 65,535 iterations in all: past
  // kOverflowSolvable the frame ends with a capacity_exceeded error naming
  // this counter (on every backend alike), never a silently partial pass.
  constexpr std::uint32_t kOverflowSolvable = 60000;
  program.counter("contacts in the overflow set", c.table, c.colors, std::min(c.capacity, kOverflowSolvable));
  const auto step = [&](std::uint32_t which, std::uint32_t count_or_counter, bool indirect) {
    p.step = which;
    const std::initializer_list<BufferHandle> bindings{c.table, contacts, positions, c.colour,
                                                       c.lists, c.order,  c.owner,   c.masks};
    if (indirect)
      program.dispatch_indirect(Kernel::contact_coloring, count_or_counter, bindings, p);
    else
      program.dispatch(Kernel::contact_coloring, count_or_counter, bindings, p);
    program.barrier();
  };
  step(SINEW_COLOR_STEP_INIT, c.capacity, false);
  for (std::uint32_t r = 0; r < c.rounds; ++r) {
    p.round = r;
    p.list_in = r % 2;
    // The list this round appends to starts empty; nothing reads its size
    // while the claims run.
    program.fill(c.table, c.count_word() + 1 + (1 - p.list_in), 1, 0);
    step(SINEW_COLOR_STEP_CLAIM, lists[p.list_in], true);
    step(SINEW_COLOR_STEP_DECIDE, lists[p.list_in], true);
  }
  p.list_in = c.rounds % 2;
  step(SINEW_COLOR_STEP_FINISH, lists[p.list_in], true);
  step(SINEW_COLOR_STEP_TABLE, 1, false);
  // Colours (the keys) up to `colors`, the overflow set's: bit_width bits.
  append_radix_sort(program, {c.table, c.count_word(), c.capacity}, 32, c.colour, c.order, c.colour_tmp, c.order_tmp,
                    {c.scratch, 0}, static_cast<std::uint32_t>(std::bit_width(c.colors)));
  program.barrier();
}

Result<CappedColoring> read_device_contact_coloring(Device& device, const DeviceContactColoring& c,
                                                    std::vector<std::uint32_t>* order_out) {
  std::vector<std::uint32_t> table(c.table_words());
  if (Status s = device.read_buffer(c.table, 0, table.data(), table.size() * 4); !s) return s.error();
  const std::uint32_t n = std::min(table[c.count_word()], c.capacity);
  std::vector<std::uint32_t> order(n), keys(n);
  if (n > 0) {
    if (Status s = device.read_buffer(c.order, 0, order.data(), std::size_t{n} * 4); !s) return s.error();
    if (Status s = device.read_buffer(c.colour, 0, keys.data(), std::size_t{n} * 4); !s) return s.error();
  }
  CappedColoring out;
  out.color_of.assign(n, UINT32_MAX);
  out.color_sizes.assign(table.begin(), table.begin() + c.table_colors());
  out.out_of_rounds = table[c.out_of_rounds_word()];
  const auto internal = [](const std::string& what) {
    return Error(ErrorCode::internal, "internal: the device's contact colouring " + what);
  };
  for (std::uint32_t k = 0; k < c.table_colors(); ++k) {
    const std::uint32_t first = table[c.table_colors() + k], count = table[k];
    if (std::uint64_t{first} + count > n) return internal("has colour " + std::to_string(k) + " past the contacts");
    for (std::uint32_t s = first; s < first + count; ++s) {
      if (order[s] >= n || out.color_of[order[s]] != UINT32_MAX || keys[s] != k)
        return internal("has slot " + std::to_string(s) + " out of place");
      out.color_of[order[s]] = k;
    }
  }
  for (std::uint32_t k : out.color_of)
    if (k == UINT32_MAX) return internal("left a contact without a colour");
  if (order_out) *order_out = std::move(order);
  return out;
}

}  // namespace sinew
