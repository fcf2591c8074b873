// bleeding_organ_scene.cpp — see bleeding_organ_scene.h.
#include "bleeding_organ_scene.h"

#include <algorithm>
#include <cmath>

namespace sinew::examples {
namespace {

using V3 = std::array<double, 3>;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDrainBall = 1.0;  // the drain's radius [m]: its top is nearly flat under the kidney

}  // namespace

void add_bleeding_organ_options(CommandLine& cli, BleedingOrganOptions& options) {
  cli.app().add_option("--flow", options.flow_ml, "The vessel's mean flow [ml/s] (pulsing +-50% at 72 beats a minute)")
      ->check(at_least(0));
  cli.app().add_option("--suction", options.suction_start, "When the suction tip starts down onto the wound [s]")
      ->check(at_least(0));
  cli.app().add_option("--capacity", options.capacity, "The most fluid particles at once")->check(at_least(1));
  cli.app().add_option("--substeps", options.substeps, "The tissue's substeps per frame")->check(at_least(1));
  cli.app().add_option("--mesh", options.mesh_path, "kidney_57k's .node file (millimetres)");
}

Result<BleedingOrganScene> make_bleeding_organ_scene(const BleedingOrganOptions& options) {
  if (!(options.flow_ml >= 0.0) || !std::isfinite(options.flow_ml))
    return Error(ErrorCode::bad_parameter, "bleeding organ: flow must be finite and >= 0 ml/s");
  if (!(options.suction_start >= 0.0) || !std::isfinite(options.suction_start))
    return Error(ErrorCode::bad_parameter, "bleeding organ: suction start must be finite and >= 0 s");
  if (options.capacity == 0) return Error(ErrorCode::bad_parameter, "bleeding organ: capacity must be > 0");
  if (options.substeps < 1) return Error(ErrorCode::bad_parameter, "bleeding organ: substeps must be >= 1");
  auto mesh = read_tetgen(options.mesh_path);
  if (!mesh) return mesh.error();
  scale_mesh(*mesh, 1e-3);
  // Laid on its back: the file's thinnest axis (z) up, a rotation about x
  // that keeps every tet's orientation.
  for (auto& v : mesh->vertices) v = {v[0], v[2], -v[1]};
  V3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  for (const auto& v : mesh->vertices)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);

  BleedingOrganScene s;
  s.mesh = *mesh;
  s.flow = options.flow_ml * 1e-6;
  s.suction_start = options.suction_start;
  s.drain_level = lo[1] + 0.7 * (hi[1] - lo[1]);
  s.drain_centre = {0.5 * (lo[0] + hi[0]), s.drain_level - kDrainBall, 0.5 * (lo[2] + hi[2])};
  // The wound: the kidney's highest vertex. (A shallow dip in its upper
  // face, 4 mm deep near (69, -48) mm, was tried first: its surface folds
  // there, and blood landing on the fold reached 5 m/s within 4 frames.)
  for (const auto& v : s.mesh.vertices)
    if (v[1] >= hi[1]) s.wound = v;

  TetBodyDesc body;
  body.mesh = s.mesh;
  body.density = 1050.0;
  if (auto made = body.set_material(TetMaterial::corotational, 2e4, 0.45); !made) return made.error();
  body.velocity_damping = 2.0;
  const double rest = lo[1] + 0.5 * (hi[1] - lo[1]);
  for (std::uint32_t v = 0; v < body.mesh.vertices.size(); ++v)
    if (body.mesh.vertices[v][1] < rest) body.pinned.push_back(v);
  // Only the surface the blood can reach carries boundary particles: every
  // triangle with a vertex above the drain level less 8 mm (the drain
  // ball's top falls 2.5 mm below its level 70 mm off its centre, and a
  // particle moves at most 0.8 mm a step).
  TriMesh surface = extract_boundary_surface(body.mesh);
  s.surface_triangles = static_cast<std::uint32_t>(surface.triangles.size());
  std::erase_if(surface.triangles, [&](const std::array<std::uint32_t, 3>& t) {
    double top = -1e30;
    for (std::uint32_t v : t) top = std::max(top, surface.vertices[v][1]);
    return top < s.drain_level - 8e-3;
  });
  s.coupled_triangles = static_cast<std::uint32_t>(surface.triangles.size());
  s.scene.tet_bodies.push_back(std::move(body));
  s.scene.solver.time_step = BleedingOrganScene::kFrame;
  s.scene.solver.substeps = options.substeps;
  s.scene.solver.iterations = 1;

  // The blood: c0 = 5 m/s for flows up to about 0.5 m/s (density within
  // about 1%); 136 steps of 1.23e-4 s per 60 Hz frame (the CFL bound 0.4 h
  // / (c0 + v) is 1.6e-4 s at rest and 1.23e-4 s at 1.5 m/s).
  SceneFluidDesc blood;
  FluidDesc& f = blood.fluid;
  f.settings.spacing = BleedingOrganScene::kSpacing;
  f.settings.rest_density = BleedingOrganScene::kRho;
  f.settings.speed_of_sound = 5.0;
  f.settings.time_step = BleedingOrganScene::kFrame / BleedingOrganScene::kStepsPerFrame;
  f.settings.viscosity = 0.2;
  f.capacity = options.capacity;
  f.emitters.push_back(s.vessel_at(0.0));
  f.sinks.push_back(s.suction_at(0.0));
  f.sinks.push_back({.centre = s.drain_centre, .radius = kDrainBall});
  blood.surfaces.push_back({.body_kind = BodyKind::tet, .body = 0, .triangles = surface.triangles});
  s.scene.fluid = blood;
  return s;
}

FluidEmitter BleedingOrganScene::vessel_at(double t) const {
  // The cut vessel: a 2 mm disc 2 mm above the wound, bleeding down and a
  // little sideways (a vessel cut at an angle); the heart's 72 beats a minute.
  const double rate = flow * (1.0 + 0.5 * std::sin(2.0 * kPi * 1.2 * t));
  return {.centre = {wound[0], wound[1] + 2e-3, wound[2]}, .direction = {0.0, -1.0, 0.0}, .radius = 2e-3,
          .flow_rate = rate};
}

FluidSink BleedingOrganScene::suction_at(double t) const {
  const V3 parked{wound[0], wound[1] + 0.5, wound[2]};
  if (t < suction_start) return {.centre = parked, .radius = kSuctionRadius};
  // Down onto the wound in 0.25 s (its centre 3 mm above the surface, 8 mm
  // beside the vessel), then circling it at 6 mm radius, 0.5 Hz.
  const double down = std::min((t - suction_start) / 0.25, 1.0);
  const double turn = 2.0 * kPi * 0.5 * std::max(t - suction_start - 0.25, 0.0);
  const V3 working{wound[0] + 8e-3 * std::cos(turn), wound[1] + 3e-3, wound[2] + 8e-3 * std::sin(turn)};
  V3 c;
  for (int a = 0; a < 3; ++a) c[a] = parked[a] + down * (working[a] - parked[a]);
  return {.centre = c, .radius = kSuctionRadius};
}

Status BleedingOrganScene::script(SceneFluid& fluid, double t) const {
  if (Status s = fluid.set_emitter(0, vessel_at(t)); !s) return s;
  return fluid.set_sink(0, suction_at(t));
}

TetContainment::TetContainment(const TetMesh& mesh, const std::vector<float>& x, std::uint32_t first, double cell)
    : mesh_(mesh), x_(x), first_(first), cell_(cell) {
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t) {
    V3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
    for (std::uint32_t v : mesh.tets[t]) {
      const V3 p = at(v);
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    }
    const auto l = key(lo), h = key(hi);
    for (long i = l[0]; i <= h[0]; ++i)
      for (long j = l[1]; j <= h[1]; ++j)
        for (long k = l[2]; k <= h[2]; ++k)
          bins_[((long long)(i & 0xfffff) << 40) | ((long long)(j & 0xfffff) << 20) | (long long)(k & 0xfffff)]
              .push_back(t);
  }
}

bool TetContainment::inside(const V3& p) const {
  const auto k = key(p);
  const auto it =
      bins_.find(((long long)(k[0] & 0xfffff) << 40) | ((long long)(k[1] & 0xfffff) << 20) | (long long)(k[2] & 0xfffff));
  if (it == bins_.end()) return false;
  return std::any_of(it->second.begin(), it->second.end(), [&](std::uint32_t t) { return in_tet(t, p); });
}

std::array<long, 3> TetContainment::key(const V3& p) const {
  return {long(std::floor(p[0] / cell_)), long(std::floor(p[1] / cell_)), long(std::floor(p[2] / cell_))};
}

V3 TetContainment::at(std::uint32_t v) const {
  const std::size_t i = 4 * std::size_t{first_ + v};
  return {x_[i], x_[i + 1], x_[i + 2]};
}

bool TetContainment::in_tet(std::uint32_t t, const V3& p) const {
  const auto& T = mesh_.tets[t];
  const V3 a = at(T[0]), b = at(T[1]), c = at(T[2]), d = at(T[3]);
  auto sub = [](const V3& u, const V3& v) { return V3{u[0] - v[0], u[1] - v[1], u[2] - v[2]}; };
  auto det = [](const V3& u, const V3& v, const V3& w) {
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
  };
  const V3 e1 = sub(b, a), e2 = sub(c, a), e3 = sub(d, a), r = sub(p, a);
  const double vol = det(e1, e2, e3);
  if (vol == 0.0) return false;
  const double l1 = det(r, e2, e3) / vol, l2 = det(e1, r, e3) / vol, l3 = det(e1, e2, r) / vol;
  return l1 >= 0 && l2 >= 0 && l3 >= 0 && l1 + l2 + l3 <= 1;
}

void RemovalBooks::update(const std::vector<FluidParticle>& particles, const FluidSink& suction,
                          const BleedingOrganScene& scene, double reach) {
  std::unordered_map<std::uint32_t, std::array<float, 3>> now;
  now.reserve(particles.size());
  for (const FluidParticle& p : particles) {
    now[p.id] = {float(p.position[0]), float(p.position[1]), float(p.position[2])};
    if (!alive_.count(p.id)) ++seen;
  }
  for (const auto& [id, x] : alive_) {
    if (now.count(id)) continue;
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) d2 += (x[a] - suction.centre[a]) * (x[a] - suction.centre[a]);
    const double r = suction.radius + reach;
    if (d2 < r * r) ++near_tip;
    else if (x[1] < scene.drain_level + reach) ++drained;
    else ++unexplained;
  }
  alive_ = std::move(now);
}

}  // namespace sinew::examples
