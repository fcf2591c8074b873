// dissection_scene.cpp — the reference scene S2 (dissection_scene.h).
// The two-way attachments: xPBD distance constraints between barycentric
// points of two bodies (Macklin, Mueller and Chentanez, "XPBD", MIG 2016);
// the burns and cuts: Topology (docs/cutting.md).
#include "dissection_scene.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "sinew/graspers.h"
#include "sinew/mesh.h"
#include "sinew/tools.h"
#include "sinew/topology.h"

namespace sinew::examples {

namespace {

using V3 = std::array<double, 3>;

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
V3 particle(const std::vector<float>& x, std::uint32_t i) { return {x[4 * i], x[4 * i + 1], x[4 * i + 2]}; }

constexpr double kCell = 1e-3;                 // the membrane's cells [m]
constexpr int kNx = 60, kNz = 50;              // its cells: 60 x 50 mm, 6,000 triangles
constexpr double kGap = 1e-3;                  // membrane to each organ at rest [m]
constexpr double kAttachReach = 3e-3;          // membrane vertices this near the gallbladder attach to it [m]
constexpr double kSlabCell = 4e-3;             // the liver bed's cubes [m]
constexpr int kSlabNy = 2;                     // its cubes through its 8 mm thickness
constexpr double kHandleAbove = 0.1;           // the handles ride this far above their working parts [m]
constexpr V3 kJawHalf{0.003, 0.002, 0.003};    // [m]: the jaws close on 7 x 7 membrane vertices
constexpr double kHoldStiffness = 300.0;       // [N/m], all the holds together (their pull on the handle)
constexpr double kCauteryRadius = 2e-3;        // [m]
constexpr double kCauteryDwell = 0.05;         // [s]
constexpr double kToolMass = 0.3;              // [kg]

ToolDesc handle(const V3& position) {
  ToolDesc t;
  t.radius = 0.003;
  t.half_height = 0.015;
  t.mass = kToolMass;
  t.inertia = {1e-4, 1e-4, 1e-4};  // the instrument's, handle included (as S1's)
  t.position = position;
  t.gravity = false;               // the hand carries the instrument
  return t;
}

// A box of tets: nx x ny x nz cubes of `cell` from `lo`, each cube six tets
// around its main diagonal (Kuhn's subdivision: neighbours' faces match).
TetMesh slab(const V3& lo, int nx, int ny, int nz, double cell) {
  TetMesh m;
  auto id = [&](int i, int j, int k) { return static_cast<std::uint32_t>((i * (ny + 1) + j) * (nz + 1) + k); };
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j)
      for (int k = 0; k <= nz; ++k) m.vertices.push_back({lo[0] + i * cell, lo[1] + j * cell, lo[2] + k * cell});
  static constexpr int kPaths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (const auto& path : kPaths) {
          int c[3] = {i, j, k};
          std::array<std::uint32_t, 4> t{};
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[path[s]];
            t[s + 1] = id(c[0], c[1], c[2]);
          }
          // Positive volume for the solver's convention.
          const V3 a = sub(m.vertices[t[1]], m.vertices[t[0]]), b = sub(m.vertices[t[2]], m.vertices[t[0]]),
                   d = sub(m.vertices[t[3]], m.vertices[t[0]]);
          if (dot(cross(a, b), d) < 0.0) std::swap(t[2], t[3]);
          m.tets.push_back(t);
        }
  return m;
}

// Whether p lies inside tet (a, b, c, d); depth: its distance to the nearest face [m].
bool inside_tet(const V3& p, const V3& a, const V3& b, const V3& c, const V3& d, double& depth) {
  const V3 v[4] = {a, b, c, d};
  static constexpr int kFaces[4][4] = {{1, 2, 3, 0}, {0, 3, 2, 1}, {0, 1, 3, 2}, {0, 2, 1, 3}};
  depth = std::numeric_limits<double>::infinity();
  for (const auto& f : kFaces) {
    V3 n = cross(sub(v[f[1]], v[f[0]]), sub(v[f[2]], v[f[0]]));
    const double len = std::sqrt(dot(n, n));
    if (len == 0.0) return false;
    n = {n[0] / len, n[1] / len, n[2] / len};
    // Oriented towards the opposite vertex: p inside when on its side of every face.
    const double side = dot(n, sub(v[f[3]], v[f[0]])) > 0.0 ? 1.0 : -1.0;
    const double s = side * dot(n, sub(p, v[f[0]]));
    if (s < 0.0) return false;
    depth = std::min(depth, s);
  }
  return true;
}

}  // namespace

double DissectionScene::cautery_radius() const { return kCauteryRadius; }

Result<std::unique_ptr<DissectionScene>> DissectionScene::create(const DissectionSettings& settings) {
  if (!(settings.script_speed > 0.0 && std::isfinite(settings.script_speed)))
    return Error(ErrorCode::bad_parameter,
                 "dissection: script_speed must be finite and > 0 (got " + std::to_string(settings.script_speed) + ")");
  if (settings.topology_every < 1)
    return Error(ErrorCode::bad_parameter,
                 "dissection: topology_every must be >= 1 (got " + std::to_string(settings.topology_every) + ")");
  if (!(settings.attachment_compliance >= 0.0 && std::isfinite(settings.attachment_compliance)))
    return Error(ErrorCode::bad_parameter, "dissection: attachment_compliance must be finite and >= 0 (got " +
                                               std::to_string(settings.attachment_compliance) + ")");
  std::unique_ptr<DissectionScene> self(new DissectionScene());
  DissectionScene& s = *self;
  s.settings_ = settings;
  auto mesh = read_tet_mesh(settings.gallbladder);
  if (!mesh) return mesh.error();
  scale_mesh(*mesh, 1e-3);  // millimetres -> metres

  // The gallbladder, held along its top fifth (where it lies in the liver's fossa).
  TetBodyDesc organ;
  organ.mesh = std::move(*mesh);
  organ.density = 1050.0;
  if (auto st = organ.set_material(TetMaterial::corotational, settings.gallbladder_young, 0.45); !st) return st.error();
  organ.velocity_damping = 2.0;
  V3 lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  for (const auto& p : organ.mesh.vertices)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  for (std::uint32_t v = 0; v < organ.mesh.vertices.size(); ++v)
    if (organ.mesh.vertices[v][1] > hi[1] - 0.2 * (hi[1] - lo[1])) organ.pinned.push_back(v);

  // The membrane: 60 x 50 mm, kGap under the gallbladder's lowest point,
  // centred on it in x; along z from 10 mm past its lowest point (its near
  // edge, under the gallbladder) 50 mm towards -z (its far edge, over the liver bed).
  std::uint32_t lowest = 0;
  for (std::uint32_t v = 0; v < organ.mesh.vertices.size(); ++v)
    if (organ.mesh.vertices[v][1] < organ.mesh.vertices[lowest][1]) lowest = v;
  const V3 bottom = organ.mesh.vertices[lowest];
  const double y = bottom[1] - kGap, x0 = bottom[0] - 0.5 * kNx * kCell, z_near = bottom[2] + 0.01,
               z_far = z_near - kNz * kCell;
  TriBodyDesc sheet;
  for (int i = 0; i <= kNx; ++i)
    for (int k = 0; k <= kNz; ++k) sheet.mesh.vertices.push_back({x0 + i * kCell, y, z_far + k * kCell});
  for (std::uint32_t i = 0; i < kNx; ++i)
    for (std::uint32_t k = 0; k < kNz; ++k) {
      const std::uint32_t a = i * (kNz + 1) + k, b = a + 1, c = a + kNz + 1, d = c + 1;
      sheet.mesh.triangles.push_back({a, b, d});
      sheet.mesh.triangles.push_back({a, d, c});
    }
  sheet.density = 1050.0;
  sheet.thickness = 1e-3;
  sheet.distance_compliance = 1.0 / 5e4;  // 50 kPa, as the cholecystectomy example's
  sheet.area_compliance = 1.0 / 5e4;
  sheet.velocity_damping = 2.0;

  // The liver bed: a slab kGap under the membrane's far 20 mm, wider than it
  // in x, pinned along its bottom.
  const int slab_nx = kNx / 4 + 2, slab_nz = 5;
  const V3 slab_lo{x0 - kSlabCell, y - kGap - kSlabNy * kSlabCell, z_far - kSlabCell};
  TetBodyDesc liver;
  liver.mesh = slab(slab_lo, slab_nx, kSlabNy, slab_nz, kSlabCell);
  liver.density = 1060.0;
  if (auto st = liver.set_material(TetMaterial::corotational, 10e3, 0.45); !st) return st.error();
  liver.velocity_damping = 2.0;
  for (std::uint32_t v = 0; v < liver.mesh.vertices.size(); ++v)
    if (liver.mesh.vertices[v][1] < slab_lo[1] + 1e-9) liver.pinned.push_back(v);
  s.liver_top_ = y - kGap;
  s.liver_xz_ = {slab_lo[0], slab_lo[0] + slab_nx * kSlabCell, slab_lo[2], slab_lo[2] + slab_nz * kSlabCell};

  // The attachments, two ways (BodyAttachmentDesc). To the gallbladder: each
  // membrane vertex within kAttachReach of a gallbladder vertex, to the
  // nearest, holding their rest distance (a strut of connective tissue).
  // To the liver: each membrane vertex over the slab's top (1 mm margin) to
  // the point of the top face below it (bilinear weights of its cube's four
  // top corners), kGap apart.
  SceneDesc& scene = s.scene_;
  std::vector<char> on_gallbladder(organ.mesh.vertices.size(), 0), on_liver(liver.mesh.vertices.size(), 0);
  for (std::uint32_t v = 0; v < sheet.mesh.vertices.size(); ++v) {
    const V3& p = sheet.mesh.vertices[v];
    std::uint32_t nearest = 0;
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t u = 0; u < organ.mesh.vertices.size(); ++u) {
      const V3 d = sub(organ.mesh.vertices[u], p);
      if (dot(d, d) < best) best = dot(d, d), nearest = u;
    }
    if (std::sqrt(best) <= kAttachReach) {
      scene.body_attachments.push_back({.a = {.body_kind = BodyKind::tri, .body = 0, .vertices = {v}, .weights = {1.0}},
                                        .b = {.body_kind = BodyKind::tet, .body = 0, .vertices = {nearest}, .weights = {1.0}},
                                        .compliance = settings.attachment_compliance,
                                        .rest_length = std::sqrt(best)});
      on_gallbladder[nearest] = 1;
      continue;
    }
    const double u = (p[0] - slab_lo[0]) / kSlabCell, w = (p[2] - slab_lo[2]) / kSlabCell;
    if (u < 0.25 || u > slab_nx - 0.25 || w < 0.25 || w > slab_nz - 0.25) continue;
    const int i = std::min(static_cast<int>(u), slab_nx - 1), k = std::min(static_cast<int>(w), slab_nz - 1);
    const double fu = u - i, fw = w - k;
    auto top = [&](int a, int c) { return static_cast<std::uint32_t>(((i + a) * (kSlabNy + 1) + kSlabNy) * (slab_nz + 1) + k + c); };
    BarycentricPoint b;
    b.body_kind = BodyKind::tet;
    b.body = 1;
    const double weights[4] = {(1 - fu) * (1 - fw), (1 - fu) * fw, fu * (1 - fw), fu * fw};
    const std::uint32_t corners[4] = {top(0, 0), top(0, 1), top(1, 0), top(1, 1)};
    for (int c = 0; c < 4; ++c)
      if (weights[c] > 1e-9) b.vertices.push_back(corners[c]), b.weights.push_back(weights[c]);
    double sum = 0.0;
    for (double q : b.weights) sum += q;
    for (double& q : b.weights) q /= sum;
    for (auto c : b.vertices) on_liver[c] = 1;
    scene.body_attachments.push_back({.a = {.body_kind = BodyKind::tri, .body = 0, .vertices = {v}, .weights = {1.0}},
                                      .b = std::move(b), .compliance = settings.attachment_compliance,
                                      .rest_length = kGap});
  }
  if (scene.body_attachments.empty())
    return Error(ErrorCode::bad_parameter, "dissection: no membrane vertex lies near the gallbladder or the liver bed");

  scene.gravity = {0.0, -9.81, 0.0};
  scene.solver.time_step = 1.0 / 60.0;
  scene.solver.substeps = settings.substeps;
  scene.solver.iterations = settings.iterations;
  scene.topology_changes = true;
  scene.mesh_collision.enabled = settings.mesh_collision;
  // The membrane's thickness (1 mm), its gap to each organ at rest.
  // Measured: at half of it the membrane's cut flaps passed 9 mm into the bed.
  scene.mesh_collision.thickness = kGap;
  // The membrane's folds on itself are not this scene's subject; the
  // gallbladder's and the slab's surfaces do not fold at these strains.
  scene.mesh_collision.self_collision = false;
  scene.tet_bodies.push_back(organ);
  scene.tet_bodies.push_back(liver);
  scene.tri_bodies.push_back(sheet);

  // The working parts at rest: the jaws over the membrane's free middle
  // (halfway between the last gallbladder attachment and the liver bed's
  // near edge, at x of the gallbladder's bottom); the cautery's tip at the
  // liver attachments' near line, the blade's edge across the gallbladder
  // attachments' far line, both at the membrane's -x edge, 3 mm outside it.
  double z_gb = z_near;
  for (const auto& a : scene.body_attachments)
    if (a.b.body == 0) z_gb = std::min(z_gb, sheet.mesh.vertices[a.a.vertices[0]][2]);
  const double z_lv = s.liver_xz_[3] - 0.25 * kSlabCell;
  const V3 jaws{bottom[0], y, 0.5 * (z_gb + z_lv)};
  const V3 tip{x0 - 3e-3, y, z_lv - 1e-3};
  const V3 edge{x0 - 3e-3, y, z_gb - 1.5e-3};
  s.jaw_half_ = kJawHalf;
  s.jaw_offset_ = {0.0, -kHandleAbove, 0.0};
  s.tip_offset_ = {0.0, -kHandleAbove, 0.0};
  s.jaws_ = {.position = jaws};
  s.tip_ = tip;
  scene.tools.push_back(handle(add(jaws, {0.0, kHandleAbove, 0.0})));
  scene.tools.push_back(handle(add(tip, {0.0, kHandleAbove, 0.0})));
  scene.tools.push_back(handle(add(edge, {0.0, kHandleAbove, 0.0})));
  std::size_t inside = 0;
  for (const auto& p : sheet.mesh.vertices) {
    const V3 d = sub(p, jaws);
    inside += std::abs(d[0]) <= kJawHalf[0] && std::abs(d[1]) <= kJawHalf[1] && std::abs(d[2]) <= kJawHalf[2];
  }
  s.hold_compliance_ = double(std::max<std::size_t>(inside, 1)) / kHoldStiffness;
  scene.graspers.push_back({.capacity = 64, .point_capacity = 0, .compliance = s.hold_compliance_});

  auto sim = Simulation::create(scene, {.backend = settings.backend, .threads = settings.threads, .quiet = true});
  if (!sim) return sim.error();
  s.sim_.emplace(std::move(*sim));
  const std::uint32_t gb_first = s.sim_->info().tet_body_first_particle[0];
  const std::uint32_t lv_first = s.sim_->info().tet_body_first_particle[1];
  for (std::uint32_t v = 0; v < on_gallbladder.size(); ++v)
    if (on_gallbladder[v]) s.gallbladder_attached_.push_back(gb_first + v);
  for (std::uint32_t v = 0; v < on_liver.size(); ++v)
    if (on_liver[v]) s.liver_attached_.push_back(lv_first + v);
  for (const auto& t : scene.tet_bodies[0].mesh.tets)
    s.gallbladder_tets_.push_back({gb_first + t[0], gb_first + t[1], gb_first + t[2], gb_first + t[3]});

  // The hands: the grasper lifts kLift; the cautery and the blade sweep
  // across the membrane in +x (its 60 mm and 6 mm more) while dissecting.
  using namespace haptics;
  const double k = 1.0 / settings.script_speed;
  const double sweep = kNx * kCell + 6e-3;
  std::vector<std::vector<PathKey>> keys(3);
  const V3 g0 = scene.tools[0].position, c0 = scene.tools[1].position, b0 = scene.tools[2].position;
  keys[0] = {{0.0, g0}, {kLiftStart * k, g0}, {kLiftEnd * k, add(g0, {0.0, kLift, 0.0})}, {kScriptEnd * k, add(g0, {0.0, kLift, 0.0})}};
  keys[1] = {{0.0, c0}, {kDissectStart * k, c0}, {kDissectEnd * k, add(c0, {sweep, 0.0, 0.0})}};
  keys[2] = {{0.0, b0}, {kDissectStart * k, b0}, {kDissectEnd * k, add(b0, {sweep, 0.0, 0.0})}};
  std::vector<ScriptedHandDesc> hands;
  for (std::uint32_t i = 0; i < 3; ++i) {
    // Linear between the dissecting keys: the tools move at constant speed.
    auto path = KeyframePath::create(keys[i], i == 0 ? PathInterpolation::smooth : PathInterpolation::linear);
    if (!path) return path.error();
    ScriptedHandDesc h;
    h.tool = i;
    h.path = std::move(*path);
    h.loop.rate_hz = 1000.0;
    h.loop.coupling.damping = 3.0;  // passive on the coupling spring at 1 kHz (as S1)
    h.tool_damping = 20.0;          // the tool loop's ~1.5 frames of delay (as S1, tool_bridge.h)
    h.tool_angular_damping = 2e-3;
    hands.push_back(std::move(h));
  }
  auto made = ScriptedHands::create(std::move(hands), *s.sim_, scene.solver.time_step);
  if (!made) return made.error();
  s.hands_ = std::move(*made);
  if (auto st = s.grasp(); !st) return st.error();
  return self;
}

Result<Pose> DissectionScene::tool_pose(std::uint32_t index) {
  auto tool = sim_->tools().tool(index);
  if (!tool) return tool.error();
  auto state = sim_->tools().state(*tool);
  if (!state) return state.error();
  return Pose{.position = state->position, .rotation = state->rotation};
}

Status DissectionScene::grasp() {
  auto grasper = sim_->graspers().grasper(0);
  if (!grasper) return grasper.error();
  auto held = sim_->graspers().close(*grasper, jaws_, jaw_half_);
  if (!held) return held.error();
  if (held->empty()) return Error(ErrorCode::bad_parameter, "dissection: the grasper's jaws hold no membrane vertex");
  held_ = std::move(*held);
  if (auto st = sim_->read_positions(x_); !st) return st;
  for (std::uint32_t i : held_) held_offset_.push_back(sub(particle(x_, i), jaws_.position));
  return {};
}

double DissectionScene::mean_y(const std::vector<std::uint32_t>& particles) const {
  double y = 0.0;
  for (std::uint32_t i : particles) y += x_[4 * i + 1];
  return particles.empty() ? 0.0 : y / double(particles.size());
}

Status DissectionScene::frame() {
  ++frames_;
  if (auto st = hands_->before_step(*sim_); !st) return st;
  auto grasper = sim_->graspers().grasper(0);
  auto tool = sim_->tools().tool(0);
  if (!grasper) return grasper.error();
  if (!tool) return tool.error();
  // The holds' pull on the jaws acts on the grasper's handle (S1's way).
  if (auto st = sim_->tools().apply_force(*tool, pull_, {0.0, 0.0, 0.0}); !st) return st;
  auto g = tool_pose(0);
  if (!g) return g.error();
  jaws_ = {.position = add(g->position, jaw_offset_), .rotation = g->rotation};
  if (auto st = sim_->graspers().move(*grasper, jaws_); !st) return st;

  // The cautery and the blade, while the script dissects, every
  // topology_every frames: the burn where the tip is, the cut from the
  // blade's edge at its last cut (2 mm further back: the membrane moves
  // between cuts, as the cholecystectomy example found) to where it is now.
  const double t = double(frames_) * frame_time() * settings_.script_speed;
  dissecting_ = t >= kDissectStart && t <= kDissectEnd;
  auto c = tool_pose(1), b = tool_pose(2);
  if (!c) return c.error();
  if (!b) return b.error();
  tip_ = add(c->position, tip_offset_);
  const V3 blade_mid = add(b->position, tip_offset_);
  edge_ = {add(blade_mid, {0.0, 5e-3, 0.0}), add(blade_mid, {0.0, -8e-3, 0.0})};
  last_topology_ms_ = 0.0;
  if (dissecting_ && frames_ % settings_.topology_every == 0) {
    Topology topology = sim_->topology();
    auto membrane = topology.tri_body(0);
    if (!membrane) return membrane.error();
    const auto t0 = std::chrono::steady_clock::now();
    const double burnt = frame_time() * settings_.topology_every;  // the tip touched since its last burn [s]
    auto burn = topology.cauterize(*membrane, tip_, kCauteryRadius, burnt, kCauteryDwell);
    if (!burn) return burn.error();
    auto from = last_edge_.value_or(edge_);
    for (auto& e : from) e[0] -= 2e-3;
    auto cut = topology.cut(*membrane, {from[0], from[1]}, {edge_[0], edge_[1]});
    if (!cut) return cut.error();
    last_edge_ = edge_;
    last_topology_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (const auto* e : {&*burn, &*cut})
      if (!e->triangles_removed.empty()) ++events_, removed_ += e->triangles_removed.size();
  }
  if (auto st = sim_->step(); !st) return st;
  if (auto st = hands_->after_step(*sim_); !st) return st;
  return measure_pull();
}

Status DissectionScene::measure_pull() {
  if (auto st = sim_->read_positions(x_); !st) return st;
  pull_ = {};
  for (std::size_t k = 0; k < held_.size(); ++k) {
    const V3 d = sub(particle(x_, held_[k]), add(jaws_.position, held_offset_[k]));
    for (int c = 0; c < 3; ++c) pull_[c] += d[c] / hold_compliance_;
  }
  // The lift's baseline: the attached regions where the lift begins.
  if (!baseline_ && double(frames_) * frame_time() * settings_.script_speed >= kLiftStart) {
    gallbladder_y0_ = mean_y(gallbladder_attached_);
    liver_y0_ = mean_y(liver_attached_);
    held_y0_ = mean_y(held_);
    baseline_ = true;
  }
  return {};
}

Result<DissectionCheck> DissectionScene::check() {
  if (auto st = sim_->read_positions(x_); !st) return st.error();
  DissectionCheck c;
  for (float v : x_) c.finite = c.finite && std::isfinite(v);
  c.grasp_force = pull_;
  if (baseline_) {
    c.gallbladder_lift = mean_y(gallbladder_attached_) - gallbladder_y0_;
    c.liver_lift = mean_y(liver_attached_) - liver_y0_;
    c.membrane_lift = mean_y(held_) - held_y0_;
  }
  auto membrane = sim_->topology().tri_body(0);
  if (!membrane) return membrane.error();
  auto live = sim_->topology().current_triangles(*membrane);
  if (!live) return live.error();
  c.membrane_triangles = live->size();
  const std::uint32_t first = sim_->info().tri_body_first_particle[0];
  std::vector<char> used(scene_.tri_bodies[0].mesh.vertices.size(), 0);
  for (const auto& tri : *live)
    for (std::uint32_t v : tri) used[v] = 1;
  // Inside the gallbladder (its tets, where they are now) or below the
  // liver bed's top within its x and z range (the slab's top sags little:
  // pinned 8 mm below, the membrane's pull on it is grams).
  for (std::uint32_t v = 0; v < used.size(); ++v) {
    if (!used[v]) continue;
    const V3 p = particle(x_, first + v);
    if (p[0] > liver_xz_[0] && p[0] < liver_xz_[1] && p[2] > liver_xz_[2] && p[2] < liver_xz_[3])
      c.deepest_inside = std::max(c.deepest_inside, liver_top_ - p[1]);
    for (const auto& t : gallbladder_tets_) {
      double depth = 0.0;
      if (inside_tet(p, particle(x_, t[0]), particle(x_, t[1]), particle(x_, t[2]), particle(x_, t[3]), depth))
        c.deepest_inside = std::max(c.deepest_inside, depth);
    }
  }
  return c;
}

}  // namespace sinew::examples
