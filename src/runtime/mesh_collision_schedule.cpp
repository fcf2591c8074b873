// mesh_collision_schedule.cpp — the frame's contacts put in order for the
// solver and uploaded (see mesh_collision.h): those that move a particle are
// kept, the buffers grown where the frame needs more room, the contacts
// coloured (greedy, coloring/greedy_coloring.h) and laid out colour-sorted
// (or in order, with each particle's correction slots, for the Jacobi
// schedule, or for ContactSchedule::device_colored, whose frame program
// colours them on the device: coloring/device_contact_coloring.h), then
// written to the device. Continuous collision's contacts
// join them later in the frame, in the colours kept free beyond the
// frame's (append_contacts).
#include "runtime/mesh_collision.h"

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "coloring/greedy_coloring.h"

namespace sinew {
namespace {

using collision::Contact;

// A contact's coefficients c_k (mesh_contact_params.h) from its weights.
void coefficients_of(const collision::Contact& c, float out[4]) {
  const bool vertex_triangle = c.kind == collision::Contact::Kind::vertex_triangle;
  const float sign = c.kind == collision::Contact::Kind::shape_face ? 1.0f : -1.0f;  // both weights on the triangle's side
  out[0] = c.w[0];
  out[1] = vertex_triangle ? -c.w[1] : c.w[1];
  out[2] = sign * c.w[2];
  out[3] = sign * c.w[3];
}

}  // namespace

// Orders the frame's contacts (all_) for the solver and uploads them.
Status MeshCollision::schedule_contacts(Device& device, bool& grew) {
  const std::uint32_t count = keep_movable();
  if (Status s = make_room(device, count, grew); !s) return s;
  std::vector<std::uint32_t> slot_of(count);
  if (Status s = assign_slots(device, count, slot_of, grew); !s) return s;
  fill_upload(count, slot_of);
  if (buffers_.jacobi)
    if (Status s = upload_jacobi(device); !s) return s;
  return upload_contacts(device, count);
}

// The contacts that move a particle (kept_, their particles in
// contact_particles_): contacts of immovable particles only are dropped
// (nothing to solve).
std::uint32_t MeshCollision::keep_movable() {
  std::vector<std::uint32_t>& vertices = contact_particles_;
  vertices.clear();
  kept_.clear();
  for (std::size_t k = 0; k < all_.size(); ++k) {
    const Contact& c = all_[k];
    bool moves = false;
    for (std::uint32_t v : c.v) moves |= movable_[v] != 0;
    if (!moves) continue;
    kept_.push_back(static_cast<std::uint32_t>(k));
    vertices.insert(vertices.end(), c.v.begin(), c.v.end());
  }
  const auto count = static_cast<std::uint32_t>(kept_.size());
  contact_count_ = count;
  return count;
}

// The frame's additions forgotten, the room kept for continuous
// collision's contacts and the contact buffers grown to what the frame
// needs ([out] grew: the frame program must be rebuilt).
Status MeshCollision::make_room(Device& device, std::uint32_t count, bool& grew) {
  MeshContactBuffers& b = buffers_;
  appended_.clear();
  appended_slots_.clear();
  appended_colors_ = 0;
  // The last frame's continuous contacts outgrew the room kept for them.
  if (want_colors_) reserve_colors_ = std::min<std::uint32_t>(32, 2 * reserve_colors_);
  if (want_slots_) reserve_slots_ *= 2;
  want_colors_ = want_slots_ = false;
  if (count + reserve_slots_ > b.capacity) {
    // The capacity is recorded once every buffer holds it: after a failed
    // resize the next frame tries again (a buffer already grown is only larger).
    const std::uint32_t capacity = std::max(count + reserve_slots_, 2 * b.capacity);
    for (BufferHandle h : {b.particles, b.coefficients, b.normals, b.lambda, b.lambda_sum})
      if (Status s = device.resize_buffer(h, std::size_t{capacity} * 16); !s) return s;
    if (Status s = device.resize_buffer(b.motion, std::size_t{capacity} * 4); !s) return s;
    if (b.jacobi) {
      if (Status s = device.resize_buffer(b.delta, std::size_t{capacity} * 64); !s) return s;
      if (Status s = device.resize_buffer(b.slots, std::size_t{capacity} * 16); !s) return s;
    }
    b.capacity = capacity;
    grew = true;
    // The colouring's capacity is part of its program (its init step and
    // sort): new buffers, and the program made again (grew).
    if (desc_.schedule == ContactSchedule::device_colored)
      if (Status s = make_device_coloring(device); !s) return s;
  }
  return {};
}

// Where each contact goes: colour-sorted (colour k's contacts at
// [first_k, first_k + size_k)), or in order for the Jacobi schedule.
// [out] slot_of: per kept contact, its slot; grew: the table outgrew its colours.
Status MeshCollision::assign_slots(Device& device, std::uint32_t count, std::vector<std::uint32_t>& slot_of,
                                   bool& grew) {
  MeshContactBuffers& b = buffers_;
  const std::vector<std::uint32_t>& vertices = contact_particles_;
  if (b.jacobi || b.device_colored) {
    // In their kept order: the device colours them (device_colored; the
    // colours are known after the frame, take_counters) or solves them all
    // at once (Jacobi).
    color_count_ = overflow_count_ = 0;
    for (std::uint32_t k = 0; k < count; ++k) slot_of[k] = k;
    table_.assign(std::size_t{2} * b.colors, 0);
    table_[0] = count;
  } else {
    const Coloring coloring = color_constraints(vertices, 4, movable_);
    const std::uint32_t colors = coloring.color_count();
    color_count_ = colors;
    if (colors + reserve_colors_ > b.colors) {
      const std::uint32_t room = std::max(colors + reserve_colors_, 2 * b.colors);
      if (Status s = device.resize_buffer(b.table, std::size_t{2} * room * 4); !s) return s;
      b.colors = room;  // once the table holds it
      grew = true;
    }
    table_.assign(std::size_t{2} * b.colors, 0);
    for (std::uint32_t k = 0; k < colors; ++k) table_[k] = coloring.color_sizes[k];
    for (std::uint32_t k = 1; k < colors; ++k) table_[b.colors + k] = table_[b.colors + k - 1] + table_[k - 1];
    std::vector<std::uint32_t> next(table_.begin() + b.colors, table_.begin() + b.colors + colors);
    for (std::uint32_t k = 0; k < count; ++k) slot_of[k] = next[coloring.color_of[k]]++;
  }
  return {};
}

// The kept contacts' particles, coefficients c_k (mesh_contact_params.h),
// normals and offsets, and plane motions at their slots, and the slots of
// the contacts with tools.
void MeshCollision::fill_upload(std::uint32_t count, std::span<const std::uint32_t> slot_of) {
  upload_particles_.resize(std::size_t{count} * 4);
  upload_coefficients_.resize(std::size_t{count} * 4);
  upload_normals_.resize(std::size_t{count} * 4);
  upload_motion_.assign(count, 0.0f);
  tool_slots_.clear();
  for (std::uint32_t k = 0; k < count; ++k) {
    const Contact& c = all_[kept_[k]];
    const std::size_t at = std::size_t{slot_of[k]} * 4;
    if (c.shape != Contact::kNoShape) tool_slots_.push_back({slot_of[k], c.shape});
    float coefficient[4];
    coefficients_of(c, coefficient);
    for (int j = 0; j < 4; ++j) {
      upload_particles_[at + j] = c.v[j];
      upload_coefficients_[at + j] = coefficient[j];
    }
    upload_normals_[at] = c.normal[0];
    upload_normals_[at + 1] = c.normal[1];
    upload_normals_[at + 2] = c.normal[2];
    upload_normals_[at + 3] = c.offset;
    upload_motion_[slot_of[k]] = c.motion;
  }
}

// Per touched (movable) particle, its correction slots 4 i + k in
// increasing order: a counting sort by particle, so the gather sums
// them in a fixed order.
Status MeshCollision::upload_jacobi(Device& device) {
  const std::size_t particles = movable_.size();
  MeshContactBuffers& b = buffers_;
  upload_offsets_.assign(particles + 1, 0);
  // A shape contact's repeated particle (a slot with c = 0 followed by
  // the same particle) has no correction of its own: not counted in its
  // particle's mean.
  const auto counted = [&](std::size_t s) {
    const bool repeat = s % 4 != 3 && upload_coefficients_[s] == 0.0f && upload_particles_[s] == upload_particles_[s + 1];
    return movable_[upload_particles_[s]] && !repeat;
  };
  for (std::size_t s = 0; s < upload_particles_.size(); ++s)
    if (counted(s)) ++upload_offsets_[upload_particles_[s] + 1];
  upload_touched_.clear();
  for (std::size_t p = 0; p < particles; ++p) {
    if (upload_offsets_[p + 1] > 0) upload_touched_.push_back(static_cast<std::uint32_t>(p));
    upload_offsets_[p + 1] += upload_offsets_[p];
  }
  upload_slots_.resize(upload_offsets_[particles]);
  std::vector<std::uint32_t> next(upload_offsets_.begin(), upload_offsets_.end() - 1);
  for (std::size_t s = 0; s < upload_particles_.size(); ++s)
    if (counted(s)) upload_slots_[next[upload_particles_[s]]++] = static_cast<std::uint32_t>(s);
  // Offsets of the touched particles only (the gather's CSR rows).
  compact_offsets_.clear();
  for (std::uint32_t p : upload_touched_) compact_offsets_.push_back(upload_offsets_[p]);
  compact_offsets_.push_back(upload_offsets_[particles]);
  table_[1] = static_cast<std::uint32_t>(upload_touched_.size());
  if (!upload_touched_.empty()) {
    if (Status s = device.write_buffer(b.touched, 0, upload_touched_.data(), upload_touched_.size() * 4); !s)
      return s;
    if (Status s = device.write_buffer(b.offsets, 0, compact_offsets_.data(), compact_offsets_.size() * 4); !s)
      return s;
    if (Status s = device.write_buffer(b.slots, 0, upload_slots_.data(), upload_slots_.size() * 4); !s) return s;
  }
  return {};
}

// The colour table and the contacts, written to the device.
Status MeshCollision::upload_contacts(Device& device, std::uint32_t count) {
  MeshContactBuffers& b = buffers_;
  if (b.device_colored) {  // the contacts to colour: the colouring's table, which the solve reads
    const DeviceContactColoring& c = b.coloring;
    if (Status s = device.write_buffer(c.table, std::size_t{c.count_word()} * 4, &count, 4); !s) return s;
  } else if (Status s = device.write_buffer(b.table, 0, table_.data(), table_.size() * 4); !s) {
    return s;
  }
  if (count > 0) {
    const std::size_t bytes = std::size_t{count} * 16;
    if (Status s = device.write_buffer(b.particles, 0, upload_particles_.data(), bytes); !s) return s;
    if (Status s = device.write_buffer(b.coefficients, 0, upload_coefficients_.data(), bytes); !s) return s;
    if (Status s = device.write_buffer(b.normals, 0, upload_normals_.data(), bytes); !s) return s;
    if (Status s = device.write_buffer(b.motion, 0, upload_motion_.data(), bytes / 4); !s) return s;
  }
  return {};
}

Result<std::uint32_t> MeshCollision::append_contacts(Device& device, std::span<const collision::Contact> contacts) {
  MeshContactBuffers& b = buffers_;
  if (b.jacobi) return 0u;  // scene_checks: continuous needs the coloured schedule
  const std::uint32_t colors = std::min<std::uint32_t>(32, b.colors - color_count_);
  // Greedy colours, the frame's earlier additions first (they get the
  // colours they had): the first colour whose contacts share no movable
  // particle with this one. New contacts without a colour or a slot left
  // are not added.
  std::vector<collision::Contact> all = appended_;
  color_mask_.resize(movable_.size(), 0);
  std::vector<std::uint32_t> color_of, sizes(colors, 0);
  const auto place = [&](const collision::Contact& c) {
    std::uint32_t used = 0;
    for (std::uint32_t p : c.v)
      if (movable_[p]) used |= color_mask_[p];
    std::uint32_t k = 0;
    while (k < colors && (used >> k & 1u)) ++k;
    if (k == colors) return false;
    color_of.push_back(k);
    ++sizes[k];
    for (std::uint32_t p : c.v)
      if (movable_[p]) color_mask_[p] |= 1u << k;
    return true;
  };
  for (const collision::Contact& c : appended_)
    if (!place(c)) return Error(ErrorCode::internal, "internal: a continuous contact lost its colour");
  std::uint32_t added = 0;
  for (const collision::Contact& c : contacts) {
    if (contact_count_ + all.size() >= b.capacity) {
      want_slots_ = true;
      break;
    }
    if (!place(c)) {
      want_colors_ = true;
      continue;
    }
    all.push_back(c);
    ++added;
  }
  for (const collision::Contact& c : all)
    for (std::uint32_t p : c.v) color_mask_[p] = 0;
  if (added == 0) return 0u;
  const auto n = static_cast<std::uint32_t>(all.size());
  std::uint32_t used_colors = 0;
  for (std::uint32_t k = 0; k < colors; ++k)
    if (sizes[k] > 0) used_colors = k + 1;
  // The layout: colour color_count_ + k at [first_k, first_k + sizes[k]) after the frame's contacts.
  std::vector<std::uint32_t> next(colors, contact_count_);
  for (std::uint32_t k = 1; k < colors; ++k) next[k] = next[k - 1] + sizes[k - 1];
  for (std::uint32_t k = 0; k < std::max(used_colors, appended_colors_); ++k) {
    table_[color_count_ + k] = k < colors ? sizes[k] : 0;
    table_[b.colors + color_count_ + k] = next[k];
  }
  std::vector<std::uint32_t> slot_of(n);
  for (std::uint32_t i = 0; i < n; ++i) slot_of[i] = next[color_of[i]]++;

  // The earlier additions' multipliers move with them, this substep's
  // (lambda) and the earlier substeps' sum (lambda_sum, the tool's
  // reaction: add_tool_reactions); the new ones start at 0.
  std::vector<float> lambda(std::size_t{n} * 4, 0.0f), lambda_sum(std::size_t{n} * 4, 0.0f);
  if (!appended_.empty()) {
    std::vector<float> old(appended_.size() * 4);
    for (const auto& [buffer, moved] : {std::pair{b.lambda, &lambda}, std::pair{b.lambda_sum, &lambda_sum}}) {
      if (Status s = device.read_buffer(buffer, std::size_t{contact_count_} * 16, old.data(), old.size() * 4); !s)
        return s.error();
      for (std::size_t i = 0; i < appended_.size(); ++i)
        std::copy_n(&old[std::size_t{appended_slots_[i] - contact_count_} * 4], 4,
                    &(*moved)[std::size_t{slot_of[i] - contact_count_} * 4]);
    }
  }
  const std::size_t end = std::size_t{contact_count_ + n} * 4;
  upload_particles_.resize(end);
  upload_coefficients_.resize(end);
  upload_normals_.resize(end);
  upload_motion_.resize(contact_count_ + n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const collision::Contact& c = all[i];
    const std::size_t at = std::size_t{slot_of[i]} * 4;
    float coefficient[4];
    coefficients_of(c, coefficient);
    for (int j = 0; j < 4; ++j) {
      upload_particles_[at + j] = c.v[j];
      upload_coefficients_[at + j] = coefficient[j];
    }
    for (int a = 0; a < 3; ++a) upload_normals_[at + a] = c.normal[a];
    upload_normals_[at + 3] = c.offset;
    upload_motion_[slot_of[i]] = c.motion;
  }
  // Contacts with a tool: their reaction goes to it (add_tool_reactions).
  std::erase_if(tool_slots_, [&](const auto& slot) { return slot.first >= contact_count_; });
  for (std::uint32_t i = 0; i < n; ++i)
    if (all[i].shape != collision::Contact::kNoShape) tool_slots_.push_back({slot_of[i], all[i].shape});
  const std::size_t first = std::size_t{contact_count_} * 4, bytes = std::size_t{n} * 16;
  if (Status s = device.write_buffer(b.particles, first * 4, &upload_particles_[first], bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.coefficients, first * 4, &upload_coefficients_[first], bytes); !s)
    return s.error();
  if (Status s = device.write_buffer(b.normals, first * 4, &upload_normals_[first], bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.motion, std::size_t{contact_count_} * 4, &upload_motion_[contact_count_], bytes / 4);
      !s)
    return s.error();
  if (Status s = device.write_buffer(b.lambda, first * 4, lambda.data(), bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.lambda_sum, first * 4, lambda_sum.data(), bytes); !s) return s.error();
  if (Status s = device.write_buffer(b.table, 0, table_.data(), table_.size() * 4); !s) return s.error();
  appended_ = std::move(all);
  appended_slots_ = std::move(slot_of);
  appended_colors_ = std::max(appended_colors_, used_colors);
  return added;
}

}  // namespace sinew
