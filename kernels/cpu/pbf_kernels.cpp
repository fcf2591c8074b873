// pbf_kernels.cpp — CPU reference of position-based fluids
// (kernels/shared/pbf_params.h; Macklin and Müller 2013): prediction, the
// density constraints' lambdas, their position corrections, and the
// velocities from the positions, on the neighbour grid in the order of
// nbr_query, each float operation in the order of the GPU twins
// (kernels/gpu/pbf_*.gpu).
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "cpu/cpu_kernels.h"
#include "cpu/neighbour_cells.h"
#include "cpu/sph_spline.h"
#include "pbf_params.h"

namespace sinew::kernels {
namespace {

using u32 = std::uint32_t;
using cells::visit_cells;

}  // namespace

void pbf_predict(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const PbfParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  auto* points = reinterpret_cast<float*>(bindings[1]);
  auto* velocity = reinterpret_cast<float*>(bindings[2]);
  auto* previous = reinterpret_cast<float*>(bindings[3]);
  for (u32 i = begin; i < end && i < n; ++i) {
    float* x = points + 4 * std::size_t{i};
    float* v = velocity + 4 * std::size_t{i};
    std::memcpy(previous + 4 * std::size_t{i}, x, 16);
    if (!(x[3] > 0.0f)) continue;  // a boundary particle
    v[0] = v[0] + p.dt * p.gx;
    v[1] = v[1] + p.dt * p.gy;
    v[2] = v[2] + p.dt * p.gz;
    x[0] = x[0] + p.dt * v[0];
    x[1] = x[1] + p.dt * v[1];
    x[2] = x[2] + p.dt * v[2];
  }
}

void pbf_lambda(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const PbfParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  auto* density = reinterpret_cast<float*>(bindings[4]);
  auto* lambda = reinterpret_cast<float*>(bindings[5]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    if (!(x[3] > 0.0f)) {
      density[s] = p.rho0;
      lambda[s] = 0.0f;
      continue;
    }
    float sum = 0.0f, gx = 0.0f, gy = 0.0f, gz = 0.0f, others = 0.0f;
    visit_cells(cells, ranges, p.table_mask, cells + 4 * std::size_t{s}, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      const float ex = x[0] - y[0], ey = x[1] - y[1], ez = x[2] - y[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (!(d2 < p.h2)) return;
      const float r = std::sqrt(d2);
      const float mass = std::fabs(y[3]);
      sum = sum + mass * spline::shape(r * p.inv_l);
      if (!(d2 > 0.0f)) return;  // itself: no direction
      const float c = ((mass * p.inv_rho0) * p.grad_sigma) * spline::slope(r * p.inv_l) / r;  // grad_j C_i = -c e
      gx = gx + c * ex;
      gy = gy + c * ey;
      gz = gz + c * ez;
      if (y[3] > 0.0f) others = others + ((c * c) * d2) / y[3];
    });
    const float rho = p.sigma * sum;
    density[s] = rho;
    const float compression = rho * p.inv_rho0 - 1.0f;
    const float constraint = compression > 0.0f ? compression : 0.0f;
    const float denominator = ((gx * gx + gy * gy) + gz * gz) / x[3] + others + p.epsilon;
    lambda[s] = -constraint / denominator;
  }
}

void pbf_delta(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const PbfParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* lambda = reinterpret_cast<const float*>(bindings[4]);
  auto* moved = reinterpret_cast<float*>(bindings[5]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    float* out = moved + 4 * std::size_t{s};
    std::memcpy(out, x, 16);
    if (!(x[3] > 0.0f)) continue;
    const float own = lambda[s];
    float dx = 0.0f, dy = 0.0f, dz = 0.0f;
    visit_cells(cells, ranges, p.table_mask, cells + 4 * std::size_t{s}, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      const float ex = x[0] - y[0], ey = x[1] - y[1], ez = x[2] - y[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (!(d2 < p.h2) || !(d2 > 0.0f)) return;
      const float r = std::sqrt(d2);
      const float gw = p.grad_sigma * spline::slope(r * p.inv_l) / r;
      const float k = (std::fabs(y[3]) * own) / x[3] + lambda[t];  // a boundary particle's lambda is 0
      const float c = (k * p.inv_rho0) * gw;
      dx = dx + c * ex;
      dy = dy + c * ey;
      dz = dz + c * ez;
    });
    out[0] = x[0] + dx;
    out[1] = x[1] + dy;
    out[2] = x[2] + dz;
  }
}

void pbf_finish(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const PbfParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* sorted_points = reinterpret_cast<const float*>(bindings[1]);
  const auto* order = reinterpret_cast<const u32*>(bindings[2]);
  const auto* previous = reinterpret_cast<const float*>(bindings[3]);
  const auto* sorted_velocity = reinterpret_cast<const float*>(bindings[4]);
  auto* points = reinterpret_cast<float*>(bindings[5]);
  auto* velocity = reinterpret_cast<float*>(bindings[6]);
  auto* speed2 = reinterpret_cast<float*>(bindings[7]);
  auto* pressure = reinterpret_cast<float*>(bindings[8]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = sorted_points + 4 * std::size_t{s};
    const float* w = sorted_velocity + 4 * std::size_t{s};
    std::memcpy(points + 4 * std::size_t{s}, x, 16);
    float* v = velocity + 4 * std::size_t{s};
    pressure[s] = 0.0f;
    if (!(x[3] > 0.0f)) {
      std::memcpy(v, w, 16);
      speed2[s] = 0.0f;
      continue;
    }
    const float* before = previous + 4 * std::size_t{order[s]};
    v[0] = (x[0] - before[0]) * p.inv_dt;
    v[1] = (x[1] - before[1]) * p.inv_dt;
    v[2] = (x[2] - before[2]) * p.inv_dt;
    v[3] = w[3];  // the id's bits
    speed2[s] = (v[0] * v[0] + v[1] * v[1]) + v[2] * v[2];
  }
}

}  // namespace sinew::kernels
