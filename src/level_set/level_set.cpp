// level_set.cpp — narrow-band signed distance grids on OpenVDB, and their
// NanoVDB copies for the kernels (issue 14, parts 1 and 2; the public side
// is include/sinew/level_set.h).
//
// Museth, "VDB: High-resolution sparse volumes with dynamic topology", ACM
// TOG 32(3), 2013 (the grid); Bærentzen and Aanæs, "Signed distance
// computation using the angle weighted pseudonormal", IEEE TVCG 11(3), 2005,
// for what a mesh's signed distance is (OpenVDB's meshToVolume computes it
// with a flood fill of the sign; we first check the surface is closed so
// the inside is defined).
//
// The grid's index space: voxel (i, j, k) holds the distance at the world
// point (i, j, k) * voxel_size (OpenVDB's linear transform, voxel centres
// at integers), so the samplers interpolate between those points.
//
// Hostile input (issue 39): every length is checked to fit a float (the
// device samples in float32), every voxel index to lie within +-2^30 and
// the voxels a call visits to number at most 2^30 (level_set/voxel_bounds.h)
// before OpenVDB sees them; what OpenVDB still throws becomes a named error
// (guarded), since a library call here never throws.
#include "sinew/level_set.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include <openvdb/tools/Clip.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <unordered_set>

#include "collision/shape_distance.h"
#include "level_set/level_set_impl.h"
#include "level_set/voxel_bounds.h"
#include "math/vec3.h"

namespace sinew {

namespace {

using Point = std::array<double, 3>;

void initialize_openvdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string str(double v) { return level_set::number_text(v); }

Status check_settings(const char* call, const LevelSetSettings& s) {
  if (!(s.voxel_size > 0.0) || !std::isfinite(s.voxel_size))
    return Error(ErrorCode::bad_parameter,
                 std::string(call) + ": voxel_size must be finite and > 0 [m] (got " + str(s.voxel_size) + ")");
  if (!(s.voxel_size >= level_set::kMinVoxelSize))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": voxel_size must be at least " +
                                               str(level_set::kMinVoxelSize) +
                                               " m (OpenVDB's transform refuses smaller voxels; got " +
                                               str(s.voxel_size) + ")");
  if (!(s.exterior_band >= s.voxel_size) || !std::isfinite(s.exterior_band))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": exterior_band must be finite and at least one voxel, " +
                                               str(s.voxel_size) + " m (got " + str(s.exterior_band) + ")");
  if (!(s.interior_band >= s.voxel_size))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": interior_band must be at least one voxel, " +
                                               str(s.voxel_size) + " m, or +infinity (got " + str(s.interior_band) +
                                               ")");
  if (Status st = level_set::float_finite(call, "voxel_size", s.voxel_size); !st) return st;
  if (Status st = level_set::float_finite(call, "exterior_band", s.exterior_band); !st) return st;
  if (std::isfinite(s.interior_band))
    if (Status st = level_set::float_finite(call, "interior_band", s.interior_band); !st) return st;
  return {};
}

// Runs `build` (OpenVDB work), turning what it throws into a named error.
template <class Build>
Result<LevelSet> guarded(const char* call, Build build) {
  try {
    return build();
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, std::string(call) + ": out of memory building the grid");
  } catch (const openvdb::Exception& e) {
    return Error(ErrorCode::bad_parameter, std::string(call) + ": OpenVDB refused the grid (" + e.what() + ")");
  } catch (const std::exception& e) {
    return Error(ErrorCode::internal, std::string(call) + ": " + e.what());
  }
}

Status check_point(const char* call, const char* what, const Point& p) {
  for (double c : p) {
    if (!std::isfinite(c)) return Error(ErrorCode::bad_parameter, std::string(call) + ": " + what + " is not finite");
    if (Status s = level_set::float_finite(call, what, c); !s) return s;
  }
  return {};
}

// The grid's finished form: inactive voxels and tiles outside hold
// +exterior, inside -interior (the background's sign by flood fill), a
// level-set class, and its NanoVDB copy.
LevelSet finish(openvdb::FloatGrid::Ptr grid, const LevelSetSettings& s) {
  const float inside = std::isfinite(s.interior_band) ? float(s.interior_band) : std::numeric_limits<float>::max();
  openvdb::tools::signedFloodFillWithValues(grid->tree(), float(s.exterior_band), -inside);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  auto impl = std::make_shared<LevelSet::Impl>();
  impl->grid = grid;
  impl->voxel = s.voxel_size;
  impl->exterior = s.exterior_band;
  impl->interior = s.interior_band;
  impl->nano = nanovdb::openToNanoVDB(*grid);
  return LevelSet(impl);
}

// A grid holding `distance` (a signed distance [m] of a world point) at
// every voxel of [lo, hi] (world, grown by the bands) whose distance lies
// within the bands.
template <class Distance>
Result<LevelSet> from_function(const char* call, const char* what, const Point& lo, const Point& hi,
                               const LevelSetSettings& s, Distance distance) {
  const Result<level_set::VoxelBox> box =
      level_set::voxel_box(call, what, lo, hi, s.exterior_band + s.voxel_size, s.voxel_size);
  if (!box) return box.error();
  if (Status st = level_set::check_visited(call, what, box->count(), s.voxel_size); !st) return st.error();
  return guarded(call, [&] {
    auto grid = openvdb::FloatGrid::create(float(s.exterior_band));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(s.voxel_size));
    auto access = grid->getAccessor();
    for (int i = box->first[0]; i <= box->last[0]; ++i)
      for (int j = box->first[1]; j <= box->last[1]; ++j)
        for (int k = box->first[2]; k <= box->last[2]; ++k) {
          const double d = distance(Point{i * s.voxel_size, j * s.voxel_size, k * s.voxel_size});
          if (d < s.exterior_band && d > -s.interior_band) access.setValue(openvdb::Coord(i, j, k), float(d));
        }
    return finish(grid, s);
  });
}

}  // namespace

LevelSet::LevelSet(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}

Result<LevelSet> LevelSet::from_mesh(const TriMesh& surface, const LevelSetSettings& settings) {
  constexpr const char* call = "LevelSet::from_mesh";
  if (Status s = check_settings(call, settings); !s) return s.error();
  if (surface.triangles.empty()) return Error(ErrorCode::bad_parameter, std::string(call) + ": the surface is empty");
  Point lo{}, hi{};
  for (std::size_t v = 0; v < surface.vertices.size(); ++v)
    for (int k = 0; k < 3; ++k) {
      const double c = surface.vertices[v][k];
      if (!std::isfinite(c))
        return Error(ErrorCode::bad_parameter,
                     std::string(call) + ": vertex " + std::to_string(v) + " is not finite");
      if (!(std::abs(c) <= std::numeric_limits<float>::max()))  // named only then: this runs per vertex
        return level_set::float_finite(call, "vertex " + std::to_string(v), c).error();
      lo[k] = v == 0 ? c : std::min(lo[k], c);
      hi[k] = v == 0 ? c : std::max(hi[k], c);
    }
  // The voxels OpenVDB fills: the bands about the surface (about its area
  // over h^2 voxels per layer), or the whole box with the inside filled.
  const double h = settings.voxel_size;
  const Result<level_set::VoxelBox> box =
      level_set::voxel_box(call, "the surface", lo, hi, settings.exterior_band + h, h);
  if (!box) return box.error();
  double voxels = box->count();
  if (std::isfinite(settings.interior_band)) {
    double area = 0.0;
    for (const auto& t : surface.triangles) {
      if (t[0] >= surface.vertices.size() || t[1] >= surface.vertices.size() || t[2] >= surface.vertices.size())
        continue;  // check_closed_surface counts it
      const math::Vec3 a = surface.vertices[t[0]], b = surface.vertices[t[1]], c = surface.vertices[t[2]];
      area += 0.5 * math::norm(math::cross(math::sub(b, a), math::sub(c, a)));
    }
    voxels = std::min(voxels, (area / (h * h) + 1.0) * ((settings.exterior_band + settings.interior_band) / h + 2.0));
  }
  if (Status s = level_set::check_visited(call, "the surface's bands", voxels, h); !s) return s.error();
  const Result<SurfaceReport> checked = check_closed_surface(surface);
  if (!checked) return Error(checked.error().code(), std::string(call) + ": " + checked.error().message());
  const SurfaceReport& report = *checked;
  if (!report.closed())
    return Error(ErrorCode::bad_parameter,
                 std::string(call) + ": the surface does not bound a solid (" + std::to_string(report.open_edges) +
                     " open edges, " + std::to_string(report.nonmanifold_edges) + " edges on more than two triangles, " +
                     std::to_string(report.misoriented_edges) + " edges whose triangles face opposite ways, " +
                     std::to_string(report.degenerate_triangles) + " degenerate triangles, " +
                     (report.crossings_tested ? std::to_string(report.intersecting_pairs) +
                                                    " pairs of triangles crossing each other)"
                                              : std::string("crossings not searched for)")));
  initialize_openvdb();
  return guarded(call, [&] {
    auto transform = openvdb::math::Transform::createLinearTransform(settings.voxel_size);
    std::vector<openvdb::Vec3s> points;
    points.reserve(surface.vertices.size());
    for (const auto& p : surface.vertices) points.emplace_back(float(p[0]), float(p[1]), float(p[2]));
    std::vector<openvdb::Vec3I> triangles;
    triangles.reserve(surface.triangles.size());
    for (const auto& t : surface.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    const float exterior = float(settings.exterior_band / settings.voxel_size);
    const float interior = std::isfinite(settings.interior_band) ? float(settings.interior_band / settings.voxel_size)
                                                                 : std::numeric_limits<float>::max();
    auto grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(*transform, points, triangles, {},
                                                                               exterior, interior);
    return finish(grid, settings);
  });
}

Result<LevelSet> LevelSet::sphere(const Point& centre, double radius, const LevelSetSettings& settings) {
  constexpr const char* call = "LevelSet::sphere";
  if (Status s = check_settings(call, settings); !s) return s.error();
  if (Status s = check_point(call, "centre", centre); !s) return s.error();
  if (!(radius > 0.0) || !std::isfinite(radius))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": radius must be finite and > 0 [m] (got " +
                                               str(radius) + ")");
  initialize_openvdb();
  const Point lo{centre[0] - radius, centre[1] - radius, centre[2] - radius};
  const Point hi{centre[0] + radius, centre[1] + radius, centre[2] + radius};
  if (Status s = level_set::float_finite(call, "radius", radius); !s) return s.error();
  return from_function(call, "the sphere", lo, hi, settings, [&](const Point& p) {
    return std::sqrt((p[0] - centre[0]) * (p[0] - centre[0]) + (p[1] - centre[1]) * (p[1] - centre[1]) +
                     (p[2] - centre[2]) * (p[2] - centre[2])) -
           radius;
  });
}

Result<LevelSet> LevelSet::box(const Point& lo, const Point& hi, const LevelSetSettings& settings) {
  constexpr const char* call = "LevelSet::box";
  if (Status s = check_settings(call, settings); !s) return s.error();
  if (Status s = check_point(call, "lo", lo); !s) return s.error();
  if (Status s = check_point(call, "hi", hi); !s) return s.error();
  for (int k = 0; k < 3; ++k)
    if (!(hi[k] > lo[k]))
      return Error(ErrorCode::bad_parameter, std::string(call) + ": hi must exceed lo on every axis (axis " +
                                                 std::to_string(k) + ": " + str(lo[k]) + " .. " + str(hi[k]) + ")");
  initialize_openvdb();
  // The box's exact distance (collision/shape_distance.h), centred between lo and hi.
  ColliderDesc box;
  box.shape = ColliderShape::box;
  for (int k = 0; k < 3; ++k) box.half_extents[k] = 0.5 * (hi[k] - lo[k]);
  const math::Vec3 centre{0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  return from_function(call, "the box", lo, hi, settings, [&](const Point& p) {
    return collision::shape_distance(box, centre, {1.0, 0.0, 0.0, 0.0}, p).distance;
  });
}

double LevelSet::voxel_size() const { return impl_->voxel; }
double LevelSet::exterior_band() const { return impl_->exterior; }
double LevelSet::interior_band() const { return impl_->interior; }

std::array<double, 6> LevelSet::bounds() const {
  const openvdb::CoordBBox box = impl_->grid->evalActiveVoxelBoundingBox();
  const double v = impl_->voxel;
  return {box.min()[0] * v, box.min()[1] * v, box.min()[2] * v, box.max()[0] * v, box.max()[1] * v, box.max()[2] * v};
}

std::uint64_t LevelSet::voxels() const { return impl_->grid->tree().activeVoxelCount(); }

double LevelSet::value(const Point& p) const {
  const openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*impl_->grid);
  return sampler.wsSample(openvdb::Vec3R(p[0], p[1], p[2]));
}

Point LevelSet::gradient(const Point& p) const {
  // The trilinear interpolation of the 8 surrounding voxels' central
  // differences: second-order accurate (the derivative of the trilinear
  // interpolant of the values is only first-order: 2.7% off unit length on
  // a sphere of 20 voxels' radius, against 1e-3 for this).
  const auto access = impl_->grid->getConstAccessor();
  const double v = impl_->voxel;
  int base[3];
  double f[3];
  for (int k = 0; k < 3; ++k) {
    const double u = p[k] / v;
    base[k] = static_cast<int>(std::floor(u));
    f[k] = u - base[k];
  }
  Point g{0.0, 0.0, 0.0};
  for (int corner = 0; corner < 8; ++corner) {
    const int o[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
    const openvdb::Coord c(base[0] + o[0], base[1] + o[1], base[2] + o[2]);
    double w = 1.0;
    for (int k = 0; k < 3; ++k) w *= o[k] ? f[k] : 1.0 - f[k];
    for (int k = 0; k < 3; ++k) {
      openvdb::Coord up = c, down = c;
      up[k] += 1;
      down[k] -= 1;
      g[k] += w * (double(access.getValue(up)) - double(access.getValue(down))) / (2.0 * v);
    }
  }
  return g;
}

std::span<const std::byte> LevelSet::nanovdb_bytes() const {
  return {reinterpret_cast<const std::byte*>(impl_->nano.data()), impl_->nano.size()};
}

namespace {

using math::Quat;
using math::Vec3;

// The tool as the collider shape of the same dimensions, whose distances
// collision/shape_distance.h already gives.
ColliderDesc cutter_collider(const CutterShape& shape) {
  ColliderDesc c;
  c.shape = shape.kind == CutterShape::Kind::sphere    ? ColliderShape::sphere
            : shape.kind == CutterShape::Kind::capsule ? ColliderShape::capsule
                                                       : ColliderShape::box;
  c.radius = shape.radius;
  c.half_height = shape.half_height;
  c.half_extents = shape.half_extents;
  return c;
}

// The most poses a cut places a capsule or box at (2^20: a motion of
// 2^19 voxels).
constexpr double kMaxCutPoses = 1048576.0;
// The most tool-distance evaluations one cut may make (voxels x poses),
// 2^30: tens of seconds on one core, where a burr's stroke makes ~10^5.
constexpr double kMaxCutEvaluations = 1073741824.0;

// How far the tool reaches from its origin [m].
double shape_reach(const CutterShape& shape) {
  switch (shape.kind) {
    case CutterShape::Kind::sphere: return shape.radius;
    case CutterShape::Kind::capsule: return shape.radius + shape.half_height;
    case CutterShape::Kind::box: return math::norm(Vec3{shape.half_extents[0], shape.half_extents[1], shape.half_extents[2]});
  }
  return 0.0;
}

Status check_cut(const CutterShape& shape, const Pose& from, const Pose& to) {
  const char* call = "LevelSet::cut";
  const auto positive = [&](const char* what, double v) -> Status {
    if (v > 0.0 && std::isfinite(v)) return {};
    return Error(ErrorCode::bad_parameter, std::string(call) + ": " + what + " must be finite and > 0 [m] (got " +
                                               str(v) + ")");
  };
  if (shape.kind == CutterShape::Kind::box) {
    for (double e : shape.half_extents)
      if (Status s = positive("the box's half_extents", e); !s) return s;
  } else if (Status s = positive("the radius", shape.radius); !s) {
    return s;
  }
  if (shape.kind == CutterShape::Kind::capsule && !(shape.half_height >= 0.0 && std::isfinite(shape.half_height)))
    return Error(ErrorCode::bad_parameter, std::string(call) + ": half_height must be finite and >= 0 [m]");
  for (const Pose* pose : {&from, &to}) {
    const char* which = pose == &from ? "from" : "to";
    for (double c : pose->position)
      if (!std::isfinite(c))
        return Error(ErrorCode::bad_parameter, std::string(call) + ": the " + which + " position is not finite");
    const auto& q = pose->rotation;
    const double n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(std::abs(n - 1.0) <= 1e-6))
      return Error(ErrorCode::bad_parameter,
                   std::string(call) + ": the " + which + " rotation is not a unit quaternion (|q|^2 = " + str(n) + ")");
  }
  return {};
}

}  // namespace

Result<CutReport> LevelSet::cut(const CutterShape& shape, const Pose& from, const Pose& to) {
  if (Status s = check_cut(shape, from, to); !s) return s.error();
  if (std::isfinite(impl_->interior))
    return Error(ErrorCode::bad_parameter,
                 "LevelSet::cut: the level set stores its inside only " + str(impl_->interior) +
                     " m deep; a cut makes surface anywhere inside, so build it with interior_band = +infinity");
  const double h = impl_->voxel, reach = shape_reach(shape);
  const Vec3 p0 = from.position, p1 = to.position;
  // The poses the tool is placed at: a sphere's sweep is exact (the
  // distance to the segment its centre travels); the others' farthest
  // point moves at most h / 2 between two.
  std::vector<std::pair<Vec3, Quat>> poses;
  if (shape.kind != CutterShape::Kind::sphere) {
    const double turn = 2.0 * std::acos(std::min(1.0, std::abs(math::qdot(from.rotation, to.rotation))));
    const double travel = math::norm(math::sub(p1, p0)) + reach * turn;
    // Counted in double first: a long sweep of a fine grid must not
    // overflow the int (undefined behaviour) nor allocate without bound.
    const double steps = std::max(1.0, std::ceil(travel / (0.5 * h)));
    if (!(steps <= kMaxCutPoses))
      return Error(ErrorCode::capacity_exceeded, "LevelSet::cut: the motion takes " + str(steps) +
                                                     " poses half a voxel apart, more than " + str(kMaxCutPoses) +
                                                     ": cut in shorter steps");
    const int n = static_cast<int>(steps);
    for (int k = 0; k <= n; ++k) {
      const double u = double(k) / n;
      poses.emplace_back(math::add(p0, math::mul(math::sub(p1, p0), u)), math::nlerp(from.rotation, to.rotation, u));
    }
  }
  const ColliderDesc tool = cutter_collider(shape);
  const auto tool_distance = [&](const Vec3& p) {
    if (shape.kind == CutterShape::Kind::sphere) {
      const Vec3 d = math::sub(p1, p0);
      const double dd = math::dot(d, d);
      const double u = dd > 0.0 ? std::clamp(math::dot(math::sub(p, p0), d) / dd, 0.0, 1.0) : 0.0;
      return math::norm(math::sub(p, math::add(p0, math::mul(d, u)))) - shape.radius;
    }
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [position, rotation] : poses)
      best = std::min(best, collision::shape_distance(tool, position, rotation, p).distance);
    return best;
  };
  // Every voxel within the exterior band (and a voxel) of the tool's reach
  // along its path: the solid's distances change up to there (a voxel
  // deeper keeps its old depth, larger than its distance to the new face:
  // exact within the bands of every surface, as a narrow band is).
  const double margin = reach + impl_->exterior + h;
  Point lo{}, hi{};
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min(p0[k], p1[k]);
    hi[k] = std::max(p0[k], p1[k]);
  }
  const Result<level_set::VoxelBox> box = level_set::voxel_box("LevelSet::cut", "the tool's sweep", lo, hi, margin, h);
  if (!box) return box.error();
  if (Status s = level_set::check_visited("LevelSet::cut", "the tool's sweep", box->count(), h); !s) return s.error();
  // Each voxel of the box may be tested against every pose: the total is
  // bounded too, not only each factor.
  const double evaluations = double(box->count()) * double(std::max<std::size_t>(1, poses.size()));
  if (!(evaluations <= kMaxCutEvaluations))
    return Error(ErrorCode::capacity_exceeded,
                 "LevelSet::cut: the tool's sweep spans " + str(double(box->count())) + " voxels, each tested against " +
                     str(double(poses.size())) + " poses: " + str(evaluations) + " distance evaluations, more than " +
                     str(kMaxCutEvaluations) + ": cut in shorter steps");
  const std::array<int, 3> first = box->first, last = box->last;
  auto* nano = impl_->nano.grid<float>();
  auto nano_access = nano->getAccessor();
  auto host_access = impl_->grid->getAccessor();
  using Leaf = nanovdb::NanoLeaf<float>;
  std::unordered_set<const Leaf*> leaves;
  CutReport report;
  const float ceiling = float(impl_->exterior);
  const auto inside_fraction = [h](double value) { return std::clamp(0.5 - value / h, 0.0, 1.0); };
  for (int i = first[0]; i <= last[0]; ++i)
    for (int j = first[1]; j <= last[1]; ++j)
      for (int k = first[2]; k <= last[2]; ++k) {
        const nanovdb::Coord ijk(i, j, k);
        const Leaf* leaf = nano_access.probeLeaf(ijk);
        if (!leaf) continue;  // a tile: outside, beyond the band (the inside is all stored)
        const float old_value = leaf->getValue(ijk);
        const double cut = -tool_distance(Vec3{i * h, j * h, k * h});
        if (!(cut > double(old_value))) continue;
        const float value = std::min(float(cut), ceiling);
        if (!(value > old_value)) continue;
        const_cast<Leaf*>(leaf)->setValueOnly(ijk, value);
        host_access.setValueOnly(openvdb::Coord(i, j, k), value);
        leaves.insert(leaf);
        ++report.changed_voxels;
        report.removed_volume += (inside_fraction(old_value) - inside_fraction(value)) * h * h * h;
      }
  const auto* base = reinterpret_cast<const std::byte*>(impl_->nano.data());
  for (const Leaf* leaf : leaves)
    report.changed_bytes.push_back(
        {std::uint64_t(reinterpret_cast<const std::byte*>(leaf) - base), std::uint64_t(sizeof(Leaf))});
  std::sort(report.changed_bytes.begin(), report.changed_bytes.end());
  report.changed_leaves = static_cast<std::uint32_t>(leaves.size());
  return report;
}

namespace {

// OpenVDB's mesher's output as a TriMesh [m], counter-clockwise from outside.
TriMesh mesh_of(const openvdb::FloatGrid& grid) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, 0.0);
  TriMesh mesh;
  mesh.vertices.reserve(points.size());
  for (const auto& p : points) mesh.vertices.push_back({double(p[0]), double(p[1]), double(p[2])});
  for (const auto& t : triangles) mesh.triangles.push_back({t[0], t[1], t[2]});
  for (const auto& q : quads) {
    mesh.triangles.push_back({q[0], q[1], q[2]});
    mesh.triangles.push_back({q[0], q[2], q[3]});
  }
  // Counter-clockwise from outside: the enclosed volume comes out positive.
  double volume = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    volume += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (volume < 0.0)
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace

TriMesh LevelSet::surface() const { return mesh_of(*impl_->grid); }

Result<TriMesh> LevelSet::surface_in(const std::array<double, 6>& box) const {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(box[k]) || !std::isfinite(box[k + 3]) || !(box[k] < box[k + 3]))
      return Error(ErrorCode::bad_parameter, "surface_in: the box must be finite with lo < hi on every axis (axis " +
                                                 std::to_string(k) + ": " + std::to_string(box[k]) + " .. " +
                                                 std::to_string(box[k + 3]) + ")");
  // The voxels outside become the background (outside the surface), so the
  // solid cut by the box is closed by caps on its faces.
  const openvdb::BBoxd world({box[0], box[1], box[2]}, {box[3], box[4], box[5]});
  const openvdb::FloatGrid::Ptr part = openvdb::tools::clip(*impl_->grid, world);
  return mesh_of(*part);
}

}  // namespace sinew
