// sph_flow_kernels.cpp — CPU reference of the kernels that make, remove
// and move a fluid's particles on the device (kernels/shared/
// sph_flow_params.h), in the order of operations of their GPU twins
// (kernels/gpu/sph_emit.gpu and the others).
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "cpu/cpu_kernels.h"
#include "cpu/neighbour_cells.h"
#include "sph_flow_params.h"

namespace sinew::kernels {
namespace {

using u32 = std::uint32_t;

float phase_of(const u32* state, u32 e) { return std::bit_cast<float>(state[SINEW_SPH_STATE_PHASES + e]); }
bool fires(const float* emitters, const u32* state, u32 e) {
  return phase_of(state, e) + emitters[SINEW_SPH_EMITTER_FLOATS * e + 3] >= 1.0f;
}

// A lattice point's place this step: centre + u t1 + v t2 + depth d, in
// the GPU twins' order (sph_flow_params.h, sph_emit).
void place(const SphFlowParams& p, const float* f, float phase, const float* lattice, float* x) {
  const float depth = ((phase + f[3]) - 1.0f) * p.spacing;
  const float u = lattice[0], v = lattice[1];
  for (int a = 0; a < 3; ++a) x[a] = ((f[a] + u * f[8 + a]) + v * f[12 + a]) + depth * f[4 + a];
}

}  // namespace

void sph_boundary_move(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphFlowParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  auto* points = reinterpret_cast<float*>(bindings[1]);
  auto* velocity = reinterpret_cast<float*>(bindings[2]);
  const auto* position = reinterpret_cast<const float*>(bindings[3]);
  const auto* boundary_velocity = reinterpret_cast<const float*>(bindings[4]);
  for (u32 s = begin; s < end && s < n; ++s) {
    float* v = velocity + 4 * std::size_t{s};
    const u32 id = std::bit_cast<u32>(v[3]);
    if ((id & SINEW_SPH_BOUNDARY_ID) == 0u) continue;
    const std::size_t b = id & ~SINEW_SPH_BOUNDARY_ID;
    std::memcpy(points + 4 * std::size_t{s}, position + 4 * b, 12);
    std::memcpy(v, boundary_velocity + 4 * b, 12);
  }
}

void sph_sink_flags(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphFlowParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* sinks = reinterpret_cast<const float*>(bindings[2]);
  auto* flags = reinterpret_cast<u32*>(bindings[3]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    u32 keep = 1u;
    if (x[3] > 0.0f) {
      for (u32 k = 0; k < p.sinks; ++k) {
        const float* c = sinks + 4 * std::size_t{k};
        const float dx = x[0] - c[0], dy = x[1] - c[1], dz = x[2] - c[2];
        if ((dx * dx + dy * dy) + dz * dz < c[3]) keep = 0u;
      }
    }
    flags[s] = keep;
  }
}

void sph_pack(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphFlowParams*>(params);
  const auto* counts = reinterpret_cast<const u32*>(bindings[0]);
  const u32 n = cells::count_of(p, bindings[0]);
  const u32 kept_count = counts[p.kept_word] < n ? counts[p.kept_word] : n;
  const auto* kept = reinterpret_cast<const u32*>(bindings[1]);
  const auto* points = reinterpret_cast<const float*>(bindings[2]);
  const auto* velocity = reinterpret_cast<const float*>(bindings[3]);
  auto* packed_points = reinterpret_cast<float*>(bindings[4]);
  auto* packed_velocity = reinterpret_cast<float*>(bindings[5]);
  auto* state = reinterpret_cast<u32*>(bindings[6]);
  if (begin == 0 && end > 0) state[2] += n - kept_count;
  for (u32 k = begin; k < end && k < kept_count; ++k) {
    std::memcpy(packed_points + 4 * std::size_t{k}, points + 4 * std::size_t{kept[k]}, 16);
    std::memcpy(packed_velocity + 4 * std::size_t{k}, velocity + 4 * std::size_t{kept[k]}, 16);
  }
}

void sph_emit_flags(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphFlowParams*>(params);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* emitters = reinterpret_cast<const float*>(bindings[4]);
  const auto* pattern = reinterpret_cast<const float*>(bindings[5]);
  auto* state = reinterpret_cast<u32*>(bindings[6]);
  auto* flags = reinterpret_cast<u32*>(bindings[7]);
  for (u32 i = begin; i < end && i < p.pattern; ++i) {
    const float* lattice = pattern + 4 * std::size_t{i};
    const u32 e = std::bit_cast<u32>(lattice[2]);
    flags[i] = 0u;
    if (!fires(emitters, state, e)) continue;
    float x[3];
    place(p, emitters + SINEW_SPH_EMITTER_FLOATS * e, phase_of(state, e), lattice, x);
    const int c[3] = {int(std::floor(x[0] * p.inv_cell)), int(std::floor(x[1] * p.inv_cell)),
                      int(std::floor(x[2] * p.inv_cell))};
    bool blocked = false;
    cells::visit_cells(cells, ranges, p.table_mask, c, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      const float dx = y[0] - x[0], dy = y[1] - x[1], dz = y[2] - x[2];
      if (y[3] > 0.0f && (dx * dx + dy * dy) + dz * dz < p.clear2) blocked = true;
    });
    if (blocked) {
      std::atomic_ref<u32>(state[4]).fetch_add(1u);
      continue;
    }
    flags[i] = 1u;
  }
}

void sph_emit(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphFlowParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  auto* points = reinterpret_cast<float*>(bindings[1]);
  auto* velocity = reinterpret_cast<float*>(bindings[2]);
  const auto* emitters = reinterpret_cast<const float*>(bindings[3]);
  const auto* pattern = reinterpret_cast<const float*>(bindings[4]);
  const auto* state = reinterpret_cast<const u32*>(bindings[5]);
  const auto* flags = reinterpret_cast<const u32*>(bindings[6]);
  for (u32 i = begin; i < end && i < p.pattern; ++i) {
    if (flags[i] == 0u) continue;
    u32 before = 0;  // the points made before this one (a few hundred at most: a loop, not a scan)
    for (u32 k = 0; k < i; ++k) before += flags[k];
    const u32 slot = n + before;
    if (slot >= p.capacity) continue;  // counted by sph_emit_commit's counter
    const float* lattice = pattern + 4 * std::size_t{i};
    const u32 e = std::bit_cast<u32>(lattice[2]);
    const float* f = emitters + SINEW_SPH_EMITTER_FLOATS * e;
    float* x = points + 4 * std::size_t{slot};
    place(p, f, phase_of(state, e), lattice, x);
    x[3] = p.rest_mass;
    float* w = velocity + 4 * std::size_t{slot};
    for (int a = 0; a < 3; ++a) w[a] = f[7] * f[4 + a];
    w[3] = std::bit_cast<float>(state[0] + before);
  }
}

void sph_emit_commit(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  if (begin != 0 || end == 0) return;
  const auto& p = *static_cast<const SphFlowParams*>(params);
  auto* counts = reinterpret_cast<u32*>(bindings[0]);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* emitters = reinterpret_cast<const float*>(bindings[1]);
  auto* state = reinterpret_cast<u32*>(bindings[2]);
  const auto* flags = reinterpret_cast<const u32*>(bindings[3]);
  u32 total = 0;
  for (u32 i = 0; i < p.pattern; ++i) total += flags[i];
  for (u32 e = 0; e < p.emitters; ++e) {
    const float next = phase_of(state, e) + emitters[SINEW_SPH_EMITTER_FLOATS * e + 3];
    state[SINEW_SPH_STATE_PHASES + e] = std::bit_cast<u32>(next >= 1.0f ? next - 1.0f : next);
  }
  const u32 asked = n + total;
  const u32 made = (asked < p.capacity ? asked : p.capacity) - n;
  state[3] = asked;
  counts[p.count_word] = n + made;
  state[0] += total;
  state[1] += made;
}

}  // namespace sinew::kernels
