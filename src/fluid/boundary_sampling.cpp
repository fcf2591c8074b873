// boundary_sampling.cpp — sinew/fluid.h's boundary samplers: points on a
// surface at most a spacing apart, for Akinci et al.'s boundary particles
// (2012), whose volumes make up for uneven sampling (V_b = 1 / sum W_bk),
// so the sampling need only leave no gap wider than a spacing.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include "sinew/fluid.h"

namespace sinew {
namespace {

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

void SurfaceSamples::positions_on(std::span<const float> vertex_xyz, std::size_t stride,
                                  std::vector<std::array<float, 3>>& out) const {
  out.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      float x = 0.0f;
      for (int k = 0; k < 3; ++k) x += weights[i][k] * vertex_xyz[stride * vertices[i][k] + std::size_t(a)];
      out[i][a] = x;
    }
}

void SurfaceSamples::spread_to_vertices(std::span<const std::array<float, 3>> values, std::span<float> vertex_xyz,
                                        std::size_t stride) const {
  for (std::size_t i = 0; i < points.size() && i < values.size(); ++i)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) vertex_xyz[stride * vertices[i][k] + std::size_t(a)] += weights[i][k] * values[i][a];
}

Result<SurfaceSamples> sample_surface(std::span<const std::array<double, 3>> vertices,
                                      std::span<const std::array<std::uint32_t, 3>> triangles, double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    return Error(ErrorCode::bad_parameter, "sample_surface: spacing must be finite and > 0");
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::uint32_t v : triangles[t])
      if (v >= vertices.size())
        return Error(ErrorCode::bad_parameter, "sample_surface: triangle " + std::to_string(t) + " names vertex " +
                                                   std::to_string(v) + " of " + std::to_string(vertices.size()));
  for (std::size_t v = 0; v < vertices.size(); ++v)
    for (double x : vertices[v])
      if (!std::isfinite(x))
        return Error(ErrorCode::bad_parameter, "sample_surface: vertex " + std::to_string(v) + " is not finite");
  double area = 0.0;  // a bound on the points: every edge and face at the spacing
  for (const auto& t : triangles) {
    const double e = std::max({distance(vertices[t[0]], vertices[t[1]]), distance(vertices[t[1]], vertices[t[2]]),
                               distance(vertices[t[2]], vertices[t[0]])}) / spacing + 1.0;
    area += e * e;
  }
  if (area > double(1 << 26))
    return Error(ErrorCode::bad_parameter, "sample_surface: the spacing makes too many points (about " +
                                               std::to_string(static_cast<long long>(area)) + ")");
  SurfaceSamples out;
  const auto add = [&](std::size_t t, std::array<float, 3> w) {
    const auto& tri = triangles[t];
    std::array<double, 3> x{};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) x[a] += double(w[k]) * vertices[tri[k]][a];
    out.points.push_back(x);
    out.vertices.push_back(tri);
    out.weights.push_back(w);
  };
  // Each vertex once, on the first triangle that uses it.
  std::vector<bool> done(vertices.size(), false);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      if (done[triangles[t][k]]) continue;
      done[triangles[t][k]] = true;
      std::array<float, 3> w{0.0f, 0.0f, 0.0f};
      w[k] = 1.0f;
      add(t, w);
    }
  // Each edge's inner points once, a spacing apart at most.
  std::map<std::pair<std::uint32_t, std::uint32_t>, bool> edges;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      if (!edges.emplace(std::minmax(a, b), true).second) continue;
      const int pieces = int(std::ceil(distance(vertices[a], vertices[b]) / spacing));
      for (int i = 1; i < pieces; ++i) {
        std::array<float, 3> w{0.0f, 0.0f, 0.0f};
        w[k] = float(1.0 - double(i) / pieces);
        w[(k + 1) % 3] = float(double(i) / pieces);
        add(t, w);
      }
    }
  // Each face's inside: a barycentric lattice fine enough for its longest edge.
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const double longest = std::max({distance(vertices[tri[0]], vertices[tri[1]]),
                                     distance(vertices[tri[1]], vertices[tri[2]]),
                                     distance(vertices[tri[2]], vertices[tri[0]])});
    const int pieces = int(std::ceil(longest / spacing));
    for (int i = 1; i < pieces; ++i)
      for (int j = 1; i + j < pieces; ++j) {
        const float b = float(double(i) / pieces), c = float(double(j) / pieces);
        add(t, {1.0f - b - c, b, c});
      }
  }
  return out;
}

Result<SurfaceSamples> sample_level_set(const LevelSet& level_set, double spacing) {
  const TriMesh surface = level_set.surface();
  return sample_surface(surface.vertices, surface.triangles, spacing);
}

Result<std::vector<std::array<double, 3>>> sample_box_walls(const std::array<double, 3>& lo,
                                                            const std::array<double, 3>& hi, double spacing,
                                                            int layers) {
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    return Error(ErrorCode::bad_parameter, "sample_box_walls: spacing must be finite and > 0");
  if (layers < 1) return Error(ErrorCode::bad_parameter, "sample_box_walls: layers must be >= 1");
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) {
    if (!(hi[a] > lo[a]) || !std::isfinite(hi[a] - lo[a]))
      return Error(ErrorCode::bad_parameter, "sample_box_walls: hi must be above lo on axis " + std::to_string(a));
    cells *= (hi[a] - lo[a]) / spacing + 2.0 * layers + 1.0;
  }
  if (cells > double(1 << 24))
    return Error(ErrorCode::bad_parameter, "sample_box_walls: the spacing makes too many points (more than 2^24)");
  std::vector<std::array<double, 3>> points;
  const auto count = [&](int a) { return int(std::ceil((hi[a] - lo[a]) / spacing - 1e-9)); };
  const int nx = count(0), ny = count(1), nz = count(2);
  const double sx = (hi[0] - lo[0]) / nx, sy = (hi[1] - lo[1]) / ny, sz = (hi[2] - lo[2]) / nz;
  // Layer l lies l spacings outside the faces; the floor reaches under the walls.
  for (int l = 0; l < layers; ++l) {
    const double out = l * spacing;
    for (int i = -l; i <= nx + l; ++i)
      for (int k = -l; k <= nz + l; ++k) {
        const double x = i < 0 ? lo[0] - (-i) * spacing : i > nx ? hi[0] + (i - nx) * spacing : lo[0] + i * sx;
        const double z = k < 0 ? lo[2] - (-k) * spacing : k > nz ? hi[2] + (k - nz) * spacing : lo[2] + k * sz;
        points.push_back({x, lo[1] - out, z});  // the floor
      }
    for (int j = 1; j <= ny; ++j) {
      const double y = lo[1] + j * sy;
      for (int i = -l; i <= nx + l; ++i) {
        const double x = i < 0 ? lo[0] - (-i) * spacing : i > nx ? hi[0] + (i - nx) * spacing : lo[0] + i * sx;
        points.push_back({x, y, lo[2] - out});
        points.push_back({x, y, hi[2] + out});
      }
      for (int k = -l + 1; k <= nz + l - 1; ++k) {
        const double z = k < 0 ? lo[2] - (-k) * spacing : k > nz ? hi[2] + (k - nz) * spacing : lo[2] + k * sz;
        points.push_back({lo[0] - out, y, z});
        points.push_back({hi[0] + out, y, z});
      }
    }
  }
  return points;
}

}  // namespace sinew
