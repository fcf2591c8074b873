// sph_kernels.cpp — CPU reference of the fluid's kernels
// (kernels/shared/sph_params.h: Monaghan's cubic spline, Tait's equation,
// Akinci's boundary particles). They visit the neighbour grid's cells in the order of
// nbr_query (neighbour_kernels.cpp) and round every float operation in the
// GPU twins' order (kernels/gpu/sph_*.gpu).
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "cpu/cpu_kernels.h"
#include "cpu/neighbour_cells.h"
#include "cpu/sph_spline.h"
#include "sph_params.h"

namespace sinew::kernels {
namespace {

using u32 = std::uint32_t;
using cells::visit_cells;

}  // namespace

void sph_density(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  auto* density = reinterpret_cast<float*>(bindings[4]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    if (x[3] < 0.0f) {  // a boundary particle
      density[s] = p.rho0;
      continue;
    }
    const int* c = cells + 4 * std::size_t{s};
    float sum = 0.0f;
    visit_cells(cells, ranges, p.table_mask, c, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      const float ex = y[0] - x[0], ey = y[1] - x[1], ez = y[2] - x[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (!(d2 < p.h2)) return;
      sum = sum + std::fabs(y[3]) * spline::shape(std::sqrt(d2) * p.inv_l);
    });
    density[s] = p.sigma * sum;
  }
}

void sph_gather(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* order = reinterpret_cast<const u32*>(bindings[1]);
  const auto* velocity = reinterpret_cast<const float*>(bindings[2]);
  auto* sorted_velocity = reinterpret_cast<float*>(bindings[3]);
  for (u32 s = begin; s < end && s < n; ++s)
    std::memcpy(sorted_velocity + 4 * std::size_t{s}, velocity + 4 * std::size_t{order[s]}, 16);
}

namespace {

// Tait's equation, negative pressure taken as 0 (sph_params.h).
float tait(const SphParams& p, float rho) {
  const float r = rho / p.rho0;
  const float r2 = r * r;
  const float r4 = r2 * r2;
  const float r7 = r4 * r2 * r;
  const float pressure = p.stiffness * (r7 - 1.0f);
  return pressure > 0.0f ? pressure : 0.0f;
}

}  // namespace

void sph_step(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* density = reinterpret_cast<const float*>(bindings[4]);
  const auto* sorted_velocity = reinterpret_cast<const float*>(bindings[5]);
  auto* next_points = reinterpret_cast<float*>(bindings[6]);
  auto* next_velocity = reinterpret_cast<float*>(bindings[7]);
  auto* pressure = reinterpret_cast<float*>(bindings[8]);
  auto* speed2 = reinterpret_cast<float*>(bindings[9]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    const float* v = sorted_velocity + 4 * std::size_t{s};
    const float rho = density[s];
    const float pi = tait(p, rho);
    pressure[s] = pi;
    if (!(x[3] > 0.0f)) {  // a boundary particle stays
      std::memcpy(next_points + 4 * std::size_t{s}, x, 16);
      std::memcpy(next_velocity + 4 * std::size_t{s}, v, 16);
      speed2[s] = 0.0f;
      continue;
    }
    const float own = pi / (rho * rho);
    const int* c = cells + 4 * std::size_t{s};
    float ax = 0.0f, ay = 0.0f, az = 0.0f;
    visit_cells(cells, ranges, p.table_mask, c, [&](u32 t) {
      if (t == s) return;
      const float* y = points + 4 * std::size_t{t};
      const float ex = x[0] - y[0], ey = x[1] - y[1], ez = x[2] - y[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (!(d2 < p.h2) || !(d2 > 0.0f)) return;  // beyond the support, or no direction
      const float r = std::sqrt(d2);
      const float gw = p.grad_sigma * spline::slope(r * p.inv_l) / r;  // grad W = gw (x_i - x_j)
      float factor;
      if (y[3] > 0.0f) {  // a fluid particle: pressure and viscosity
        const float* w = sorted_velocity + 4 * std::size_t{t};
        const float ux = v[0] - w[0], uy = v[1] - w[1], uz = v[2] - w[2];
        const float approach = ux * ex + uy * ey + uz * ez;
        const float rho_j = density[t];
        const float visc = approach < 0.0f ? -p.viscosity * approach / ((0.5f * (rho + rho_j)) * (d2 + p.eta2)) : 0.0f;
        const float pj = tait(p, rho_j);
        factor = y[3] * (own + pj / (rho_j * rho_j) + visc);
      } else {  // a boundary particle: its pressure mirrored, and its own viscosity
        const float* w = sorted_velocity + 4 * std::size_t{t};
        const float ux = v[0] - w[0], uy = v[1] - w[1], uz = v[2] - w[2];
        const float approach = ux * ex + uy * ey + uz * ez;
        const float visc = approach < 0.0f ? -p.boundary_viscosity * approach / (rho * (d2 + p.eta2)) : 0.0f;
        factor = -y[3] * (own + visc);
      }
      const float f = factor * gw;
      ax = ax - f * ex;
      ay = ay - f * ey;
      az = az - f * ez;
    });
    ax = ax + p.gx;
    ay = ay + p.gy;
    az = az + p.gz;
    float* xn = next_points + 4 * std::size_t{s};
    float* vn = next_velocity + 4 * std::size_t{s};
    vn[0] = v[0] + p.dt * ax;
    vn[1] = v[1] + p.dt * ay;
    vn[2] = v[2] + p.dt * az;
    vn[3] = v[3];  // the id's bits
    speed2[s] = (vn[0] * vn[0] + vn[1] * vn[1]) + vn[2] * vn[2];
    xn[0] = x[0] + p.dt * vn[0];
    xn[1] = x[1] + p.dt * vn[1];
    xn[2] = x[2] + p.dt * vn[2];
    xn[3] = x[3];
  }
}

void sph_fluid_cells(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  auto* near = reinterpret_cast<u32*>(bindings[3]);
  for (u32 s = begin; s < end && s < n; ++s) {
    if (!(points[4 * std::size_t{s} + 3] > 0.0f)) continue;  // a boundary particle
    const int* c = cells + 4 * std::size_t{s};
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) near[cells::bucket_of(c[0] + dx, c[1] + dy, c[2] + dz, p.table_mask)] = 1u;
  }
}

void sph_boundary_force(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const SphParams*>(params);
  const u32 n = cells::count_of(p, bindings[0]);
  const auto* points = reinterpret_cast<const float*>(bindings[1]);
  const auto* cells = reinterpret_cast<const int*>(bindings[2]);
  const auto* ranges = reinterpret_cast<const u32*>(bindings[3]);
  const auto* density = reinterpret_cast<const float*>(bindings[4]);
  const auto* sorted_velocity = reinterpret_cast<const float*>(bindings[5]);
  auto* impulse = reinterpret_cast<float*>(bindings[6]);
  const auto* near = reinterpret_cast<const u32*>(bindings[7]);
  for (u32 s = begin; s < end && s < n; ++s) {
    const float* x = points + 4 * std::size_t{s};
    if (x[3] > 0.0f) continue;  // a fluid particle
    const int* own = cells + 4 * std::size_t{s};
    if (near[cells::bucket_of(own[0], own[1], own[2], p.table_mask)] == 0u) continue;  // no fluid within h
    const float* w = sorted_velocity + 4 * std::size_t{s};
    const float psi = -x[3];
    const int* c = cells + 4 * std::size_t{s};
    float fx = 0.0f, fy = 0.0f, fz = 0.0f;
    visit_cells(cells, ranges, p.table_mask, c, [&](u32 t) {
      const float* y = points + 4 * std::size_t{t};
      if (!(y[3] > 0.0f)) return;  // boundary particles do not push each other
      // sph_step's terms for fluid particle i = t against this one, in its order.
      const float ex = y[0] - x[0], ey = y[1] - x[1], ez = y[2] - x[2];
      const float d2 = ex * ex + ey * ey + ez * ez;
      if (!(d2 < p.h2) || !(d2 > 0.0f)) return;
      const float r = std::sqrt(d2);
      const float gw = p.grad_sigma * spline::slope(r * p.inv_l) / r;
      const float* v = sorted_velocity + 4 * std::size_t{t};
      const float ux = v[0] - w[0], uy = v[1] - w[1], uz = v[2] - w[2];
      const float approach = ux * ex + uy * ey + uz * ez;
      const float rho = density[t];
      const float own = tait(p, rho) / (rho * rho);
      const float visc = approach < 0.0f ? -p.boundary_viscosity * approach / (rho * (d2 + p.eta2)) : 0.0f;
      const float f = y[3] * ((psi * (own + visc)) * gw);
      fx = fx + f * ex;
      fy = fy + f * ey;
      fz = fz + f * ez;
    });
    const u32 id = std::bit_cast<u32>(w[3]) & 0x7fffffffu;
    float* out = impulse + 4 * std::size_t{id};
    out[0] = out[0] + p.dt * fx;
    out[1] = out[1] + p.dt * fy;
    out[2] = out[2] + p.dt * fz;
  }
}

}  // namespace sinew::kernels
