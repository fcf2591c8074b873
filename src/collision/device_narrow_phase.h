// device_narrow_phase.h — the narrow phase of triangle surfaces in a kernel
// on any backend (issue 12, part 2 on the device): the candidate pairs a
// device BVH traversal appended (device_bvh.h) become contacts on the
// device, without a round trip through the host: the contacts of
// collision::triangle_contacts (narrow_phase.h), bit for bit on the CPU
// backend and on devices that round division and square roots correctly
// (PoCL, lavapipe: tests/device_narrow_phase_test.cpp; NVIDIA's Vulkan
// driver does not: expect last-bit differences there, README). The kernel,
// its ownership rule and its output layout:
// kernels/shared/narrow_phase_params.h.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "backends/backend.h"
#include "collision/narrow_phase.h"
#include "program/primitives.h"

namespace sinew::collision {

/// A triangle list and its ownership (narrow_phase.h) on a device.
struct DeviceTriangles {
  std::uint32_t count = 0;  ///< triangles
  BufferHandle triangles;   ///< 3 vertex indices per triangle
  BufferHandle owners;      ///< 6 per triangle: TriangleOwnership::owner
};

/// Uploads `triangles` (3 vertex indices each) and their ownership
/// (computed here, once per mesh). Errors: an empty list or one whose
/// length is no multiple of 3, named; device errors pass through.
Result<DeviceTriangles> make_device_triangles(Device& device, std::span<const std::uint32_t> triangles);

/// Where the contacts go: SINEW_CONTACT_WORDS (16) words per contact, room
/// for `capacity` of them, and two words of the caller's counts buffer (the
/// one its traversal counts pairs in): the contacts made, and the pairs
/// skipped for a zero-area triangle or a non-finite corner.
struct DeviceContacts {
  BufferHandle contacts;
  std::uint32_t capacity = 0;
  BufferHandle counts;
  std::uint32_t contact_word = 0;
  std::uint32_t bad_word = 0;
};

/// Creates room for `capacity` (1 .. 2^27) contacts; their count goes to
/// word `first_free_word` of `counts` and the bad-pair count to the word
/// after it (the buffer must hold both; the traversal's pair counter uses
/// another word of it).
Result<DeviceContacts> make_device_contacts(Device& device, std::uint32_t capacity, BufferHandle counts,
                                            std::uint32_t first_free_word);

/// Appends the contacts of the pairs a traversal appended earlier in
/// `program` (append_device_bvh_self_pairs or _tree_pairs with
/// `pair_count`, which declared it a counter; in the same buffer as
/// out.counts): the contact and bad-pair words are zeroed, the kernel runs
/// over the pairs found (an indirect dispatch), and the contact word is
/// declared a counter of out.capacity named `label` (a frame that makes
/// more fails with capacity_exceeded). One narrow phase per `out` in a
/// program: a second one zeroes the count and overwrites the first one's
/// contacts.
/// [in] positions: xyzw per vertex [m] (a pair with a non-finite corner is
///      counted as bad, like one with a zero-area triangle). [in] pairs: 2
///      triangle indices per pair, as the traversal wrote them. The
///      buffers' sizes are the caller's to keep consistent: the kernel does
///      not check indices against them.
/// Errors (bad_parameter): invalid buffers, a thickness not > 0 and
/// finite, a pair count in another buffer than out.counts, not declared a
/// counter in `program` (or declared with another capacity), or on the
/// word of the contact or bad-pair count.
Status append_device_triangle_contacts(FrameProgram& program, BufferHandle positions, const DeviceTriangles& triangles,
                                       BufferHandle pairs, const DeviceCount& pair_count, const DeviceContacts& out,
                                       float thickness, const std::string& label = "narrow phase contacts");

/// Reads the contacts the kernel made (after the program ran), sorted by
/// kind then particles and without the duplicates the ownership rule
/// leaves (as triangle_contacts returns them). Errors: capacity_exceeded
/// when the traversal found more pairs than `pair_count` holds (the pairs
/// past it made no contacts) or the kernel more contacts than out.capacity,
/// with the number there was; bad_parameter naming how many pairs held a
/// zero-area triangle or a non-finite corner; device errors pass through.
Result<std::vector<Contact>> read_device_contacts(Device& device, const DeviceContacts& out,
                                                  const DeviceCount& pair_count);

}  // namespace sinew::collision
