// check_tet_mesh and scale_mesh.
//
// The checks run in double precision. The volume tolerance is per tet:
// 1e-12 of the cube of the tet's own longest edge. It is a flatness test
// (volume / longest edge^3, a shape measure), so the verdict depends neither
// on units (mm or m) nor on the mesh size or its grading: the small tets of
// a graded mesh are judged by their own size, not by the whole mesh's.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "math/vec3.h"
#include "sinew/mesh.h"

namespace sinew {
namespace {

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string tet_text(std::size_t t, const std::array<std::uint32_t, 4>& tet) {
  return "tet " + std::to_string(t) + " (vertices " + std::to_string(tet[0]) + " " + std::to_string(tet[1]) +
         " " + std::to_string(tet[2]) + " " + std::to_string(tet[3]) + ")";
}

// Six times the signed volume: dot(b - a, cross(c - a, d - a)).
double orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  return math::dot(math::sub(b, a), math::cross(math::sub(c, a), math::sub(d, a)));
}

Status check_vertices(const TetMesh& mesh, const std::string& origin) {
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Vec3d& p = mesh.vertices[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return Error(ErrorCode::bad_parameter,
                   origin + ": vertex " + std::to_string(v) + " has a non-finite coordinate (" +
                   short_number(p[0]) + ", " + short_number(p[1]) + ", " + short_number(p[2]) + ")");
    }
  }
  return {};
}

Status check_indices(const TetMesh& mesh, const std::string& origin) {
  const std::size_t n = mesh.vertices.size();
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& tet = mesh.tets[t];
    for (std::uint32_t v : tet) {
      if (v >= n) {
        return Error(ErrorCode::bad_parameter,
                     origin + ": " + tet_text(t, tet) + " refers to vertex " + std::to_string(v) +
                     ", but the mesh has only " + std::to_string(n) + " vertices");
      }
    }
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        if (tet[static_cast<std::size_t>(i)] == tet[static_cast<std::size_t>(j)]) {
          return Error(ErrorCode::bad_parameter,
                       origin + ": " + tet_text(t, tet) + " repeats vertex " +
                       std::to_string(tet[static_cast<std::size_t>(i)]));
        }
      }
    }
  }
  return {};
}

double squared_distance(const Vec3d& a, const Vec3d& b) {
  const Vec3d d = math::sub(b, a);
  return math::dot(d, d);
}

double longest_edge(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  const double longest = std::max({squared_distance(a, b), squared_distance(a, c), squared_distance(a, d),
                                   squared_distance(b, c), squared_distance(b, d), squared_distance(c, d)});
  return std::sqrt(longest);
}

// [pre] vertices finite, indices valid.
Status check_volumes(const TetMesh& mesh, const std::string& origin) {
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const auto& tet = mesh.tets[t];
    const Vec3d& a = mesh.vertices[tet[0]];
    const Vec3d& b = mesh.vertices[tet[1]];
    const Vec3d& c = mesh.vertices[tet[2]];
    const Vec3d& d = mesh.vertices[tet[3]];
    const double volume = orientation(a, b, c, d) / 6.0;
    const double edge = longest_edge(a, b, c, d);
    const double min_volume = 1e-12 * edge * edge * edge;
    if (volume > min_volume) continue;
    // A sliver that is inverted by less than the tolerance is reported as
    // zero-volume: its sign is not meaningful at that size.
    const char* what = volume < -min_volume ? " is inverted" : " has zero volume";
    return Error(ErrorCode::bad_parameter,
                 origin + ": " + tet_text(t, tet) + what + " (signed volume " + short_number(volume) +
                 ", minimum " + short_number(min_volume) + ")");
  }
  return {};
}

}  // namespace

Status check_tet_mesh(const TetMesh& mesh, const std::string& origin) {
  if (mesh.tets.empty()) return Error(ErrorCode::bad_parameter, origin + ": mesh has no tets");
  if (Status s = check_vertices(mesh, origin); !s) return s;
  if (Status s = check_indices(mesh, origin); !s) return s;
  return check_volumes(mesh, origin);
}

void scale_mesh(TetMesh& mesh, double factor) {
  for (Vec3d& p : mesh.vertices) {
    for (double& x : p) x *= factor;
  }
}

void scale_mesh(TriMesh& mesh, double factor) {
  for (Vec3d& p : mesh.vertices) {
    for (double& x : p) x *= factor;
  }
}

}  // namespace sinew
