// sph_kernels_avx2.cpp — the fluid's density and step (sph_kernels.cpp,
// kernels/shared/sph_params.h) with each neighbour's term computed eight
// candidates at a time with AVX2, for the CPU backend's speed. Bitwise
// equal to the scalar reference: the same cells in the same order, every
// term rounded as the reference rounds it (no fused multiply-add, correctly
// rounded square roots and divisions), and the terms summed one by one in
// candidate order, so no sum is reassociated
// (SphSolver.TheAvx2KernelsAreBitwiseTheReference compares them bit for bit).
//
// Each kernel puts up to eight particles of one cell in the lanes and
// broadcasts each shared candidate to them. Tried and measured slower
// (README, "SPH fluid"): candidates in the lanes for the density and step,
// and packing the neighbours first to compute terms only for them, with
// each cell's candidates copied into arrays of each field.
//
// Only the functions in the target("avx2") region use AVX2; the CPU backend
// calls these only where cpu_has_avx2(). The scalar helpers below (the
// spline, Tait's equation, the bucket hash) are deliberate copies of the
// reference's: an inline function shared with a file built without AVX2
// could be emitted here with AVX2 instructions and picked by the linker
// for every caller. (avx2_cells.h is shared only by AVX2 files.)
#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "cpu/avx2_cells.h"
#include "cpu/avx2_lanes.h"
#include "cpu/sph_kernels.h"
#include "sph_params.h"

namespace sinew::kernels {

#pragma GCC push_options
#pragma GCC target("avx2")

namespace {

using u32 = std::uint32_t;

u32 count_of(const SphParams& p, const std::byte* counts) {
  const u32 stored = reinterpret_cast<const u32*>(counts)[p.count_word];
  return stored < p.capacity ? stored : p.capacity;
}

__m256 select(__m256 when, __m256 yes, __m256 no) { return _mm256_blendv_ps(no, yes, when); }

// The cubic spline's w(q) and w'(q) (sph_params.h), lane by lane.
__m256 cubic_lanes(__m256 q) {
  using namespace avx2;
  const __m256 near = sub(_mm256_set1_ps(1.0f), mul(mul(_mm256_set1_ps(1.5f), q), q));
  const __m256 inner = add(near, mul(mul(mul(_mm256_set1_ps(0.75f), q), q), q));
  const __m256 t = sub(_mm256_set1_ps(2.0f), q);
  const __m256 outer = mul(mul(mul(_mm256_set1_ps(0.25f), t), t), t);
  return select(_mm256_cmp_ps(q, _mm256_set1_ps(1.0f), _CMP_LT_OQ), inner, outer);
}
__m256 cubic_slope_lanes(__m256 q) {
  using namespace avx2;
  const __m256 inner = sub(mul(mul(_mm256_set1_ps(2.25f), q), q), mul(_mm256_set1_ps(3.0f), q));
  const __m256 t = sub(_mm256_set1_ps(2.0f), q);
  const __m256 outer = mul(mul(_mm256_set1_ps(-0.75f), t), t);
  return select(_mm256_cmp_ps(q, _mm256_set1_ps(1.0f), _CMP_LT_OQ), inner, outer);
}

// Tait's equation, negative pressure taken as 0 (sph_params.h).
float tait_one(const SphParams& p, float rho) {
  const float r = rho / p.rho0;
  const float r2 = r * r;
  const float r4 = r2 * r2;
  const float r7 = r4 * r2 * r;
  const float pressure = p.stiffness * (r7 - 1.0f);
  return pressure > 0.0f ? pressure : 0.0f;
}

// Whether the particles s .. s + k - 1 are all boundary particles (w < 0,
// or not > 0 as the kernels test it). A boundary particle needs no sums in
// sph_density and sph_step, and on a sampled organ most cells hold only
// boundary particles (blood_on_organ: 48,168 boundary against a few
// hundred fluid particles).
bool all_boundary(const float* points, u32 s, u32 k) {
  for (u32 j = 0; j < k; ++j)
    if (points[4 * std::size_t{s + j} + 3] > 0.0f) return false;
  return true;
}

}  // namespace

void sph_density_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  using namespace avx2;
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  auto* density = reinterpret_cast<float*>(bindings[4]);
  const __m256 h2 = _mm256_set1_ps(p.h2), inv_l = _mm256_set1_ps(p.inv_l), zero = _mm256_setzero_ps();
  const u32 last = end < n ? end : n;
  avx2::CellRuns runs;
  // Up to eight particles of one cell at a time, one a lane: they share
  // their candidates, each read once and broadcast to every lane, and each
  // lane sums its terms in candidate order. A lane a candidate is not
  // within the support of adds +0, which leaves its sum (>= +0) bitwise as
  // it was, so each particle's density is the reference's.
  for (u32 s = begin; s < last;) {
    const int* c = cells + 4 * std::size_t{s};
    const u32 k = avx2::same_cell_run(cells, s, last);
    if (all_boundary(points, s, k)) {  // what the lanes would write, without their sums
      for (u32 j = 0; j < k; ++j) density[s + j] = p.rho0;
      s += k;
      continue;
    }
    u32 index[8];
    for (u32 j = 0; j < 8; ++j) index[j] = s + (j < k ? j : 0);
    const Lanes x = load_particles(points, index);
    runs.look_up(c, cells, ranges, p.table_mask);
    __m256 sum = zero;
    for (const avx2::CellRuns::Run& r : runs.runs)
      for (u32 t = r.begin; t < r.end; ++t) {
        const float* y = points + 4 * std::size_t{t};
        if (r.mixed) {
          const int* ct = cells + 4 * std::size_t{t};
          if (!(ct[0] == r.cx && ct[1] == r.cy && ct[2] == r.cz)) continue;
        }
        const __m256 ex = sub(_mm256_set1_ps(y[0]), x.x), ey = sub(_mm256_set1_ps(y[1]), x.y),
                     ez = sub(_mm256_set1_ps(y[2]), x.z);
        const __m256 d2 = add(add(mul(ex, ex), mul(ey, ey)), mul(ez, ez));
        const __m256 inside = _mm256_cmp_ps(d2, h2, _CMP_LT_OQ);
        if (_mm256_movemask_ps(inside) == 0) continue;
        const __m256 term = mul(_mm256_set1_ps(std::fabs(y[3])), cubic_lanes(mul(_mm256_sqrt_ps(d2), inv_l)));
        sum = add(sum, _mm256_and_ps(term, inside));
      }
    alignas(32) float rho[8];
    _mm256_store_ps(rho, mul(_mm256_set1_ps(p.sigma), sum));
    for (u32 j = 0; j < k; ++j) density[s + j] = points[4 * std::size_t{s + j} + 3] < 0.0f ? p.rho0 : rho[j];
    s += k;
  }
}

void sph_step_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  using namespace avx2;
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* density = reinterpret_cast<const float*>(bindings[4]);
  const auto* sorted_velocity = reinterpret_cast<const float*>(bindings[5]);
  auto* next_points = reinterpret_cast<float*>(bindings[6]);
  auto* next_velocity = reinterpret_cast<float*>(bindings[7]);
  auto* pressure = reinterpret_cast<float*>(bindings[8]);
  auto* speed2 = reinterpret_cast<float*>(bindings[9]);
  const __m256 h2 = _mm256_set1_ps(p.h2), inv_l = _mm256_set1_ps(p.inv_l), zero = _mm256_setzero_ps();
  const __m256 grad_sigma = _mm256_set1_ps(p.grad_sigma), eta2 = _mm256_set1_ps(p.eta2), half = _mm256_set1_ps(0.5f);
  const __m256 minus_viscosity = _mm256_set1_ps(-p.viscosity), minus_boundary = _mm256_set1_ps(-p.boundary_viscosity);
  const u32 last = end < n ? end : n;
  avx2::CellRuns runs;
  // As sph_density_avx2: up to eight particles of one cell in the lanes,
  // each candidate read once and broadcast; a lane it is not a neighbour
  // of subtracts +0, which leaves every float bitwise as it was.
  for (u32 s = begin; s < last;) {
    const int* c = cells + 4 * std::size_t{s};
    const u32 k = avx2::same_cell_run(cells, s, last);
    if (all_boundary(points, s, k)) {  // boundary particles stay: the reference's outputs, without the sums
      for (u32 i = s; i < s + k; ++i) {
        pressure[i] = tait_one(p, density[i]);
        std::memcpy(next_points + 4 * std::size_t{i}, points + 4 * std::size_t{i}, 16);
        std::memcpy(next_velocity + 4 * std::size_t{i}, sorted_velocity + 4 * std::size_t{i}, 16);
        speed2[i] = 0.0f;
      }
      s += k;
      continue;
    }
    alignas(32) float rho_of[8], own_of[8];
    u32 index[8];
    for (u32 j = 0; j < 8; ++j) {
      index[j] = s + (j < k ? j : 0);
      const float rho = density[index[j]];
      const float pi = tait_one(p, rho);
      if (j < k) pressure[s + j] = pi;
      rho_of[j] = rho;
      own_of[j] = pi / (rho * rho);
    }
    const Lanes x = load_particles(points, index);
    const Lanes v = load_particles(sorted_velocity, index);
    const __m256 rho_i = _mm256_load_ps(rho_of), own_i = _mm256_load_ps(own_of);
    runs.look_up(c, cells, ranges, p.table_mask);
    __m256 ax = zero, ay = zero, az = zero;
    for (const avx2::CellRuns::Run& r : runs.runs)
      for (u32 t = r.begin; t < r.end; ++t) {
        const float* y = points + 4 * std::size_t{t};
        if (r.mixed) {
          const int* ct = cells + 4 * std::size_t{t};
          if (!(ct[0] == r.cx && ct[1] == r.cy && ct[2] == r.cz)) continue;
        }
        const __m256 ex = sub(x.x, _mm256_set1_ps(y[0])), ey = sub(x.y, _mm256_set1_ps(y[1])),
                     ez = sub(x.z, _mm256_set1_ps(y[2]));
        const __m256 d2 = add(add(mul(ex, ex), mul(ey, ey)), mul(ez, ez));
        const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(d2, h2, _CMP_LT_OQ), _mm256_cmp_ps(d2, zero, _CMP_GT_OQ));
        if (_mm256_movemask_ps(inside) == 0) continue;
        const __m256 dist = _mm256_sqrt_ps(d2);
        const __m256 gw = _mm256_div_ps(mul(grad_sigma, cubic_slope_lanes(mul(dist, inv_l))), dist);
        const float* w = sorted_velocity + 4 * std::size_t{t};
        const __m256 approach = add(add(mul(sub(v.x, _mm256_set1_ps(w[0])), ex), mul(sub(v.y, _mm256_set1_ps(w[1])), ey)),
                                    mul(sub(v.z, _mm256_set1_ps(w[2])), ez));
        const __m256 closing = _mm256_cmp_ps(approach, zero, _CMP_LT_OQ);
        const __m256 d2_eta = add(d2, eta2);
        __m256 factor;
        if (y[3] > 0.0f) {  // a fluid neighbour: both pressures and the viscosity
          const float rho_j = density[t];
          const __m256 rj = _mm256_set1_ps(rho_j);
          const __m256 visc = select(
              closing, _mm256_div_ps(mul(minus_viscosity, approach), mul(mul(half, add(rho_i, rj)), d2_eta)), zero);
          const float pj = tait_one(p, rho_j) / (rho_j * rho_j);
          factor = mul(_mm256_set1_ps(y[3]), add(add(own_i, _mm256_set1_ps(pj)), visc));
        } else {  // a boundary neighbour: its pressure mirrored, and its own viscosity
          const __m256 visc = select(closing, _mm256_div_ps(mul(minus_boundary, approach), mul(rho_i, d2_eta)), zero);
          factor = mul(_mm256_set1_ps(-y[3]), add(own_i, visc));
        }
        const __m256 f = mul(factor, gw);
        ax = sub(ax, _mm256_and_ps(mul(f, ex), inside));
        ay = sub(ay, _mm256_and_ps(mul(f, ey), inside));
        az = sub(az, _mm256_and_ps(mul(f, ez), inside));
      }
    alignas(32) float fx[8], fy[8], fz[8];
    _mm256_store_ps(fx, ax);
    _mm256_store_ps(fy, ay);
    _mm256_store_ps(fz, az);
    for (u32 j = 0; j < k; ++j) {
      const u32 i = s + j;
      const float* xi = points + 4 * std::size_t{i};
      const float* vi = sorted_velocity + 4 * std::size_t{i};
      float* xn = next_points + 4 * std::size_t{i};
      float* vn = next_velocity + 4 * std::size_t{i};
      if (!(xi[3] > 0.0f)) {  // a boundary particle stays
        std::memcpy(xn, xi, 16);
        std::memcpy(vn, vi, 16);
        speed2[i] = 0.0f;
        continue;
      }
      const float gx = fx[j] + p.gx, gy = fy[j] + p.gy, gz = fz[j] + p.gz;
      vn[0] = vi[0] + p.dt * gx;
      vn[1] = vi[1] + p.dt * gy;
      vn[2] = vi[2] + p.dt * gz;
      vn[3] = vi[3];  // the id's bits
      speed2[i] = (vn[0] * vn[0] + vn[1] * vn[1]) + vn[2] * vn[2];
      xn[0] = xi[0] + p.dt * vn[0];
      xn[1] = xi[1] + p.dt * vn[1];
      xn[2] = xi[2] + p.dt * vn[2];
      xn[3] = xi[3];
    }
    s += k;
  }
}

void sph_boundary_force_avx2(const void* params, std::byte* const* bindings, std::uint32_t begin,
                             std::uint32_t end) {
  using namespace avx2;
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* density = reinterpret_cast<const float*>(bindings[4]);
  const auto* sorted_velocity = reinterpret_cast<const float*>(bindings[5]);
  auto* impulse = reinterpret_cast<float*>(bindings[6]);
  const auto* near = reinterpret_cast<const u32*>(bindings[7]);
  const __m256 h2 = _mm256_set1_ps(p.h2), inv_l = _mm256_set1_ps(p.inv_l), zero = _mm256_setzero_ps();
  const __m256 grad_sigma = _mm256_set1_ps(p.grad_sigma), eta2 = _mm256_set1_ps(p.eta2);
  const __m256 minus_boundary = _mm256_set1_ps(-p.boundary_viscosity);
  const u32 last = end < n ? end : n;
  avx2::CellRuns runs;
  // As sph_step_avx2: up to eight particles of one cell in the lanes (the
  // fluid ones among them are skipped at the end), each fluid candidate
  // broadcast; a lane it is not a neighbour of adds +0, which leaves every
  // float bitwise as it was.
  for (u32 s = begin; s < last;) {
    const int* c = cells + 4 * std::size_t{s};
    u32 k = 1;
    bool any_boundary = !(points[4 * std::size_t{s} + 3] > 0.0f);
    while (k < 8 && s + k < last && cells[4 * std::size_t{s + k}] == c[0] && cells[4 * std::size_t{s + k} + 1] == c[1] &&
           cells[4 * std::size_t{s + k} + 2] == c[2]) {
      any_boundary = any_boundary || !(points[4 * std::size_t{s + k} + 3] > 0.0f);
      ++k;
    }
    // No boundary particle, or no fluid in the 27 cells around (sph_fluid_cells).
    if (!any_boundary || near[bucket_of(c[0], c[1], c[2], p.table_mask)] == 0u) {
      s += k;
      continue;
    }
    u32 index[8];
    for (u32 j = 0; j < 8; ++j) index[j] = s + (j < k ? j : 0);
    const Lanes x = load_particles(points, index);
    const Lanes w = load_particles(sorted_velocity, index);
    const __m256 psi = negate(x.w);
    runs.look_up(c, cells, ranges, p.table_mask);
    __m256 fx = zero, fy = zero, fz = zero;
    // The candidates that are fluid particles, in order: on a sampled organ
    // most runs hold only boundary particles, so their w's are tested eight
    // at a time (a gather) and the runs skipped whole.
    const __m256i w_offsets = _mm256_setr_epi32(3, 7, 11, 15, 19, 23, 27, 31);
    const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for (const avx2::CellRuns::Run& r : runs.runs)
      for (u32 t0 = r.begin; t0 < r.end; t0 += 8) {
        const u32 count = r.end - t0 < 8 ? r.end - t0 : 8;
        const __m256 valid = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(int(count)), lane_index));
        const __m256 ws = _mm256_mask_i32gather_ps(zero, points + 4 * std::size_t{t0}, w_offsets, valid, 4);
        unsigned fluid = unsigned(_mm256_movemask_ps(_mm256_cmp_ps(ws, zero, _CMP_GT_OQ)));
        for (; fluid != 0; fluid &= fluid - 1) {
          const u32 t = t0 + u32(__builtin_ctz(fluid));
          const float* y = points + 4 * std::size_t{t};
          if (r.mixed) {
            const int* ct = cells + 4 * std::size_t{t};
            if (!(ct[0] == r.cx && ct[1] == r.cy && ct[2] == r.cz)) continue;
          }
          const __m256 ex = sub(_mm256_set1_ps(y[0]), x.x), ey = sub(_mm256_set1_ps(y[1]), x.y),
                       ez = sub(_mm256_set1_ps(y[2]), x.z);
          const __m256 d2 = add(add(mul(ex, ex), mul(ey, ey)), mul(ez, ez));
          const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(d2, h2, _CMP_LT_OQ), _mm256_cmp_ps(d2, zero, _CMP_GT_OQ));
          if (_mm256_movemask_ps(inside) == 0) continue;
          const __m256 dist = _mm256_sqrt_ps(d2);
          const __m256 gw = _mm256_div_ps(mul(grad_sigma, cubic_slope_lanes(mul(dist, inv_l))), dist);
          const float* v = sorted_velocity + 4 * std::size_t{t};
          const __m256 approach =
              add(add(mul(sub(_mm256_set1_ps(v[0]), w.x), ex), mul(sub(_mm256_set1_ps(v[1]), w.y), ey)),
                  mul(sub(_mm256_set1_ps(v[2]), w.z), ez));
          const float rho = density[t];
          const __m256 rho_j = _mm256_set1_ps(rho);
          const __m256 own = _mm256_set1_ps(tait_one(p, rho) / (rho * rho));
          const __m256 visc = select(_mm256_cmp_ps(approach, zero, _CMP_LT_OQ),
                                     _mm256_div_ps(mul(minus_boundary, approach), mul(rho_j, add(d2, eta2))), zero);
          const __m256 f = mul(_mm256_set1_ps(y[3]), mul(mul(psi, add(own, visc)), gw));
          fx = add(fx, _mm256_and_ps(mul(f, ex), inside));
          fy = add(fy, _mm256_and_ps(mul(f, ey), inside));
          fz = add(fz, _mm256_and_ps(mul(f, ez), inside));
        }
      }
    alignas(32) float gx[8], gy[8], gz[8];
    _mm256_store_ps(gx, fx);
    _mm256_store_ps(gy, fy);
    _mm256_store_ps(gz, fz);
    for (u32 j = 0; j < k; ++j) {
      const float* xi = points + 4 * std::size_t{s + j};
      if (xi[3] > 0.0f) continue;  // a fluid particle
      u32 id;
      std::memcpy(&id, sorted_velocity + 4 * std::size_t{s + j} + 3, 4);
      float* out = impulse + 4 * std::size_t{id & 0x7fffffffu};
      out[0] = out[0] + p.dt * gx[j];
      out[1] = out[1] + p.dt * gy[j];
      out[2] = out[2] + p.dt * gz[j];
    }
    s += k;
  }
}

#pragma GCC pop_options

}  // namespace sinew::kernels
