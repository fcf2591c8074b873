// stats_kernels.cpp — CPU reference kernels of the per-frame statistics.
//
// Each term is a double-float (dd_math.h): the exact float inputs combined
// with error-free products and sums, so the totals keep ~48 bits however
// many terms they add. reduce_dd_blocks adds them in the pairwise tree of
// reduce_blocks (primitive_kernels.cpp), the order the GPU twins follow.
#include "cpu/cpu_kernels.h"

#include <algorithm>
#include <cmath>

#include "contact_params.h"
#include "cpu/dd_math.h"
#include "math/vec4.h"
#include "primitive_params.h"
#include "stats_params.h"

namespace sinew::kernels {
namespace {

constexpr std::uint32_t kBlock = SINEW_PRIMITIVE_BLOCK;

void store(float* out, std::uint32_t at, dd v) {
  out[2 * at] = v.hi;
  out[2 * at + 1] = v.lo;
}

// b - a exactly.
dd difference(float b, float a) { return two_sum(b, -a); }

dd dd_sub(dd a, dd b) { return dd_add(a, dd_neg(b)); }

// dot(a - r, cross(b - r, c - r)), six times the signed volume of the tet
// (r, a, b, c), from exact differences (the difference of two floats is
// exact as a pair).
dd six_volume(float4 a, float4 b, float4 c, float4 r) {
  const dd e1[3] = {difference(a.x, r.x), difference(a.y, r.y), difference(a.z, r.z)};
  const dd e2[3] = {difference(b.x, r.x), difference(b.y, r.y), difference(b.z, r.z)};
  const dd e3[3] = {difference(c.x, r.x), difference(c.y, r.y), difference(c.z, r.z)};
  const dd n[3] = {dd_sub(dd_mul(e2[1], e3[2]), dd_mul(e2[2], e3[1])),
                   dd_sub(dd_mul(e2[2], e3[0]), dd_mul(e2[0], e3[2])),
                   dd_sub(dd_mul(e2[0], e3[1]), dd_mul(e2[1], e3[0]))};
  return dd_add(dd_add(dd_mul(e1[0], n[0]), dd_mul(e1[1], n[1])), dd_mul(e1[2], n[2]));
}

}  // namespace

void stats_kinetic_energy(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const StatsParams*>(params);
  const auto* x = reinterpret_cast<const float4*>(bindings[0]);
  const auto* v = reinterpret_cast<const float4*>(bindings[1]);
  auto* terms = reinterpret_cast<float*>(bindings[2]);
  for (std::uint32_t i = begin; i < end && i < p.count; ++i) {
    if (x[i].w == 0.0f) {  // immovable: no kinetic energy
      store(terms, i, {0.0f, 0.0f});
      continue;
    }
    const dd v2 = dd_add(dd_add(two_prod(v[i].x, v[i].x), two_prod(v[i].y, v[i].y)), two_prod(v[i].z, v[i].z));
    const dd mass = dd_div(dd{1.0f, 0.0f}, dd{x[i].w, 0.0f});
    const dd e = dd_mul(mass, v2);
    store(terms, i, {0.5f * e.hi, 0.5f * e.lo});  // halving is exact
  }
}

void stats_surface_volume(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const StatsParams*>(params);
  const auto* x = reinterpret_cast<const float4*>(bindings[0]);
  const auto* faces = reinterpret_cast<const uint4*>(bindings[1]);
  auto* terms = reinterpret_cast<float*>(bindings[2]);
  for (std::uint32_t i = begin; i < end && i < p.count; ++i) {
    store(terms, i, six_volume(x[faces[i].x], x[faces[i].y], x[faces[i].z], x[faces[i].w]));
  }
}

void stats_inverted_tets(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const StatsParams*>(params);
  const auto* x = reinterpret_cast<const float4*>(bindings[0]);
  const auto* tets = reinterpret_cast<const uint4*>(bindings[1]);
  auto* flags = reinterpret_cast<std::uint32_t*>(bindings[2]);
  for (std::uint32_t i = begin; i < end && i < p.count; ++i) {
    const float4 a = x[tets[i].y], b = x[tets[i].z], c = x[tets[i].w], r = x[tets[i].x];
    // The sign in float where it is certain (Shewchuk's filter: the error of
    // the float determinant is far below 1e-5 of its permanent); the
    // double-float determinant only for the nearly flat rest. The float
    // path costs a tenth of the double-float one.
    const float e1[3] = {a.x - r.x, a.y - r.y, a.z - r.z};
    const float e2[3] = {b.x - r.x, b.y - r.y, b.z - r.z};
    const float e3[3] = {c.x - r.x, c.y - r.y, c.z - r.z};
    const float p0 = e2[1] * e3[2], p1 = e2[2] * e3[1], p2 = e2[2] * e3[0];
    const float p3 = e2[0] * e3[2], p4 = e2[0] * e3[1], p5 = e2[1] * e3[0];
    const float det = (e1[0] * (p0 - p1) + e1[1] * (p2 - p3)) + e1[2] * (p4 - p5);
    const float permanent = (std::fabs(e1[0]) * (std::fabs(p0) + std::fabs(p1)) +
                             std::fabs(e1[1]) * (std::fabs(p2) + std::fabs(p3))) +
                            std::fabs(e1[2]) * (std::fabs(p4) + std::fabs(p5));
    if (std::fabs(det) > 1e-5f * permanent) {
      flags[i] = det < 0.0f ? 1u : 0u;
    } else {
      flags[i] = six_volume(a, b, c, r).hi < 0.0f ? 1u : 0u;
    }
  }
}

void stats_tool_terms(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const StatsParams*>(params);
  const auto* slots = reinterpret_cast<const float4*>(bindings[0]);
  auto* terms = reinterpret_cast<float*>(bindings[1]);
  for (std::uint32_t i = begin; i < end && i < p.count; ++i) {
    const float4 touch = slots[std::size_t{i} * SINEW_CONTACT_IMPULSE_FLOAT4S + 4];  // (r, m)
    const float m = touch.w;
    const std::uint32_t at = SINEW_TOOL_TERMS * i;
    if (!(m > 0.0f)) {
      for (std::uint32_t k = 0; k < SINEW_TOOL_TERMS; ++k) store(terms, at + k, {0.0f, 0.0f});
      continue;
    }
    const float r[3] = {touch.x, touch.y, touch.z};
    const dd r2 = dd_add(dd_add(two_prod(r[0], r[0]), two_prod(r[1], r[1])), two_prod(r[2], r[2]));
    const dd mass{m, 0.0f};
    store(terms, at, mass);
    const int ij[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (std::uint32_t k = 0; k < 6; ++k) {
      const int a = ij[k][0], b = ij[k][1];
      const dd diagonal = a == b ? r2 : dd{0.0f, 0.0f};
      store(terms, at + 1 + k, dd_mul(mass, dd_sub(diagonal, two_prod(r[a], r[b]))));
    }
  }
}

void reduce_dd_blocks(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const ReduceDdParams*>(params);
  const auto* counts = reinterpret_cast<const std::uint32_t*>(bindings[0]);
  const std::uint32_t n = std::min(counts[p.count_word], p.capacity);
  const std::uint32_t m =
      static_cast<std::uint32_t>((std::uint64_t{n} + (std::uint64_t{1} << p.level_shift) - 1) >> p.level_shift);
  const auto* values = reinterpret_cast<const float*>(bindings[1]);
  auto* partials = reinterpret_cast<float*>(bindings[2]);
  for (std::uint32_t b = begin; b < end; ++b) {
    dd v[kBlock];
    for (std::uint32_t t = 0; t < kBlock; ++t) {
      const std::uint32_t i = b * kBlock + t;
      v[t] = {0.0f, 0.0f};
      if (i >= m) continue;
      const float* item = values + p.in_offset + std::size_t{i} * p.in_stride;
      if (p.mode == SINEW_DD_PAIRS) v[t] = {item[0], item[1]};
      if (p.mode == SINEW_DD_FLOATS) v[t] = {item[0], 0.0f};
      if (p.mode == SINEW_DD_SQUARES) v[t] = two_prod(item[0], item[0]);
    }
    for (std::uint32_t s = kBlock / 2; s > 0; s /= 2)
      for (std::uint32_t t = 0; t < s; ++t) v[t] = dd_add(v[t], v[t + s]);
    partials[p.out_offset + 2 * b] = v[0].hi;
    partials[p.out_offset + 2 * b + 1] = v[0].lo;
  }
}

}  // namespace sinew::kernels
