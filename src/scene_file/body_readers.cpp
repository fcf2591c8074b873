// body_readers.cpp — tet, tri and line bodies of a scene file: their
// meshes (a file relative to the scene file, a generated grid, or inline
// arrays), pins selected by index or box, and materials.
#include <algorithm>
#include <limits>

#include "scene_file/readers.h"
#include "sinew/mesh.h"

namespace sinew::scene_file {
namespace {

struct Box {
  Vec3d lo{}, hi{};
  [[nodiscard]] bool holds(const Vec3d& p) const {
    return p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && p[2] >= lo[2] && p[2] <= hi[2];
  }
};

bool read_box(const Json& v, const std::string& path, Context& ctx, Box& out) {
  Object o(v, path, ctx);
  o.read("min", out.lo, true);
  o.read("max", out.hi, true);
  o.finish();
  return !ctx.failed();
}


// Reading a mesh file failed: the reader's message, under the key's path.
void mesh_file_error(Context& ctx, const std::string& path, const Error& e) {
  ctx.fail(e.code() == ErrorCode::bad_parameter ? ErrorCode::bad_input_file : e.code(), path, e.message());
}

void read_scale(Object& o, double& scale) {
  o.read("scale", scale);
  if (!o.ctx().failed() && !(scale > 0.0)) o.ctx().fail(ErrorCode::bad_parameter, o.path("scale"), "must be > 0");
}

// "grid": {"cells": [nx, ny, nz], "origin", "cell_size" or "size", "split"}.
void read_grid(const Json& v, const std::string& path, Context& ctx, TetMesh& out) {
  Object o(v, path, ctx);
  TetGridDesc grid;
  std::array<std::uint32_t, 3> cells{1, 1, 1};
  if (const Json* c = o.find("cells")) read_uint32s(*c, o.path("cells"), ctx, cells);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("cells"), "is required");
  for (int a = 0; a < 3 && !ctx.failed(); ++a)
    if (cells[a] < 1 || cells[a] > 4096)
      ctx.fail(ErrorCode::bad_parameter, o.path("cells") + "/" + std::to_string(a), "must be in [1, 4096]");
  // A bound on the file's work: a typo must not ask for 10^11 tets.
  if (!ctx.failed() && double(cells[0]) * double(cells[1]) * double(cells[2]) > 1e6)
    ctx.fail(ErrorCode::bad_parameter, o.path("cells"), "makes more than 10^6 cells (6 million tets)");
  if (ctx.failed()) return;
  grid.nx = static_cast<int>(cells[0]), grid.ny = static_cast<int>(cells[1]), grid.nz = static_cast<int>(cells[2]);
  o.read("origin", grid.origin);
  if (o.has("size") == o.has("cell_size")) {
    ctx.fail(ErrorCode::bad_input_file, path, "needs one of \"size\" (the whole grid) or \"cell_size\"");
    return;
  }
  if (o.has("size")) {
    Vec3d size{};
    o.read("size", size);
    // As a C++ scene would write it: size / cells, per axis.
    grid.cell_size = {size[0] / grid.nx, size[1] / grid.ny, size[2] / grid.nz};
  } else {
    o.read("cell_size", grid.cell_size);
  }
  if (const Json* s = o.find("split"))
    read_enum(*s, o.path("split"), ctx, {{"six", TetsPerCell::six}, {"five", TetsPerCell::five}}, grid.split);
  o.finish();
  if (ctx.failed()) return;
  auto mesh = make_tet_grid(grid);
  if (!mesh) return ctx.fail(ErrorCode::bad_parameter, path, mesh.error().message());
  out = std::move(*mesh);
}

// "remove": [boxes]: tets whose centroid lies in a box go (a pit, a slit).
void remove_tets(const Json& v, const std::string& path, Context& ctx, TetMesh& mesh) {
  std::vector<Box> boxes;
  read_array(v, path, ctx, [&](const Json& b, const std::string& p) {
    Box box;
    if (read_box(b, p, ctx, box)) boxes.push_back(box);
  });
  if (ctx.failed()) return;
  std::erase_if(mesh.tets, [&](const std::array<std::uint32_t, 4>& t) {
    Vec3d c{};
    for (std::uint32_t i : t)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * mesh.vertices[i][a];
    return std::any_of(boxes.begin(), boxes.end(), [&](const Box& b) { return b.holds(c); });
  });
}

void read_vertices(const Json& v, const std::string& path, Context& ctx, std::vector<Vec3d>& out) {
  read_array(v, path, ctx, [&](const Json& p, const std::string& pp) {
    Vec3d x{};
    if (read_doubles(p, pp, ctx, x)) out.push_back(x);
  });
}

template <std::size_t N>
void read_index_tuples(const Json& v, const std::string& path, Context& ctx,
                       std::vector<std::array<std::uint32_t, N>>& out) {
  read_array(v, path, ctx, [&](const Json& p, const std::string& pp) {
    std::array<std::uint32_t, N> t{};
    if (read_uint32s(p, pp, ctx, t)) out.push_back(t);
  });
}

// Every index of inline elements names a vertex (what later passes over the
// mesh, boxes and surfaces, rely on).
template <std::size_t N>
void check_indices(const std::vector<std::array<std::uint32_t, N>>& elements, std::size_t vertices,
                   const std::string& path, Context& ctx) {
  for (std::size_t e = 0; e < elements.size() && !ctx.failed(); ++e)
    for (std::size_t k = 0; k < N; ++k)
      if (elements[e][k] >= vertices)
        return ctx.fail(ErrorCode::bad_parameter, path + "/" + std::to_string(e) + "/" + std::to_string(k),
                        "vertex " + std::to_string(elements[e][k]) + " is out of range (there are " +
                            std::to_string(vertices) + ")");
}

// "axes": where each of the mesh's axes goes, e.g. ["x", "z", "-y"] (new x =
// old x, new y = old z, new z = -old y): an exact turn by quarter turns (a
// mesh modelled lying on another side). A reflection would turn every tet
// inside out, so it is refused.
void read_axes(Object& o, std::array<int, 3>& from, std::array<double, 3>& sign) {
  const Json* a = o.find("axes");
  if (!a) return;
  Context& ctx = o.ctx();
  const std::string path = o.path("axes");
  if (!a->is_array() || a->size() != 3)
    return ctx.fail(ErrorCode::bad_input_file, path, "must be three of \"x\", \"y\", \"z\", each maybe with a \"-\"");
  int used = 0;
  for (int k = 0; k < 3; ++k) {
    const Json& e = (*a)[static_cast<std::size_t>(k)];
    const std::string name = e.is_string() ? e.get<std::string>() : "";
    const bool minus = !name.empty() && name[0] == '-';
    const std::string axis = minus ? name.substr(1) : name;
    if (axis != "x" && axis != "y" && axis != "z")
      return ctx.fail(ErrorCode::bad_input_file, path + "/" + std::to_string(k),
                      "must be one of \"x\", \"y\", \"z\", \"-x\", \"-y\", \"-z\"");
    from[k] = axis[0] - 'x';
    sign[k] = minus ? -1.0 : 1.0;
    used |= 1 << from[k];
  }
  if (used != 7) return ctx.fail(ErrorCode::bad_parameter, path, "must name each of x, y and z once");
  // The permutation's parity times the signs: +1 for a rotation.
  const bool odd = (from[0] == 0) + (from[1] == 1) + (from[2] == 2) == 1;
  if ((odd ? -1.0 : 1.0) * sign[0] * sign[1] * sign[2] < 0.0)
    ctx.fail(ErrorCode::bad_parameter, path, "is a reflection, which turns every tet inside out (flip one sign)");
}

// A tet body's "mesh": {"file", "scale", "axes", "translate"} | {"grid", "remove"} | {"vertices", "tets"}.
void read_tet_mesh_source(const Json& v, const std::string& path, const Where& where, Context& ctx, TetMesh& out) {
  Object o(v, path, ctx);
  const int sources = o.has("file") + o.has("grid") + o.has("vertices");
  if (!ctx.failed() && sources != 1)
    return ctx.fail(ErrorCode::bad_input_file, path, "needs exactly one of \"file\", \"grid\" or \"vertices\"");
  double scale = 1.0;
  read_scale(o, scale);
  // Placed where the scene needs it (a mesh file's own coordinates rarely
  // are): added after the scale, as a C++ scene adds it to scaled vertices.
  Vec3d translate{0.0, 0.0, 0.0};
  o.read("translate", translate);
  std::array<int, 3> from{0, 1, 2};
  std::array<double, 3> sign{1.0, 1.0, 1.0};
  read_axes(o, from, sign);
  if (o.has("file")) {
    const std::filesystem::path p = read_file_member(o, where, ctx);
    if (ctx.failed()) return;
    auto mesh = read_tet_mesh(p);
    if (!mesh) return mesh_file_error(ctx, o.path("file"), mesh.error());
    out = std::move(*mesh);
  } else if (const Json* g = o.find("grid")) {
    read_grid(*g, o.path("grid"), ctx, out);
  } else {
    if (const Json* vs = o.find("vertices")) read_vertices(*vs, o.path("vertices"), ctx, out.vertices);
    if (const Json* ts = o.find("tets")) read_index_tuples(*ts, o.path("tets"), ctx, out.tets);
    else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("tets"), "is required with \"vertices\"");
    check_indices(out.tets, out.vertices.size(), o.path("tets"), ctx);
  }
  if (const Json* r = o.find("remove")) {
    remove_tets(*r, o.path("remove"), ctx, out);
    // Vertices left without a tet are dropped (and the rest renumbered in
    // the order the tets use them); a mesh that uses them all keeps its numbering.
    std::vector<bool> used(out.vertices.size(), false);
    for (const auto& t : out.tets)
      for (std::uint32_t i : t) used[i] = true;
    if (std::find(used.begin(), used.end(), false) != used.end()) out = drop_unused_vertices(out);
  }
  o.finish();
  if (!ctx.failed() && scale != 1.0) scale_mesh(out, scale);
  // After the scale, before the translation; exact (a copy and a sign).
  if (!ctx.failed() && (from != std::array<int, 3>{0, 1, 2} || sign != std::array<double, 3>{1.0, 1.0, 1.0}))
    for (auto& vertex : out.vertices) {
      const Vec3d old = vertex;
      for (int k = 0; k < 3; ++k) vertex[k] = sign[k] * old[from[k]];
    }
  if (!ctx.failed() && translate != Vec3d{0.0, 0.0, 0.0})
    for (auto& vertex : out.vertices)
      for (int k = 0; k < 3; ++k) vertex[k] += translate[k];
}

// A tri body's "mesh": {"file" (binary STL), "scale"} | {"vertices", "triangles"}.
void read_tri_mesh_source(const Json& v, const std::string& path, const Where& where, Context& ctx, TriMesh& out) {
  Object o(v, path, ctx);
  if (!ctx.failed() && o.has("file") == o.has("vertices"))
    return ctx.fail(ErrorCode::bad_input_file, path, "needs exactly one of \"file\" or \"vertices\"");
  double scale = 1.0;
  read_scale(o, scale);
  if (o.has("file")) {
    const std::filesystem::path p = read_file_member(o, where, ctx);
    if (ctx.failed()) return;
    auto mesh = read_stl(p);
    if (!mesh) return mesh_file_error(ctx, o.path("file"), mesh.error());
    out = std::move(*mesh);
  } else {
    if (const Json* vs = o.find("vertices")) read_vertices(*vs, o.path("vertices"), ctx, out.vertices);
    if (const Json* ts = o.find("triangles")) read_index_tuples(*ts, o.path("triangles"), ctx, out.triangles);
    else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("triangles"), "is required with \"vertices\"");
    check_indices(out.triangles, out.vertices.size(), o.path("triangles"), ctx);
  }
  o.finish();
  if (!ctx.failed() && scale != 1.0) scale_mesh(out, scale);
}

// "pinned": an array of vertex indices and boxes ({"min", "max"}: every
// vertex inside, bounds included), as a sorted list without repeats.
void read_pins(const Json& v, const std::string& path, Context& ctx, const std::vector<Vec3d>& vertices,
               std::vector<std::uint32_t>& out) {
  read_array(v, path, ctx, [&](const Json& item, const std::string& p) {
    if (item.is_object()) {
      Box box;
      if (!read_box(item, p, ctx, box)) return;
      for (std::uint32_t i = 0; i < vertices.size(); ++i)
        if (box.holds(vertices[i])) out.push_back(i);
      return;
    }
    std::uint32_t i = 0;
    if (!read_uint32(item, p, ctx, i)) return;
    if (i >= vertices.size())
      return ctx.fail(ErrorCode::bad_parameter, p,
                      "vertex " + std::to_string(i) + " is out of range (the mesh has " +
                          std::to_string(vertices.size()) + ")");
    out.push_back(i);
  });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

void read_initial(Object& o, std::vector<Vec3d>& out) {
  if (const Json* iv = o.find("initial_vertices")) read_vertices(*iv, o.path("initial_vertices"), o.ctx(), out);
}

// "elastic": {"youngs_modulus", "poisson_ratio"} -> set_elastic, with its
// error under that key.
template <class Body>
void read_elastic(Object& o, Body& body) {
  const Json* e = o.find("elastic");
  if (!e) return;
  Object eo(*e, o.path("elastic"), o.ctx());
  double young = 0.0, poisson = 0.0;
  eo.read("youngs_modulus", young, true);
  eo.read("poisson_ratio", poisson, true);
  eo.finish();
  if (o.ctx().failed()) return;
  if (Status s = body.set_elastic(young, poisson); !s) {
    const auto [path, rule] = split_scene_message(s.error().message(), {"youngs_modulus", "poisson_ratio"});
    o.ctx().fail(ErrorCode::bad_parameter, o.path("elastic") + path, rule);
  }
}

}  // namespace

std::filesystem::path resolve_file(const Where& where, const std::string& name, const std::string& path,
                                   Context& ctx) {
  std::error_code ec;
  if (name.starts_with(kDataPrefix)) {
    const DataFolder data = data_folder();
    const std::filesystem::path p = data.path / name.substr(kDataPrefix.size());
    if (!std::filesystem::is_regular_file(p, ec))
      ctx.fail(ErrorCode::bad_input_file, path,
               p.string() + " is not a readable file (\"" + std::string(kDataPrefix) + "\" names are found in " +
                   (data.from_environment ? "the environment variable SINEW_DATA_DIR's folder, " + data.path.string()
                                          : "the build's data folder " + data.path.string() +
                                                "; the environment variable SINEW_DATA_DIR names another") +
                   ")");
    return p;
  }
  const std::filesystem::path p = std::filesystem::path(name).is_absolute() ? std::filesystem::path(name)
                                                                             : where.base_dir / name;
  if (!std::filesystem::is_regular_file(p, ec))
    ctx.fail(ErrorCode::bad_input_file, path, p.string() + " is not a readable file");
  return p;
}

std::filesystem::path read_file_member(Object& o, const Where& where, Context& ctx) {
  std::string file;
  o.read("file", file);
  if (ctx.failed()) return {};
  return resolve_file(where, file, o.path("file"), ctx);
}

void read_tet_body(const Json& v, const std::string& path, const Where& where, Context& ctx, TetBodyDesc& out,
                   std::string& name) {
  Object o(v, path, ctx);
  o.read("name", name);
  if (const Json* m = o.find("mesh")) read_tet_mesh_source(*m, o.path("mesh"), where, ctx, out.mesh);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("mesh"), "is required");
  read_initial(o, out.initial_vertices);
  o.read("density", out.density);
  read_elastic(o, out);
  if (const Json* m = o.find("material")) {
    read_enum(*m, o.path("material"), ctx,
              {{"none", TetMaterial::none}, {"neo_hookean", TetMaterial::neo_hookean}, {"stvk", TetMaterial::stvk},
               {"corotational", TetMaterial::corotational}},
              out.material);
    // An FEM material replaces the edge and volume constraints (set_material)
    // unless the file turns them on again below.
    if (out.material != TetMaterial::none) out.distance_constraints = out.volume_constraints = false;
  }
  o.read("youngs_modulus", out.youngs_modulus);
  o.read("poisson_ratio", out.poisson_ratio);
  o.read("distance_constraints", out.distance_constraints);
  o.read("distance_compliance", out.distance_compliance);
  o.read("volume_constraints", out.volume_constraints);
  o.read("volume_compliance", out.volume_compliance);
  if (const Json* p = o.find("pinned")) read_pins(*p, o.path("pinned"), ctx, out.mesh.vertices, out.pinned);
  o.read("tear_strain", out.tear_strain);
  o.read("velocity_damping", out.velocity_damping);
  o.read("stiffness_damping", out.stiffness_damping);
  o.finish();
}

void read_tri_body(const Json& v, const std::string& path, const Where& where, Context& ctx, TriBodyDesc& out,
                   std::string& name) {
  Object o(v, path, ctx);
  o.read("name", name);
  if (const Json* m = o.find("mesh")) read_tri_mesh_source(*m, o.path("mesh"), where, ctx, out.mesh);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("mesh"), "is required");
  read_initial(o, out.initial_vertices);
  o.read("thickness", out.thickness);
  o.read("density", out.density);
  o.read("distance_constraints", out.distance_constraints);
  o.read("distance_compliance", out.distance_compliance);
  o.read("area_constraints", out.area_constraints);
  o.read("area_compliance", out.area_compliance);
  o.read("bending_compliance", out.bending_compliance);
  if (const Json* p = o.find("pinned")) read_pins(*p, o.path("pinned"), ctx, out.mesh.vertices, out.pinned);
  o.read("tear_strain", out.tear_strain);
  o.read("velocity_damping", out.velocity_damping);
  o.read("stiffness_damping", out.stiffness_damping);
  o.finish();
}

void read_line_body(const Json& v, const std::string& path, Context& ctx, LineBodyDesc& out, std::string& name) {
  Object o(v, path, ctx);
  o.read("name", name);
  if (const Json* vs = o.find("vertices")) read_vertices(*vs, o.path("vertices"), ctx, out.vertices);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("vertices"), "is required");
  read_initial(o, out.initial_vertices);
  // "masses" per vertex, or one "mass" for every vertex.
  if (!ctx.failed() && o.has("masses") == o.has("mass"))
    return ctx.fail(ErrorCode::bad_input_file, path, "needs exactly one of \"masses\" or \"mass\" (per vertex)");
  if (const Json* ms = o.find("masses")) {
    read_array(*ms, o.path("masses"), ctx, [&](const Json& m, const std::string& p) {
      double x = 0.0;
      if (read_double(m, p, ctx, x)) out.masses.push_back(x);
    });
  } else {
    double mass = 0.0;
    o.read("mass", mass);
    out.masses.assign(out.vertices.size(), mass);
  }
  // "segments", or absent: a chain through the vertices in order.
  if (const Json* s = o.find("segments")) {
    read_index_tuples(*s, o.path("segments"), ctx, out.segments);
  } else {
    for (std::uint32_t i = 0; i + 1 < out.vertices.size(); ++i) out.segments.push_back({i, i + 1});
  }
  o.read("compliance", out.compliance);
  o.read("bending_compliance", out.bending_compliance);
  if (const Json* p = o.find("pinned")) read_pins(*p, o.path("pinned"), ctx, out.vertices, out.pinned);
  o.read("tear_strain", out.tear_strain);
  o.read("velocity_damping", out.velocity_damping);
  o.read("stiffness_damping", out.stiffness_damping);
  o.finish();
}

void select_triangles(const Json& v, const std::string& path, Context& ctx, const std::vector<Vec3d>& vertices,
                      const std::vector<std::array<std::uint32_t, 3>>& triangles,
                      std::vector<std::array<std::uint32_t, 3>>& out, TriangleTest test) {
  std::vector<Box> boxes;
  read_array(v, path, ctx, [&](const Json& b, const std::string& p) {
    Box box;
    if (read_box(b, p, ctx, box)) boxes.push_back(box);
  });
  if (ctx.failed()) return;
  const auto in_a_box = [&](const Vec3d& p) {
    return std::any_of(boxes.begin(), boxes.end(), [&](const Box& b) { return b.holds(p); });
  };
  for (const auto& t : triangles) {
    if (test == TriangleTest::any_vertex) {
      if (in_a_box(vertices[t[0]]) || in_a_box(vertices[t[1]]) || in_a_box(vertices[t[2]])) out.push_back(t);
      continue;
    }
    Vec3d c{};
    for (std::uint32_t i : t)
      for (int a = 0; a < 3; ++a) c[a] += vertices[i][a] / 3.0;
    if (in_a_box(c)) out.push_back(t);
  }
}

}  // namespace sinew::scene_file
