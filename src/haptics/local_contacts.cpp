// src/haptics/local_contacts.cpp — the haptic tick's contact solve: the
// proxy between the virtual coupling's spring and the local contact planes
// (the intermediate representation of Adachi et al. 1995 and Mark et al.
// 1996 with compliant planes; the model and its energy are in
// sinew/haptics/local_contacts.h). Newton's method on the active set: E is
// convex and piecewise quadratic, so on a fixed active set one linear
// solve finds its minimum; the set is then recomputed at the new point.
#include "sinew/haptics/local_contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "math/mat3.h"
#include "math/vec3.h"

namespace sinew::haptics {
namespace {

using V3 = math::Vec3;
using M3 = math::Mat3;

bool usable(const LocalContact& c) { return c.stiffness > 0.0; }

// g_i + offset + n_i . (x - x0): the contact's gap with the tool's centre at x.
double gap_at(const LocalContact& c, double offset, const V3& x, const V3& x0) {
  return c.gap + offset + math::dot(c.normal, math::sub(x, x0));
}

}  // namespace

LocalContactSolution solve_local_contacts(const LocalContactModel& model, const std::array<double, 3>& device,
                                          double coupling_stiffness, double gap_offset) noexcept {
  LocalContactSolution out;
  const double k_c = coupling_stiffness;
  const V3& x0 = model.tool_position;
  const std::size_t n = model.count < kMaxLocalContacts ? std::size_t(model.count) : kMaxLocalContacts;
  V3 x = device;  // free space: the proxy is the device
  std::uint32_t active_mask = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (usable(model.contacts[i]) && gap_at(model.contacts[i], gap_offset, x, x0) < 0.0) active_mask |= 1u << i;
  M3 inv{V3{1, 0, 0}, V3{0, 1, 0}, V3{0, 0, 1}};
  const std::uint32_t max_steps = 2 * kMaxLocalContacts + 2;
  out.converged = false;
  for (std::uint32_t step = 0; step < max_steps; ++step) {
    // (K I + sum_A k n n^T) x = K a - sum_A k (g - n . x0) n
    M3 a{V3{k_c, 0, 0}, V3{0, k_c, 0}, V3{0, 0, k_c}};
    V3 rhs = math::mul(device, k_c);
    for (std::size_t i = 0; i < n; ++i) {
      if (!(active_mask & (1u << i))) continue;
      const LocalContact& c = model.contacts[i];
      for (int r = 0; r < 3; ++r)
        for (int col = 0; col < 3; ++col) a[r][col] += c.stiffness * c.normal[r] * c.normal[col];
      rhs = math::sub(rhs, math::mul(c.normal, c.stiffness * (c.gap + gap_offset - math::dot(c.normal, x0))));
    }
    if (!math::invert3(a, inv)) break;  // cannot happen with K > 0: a is positive definite
    x = math::mul3(inv, rhs);
    out.iterations = step + 1;
    std::uint32_t next = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (usable(model.contacts[i]) && gap_at(model.contacts[i], gap_offset, x, x0) < 0.0) next |= 1u << i;
    if (next == active_mask) {
      out.converged = true;
      break;
    }
    active_mask = next;
  }
  // Forces and energy at the proxy.
  out.proxy = x;
  const V3 stretch = math::sub(x, device);
  out.energy = 0.5 * k_c * math::dot(stretch, stretch);
  for (std::size_t i = 0; i < n; ++i) {
    const LocalContact& c = model.contacts[i];
    if (!usable(c)) continue;
    const double g = gap_at(c, gap_offset, x, x0);
    if (!(g < 0.0)) continue;
    const double lambda = -c.stiffness * g;
    out.force = math::add(out.force, math::mul(c.normal, lambda));
    out.energy += 0.5 * c.stiffness * g * g;
    ++out.active;
  }
  // dx/da = K (K I + sum_A k n n^T)^-1 on the final active set.
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) out.sensitivity[3 * r + col] = k_c * inv[r][col];
  return out;
}

LocalContactSolution LocalContactRenderer::render(const LocalContactModel& newest, std::uint64_t sequence,
                                                  const std::array<double, 3>& device,
                                                  const std::array<double, 3>& commanded,
                                                  double coupling_stiffness) noexcept {
  if (sequence != sequence_) {  // a new frame's model: tried at no offset first
    model_ = newest;
    sequence_ = sequence;
    offset_ = 0.0;
  }
  // The most the stored energy may be now: what it was plus what the hand
  // put in over the tick against the commanded force.
  const double allowed =
      started_ ? energy_ - math::dot(commanded, math::sub(device, device_)) : std::numeric_limits<double>::infinity();
  LocalContactSolution s = solve_local_contacts(model_, device, coupling_stiffness, offset_);
  const auto energy_at = [&](double offset) {
    return solve_local_contacts(model_, device, coupling_stiffness, offset).energy;
  };
  if (std::isfinite(s.energy) && std::isfinite(allowed)) {
    constexpr int kBisections = 24;
    if (s.energy > allowed) {
      // Back the planes off: the least offset above the current one that
      // stores no more than allowed. V falls as the offset grows and is 0
      // once every plane is clear of the proxy (at most the deepest
      // penetration further).
      double lo = offset_, hi = offset_;
      for (std::size_t i = 0; i < std::size_t(model_.count) && i < kMaxLocalContacts; ++i) {
        const LocalContact& c = model_.contacts[i];
        hi = std::max(hi, offset_ - (c.gap + offset_ + math::dot(c.normal, math::sub(device, model_.tool_position))));
      }
      hi += 1e-9;
      if (energy_at(hi) <= allowed) {
        for (int k = 0; k < kBisections; ++k) {
          const double mid = 0.5 * (lo + hi);
          (energy_at(mid) <= allowed ? hi : lo) = mid;
        }
      }
      offset_ = hi;  // allowed < 0 (the tick's sampling alone): as little stored as can be
      s = solve_local_contacts(model_, device, coupling_stiffness, offset_);
    } else if (offset_ > 0.0) {
      // Room left: bring the planes back towards the model, as far as it allows.
      if (energy_at(0.0) <= allowed) {
        offset_ = 0.0;
      } else {
        double lo = 0.0, hi = offset_;
        for (int k = 0; k < kBisections; ++k) {
          const double mid = 0.5 * (lo + hi);
          (energy_at(mid) <= allowed ? hi : lo) = mid;
        }
        offset_ = hi;
      }
      s = solve_local_contacts(model_, device, coupling_stiffness, offset_);
    }
  }
  energy_ = s.energy;
  device_ = device;
  started_ = true;
  return s;
}

}  // namespace sinew::haptics
