// shape_meshes.cpp — see shape_meshes.h.
#include "view/shape_meshes.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sinew::view {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// A surface of revolution about y: rings of (radius, y, normal's radial
// part, normal's y) joined by quads; the first and last rings may have
// radius 0 (poles, tips).
struct Ring {
  float r, y, nr, ny;
};
void revolve(const std::vector<Ring>& rings, int slices, MeshData& out) {
  const auto base = static_cast<std::uint32_t>(out.vertices.size() / 9);
  for (const Ring& ring : rings)
    for (int s = 0; s <= slices; ++s) {
      const float a = 2 * kPi * s / slices, c = std::cos(a), sn = std::sin(a);
      out.add({ring.r * c, ring.y, ring.r * sn}, normalize({ring.nr * c, ring.ny, ring.nr * sn}));
    }
  const auto row = static_cast<std::uint32_t>(slices + 1);
  for (std::uint32_t i = 0; i + 1 < rings.size(); ++i)
    for (std::uint32_t s = 0; s < static_cast<std::uint32_t>(slices); ++s) {
      const std::uint32_t a = base + i * row + s, b = a + row;
      out.indices.insert(out.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
}

// A hemisphere's rings from the equator (at y0) to the pole, towards `sign` y.
void add_cap(std::vector<Ring>& rings, float radius, float y0, float sign, int stacks, bool from_pole) {
  std::vector<Ring> cap;
  for (int i = 0; i <= stacks; ++i) {
    const float a = 0.5f * kPi * i / stacks;  // 0 at the equator
    cap.push_back({radius * std::cos(a), y0 + sign * radius * std::sin(a), std::cos(a), sign * std::sin(a)});
  }
  if (from_pole) std::reverse(cap.begin(), cap.end());
  rings.insert(rings.end(), cap.begin(), cap.end());
}

}  // namespace

std::uint32_t MeshData::add(V3 p, V3 n, V3 c) {
  vertices.insert(vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z, c.x, c.y, c.z});
  return static_cast<std::uint32_t>(vertices.size() / 9 - 1);
}

MeshData unit_sphere(int slices, int stacks) { return capsule(1.0, 0.0, slices, stacks / 2); }

MeshData capsule(double radius, double half_height, int slices, int stacks) {
  const auto r = static_cast<float>(radius), h = static_cast<float>(half_height);
  std::vector<Ring> rings;
  add_cap(rings, r, -h, -1.0f, stacks, true);  // bottom pole up to the equator
  add_cap(rings, r, h, 1.0f, stacks, false);   // top equator up to the pole
  MeshData out;
  revolve(rings, slices, out);
  return out;
}

MeshData cylinder(double radius, double half_height, int slices) {
  const auto r = static_cast<float>(radius), h = static_cast<float>(half_height);
  MeshData out;
  revolve({{r, -h, 1, 0}, {r, h, 1, 0}}, slices, out);                   // the side
  revolve({{0, h, 0, 1}, {r, h, 0, 1}}, slices, out);                    // the top cap
  revolve({{r, -h, 0, -1}, {0, -h, 0, -1}}, slices, out);                // the bottom cap
  return out;
}

MeshData unit_box() {
  MeshData out;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto corner = [&](float a, float b) {
        float p[3];
        p[axis] = sign, p[u] = a, p[v] = b;
        float n[3] = {0, 0, 0};
        n[axis] = sign;
        return out.add({p[0], p[1], p[2]}, {n[0], n[1], n[2]});
      };
      const std::uint32_t a = corner(-1, -1), b = corner(1, -1), c = corner(1, 1), d = corner(-1, 1);
      out.indices.insert(out.indices.end(), {a, b, c, a, c, d});
    }
  return out;
}

MeshData unit_square() {
  MeshData out;
  const std::uint32_t a = out.add({-1, 0, -1}, {0, 1, 0}), b = out.add({1, 0, -1}, {0, 1, 0}),
                      c = out.add({1, 0, 1}, {0, 1, 0}), d = out.add({-1, 0, 1}, {0, 1, 0});
  out.indices = {a, c, b, a, d, c};
  return out;
}

MeshData unit_arrow(int slices) {
  MeshData out;
  revolve({{0.02f, 0.0f, 1, 0}, {0.02f, 0.75f, 1, 0}}, slices, out);     // the shaft
  revolve({{0.06f, 0.75f, 1, 0.4f}, {0.0f, 1.0f, 1, 0.4f}}, slices, out);  // the head
  revolve({{0.0f, 0.75f, 0, -1}, {0.06f, 0.75f, 0, -1}}, slices, out);   // under the head
  return out;
}

MeshData tube(std::span<const Vec3d> polyline, double radius, int slices) {
  MeshData out;
  const auto r = static_cast<float>(radius);
  for (std::size_t k = 1; k < polyline.size(); ++k) {
    const V3 a(polyline[k - 1]), b(polyline[k]);
    const V3 d = normalize(b - a);
    const V3 helper = std::fabs(d.x) < 0.9f ? V3{1, 0, 0} : V3{0, 0, 1};
    const V3 x = normalize(cross(helper, d)), z = cross(d, x);
    const auto base = static_cast<std::uint32_t>(out.vertices.size() / 9);
    for (int s = 0; s <= slices; ++s) {
      const float angle = 2 * kPi * s / slices;
      const V3 n = x * std::cos(angle) + z * std::sin(angle);
      out.add(a + n * r, n);
      out.add(b + n * r, n);
    }
    for (std::uint32_t s = 0; s < static_cast<std::uint32_t>(slices); ++s) {
      const std::uint32_t i = base + 2 * s;
      out.indices.insert(out.indices.end(), {i, i + 1, i + 2, i + 2, i + 1, i + 3});
    }
  }
  return out;
}

MeshData surface_mesh(const TriMesh& surface) {
  std::vector<float> xyzw;
  xyzw.reserve(surface.vertices.size() * 4);
  for (const Vec3d& v : surface.vertices)
    xyzw.insert(xyzw.end(), {static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]), 1.0f});
  MeshData out;
  body_vertices(xyzw, surface.triangles, {}, out);
  for (const auto& t : surface.triangles) out.indices.insert(out.indices.end(), t.begin(), t.end());
  return out;
}

void body_vertices(std::span<const float> xyzw, std::span<const std::array<std::uint32_t, 3>> triangles,
                   std::span<const float> colours, MeshData& out) {
  const std::size_t n = xyzw.size() / 4;
  out.vertices.assign(n * 9, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    float* v = &out.vertices[9 * i];
    v[0] = xyzw[4 * i], v[1] = xyzw[4 * i + 1], v[2] = xyzw[4 * i + 2];
    if (colours.size() >= 3 * n) v[6] = colours[3 * i], v[7] = colours[3 * i + 1], v[8] = colours[3 * i + 2];
    else v[6] = v[7] = v[8] = 1.0f;
  }
  // The cross product's length is twice the area: an area-weighted sum.
  for (const auto& t : triangles) {
    if (t[0] >= n || t[1] >= n || t[2] >= n) continue;
    const V3 a{xyzw[4 * t[0]], xyzw[4 * t[0] + 1], xyzw[4 * t[0] + 2]};
    const V3 b{xyzw[4 * t[1]], xyzw[4 * t[1] + 1], xyzw[4 * t[1] + 2]};
    const V3 c{xyzw[4 * t[2]], xyzw[4 * t[2] + 1], xyzw[4 * t[2] + 2]};
    const V3 f = cross(b - a, c - a);
    for (std::uint32_t k : t) {
      float* v = &out.vertices[9 * k + 3];
      v[0] += f.x, v[1] += f.y, v[2] += f.z;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    float* v = &out.vertices[9 * i + 3];
    const V3 nn = normalize({v[0], v[1], v[2]});
    v[0] = nn.x, v[1] = nn.y, v[2] = nn.z;
  }
}

V3 speed_colour(float speed, float top) {
  const float s = std::clamp(top > 0 ? speed / top : 0.0f, 0.0f, 1.0f);
  if (s < 0.5f) return {0.1f, 0.2f + 1.4f * s, 0.9f - 1.4f * s};
  return {0.1f + 1.8f * (s - 0.5f), 0.9f - 1.4f * (s - 0.5f), 0.2f};
}

}  // namespace sinew::view
