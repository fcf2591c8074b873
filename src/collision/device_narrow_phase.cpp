// device_narrow_phase.cpp — the host side of the narrow phase kernel (see
// device_narrow_phase.h): uploads, the dispatch over the pairs a traversal
// counted, and the read-back into collision::Contact.
#include "collision/device_narrow_phase.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>

#include "narrow_phase_params.h"

namespace sinew::collision {

Result<DeviceTriangles> make_device_triangles(Device& device, std::span<const std::uint32_t> triangles) {
  if (triangles.empty() || triangles.size() % 3 != 0)
    return Error(ErrorCode::bad_parameter, "device triangles: " + std::to_string(triangles.size()) +
                                               " indices, not a positive multiple of 3");
  DeviceTriangles d;
  d.count = static_cast<std::uint32_t>(triangles.size() / 3);
  const TriangleOwnership ownership = triangle_ownership(triangles);
  std::vector<std::uint32_t> owners;
  owners.reserve(6 * std::size_t{d.count});
  for (const auto& o : ownership.owner) owners.insert(owners.end(), o.begin(), o.end());
  auto made = device.create_buffer(triangles.size() * 4, "narrow phase triangles");
  if (!made) return made.error();
  d.triangles = *made;
  if (Status s = device.write_buffer(d.triangles, 0, triangles.data(), triangles.size() * 4); !s) return s.error();
  made = device.create_buffer(owners.size() * 4, "narrow phase owners");
  if (!made) return made.error();
  d.owners = *made;
  if (Status s = device.write_buffer(d.owners, 0, owners.data(), owners.size() * 4); !s) return s.error();
  return d;
}

Result<DeviceContacts> make_device_contacts(Device& device, std::uint32_t capacity, BufferHandle counts,
                                            std::uint32_t first_free_word) {
  if (capacity == 0 || capacity > (1u << 27))
    return Error(ErrorCode::bad_parameter, "device contacts: the capacity must be 1 .. 2^27 (got " +
                                               std::to_string(capacity) + "): the kernel indexes 16 words per contact in 32 bits");
  if (!counts.valid()) return Error(ErrorCode::bad_parameter, "device contacts: the counts buffer must be valid");
  auto made = device.create_buffer(std::size_t{capacity} * SINEW_CONTACT_WORDS * 4, "narrow phase contacts");
  if (!made) return made.error();
  DeviceContacts d;
  d.contacts = *made;
  d.capacity = capacity;
  d.counts = counts;
  d.contact_word = first_free_word;
  d.bad_word = first_free_word + 1;
  return d;
}

Status append_device_triangle_contacts(FrameProgram& program, BufferHandle positions, const DeviceTriangles& triangles,
                                       BufferHandle pairs, const DeviceCount& pair_count, const DeviceContacts& out,
                                       float thickness, const std::string& label) {
  if (!positions.valid() || !triangles.triangles.valid() || !triangles.owners.valid() || !pairs.valid() ||
      !out.contacts.valid() || !out.counts.valid())
    return Error(ErrorCode::bad_parameter,
                 "device narrow phase: the positions, triangles, owners, pairs, contacts and counts buffers must be valid");
  if (!(thickness > 0.0f) || !std::isfinite(thickness))
    return Error(ErrorCode::bad_parameter, "device narrow phase: the thickness must be finite and > 0 [m] (got " +
                                               std::to_string(thickness) + ")");
  if (!(pair_count.buffer == out.counts))
    return Error(ErrorCode::bad_parameter, "device narrow phase: the pair count must be in the contacts' counts buffer");
  const auto& declared = program.counters();
  const auto counter = std::find_if(declared.begin(), declared.end(), [&](const Counter& c) {
    return c.buffer == pair_count.buffer && c.word == pair_count.word;
  });
  if (counter == declared.end())
    return Error(ErrorCode::bad_parameter,
                 "device narrow phase: no traversal before it declared the pair count (word " +
                     std::to_string(pair_count.word) + ") a counter");
  if (counter->capacity != pair_count.capacity)
    return Error(ErrorCode::bad_parameter, "device narrow phase: the pair counter was declared with capacity " +
                                               std::to_string(counter->capacity) + ", not " +
                                               std::to_string(pair_count.capacity));
  if (out.contact_word == pair_count.word || out.bad_word == pair_count.word || out.contact_word == out.bad_word)
    return Error(ErrorCode::bad_parameter, "device narrow phase: the pair, contact and bad-pair counts need three "
                                           "different words (pairs " + std::to_string(pair_count.word) + ", contacts " +
                                               std::to_string(out.contact_word) + ", bad pairs " +
                                               std::to_string(out.bad_word) + ")");
  kernels::TrianglePairsParams p{};
  p.pair_capacity = pair_count.capacity;
  p.pair_count_word = pair_count.word;
  p.contact_capacity = out.capacity;
  p.contact_count_word = out.contact_word;
  p.bad_word = out.bad_word;
  p.thickness = thickness;
  program.fill(out.counts, out.contact_word, 1, 0u);
  program.fill(out.counts, out.bad_word, 1, 0u);
  program.barrier();
  program.dispatch_indirect(Kernel::narrow_triangle_pairs, static_cast<std::uint32_t>(counter - declared.begin()),
                            {positions, triangles.triangles, triangles.owners, pairs, out.counts, out.contacts}, p);
  program.barrier();
  program.counter(label, out.counts, out.contact_word, out.capacity);
  return {};
}

Result<std::vector<Contact>> read_device_contacts(Device& device, const DeviceContacts& out,
                                                  const DeviceCount& pair_count) {
  std::uint32_t made = 0, bad = 0, pairs = 0;
  for (auto [word, value] : {std::pair{out.contact_word, &made}, std::pair{out.bad_word, &bad},
                             std::pair{pair_count.word, &pairs}})
    if (Status s = device.read_buffer(out.counts, std::size_t{word} * 4, value, 4); !s) return s.error();
  if (pairs > pair_count.capacity)
    return Error(ErrorCode::capacity_exceeded, "device narrow phase: the traversal found " + std::to_string(pairs) +
                                                   " pairs, more than the capacity of " +
                                                   std::to_string(pair_count.capacity) +
                                                   ": the pairs past it made no contacts");
  if (bad > 0)
    return Error(ErrorCode::bad_parameter, "device narrow phase: " + std::to_string(bad) +
                                               " candidate pairs hold a zero-area triangle or a non-finite corner: a "
                                               "colliding triangle needs a normal");
  if (made > out.capacity)
    return Error(ErrorCode::capacity_exceeded, "device narrow phase: " + std::to_string(made) +
                                                   " contacts made, more than the capacity of " +
                                                   std::to_string(out.capacity) + " (declare at least " +
                                                   std::to_string(made) + ")");
  std::vector<std::uint32_t> raw(std::size_t{made} * SINEW_CONTACT_WORDS);
  if (made > 0)
    if (Status s = device.read_buffer(out.contacts, 0, raw.data(), raw.size() * 4); !s) return s.error();
  std::vector<Contact> contacts(made);
  for (std::size_t k = 0; k < made; ++k) {
    const std::uint32_t* r = &raw[k * SINEW_CONTACT_WORDS];
    Contact& c = contacts[k];
    c.kind = r[0] == 0 ? Contact::Kind::vertex_triangle : Contact::Kind::edge_edge;
    for (int i = 0; i < 4; ++i) c.v[i] = r[1 + i], c.w[i] = std::bit_cast<float>(r[5 + i]);
    for (int i = 0; i < 3; ++i) c.normal[i] = std::bit_cast<float>(r[9 + i]);
    c.distance = std::bit_cast<float>(r[12]);
  }
  sort_unique_contacts(contacts);
  return contacts;
}

}  // namespace sinew::collision
