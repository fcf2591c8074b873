// ccd_kernels.cpp — CPU reference of the continuous collision kernel
// (kernels/shared/ccd_params.h): the inclusion-based query of
// src/ccd/inclusion_ccd.cpp (Wang et al., TOG 2021) in single precision,
// with the float error bound, written in the GPU twin's order
// (kernels/gpu/ccd_queries.gpu). One query per item. The twin writes its
// search loop without inner loops and keeps a least-start-time per stack
// entry (a device may cap loop iterations); here loops are free, and giving
// up scans the open boxes for the same least start time.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "ccd_params.h"
#include "cpu/cpu_kernels.h"
#include "math/vec4.h"

namespace sinew::kernels {
namespace {

float min2(float a, float b) { return b < a ? b : a; }
float max2(float a, float b) { return a < b ? b : a; }

struct Query {
  float4 x0[4], d[4];
  bool edge_edge = false;
  float threshold[3], close[3];
  float4 normal[5];
  float normal_threshold[5];
  int directions = 0;
};

float4 corner(const Query& q, float t, float u, float v) {
  float4 x[4];
  for (int i = 0; i < 4; ++i) x[i] = q.x0[i] + t * q.d[i];
  float4 base, e1, e2;
  if (!q.edge_edge) {
    base = x[0] - x[1];
    e1 = x[2] - x[1];
    e2 = x[3] - x[1];
  } else {
    base = x[0] - x[2];
    e1 = x[0] - x[1];  // -(a1 - a0): F = (base - u e1) - v e2
    e2 = x[3] - x[2];
  }
  const float4 w = base - u * e1;
  return w - v * e2;
}

// 0 apart, 1 maybe, 2 close at box.t0, 3 close at box.t1 only.
int include(const Query& q, const float (&box)[6]) {
  float4 f[8];
  for (int c = 0; c < 8; ++c)
    f[c] = corner(q, (c & 4) ? box[1] : box[0], (c & 2) ? box[3] : box[2], (c & 1) ? box[5] : box[4]);
  float lo[3] = {f[0].x, f[0].y, f[0].z}, hi[3] = {f[0].x, f[0].y, f[0].z};
  for (int c = 1; c < 8; ++c) {
    const float v[3] = {f[c].x, f[c].y, f[c].z};
    for (int k = 0; k < 3; ++k) lo[k] = min2(lo[k], v[k]), hi[k] = max2(hi[k], v[k]);
  }
  for (int k = 0; k < 3; ++k)
    if (lo[k] > q.threshold[k]) return 0;
  for (int k = 0; k < 3; ++k)
    if (hi[k] < -q.threshold[k]) return 0;
  for (int k = 0; k < q.directions; ++k) {
    float g_lo = dot3(q.normal[k], f[0]), g_hi = g_lo;
    for (int c = 1; c < 8; ++c) {
      const float g = dot3(q.normal[k], f[c]);
      g_lo = min2(g_lo, g), g_hi = max2(g_hi, g);
    }
    if (g_lo > q.normal_threshold[k] || g_hi < -q.normal_threshold[k]) return 0;
  }
  // 2: a close corner at box.t0; 3: only at box.t1 (split in time first;
  // inclusion_ccd.cpp says why the t1 corners do not end the search).
  int late = 1;
  for (int c = 0; c < 8; ++c) {
    const float u = (c & 2) ? box[3] : box[2], v = (c & 1) ? box[5] : box[4];
    if (!q.edge_edge && u + v > 1.0f) continue;
    if (std::abs(f[c].x) <= q.close[0] && std::abs(f[c].y) <= q.close[1] && std::abs(f[c].z) <= q.close[2]) {
      if (c < 4) return 2;
      late = 3;
    }
  }
  return late;
}

}  // namespace

void ccd_queries(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end) {
  const auto& p = *static_cast<const CcdParams*>(params);
  const auto* points = reinterpret_cast<const float*>(bindings[0]);
  const auto* kinds = reinterpret_cast<const std::uint32_t*>(bindings[1]);
  auto* hits = reinterpret_cast<std::uint32_t*>(bindings[2]);
  const float eps = 5.9604645e-8f;  // 2^-24
  for (std::uint32_t index = begin; index < end && index < p.count; ++index) {
    Query q;
    q.edge_edge = kinds[index] != 0u;
    float m[3] = {0.0f, 0.0f, 0.0f};
    float4 ends[4], middle[4];
    for (int i = 0; i < 4; ++i) {
      const float* s = points + 4 * (8 * std::size_t{index} + std::size_t(i));
      const float* e = points + 4 * (8 * std::size_t{index} + 4 + std::size_t(i));
      q.x0[i] = {s[0], s[1], s[2], 0.0f};
      q.d[i] = {e[0] - s[0], e[1] - s[1], e[2] - s[2], 0.0f};
      for (int k = 0; k < 3; ++k) m[k] = max2(m[k], max2(std::abs(s[k]), std::abs(e[k])));
    }
    for (int k = 0; k < 3; ++k) {
      q.threshold[k] = (p.min_separation + (68.0f * eps * m[k] + 1e-36f)) * (1.0f + 8.0f * eps);
      q.close[k] = q.threshold[k] + p.tolerance;
    }
    for (int i = 0; i < 4; ++i) ends[i] = q.x0[i] + q.d[i], middle[i] = q.x0[i] + 0.5f * q.d[i];
    const int e1_from = q.edge_edge ? 0 : 1, e1_to = q.edge_edge ? 1 : 2, e2_from = q.edge_edge ? 2 : 1;
    float4 candidate[5];
    candidate[0] = cross3(q.x0[e1_to] - q.x0[e1_from], q.x0[3] - q.x0[e2_from]);
    candidate[1] = cross3(ends[e1_to] - ends[e1_from], ends[3] - ends[e2_from]);
    const float4 me1 = middle[e1_to] - middle[e1_from], me2 = middle[3] - middle[e2_from];
    const float4 plane = cross3(me1, me2);
    candidate[2] = cross3(plane, me1);
    candidate[3] = cross3(plane, me2);
    candidate[4] = cross3(plane, middle[3] - middle[2]);
    const int candidates = q.edge_edge ? 4 : 5;
    for (int k = 0; k < candidates; ++k) {
      const float4 n = candidate[k];
      const float scale = max2(max2(std::abs(n.x), std::abs(n.y)), std::abs(n.z));
      if (!(scale > 0.0f) || std::isinf(scale)) continue;
      const float4 unit = (1.0f / scale) * n;
      const float norm1 = std::abs(unit.x) + std::abs(unit.y) + std::abs(unit.z);
      const float weighted = std::abs(unit.x) * m[0] + std::abs(unit.y) * m[1] + std::abs(unit.z) * m[2];
      q.normal[q.directions] = unit;
      q.normal_threshold[q.directions] =
          (p.min_separation * norm1 + (92.0f * eps * weighted + 1e-36f)) * (1.0f + 16.0f * eps);
      ++q.directions;
    }
    float speed = 0.0f;
    for (int i = 0; i < 4; ++i) speed = max2(speed, max2(max2(std::abs(q.d[i].x), std::abs(q.d[i].y)), std::abs(q.d[i].z)));
    const auto extent = [](float4 a, float4 b) {
      return max2(max2(max2(std::abs(a.x), std::abs(a.y)), std::abs(a.z)), max2(max2(std::abs(b.x), std::abs(b.y)), std::abs(b.z)));
    };
    const float along_u = extent(q.x0[e1_to] - q.x0[e1_from], ends[e1_to] - ends[e1_from]);
    const float along_v = extent(q.x0[3] - q.x0[e2_from], ends[3] - ends[e2_from]);
    const float finest = 1.1920929e-7f;  // 2^-23
    const float scales[3] = {speed, along_u, along_v};
    float tol[3];
    for (int k = 0; k < 3; ++k) tol[k] = scales[k] > 0.0f ? max2(finest, min2(1.0f, p.tolerance / scales[k])) : 1.0f;

    float stack[SINEW_CCD_STACK][6];
    std::uint32_t top = 1;
    stack[0][0] = 0.0f, stack[0][1] = 1.0f, stack[0][2] = 0.0f, stack[0][3] = 1.0f, stack[0][4] = 0.0f, stack[0][5] = 1.0f;
    float earliest = 2.0f;  // no touch yet
    std::uint32_t boxes = 0, gave_up = 0;
    const auto give_up = [&](const float (&box)[6]) {
      float first = min2(earliest, box[0]);
      for (std::uint32_t b = 0; b < top; ++b) first = min2(first, stack[b][0]);
      earliest = first;
      gave_up = 1;
    };
    while (top > 0) {
      --top;
      float box[6];
      for (int k = 0; k < 6; ++k) box[k] = stack[top][k];
      if (box[0] >= earliest) continue;
      if (boxes == p.max_boxes) {
        give_up(box);
        break;
      }
      ++boxes;
      const int inclusion = include(q, box);
      if (inclusion == 0) continue;
      const float width[3] = {box[1] - box[0], box[3] - box[2], box[5] - box[4]};
      int split = -1;
      if ((box[1] > earliest || inclusion == 3) && width[0] > tol[0]) {
        split = 0;
      } else {
        float widest = 1.0f;
        for (int k = 0; k < 3; ++k) {
          const float ratio = width[k] / tol[k];
          if (width[k] > tol[k] && ratio > widest) widest = ratio, split = k;
        }
      }
      if (split < 0 || inclusion == 2) {
        earliest = box[0];
        continue;
      }
      if (top + 2 > SINEW_CCD_STACK) {
        give_up(box);
        break;
      }
      const float mid = 0.5f * (box[2 * split] + box[2 * split + 1]);
      for (int half = 1; half >= 0; --half) {
        float child[6];
        for (int k = 0; k < 6; ++k) child[k] = box[k];
        if (half == 1) child[2 * split] = mid;
        else child[2 * split + 1] = mid;
        if (!q.edge_edge && child[2] + child[4] > 1.0f) continue;
        for (int k = 0; k < 6; ++k) stack[top][k] = child[k];
        ++top;
      }
    }
    const std::uint32_t touch = earliest <= 1.0f ? 1u : 0u;
    hits[4 * std::size_t{index}] = touch;
    hits[4 * std::size_t{index} + 1] = std::bit_cast<std::uint32_t>(touch ? earliest : 1.0f);
    hits[4 * std::size_t{index} + 2] = gave_up;
    hits[4 * std::size_t{index} + 3] = boxes;
  }
}

}  // namespace sinew::kernels
