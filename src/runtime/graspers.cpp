// graspers.cpp — see graspers.h.
#include "runtime/graspers.h"

#include <cmath>
#include <string>

#include "compiler/float_words.h"
#include "contact_params.h"
#include "math/vec3.h"

namespace sinew {

namespace {

constexpr std::size_t kTargetFloats = sizeof(kernels::TargetEntry) / 4;

math::Vec3 place(const Pose& pose, const std::array<double, 3>& local) {
  return math::add(pose.position, math::rotate(pose.rotation, local));
}

}  // namespace

Graspers::Graspers(const SceneDesc& scene, const CompiledScene& compiled) {
  for (std::size_t i = 0; i < scene.graspers.size(); ++i)
    graspers_.push_back({compiled.grasper_block[i], compiled.grasper_first_target[i], scene.graspers[i].capacity, {}, {}});
}

Result<std::vector<std::uint32_t>> Graspers::close(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                                   std::vector<float>& targets, const ParticleOrder& order,
                                                   std::size_t index, const Pose& pose,
                                                   const std::array<double, 3>& half_extents,
                                                   std::span<const float> xyzw) {
  Grasper& g = graspers_[index];
  const std::string name = "grasper " + std::to_string(index);
  if (!g.held.empty()) return Error(ErrorCode::bad_parameter, name + " is closed already (open it first)");
  // The query: movable particles (inverse mass > 0 on the device's copy,
  // which xyzw carries in w) inside the jaws' box, in the grasper's frame.
  std::vector<std::uint32_t> held;
  std::vector<std::array<double, 3>> offsets;
  const math::Quat inverse = math::conj(pose.rotation);
  for (std::uint32_t p = 0; 4 * std::size_t{p} + 3 < xyzw.size(); ++p) {
    if (!(xyzw[4 * p + 3] > 0.0f)) continue;
    const math::Vec3 x{xyzw[4 * p], xyzw[4 * p + 1], xyzw[4 * p + 2]};
    const math::Vec3 local = math::rotate(inverse, math::sub(x, pose.position));
    if (std::abs(local[0]) <= half_extents[0] && std::abs(local[1]) <= half_extents[1] &&
        std::abs(local[2]) <= half_extents[2]) {
      held.push_back(p);
      offsets.push_back(local);
    }
  }
  if (held.size() > g.capacity)
    return Error(ErrorCode::capacity_exceeded, name + " would hold " + std::to_string(held.size()) +
                                                   " particles, more than its capacity " + std::to_string(g.capacity) +
                                                   " (GrasperDesc::capacity); it holds none");
  // Each held particle's slot and its target, where the particle is now.
  std::vector<std::uint32_t> slots(held.size());
  for (std::size_t i = 0; i < held.size(); ++i) {
    slots[i] = order.device_of[held[i]];
    kernels::TargetEntry e{};
    e.start_x = e.end_x = xyzw[4 * held[i]];
    e.start_y = e.end_y = xyzw[4 * held[i] + 1];
    e.start_z = e.end_z = xyzw[4 * held[i] + 2];
    store_words(targets, (g.first_target + i) * kTargetFloats, e);
  }
  if (!slots.empty())
    if (Status s = device.write_buffer(buffers.blocks[g.block].particles, 0, slots.data(), slots.size() * 4); !s)
      return s.error();
  shape.blocks[g.block].color_counts = {static_cast<std::uint32_t>(held.size())};
  g.held = held;
  g.offsets = std::move(offsets);
  return held;
}

void Graspers::move(std::vector<float>& targets, std::size_t index, const Pose& pose) {
  Grasper& g = graspers_[index];
  for (std::size_t i = 0; i < g.held.size(); ++i) {
    auto e = load_words<kernels::TargetEntry>(targets, (g.first_target + i) * kTargetFloats);
    const math::Vec3 x = place(pose, g.offsets[i]);
    e.end_x = static_cast<float>(x[0]);
    e.end_y = static_cast<float>(x[1]);
    e.end_z = static_cast<float>(x[2]);
    store_words(targets, (g.first_target + i) * kTargetFloats, e);
  }
}

Result<std::vector<std::uint32_t>> Graspers::open(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                                  std::size_t index) {
  Grasper& g = graspers_[index];
  if (!g.held.empty()) {
    const std::vector<float> zeros(g.held.size(), 0.0f);
    if (Status s = device.write_buffer(buffers.blocks[g.block].residual, 0, zeros.data(), zeros.size() * 4); !s)
      return s.error();
  }
  std::vector<std::uint32_t> released = std::move(g.held);
  g.held.clear();
  g.offsets.clear();
  shape.blocks[g.block].color_counts = {0};
  return released;
}

}  // namespace sinew
