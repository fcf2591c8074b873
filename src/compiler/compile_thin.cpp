// compile_thin.cpp — triangle bodies (membranes, vessel walls) and thread
// bending: particles, lumped masses and the constraints of
// include/sinew/scene.h (TriBodyDesc, LineBodyDesc).
//
// Rest values (lengths, areas, dihedral angles, Kelager offsets) are
// computed from the float particle positions with the very functions the
// kernels use (kernels/math/xpbd_math.h, thin_math.h), so a body at
// rest has C == 0 exactly and stays bitwise at rest.
//
// Triangle bodies:
//  - mass: density * thickness * A, a third to each vertex of the triangle
//    (A its float rest area); vertices in no triangle, and pinned ones, get
//    mass 0 (immovable);
//  - one distance constraint per unique edge, alpha = c_d L^2 / (A_e t) with
//    A_e the sum of A/3 over the edge's triangles (the membrane analogue of
//    a tet edge's V/6 share);
//  - one area constraint per triangle, C = A - A0 and alpha = c_a A0 / t:
//    the energy (K/2) (dA/A0)^2 A0 t with K = 1/c_a is C^2 / (2 alpha) for
//    exactly this alpha;
//  - one dihedral constraint per interior edge, that is an edge of exactly
//    two triangles, alpha = bending_compliance. An edge of three or more
//    triangles (a non-manifold junction, e.g. a septum meeting a wall) gets
//    no bending constraint, and is not an error: which pairs of its
//    triangles should keep their angle is not defined by the mesh; its
//    distance and area constraints still hold it together. Two triangles
//    on the same three vertices (a doubled face) get none either.
#include <algorithm>
#include <string>
#include <tuple>
#include <vector>

#include "compiler/scene_compiler.h"
#include "math/thin_math.h"
#include "math/xpbd_math.h"
#include "thin_params.h"

namespace sinew {
namespace {

// A triangle's edge from -> to in its winding order, with the vertex
// opposite it; sorted by the undirected key (lo, hi), then by triangle.
struct HalfEdge {
  std::uint32_t lo, hi;
  std::uint32_t triangle;
  std::uint32_t from, to, opposite;
  friend bool operator<(const HalfEdge& a, const HalfEdge& b) {
    return std::tie(a.lo, a.hi, a.triangle) < std::tie(b.lo, b.hi, b.triangle);
  }
};

}  // namespace

Status add_tri_body(SceneBuilder& b, const TriBodyDesc& body, const std::string& name) {
  const std::uint32_t first = b.add_vertices(body.mesh.vertices, body.velocity_damping);
  const auto& tris = body.mesh.triangles;
  const auto at = [&](std::uint32_t v) { return b.positions[first + v]; };

  // Rest areas in float, as the kernel computes them; lumped masses.
  std::vector<float> rest_area(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const auto& q = tris[t];
    const float a = kernels::thin::triangle_area(at(q[0]), at(q[1]), at(q[2]));
    if (!(a > 0.0f))
      return Error(ErrorCode::bad_parameter,
                   name + ".mesh: triangle " + std::to_string(t) +
                   " has no positive area in single precision (too small for float32 positions)");
    rest_area[t] = a;
    for (std::uint32_t k : q) b.mass[first + k] += body.density * body.thickness * a / 3.0;
  }

  if (body.area_constraints) {
    RawConstraints& area = b.constraints(Kernel::xpbd_solve_area, 3, SINEW_AREA_DATA_STRIDE);
    for (std::size_t t = 0; t < tris.size(); ++t) {
      for (std::uint32_t k : tris[t]) area.particles.push_back(first + k);
      const double alpha = body.area_compliance * rest_area[t] / body.thickness;
      if (Status s = check_device_compliance(name, ".area_compliance", alpha, b.step); !s) return s;
      area.data.push_back(rest_area[t]);
      area.data.push_back(static_cast<float>(alpha));
    }
  }

  // Half-edges grouped by undirected edge: the edges of the mesh and the
  // triangles around each.
  std::vector<HalfEdge> half;
  half.reserve(tris.size() * 3);
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t from = tris[t][k], to = tris[t][(k + 1) % 3], opposite = tris[t][(k + 2) % 3];
      half.push_back({std::min(from, to), std::max(from, to), static_cast<std::uint32_t>(t), from, to, opposite});
    }
  std::sort(half.begin(), half.end());

  // (b.raw is a deque: making one block leaves references to the others valid.)
  RawConstraints* distance = body.distance_constraints ? &b.distance_constraints(body.stiffness_damping) : nullptr;
  RawConstraints* dihedral = body.bending_compliance >= 0.0
                                 ? &b.constraints(Kernel::xpbd_solve_dihedral, 4, SINEW_DIHEDRAL_DATA_STRIDE)
                                 : nullptr;
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i;
    double share = 0.0;  // A_e: a third of the area of each triangle at this edge
    for (; j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi; ++j)
      share += rest_area[half[j].triangle] / 3.0;
    const HalfEdge& e = half[i];
    if (distance) {
      // > 0: a zero-length edge would have made its triangles' areas 0.
      const float len = kernels::edge_length(at(e.lo), at(e.hi));
      const double alpha = body.distance_compliance * static_cast<double>(len) * len / (share * body.thickness);
      if (Status s = check_device_compliance(name, ".distance_compliance", alpha, b.step); !s) return s;
      distance->particles.push_back(first + e.lo);
      distance->particles.push_back(first + e.hi);
      distance->data.push_back(len);
      distance->data.push_back(static_cast<float>(alpha));
    }
    if (dihedral && j - i == 2 && half[i].opposite != half[i + 1].opposite) {
      // The edge in the winding of the first triangle; the second's wing.
      const std::uint32_t p[4] = {e.from, e.to, e.opposite, half[i + 1].opposite};
      for (std::uint32_t k : p) dihedral->particles.push_back(first + k);
      dihedral->data.push_back(kernels::thin::dihedral_angle(at(p[0]), at(p[1]), at(p[2]), at(p[3])));
      dihedral->data.push_back(static_cast<float>(body.bending_compliance));
    }
    i = j;
  }

  if (!body.initial_vertices.empty()) b.initial.emplace_back(first, &body.initial_vertices);
  for (std::uint32_t p : body.pinned) b.mass[first + p] = 0.0;
  return {};
}

// Kelager et al. 2010 (see LineBodyDesc): every vertex joined to exactly two
// segments bends with the triangle (previous, vertex, next). A vertex whose
// two segments join it to the same neighbour (a doubled segment) has no such
// triangle and gets none.
Status add_line_bending(SceneBuilder& b, const LineBodyDesc& body, std::uint32_t first, const std::string&) {
  const std::size_t n = body.vertices.size();
  std::vector<std::uint32_t> degree(n, 0);
  std::vector<std::uint32_t> neighbour(2 * n, 0);  // the first two neighbours of each vertex
  for (const auto& [p, q] : body.segments) {
    if (degree[p] < 2) neighbour[2 * p + degree[p]] = q;
    if (degree[q] < 2) neighbour[2 * q + degree[q]] = p;
    ++degree[p];
    ++degree[q];
  }
  RawConstraints& bending =
      b.constraints(Kernel::xpbd_solve_line_bending, 3, SINEW_LINE_BENDING_DATA_STRIDE);
  for (std::uint32_t v = 0; v < n; ++v) {
    if (degree[v] != 2 || neighbour[2 * v] == neighbour[2 * v + 1]) continue;
    const kernels::float4 b0 = b.positions[first + neighbour[2 * v]], x = b.positions[first + v],
                          b1 = b.positions[first + neighbour[2 * v + 1]];
    // > 0: add_line_body has checked every segment's float length.
    const float mean_length = 0.5f * (kernels::edge_length(b0, x) + kernels::edge_length(x, b1));
    bending.particles.push_back(first + neighbour[2 * v]);
    bending.particles.push_back(first + v);
    bending.particles.push_back(first + neighbour[2 * v + 1]);
    bending.data.push_back(kernels::thin::line_bending_offset(b0, x, b1));
    bending.data.push_back(static_cast<float>(body.bending_compliance));
    bending.data.push_back(mean_length);
    bending.data.push_back(0.0f);
  }
  return {};
}

}  // namespace sinew
