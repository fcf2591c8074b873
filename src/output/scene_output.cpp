// scene_output.cpp — SceneOutput (vtk_output.h): every body, collider,
// tool, needle and the fluid of a Simulation, one .vtu per block per frame,
// a .vtm per frame and one .pvd.
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "runtime/simulation_internals.h"
#include "sinew/display_surfaces.h"
#include "sinew/simulation.h"
#include "sinew/vtk_output.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;
using Mat3 = std::array<double, 9>;  // row-major

// The inverse of the rest edge matrix [x1 - x0, x2 - x0, x3 - x0] (columns);
// zeros for a flat tet (check_scene refuses them; kept safe here).
Mat3 rest_inverse(const std::vector<Vec3d>& x, const std::array<std::uint32_t, 4>& t) {
  Mat3 m{};
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m[3 * r + c] = x[t[c + 1]][r] - x[t[0]][r];
  const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                     m[2] * (m[3] * m[7] - m[4] * m[6]);
  if (det == 0.0 || !std::isfinite(det)) return Mat3{};
  const double d = 1.0 / det;
  return {(m[4] * m[8] - m[5] * m[7]) * d, (m[2] * m[7] - m[1] * m[8]) * d, (m[1] * m[5] - m[2] * m[4]) * d,
          (m[5] * m[6] - m[3] * m[8]) * d, (m[0] * m[8] - m[2] * m[6]) * d, (m[2] * m[3] - m[0] * m[5]) * d,
          (m[3] * m[7] - m[4] * m[6]) * d, (m[1] * m[6] - m[0] * m[7]) * d, (m[0] * m[4] - m[1] * m[3]) * d};
}

// |E|_F of the Green strain E = (F^T F - I) / 2, F = Ds Dm^-1, from the
// current positions (xyzw) of the tet's vertices.
float green_strain(std::span<const float> x, const std::array<std::uint32_t, 4>& t, const Mat3& dm_inv) {
  Mat3 ds{};
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) ds[3 * r + c] = double(x[4 * t[c + 1] + r]) - double(x[4 * t[0] + r]);
  Mat3 f{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) f[3 * r + c] += ds[3 * r + k] * dm_inv[3 * k + c];
  double sum = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      double ftf = 0.0;
      for (int k = 0; k < 3; ++k) ftf += f[3 * k + r] * f[3 * k + c];
      const double e = 0.5 * (ftf - (r == c ? 1.0 : 0.0));
      sum += e * e;
    }
  return static_cast<float>(std::sqrt(sum));
}

// Which of `all` (a body's elements) are in `live` (the live ones, by value).
template <std::size_t N>
std::vector<float> alive_flags(const std::vector<std::array<std::uint32_t, N>>& all,
                               const std::vector<std::array<std::uint32_t, N>>& live) {
  std::vector<std::array<std::uint32_t, N>> sorted = live;
  std::sort(sorted.begin(), sorted.end());
  std::vector<float> flags(all.size());
  for (std::size_t i = 0; i < all.size(); ++i)
    flags[i] = std::binary_search(sorted.begin(), sorted.end(), all[i]) ? 1.0f : 0.0f;
  return flags;
}

std::string default_name(BodyKind kind, std::size_t index) {
  return (kind == BodyKind::tet ? "tet" : kind == BodyKind::tri ? "tri" : "line") + std::to_string(index);
}

}  // namespace

struct SceneOutput::State {
  SceneDesc scene;
  fs::path folder;
  SceneOutputSettings settings;
  std::vector<std::string> tet_names, tri_names, line_names;
  std::vector<std::vector<Mat3>> rest_inverses;  // per tet body, per tet
  double plane_half = 1.0;
  std::vector<std::optional<TriMesh>> tool_surfaces;  // level-set tools' surfaces in their frame, made once
  std::vector<std::pair<std::string, TriMesh>> extra_surfaces;
  std::vector<std::pair<std::string, std::vector<std::array<double, 3>>>> extra_polylines;
  std::vector<fs::path> frame_files;
  std::vector<double> times;
  // Per write: the frame's blocks, and reused buffers.
  std::vector<VtkBlock> blocks;
  std::vector<float> x, v, xyz, displacement, velocity, strain, alive, force;
  std::vector<std::uint32_t> connectivity, offsets;
  std::vector<VtkCellType> types;
  std::vector<FluidParticle> particles;
  int frame = 0;

  Status write_grid(const std::string& name, const VtkGrid& grid) {
    const fs::path path = folder / (name + "_" + std::to_string(frame) + ".vtu");
    if (Status s = write_vtu(path, grid); !s) return s;
    blocks.push_back({name, path});
    return {};
  }

  // Cells of N points each from `cells`; those with alive[i] == 0 empty.
  template <std::size_t N>
  void set_cells(const std::vector<std::array<std::uint32_t, N>>& cells, std::span<const float> flags,
                 VtkCellType type) {
    connectivity.clear(), offsets.clear(), types.clear();
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const bool live = flags.empty() || flags[i] != 0.0f;
      if (live) connectivity.insert(connectivity.end(), cells[i].begin(), cells[i].end());
      offsets.push_back(static_cast<std::uint32_t>(connectivity.size()));
      types.push_back(live ? type : VtkCellType::empty);
    }
  }

  // displacement (from `rest`) and velocity of the body's `count` particles from `first`.
  void body_point_fields(std::size_t first, const std::vector<Vec3d>& rest) {
    displacement.resize(3 * rest.size());
    velocity.resize(3 * rest.size());
    for (std::size_t p = 0; p < rest.size(); ++p)
      for (std::size_t k = 0; k < 3; ++k) {
        displacement[3 * p + k] = static_cast<float>(double(x[4 * (first + p) + k]) - rest[p][k]);
        velocity[3 * p + k] = v[4 * (first + p) + k];
      }
  }

  // alive: 1 per element of `all`, 0 for those removed (scenes with topology changes).
  template <std::size_t N, typename IdOf, typename LiveOf>
  Status load_alive(const std::vector<std::array<std::uint32_t, N>>& all, IdOf id_of, LiveOf live_of) {
    alive.assign(all.size(), 1.0f);
    if (!scene.topology_changes) return {};
    auto id = id_of();
    if (!id) return id.error();
    auto live = live_of(*id);
    if (!live) return live.error();
    alive = alive_flags(all, *live);
    return {};
  }

  Status write_tet_body(Simulation& sim, std::size_t b) {
    const TetBodyDesc& body = scene.tet_bodies[b];
    const std::size_t first = sim.info().tet_body_first_particle[b];
    const std::span<const float> bx = std::span<const float>(x).subspan(4 * first, 4 * body.mesh.vertices.size());
    Topology topology = sim.topology();
    if (Status s = load_alive(body.mesh.tets, [&] { return topology.tet_body(b); },
                              [&](TetBodyId id) { return topology.current_tets(id); });
        !s)
      return s;
    strain.resize(body.mesh.tets.size());
    for (std::size_t t = 0; t < body.mesh.tets.size(); ++t)
      strain[t] = alive[t] != 0.0f ? green_strain(bx, body.mesh.tets[t], rest_inverses[b][t]) : 0.0f;
    body_point_fields(first, body.mesh.vertices);
    set_cells(body.mesh.tets, alive, VtkCellType::tetra);
    const VertexField point_fields[] = {{"displacement", 3, displacement}, {"velocity", 3, velocity}};
    const VertexField cell_fields[] = {{"green_strain", 1, strain}, {"alive", 1, alive}};
    return write_grid(tet_names[b], {.positions = bx, .stride = 4, .connectivity = connectivity, .offsets = offsets,
                                     .types = types, .point_fields = point_fields, .cell_fields = cell_fields});
  }

  Status write_tri_body(Simulation& sim, std::size_t b) {
    const TriBodyDesc& body = scene.tri_bodies[b];
    const std::size_t first = sim.info().tri_body_first_particle[b];
    const std::span<const float> bx = std::span<const float>(x).subspan(4 * first, 4 * body.mesh.vertices.size());
    Topology topology = sim.topology();
    if (Status s = load_alive(body.mesh.triangles, [&] { return topology.tri_body(b); },
                              [&](TriBodyId id) { return topology.current_triangles(id); });
        !s)
      return s;
    body_point_fields(first, body.mesh.vertices);
    set_cells(body.mesh.triangles, alive, VtkCellType::triangle);
    const VertexField point_fields[] = {{"displacement", 3, displacement}, {"velocity", 3, velocity}};
    const VertexField cell_fields[] = {{"alive", 1, alive}};
    return write_grid(tri_names[b], {.positions = bx, .stride = 4, .connectivity = connectivity, .offsets = offsets,
                                     .types = types, .point_fields = point_fields, .cell_fields = cell_fields});
  }

  Status write_line_body(Simulation& sim, std::size_t b) {
    const LineBodyDesc& body = scene.line_bodies[b];
    const std::size_t first = sim.info().line_body_first_particle[b];
    const std::span<const float> bx = std::span<const float>(x).subspan(4 * first, 4 * body.vertices.size());
    body_point_fields(first, body.vertices);
    set_cells(body.segments, {}, VtkCellType::line);
    const VertexField point_fields[] = {{"displacement", 3, displacement}, {"velocity", 3, velocity}};
    return write_grid(line_names[b], {.positions = bx, .stride = 4, .connectivity = connectivity, .offsets = offsets,
                                      .types = types, .point_fields = point_fields, .cell_fields = {}});
  }

  // A rigid shape's block: its surface (or polyline: triangles empty and
  // `points` set), with a constant velocity and contact force on every point
  // when given.
  Status write_shape(const std::string& name, const std::vector<Vec3d>& points,
                     const std::vector<std::array<std::uint32_t, 3>>& triangles, bool polyline,
                     const std::array<double, 3>* shape_velocity, const std::array<double, 3>* contact_force) {
    xyz.clear();
    for (const Vec3d& p : points) xyz.insert(xyz.end(), {float(p[0]), float(p[1]), float(p[2])});
    connectivity.clear(), offsets.clear(), types.clear();
    if (polyline) {
      for (std::uint32_t i = 0; i < points.size(); ++i) connectivity.push_back(i);
      offsets.push_back(static_cast<std::uint32_t>(points.size()));
      types.push_back(VtkCellType::poly_line);
    } else {
      set_cells(triangles, {}, VtkCellType::triangle);
    }
    std::vector<VertexField> fields;
    const auto constant = [&](std::vector<float>& out, const std::array<double, 3>& value) {
      out.clear();
      for (std::size_t p = 0; p < points.size(); ++p) out.insert(out.end(), {float(value[0]), float(value[1]), float(value[2])});
    };
    if (shape_velocity) constant(velocity, *shape_velocity), fields.push_back({"velocity", 3, velocity});
    if (contact_force) constant(force, *contact_force), fields.push_back({"contact_force", 3, force});
    return write_grid(name, {.positions = xyz, .stride = 3, .connectivity = connectivity, .offsets = offsets,
                             .types = types, .point_fields = fields, .cell_fields = {}});
  }

  Status write_colliders(Simulation& sim) {
    for (std::size_t c = 0; c < scene.colliders.size(); ++c) {
      const ColliderDesc& d = scene.colliders[c];
      const Pose pose = SimulationInternals::collider_pose(sim, c);
      TriMesh mesh;
      switch (d.shape) {
        case ColliderShape::plane: mesh = plane_surface(plane_half, pose); break;
        case ColliderShape::sphere: mesh = capsule_surface(d.radius, 0.0, pose); break;
        case ColliderShape::capsule: mesh = capsule_surface(d.radius, d.half_height, pose); break;
        case ColliderShape::box: mesh = box_surface(d.half_extents, pose); break;
        case ColliderShape::cylinder: mesh = cylinder_surface(d.radius, d.half_height, pose); break;
        case ColliderShape::level_set:
          if (!settings.level_set_surfaces || !d.level_set) continue;
          mesh = posed_surface(d.level_set->surface(), pose);
          break;
        case ColliderShape::implicit: continue;  // no surface of its own
      }
      if (Status s = write_shape("collider" + std::to_string(c), mesh.vertices, mesh.triangles, false, nullptr, nullptr); !s)
        return s;
    }
    return {};
  }

  Status write_tools(Simulation& sim) {
    Tools tools = sim.tools();
    for (std::size_t t = 0; t < scene.tools.size(); ++t) {
      const ToolDesc& d = scene.tools[t];
      auto id = tools.tool(t);
      if (!id) return id.error();
      auto state = tools.state(*id);
      if (!state) return state.error();
      const Pose pose{.position = state->position, .rotation = state->rotation};
      TriMesh mesh;
      if (d.shape == ToolShape::capsule) {
        mesh = capsule_surface(d.radius, d.half_height, pose);
      } else {
        if (!settings.level_set_surfaces || !d.level_set) continue;
        if (!tool_surfaces[t]) tool_surfaces[t] = d.level_set->surface();
        mesh = posed_surface(*tool_surfaces[t], pose);
      }
      if (Status s = write_shape("tool" + std::to_string(t), mesh.vertices, mesh.triangles, false, &state->velocity,
                                 &state->contact_force);
          !s)
        return s;
    }
    return {};
  }

  Status write_needles(Simulation& sim) {
    Needles needles = sim.needles();
    for (std::size_t n = 0; n < scene.needles.size(); ++n) {
      auto id = needles.needle(n);
      if (!id) return id.error();
      auto state = needles.state(*id);
      if (!state) return state.error();
      const auto curve =
          posed_points(scene.needles[n].curve, Pose{.position = state->position, .rotation = state->rotation});
      if (Status s = write_shape("needle" + std::to_string(n), curve, {}, true, &state->velocity, &state->reaction_force); !s)
        return s;
    }
    return {};
  }

  Status write_fluid(Simulation& sim) {
    if (Status s = sim.fluid().read(particles); !s) return s;
    xyz.clear(), velocity.clear(), strain.clear(), alive.clear();  // strain: density, alive: pressure
    for (const FluidParticle& p : particles) {
      xyz.insert(xyz.end(), p.position.begin(), p.position.end());
      velocity.insert(velocity.end(), p.velocity.begin(), p.velocity.end());
      strain.push_back(p.density);
      alive.push_back(p.pressure);
    }
    connectivity.resize(particles.size()), offsets.resize(particles.size());
    for (std::uint32_t i = 0; i < particles.size(); ++i) connectivity[i] = i, offsets[i] = i + 1;
    types.assign(particles.size(), VtkCellType::vertex);
    const VertexField fields[] = {{"density", 1, strain}, {"pressure", 1, alive}, {"velocity", 3, velocity}};
    return write_grid("fluid", {.positions = xyz, .stride = 3, .connectivity = connectivity, .offsets = offsets,
                                .types = types, .point_fields = fields, .cell_fields = {}});
  }

  // Whether `name` is a collider's, tool's, needle's or the fluid's block.
  [[nodiscard]] bool shape_block(const std::string& name) const {
    for (const auto& [prefix, count] : {std::pair{"collider", scene.colliders.size()}, std::pair{"tool", scene.tools.size()},
                                        std::pair{"needle", scene.needles.size()}})
      for (std::size_t i = 0; i < count; ++i)
        if (name == prefix + std::to_string(i)) return true;
    return name == "fluid" && scene.fluid.has_value();
  }
  // Whether `name` is a block of the scene.
  [[nodiscard]] bool scene_block(const std::string& name) const {
    for (const auto* names : {&tet_names, &tri_names, &line_names})
      if (std::find(names->begin(), names->end(), name) != names->end()) return true;
    return shape_block(name);
  }
};

Result<SceneOutput> SceneOutput::create(const SceneDesc& scene, std::filesystem::path folder,
                                        SceneOutputSettings settings) {
  auto st = std::make_unique<State>();
  st->scene = scene;
  st->folder = std::move(folder);
  if (settings.name.empty()) return Error(ErrorCode::bad_parameter, "SceneOutput: the output's name is empty");
  st->tet_names.resize(scene.tet_bodies.size());
  st->tri_names.resize(scene.tri_bodies.size());
  st->line_names.resize(scene.line_bodies.size());
  const auto names_of = [&](BodyKind kind) -> std::vector<std::string>& {
    return kind == BodyKind::tet ? st->tet_names : kind == BodyKind::tri ? st->tri_names : st->line_names;
  };
  for (const SceneBodyName& b : settings.bodies) {
    std::vector<std::string>& names = names_of(b.kind);
    if (b.index >= names.size())
      return Error(ErrorCode::bad_parameter, "SceneOutput: body name '" + b.name + "' is for " +
                                                 default_name(b.kind, b.index) + ", past the scene's bodies");
    names[b.index] = b.name;
  }
  std::set<std::string> seen;
  for (BodyKind kind : {BodyKind::tet, BodyKind::tri, BodyKind::line}) {
    std::vector<std::string>& names = names_of(kind);
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i].empty()) names[i] = default_name(kind, i);
      if (!seen.insert(names[i]).second)
        return Error(ErrorCode::bad_parameter, "SceneOutput: two bodies are named '" + names[i] + "'");
    }
  }
  for (const std::string& name : seen)
    if (st->shape_block(name))
      return Error(ErrorCode::bad_parameter, "SceneOutput: body name '" + name + "' is a collider's, tool's, needle's or the fluid's block");
  // Rest edge matrices' inverses, for the strain.
  for (const TetBodyDesc& body : scene.tet_bodies) {
    std::vector<Mat3>& inv = st->rest_inverses.emplace_back();
    inv.reserve(body.mesh.tets.size());
    for (const auto& t : body.mesh.tets) inv.push_back(rest_inverse(body.mesh.vertices, t));
  }
  // A plane is drawn as large as the scene's rest bounding box.
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  const auto grow = [&](const std::vector<Vec3d>& points) {
    for (const Vec3d& p : points)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  };
  for (const auto& b : scene.tet_bodies) grow(b.mesh.vertices);
  for (const auto& b : scene.tri_bodies) grow(b.mesh.vertices);
  for (const auto& b : scene.line_bodies) grow(b.vertices);
  double side = 0.0;
  for (int k = 0; k < 3; ++k) side = std::max(side, hi[k] - lo[k]);
  st->plane_half = settings.plane_half_size > 0.0 ? settings.plane_half_size : side > 0.0 ? side : 1.0;
  st->tool_surfaces.resize(scene.tools.size());
  std::error_code ec;
  fs::create_directories(st->folder, ec);
  if (ec) return Error(ErrorCode::bad_input_file, st->folder.string() + ": cannot be made (" + ec.message() + ")");
  st->settings = std::move(settings);
  return SceneOutput(std::move(st));
}

SceneOutput::SceneOutput(std::unique_ptr<State> state) : state_(std::move(state)) {}
SceneOutput::SceneOutput(SceneOutput&&) noexcept = default;
SceneOutput& SceneOutput::operator=(SceneOutput&&) noexcept = default;
SceneOutput::~SceneOutput() = default;

void SceneOutput::add_surface(const std::string& name, const TriMesh& surface) {
  state_->extra_surfaces.emplace_back(name, surface);
}

void SceneOutput::add_polyline(const std::string& name, std::span<const std::array<double, 3>> points) {
  state_->extra_polylines.emplace_back(name, std::vector<std::array<double, 3>>(points.begin(), points.end()));
}

Status SceneOutput::write(Simulation& sim, int frame) {
  State& st = *state_;
  st.frame = frame;
  st.blocks.clear();
  // The added shapes are for this frame only, whatever happens below.
  auto surfaces = std::move(st.extra_surfaces);
  auto polylines = std::move(st.extra_polylines);
  st.extra_surfaces.clear(), st.extra_polylines.clear();
  if (Status s = sim.read_positions(st.x); !s) return s;
  if (Status s = sim.read_velocities(st.v); !s) return s;
  for (std::size_t b = 0; b < st.scene.tet_bodies.size(); ++b)
    if (Status s = st.write_tet_body(sim, b); !s) return s;
  for (std::size_t b = 0; b < st.scene.tri_bodies.size(); ++b)
    if (Status s = st.write_tri_body(sim, b); !s) return s;
  for (std::size_t b = 0; b < st.scene.line_bodies.size(); ++b)
    if (Status s = st.write_line_body(sim, b); !s) return s;
  if (Status s = st.write_colliders(sim); !s) return s;
  if (Status s = st.write_tools(sim); !s) return s;
  if (Status s = st.write_needles(sim); !s) return s;
  if (st.scene.fluid)
    if (Status s = st.write_fluid(sim); !s) return s;
  std::set<std::string> added;
  const auto check_name = [&](const std::string& name) -> Status {
    if (name.empty() || st.scene_block(name) || !added.insert(name).second)
      return Error(ErrorCode::bad_parameter, "SceneOutput: an added shape's name '" + name +
                                                 "' is empty, a scene block's, or added twice in one frame");
    return {};
  };
  for (const auto& [name, mesh] : surfaces) {
    if (Status s = check_name(name); !s) return s;
    if (Status s = st.write_shape(name, mesh.vertices, mesh.triangles, false, nullptr, nullptr); !s) return s;
  }
  for (const auto& [name, points] : polylines) {
    if (Status s = check_name(name); !s) return s;
    if (Status s = st.write_shape(name, points, {}, true, nullptr, nullptr); !s) return s;
  }
  const fs::path vtm = st.folder / (st.settings.name + "_" + std::to_string(frame) + ".vtm");
  if (Status s = write_vtm(vtm, st.blocks); !s) return s;
  st.frame_files.push_back(vtm);
  st.times.push_back(sim.last_frame().time);
  return write_pvd(st.folder / (st.settings.name + ".pvd"), st.frame_files, st.times);
}

}  // namespace sinew
