// simulation_contacts.cpp — moving colliders and targets between frames, and
// the tools' rigid-body motion.
//
// Colliders and targets: each entry of the collider and target buffers
// (kernels/shared/contact_params.h) holds a pose at the start and at the end
// of the frame, which the kernels interpolate per substep. set_collider_pose
// and set_target write the end pose; after each frame the start pose becomes
// that end pose. The buffers are uploaded before a frame only when something
// changed, so static colliders cost no transfer.
//
// Tools: a tool is a capsule collider whose motion the host integrates. The
// coupling with the tissue is explicit and one frame long:
//  1. before frame n (before_frame): semi-implicit Euler over the frame with
//     the applied force and torque (apply_tool_force), gravity, and the
//     tissue's reaction measured in frame n-1: v += dt F / M, x += dt v;
//     the angular velocity likewise from the torque (inertia in the body
//     frame, the gyroscopic term implicit), q += dt/2 (0, omega) q. The
//     tool's collider then moves from its old to its new pose across frame
//     n's substeps.
//  2. during frame n the tool is an infinitely heavy kinematic collider: the
//     particles it touches are pushed out and dragged by friction, and each
//     correction's impulse (with its moment about the tool's centre) is
//     summed per particle and tool in the contact-impulse buffer.
//  3. after frame n (after_frame): the sums are read back and reduced in
//     particle order, in double precision (deterministic), to the frame's
//     average contact force and torque (reported by tool_state) and to the
//     force and torque of the frame's last substep, which step 1 uses: that
//     one belongs to the pose the tool has at the end of the frame, so the
//     scheme is symplectic Euler on the tool. (Coupling with the frame
//     average, which belongs to the middle of the frame, lags half a frame
//     and pumps energy into the tool at any mass: x_{n+1} - 2 x_n + x_{n-1}
//     = -(omega dt)^2 (x_n + x_{n-1}) / 2 has roots of modulus
//     sqrt(1 + (omega dt)^2 / 2) > 1.)
// Limits.
//  - Stability: explicit Euler on a contact of stiffness k is stable while
//    sqrt(k / M) dt < 2. That holds for a tool much heavier than the
//    particles it touches. A slender tool's tiny inertia about its own axis
//    would break it in rotation, so rotation is stabilised by the touching
//    particles' inertia; a light tool would break it in translation, so its
//    mass is floored at what the bound needs (see integrate()). Neither
//    makes a light tool right: the tissue is pushed by the tool's full
//    motion as if the tool were immovable and answers a frame later. In the
//    tests' scene (20 substeps at 60 Hz) a tool 10^4 times as heavy as a
//    particle rests; one 3 10^3 times or lighter is not held: it drifts
//    sideways and slides off the block within a few seconds (without the
//    mass floor, one 10^2 times as heavy was thrown off at 1.8 m/s). Drive a
//    light or hand-held tool through a virtual coupling (a spring-damper
//    from the user's pose, via apply_tool_force, stiff no more than the
//    bound allows) or use a shorter time step.
//  - Tunnelling: contacts are between particles (mesh vertices) and the
//    tool's surface, not the tissue's faces. A tool M times as heavy as the
//    N particles of mass m it rests on pushes them about
//    (M / (N m)) g h^2 / iterations deep per substep before the tissue's
//    response reaches them; when that nears the vertex spacing, or a tool
//    is narrower than it, the tool pushes vertices apart and passes between
//    them. More substeps (smaller h) or a finer surface mesh cure it.
//  - A resting tool keeps a small jitter (no damping is added); compare
//    averages of tool_state over a few frames.
//
// State: Impl::colliders and Impl::targets are host copies of the device
// buffers; the tools' rigid state and the impulse read-back live in
// Impl::contacts (contact_state.h), all sized in init_contacts: nothing here
// allocates per frame.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "compiler/float_words.h"
#include "contact_params.h"
#include "runtime/simulation_impl.h"

namespace sinew {
namespace {

using kernels::ColliderEntry;
using kernels::ColliderHeader;
using kernels::TargetEntry;
using V3 = std::array<double, 3>;
using Q4 = std::array<double, 4>;  // (w, x, y, z)

constexpr std::size_t kHeaderFloats = sizeof(ColliderHeader) / sizeof(float);
constexpr std::size_t kEntryFloats = sizeof(ColliderEntry) / sizeof(float);
constexpr std::size_t kTargetFloats = sizeof(TargetEntry) / sizeof(float);

std::size_t device_floats(const std::vector<float>& c) {
  const auto h = load_words<ColliderHeader>(c, 0);
  return kHeaderFloats + std::size_t{h.colliders + h.tools} * kEntryFloats;
}
std::size_t entry_at(std::size_t k) { return kHeaderFloats + k * kEntryFloats; }

std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

Status check_index(const char* call, const char* what, std::size_t index, std::size_t count) {
  if (index < count) return {};
  return Error(std::string(call) + ": index " + std::to_string(index) + " is not a " + what + " (the scene has " +
               std::to_string(count) + ")");
}

Status check_finite(const char* call, const char* name, const V3& v) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(v[k]))
      return Error(std::string(call) + ": " + name + "[" + std::to_string(k) + "] must be finite (got " + str(v[k]) +
                   ")");
  return {};
}

Status check_rotation(const char* call, const Q4& q) {
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-6)
    return Error(std::string(call) + ": rotation must be a unit quaternion (w, x, y, z) (its norm is " + str(n) + ")");
  return {};
}

void set_end_pose(ColliderEntry& e, const V3& p, const Q4& q) {
  e.end_px = static_cast<float>(p[0]);
  e.end_py = static_cast<float>(p[1]);
  e.end_pz = static_cast<float>(p[2]);
  e.end_qw = static_cast<float>(q[0]);
  e.end_qx = static_cast<float>(q[1]);
  e.end_qy = static_cast<float>(q[2]);
  e.end_qz = static_cast<float>(q[3]);
}

// Start pose := end pose; true when that changed it.
bool settle(ColliderEntry& e) {
  const bool moved = e.start_px != e.end_px || e.start_py != e.end_py || e.start_pz != e.end_pz ||
                     e.start_qw != e.end_qw || e.start_qx != e.end_qx || e.start_qy != e.end_qy ||
                     e.start_qz != e.end_qz;
  e.start_px = e.end_px;
  e.start_py = e.end_py;
  e.start_pz = e.end_pz;
  e.start_qw = e.end_qw;
  e.start_qx = e.end_qx;
  e.start_qy = e.end_qy;
  e.start_qz = e.end_qz;
  return moved;
}

V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// v rotated by the unit quaternion q (inverse: conjugate first).
V3 rotate(const Q4& q, const V3& v, bool inverse = false) {
  const V3 u{inverse ? -q[1] : q[1], inverse ? -q[2] : q[2], inverse ? -q[3] : q[3]};
  V3 t = cross(u, v);
  for (double& c : t) c *= 2.0;
  const V3 ut = cross(u, t);
  return {v[0] + q[0] * t[0] + ut[0], v[1] + q[0] * t[1] + ut[1], v[2] + q[0] * t[2] + ut[2]};
}

using M3 = std::array<V3, 3>;  // row-major

double det3(const M3& a) {
  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

// Solves a x = f by Cramer's rule; false (x untouched) when a is singular.
bool solve3(const M3& a, const V3& f, V3& x) {
  const double d = det3(a);
  if (!(std::abs(d) > 0.0) || !std::isfinite(d)) return false;
  V3 out;
  for (int k = 0; k < 3; ++k) {
    M3 m = a;
    for (int r = 0; r < 3; ++r) m[r][k] = f[r];
    out[k] = det3(m) / d;
  }
  x = out;
  return true;
}

// One Newton step of implicit Euler on I (w' - w) + dt w' x (I w') = 0 from
// w' = w, in the body frame: w' = w - J^-1 dt w x (I w) with
// J = I + dt (skew(w) I - skew(I w)).
V3 gyroscopic_step(const V3& inertia, const V3& w, double dt) {
  const V3 iw{inertia[0] * w[0], inertia[1] * w[1], inertia[2] * w[2]};
  V3 f = cross(w, iw);
  for (double& c : f) c *= dt;
  auto skew = [](const V3& v) { return M3{V3{0.0, -v[2], v[1]}, V3{v[2], 0.0, -v[0]}, V3{-v[1], v[0], 0.0}}; };
  const M3 sw = skew(w), siw = skew(iw);
  M3 j;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) j[r][c] = (r == c ? inertia[r] : 0.0) + dt * (sw[r][c] * inertia[c] - siw[r][c]);
  V3 step{0.0, 0.0, 0.0};
  if (!solve3(j, f, step)) return w;
  return {w[0] - step[0], w[1] - step[1], w[2] - step[2]};
}

// One semi-implicit Euler step of the tool over dt.
//
// The explicit coupling is stable while (omega dt)^2 = k dt^2 / M < 4 for
// the contact's stiffness k. A bound on k: within a substep of length h, a
// touching particle of mass m_i passes on at most about m_i / h^2 per unit
// of the tool's displacement per iteration, so k <= K = n_it sum_i m_i / h^2
// and dt^2 K = n_it n_sub^2 sum_i m_i (and likewise for rotation, with the
// particles' inertia sum_i m_i (|r_i|^2 I - r_i r_i^T) about the tool's
// centre). So:
//  - translation uses the tool's mass M, or dt^2 K / 4 where that is more:
//    a tool heavy enough for the bound is integrated as it is (the tests'
//    10^4 mass ratio is); a lighter one is slowed down (over-damped) rather
//    than thrown off. (Adding dt^2 K to M always, as for rotation, would
//    also let a heavy tool sink deeper before the tissue stops it.)
//  - rotation solves (I_tool + dt^2 K) dw = dt tau: (omega dt)^2 < 1 however
//    small the tool's inertia. That matters for a slender tool, whose
//    inertia about its own axis (m r^2 / 2) is tiny: without it, friction
//    spins the tool up until it rolls away. Rotation while touching is
//    slower than it would be.
// Equilibria are unchanged (no velocity change where the force and torque
// vanish). `stiffness` is n_it n_sub^2.
void integrate(ToolBody& b, double dt, double stiffness) {
  V3 force, torque;
  for (int k = 0; k < 3; ++k) {
    force[k] = b.force[k] + b.coupling_force[k] + b.mass * b.gravity[k];
    torque[k] = b.torque[k] + b.coupling_torque[k];
  }
  // Translation: the tool's own mass, raised where needed to the least
  // mass that keeps explicit Euler inside its stability bound against K:
  // dt^2 K / M <= 4 with dt^2 K = n_it n_sub^2 sum m_i (see above).
  const double mass = std::max(b.mass, 0.25 * stiffness * b.touching_mass);
  for (int k = 0; k < 3; ++k) b.velocity[k] += dt * force[k] / mass;
  // The tool's inertia in the world frame, R I R^T, plus the touching
  // particles' scaled inertia about its centre.
  M3 a;
  for (int c = 0; c < 3; ++c) {
    V3 e{0.0, 0.0, 0.0};
    e[c] = 1.0;
    V3 local = rotate(b.rotation, e, true);
    for (int k = 0; k < 3; ++k) local[k] *= b.inertia[k];
    const V3 column = rotate(b.rotation, local);
    for (int r = 0; r < 3; ++r) a[r][c] = column[r] + stiffness * b.touching_inertia[3 * r + c];
  }
  V3 dw{0.0, 0.0, 0.0};
  const V3 impulse{dt * torque[0], dt * torque[1], dt * torque[2]};
  if (solve3(a, impulse, dw))  // a is symmetric positive definite: inertia > 0
    for (int k = 0; k < 3; ++k) b.angular_velocity[k] += dw[k];
  // The gyroscopic term of Euler's equations, I dw/dt = -w x (I w) in the
  // body frame, implicitly by one Newton step (Catto, "Numerical Methods",
  // GDC 2015): explicitly, a free tumbling tool would gain energy.
  b.angular_velocity = rotate(b.rotation, gyroscopic_step(b.inertia, rotate(b.rotation, b.angular_velocity, true), dt));

  for (int k = 0; k < 3; ++k) b.position[k] += dt * b.velocity[k];
  const V3& o = b.angular_velocity;
  const Q4& q = b.rotation;
  const Q4 dq{-(o[0] * q[1] + o[1] * q[2] + o[2] * q[3]), o[0] * q[0] + o[1] * q[3] - o[2] * q[2],
              o[1] * q[0] + o[2] * q[1] - o[0] * q[3], o[2] * q[0] + o[0] * q[2] - o[1] * q[1]};  // (0, o) q
  Q4 r;
  double norm = 0.0;
  for (int k = 0; k < 4; ++k) {
    r[k] = q[k] + 0.5 * dt * dq[k];
    norm += r[k] * r[k];
  }
  norm = std::sqrt(norm);
  for (double& c : r) c /= norm;
  b.rotation = r;
  b.force = b.torque = V3{0.0, 0.0, 0.0};
}

}  // namespace

Status Simulation::Impl::init_contacts(const SceneDesc& scene, const CompiledScene& compiled) {
  colliders = compiled.colliders;
  targets = compiled.targets;
  if (colliders.size() < kHeaderFloats) {  // no collider buffer compiled: an empty header
    colliders.assign(kHeaderFloats, 0.0f);
    store_words(colliders, 0, ColliderHeader{0, 0, 1.0f, 0});
  }
  const auto header = load_words<ColliderHeader>(colliders, 0);
  if (header.colliders != scene.colliders.size() || header.tools != scene.tools.size() ||
      colliders.size() != device_floats(colliders))
    return Error("internal: the compiled collider buffer does not match the scene's colliders and tools");

  contacts = ContactState{};
  contacts.colliders = header.colliders;
  contacts.substeps = static_cast<std::uint32_t>(scene.solver.substeps);
  contacts.iterations = static_cast<std::uint32_t>(scene.solver.iterations);
  contacts.impulses.assign(std::size_t{compiled.contact_impulse_slots} * 4, 0.0f);
  for (const ToolDesc& d : scene.tools) {
    ToolBody& b = contacts.tools.emplace_back();
    b.position = d.position;
    b.rotation = d.rotation;
    if (d.gravity) b.gravity = scene.gravity;
    b.inertia = d.inertia;
    b.mass = d.mass;
  }
  return {};
}

Status Simulation::Impl::before_frame() {
  ContactState& c = contacts;
  for (std::size_t t = 0; t < c.tools.size(); ++t) {
    ToolBody& b = c.tools[t];
    const std::size_t at = entry_at(c.colliders + t);
    auto e = load_words<ColliderEntry>(colliders, at);
    integrate(b, time_step, double(c.iterations) * c.substeps * c.substeps);
    settle(e);  // the frame starts where the last one ended
    set_end_pose(e, b.position, b.rotation);
    store_words(colliders, at, e);
    c.colliders_dirty = true;
  }
  if (c.colliders_dirty) {
    if (Status s = device->write_buffer(buffers.colliders, 0, colliders.data(), colliders.size() * sizeof(float)); !s)
      return s;
    c.colliders_dirty = false;
  }
  if (c.targets_dirty && !targets.empty()) {
    if (Status s = device->write_buffer(buffers.targets, 0, targets.data(), targets.size() * sizeof(float)); !s)
      return s;
  }
  c.targets_dirty = false;
  return {};
}

Status Simulation::Impl::after_frame() {
  ContactState& c = contacts;
  // What moved during this frame stays at its end pose from now on.
  for (std::uint32_t k = 0; k < c.colliders; ++k) {
    auto e = load_words<ColliderEntry>(colliders, entry_at(k));
    if (settle(e)) {
      store_words(colliders, entry_at(k), e);
      c.colliders_dirty = true;
    }
  }
  for (std::size_t at = 0; at + kTargetFloats <= targets.size(); at += kTargetFloats) {
    auto e = load_words<TargetEntry>(targets, at);
    if (e.start_x != e.end_x || e.start_y != e.end_y || e.start_z != e.end_z) {
      e.start_x = e.end_x;
      e.start_y = e.end_y;
      e.start_z = e.end_z;
      store_words(targets, at, e);
      c.targets_dirty = true;
    }
  }
  if (c.tools.empty()) return {};

  // The tissue's reaction on each tool: the frame's impulse sums, reduced
  // in particle order in double precision.
  if (!c.impulses.empty())
    if (Status s = device->read_buffer(buffers.contact_impulses, 0, c.impulses.data(), c.impulses.size() * sizeof(float));
        !s)
      return s;
  const std::size_t tools = c.tools.size();
  const std::size_t particles = c.impulses.size() / (4 * SINEW_CONTACT_IMPULSE_FLOAT4S * tools);
  const double h = time_step / c.substeps;
  for (std::size_t t = 0; t < tools; ++t) {
    double sums[4][3] = {};  // frame impulse, its moment, last substep's impulse, its moment
    double mass = 0.0;
    std::array<double, 9> inertia{};
    for (std::size_t p = 0; p < particles; ++p) {
      const float* slot = c.impulses.data() + (p * tools + t) * SINEW_CONTACT_IMPULSE_FLOAT4S * 4;
      for (int s = 0; s < 4; ++s)
        for (int k = 0; k < 3; ++k) sums[s][k] += slot[4 * s + k];
      const double m = slot[19];
      if (m > 0.0) {  // touching at the end of the frame: lever r = slot[16..18]
        const V3 r{slot[16], slot[17], slot[18]};
        const double r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        mass += m;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) inertia[3 * i + j] += m * ((i == j ? r2 : 0.0) - r[i] * r[j]);
      }
    }
    ToolBody& b = c.tools[t];
    for (int k = 0; k < 3; ++k) {
      b.contact_force[k] = sums[0][k] / time_step;
      b.contact_torque[k] = sums[1][k] / time_step;
      b.coupling_force[k] = sums[2][k] / h;
      b.coupling_torque[k] = sums[3][k] / h;
    }
    b.touching_mass = mass;
    b.touching_inertia = inertia;
  }
  return {};
}

Status Simulation::set_collider_pose(std::size_t index, const std::array<double, 3>& position,
                                     const std::array<double, 4>& rotation) {
  constexpr const char* call = "set_collider_pose";
  if (Status s = check_index(call, "collider", index, impl_->contacts.colliders); !s) return s;
  if (Status s = check_finite(call, "position", position); !s) return s;
  if (Status s = check_rotation(call, rotation); !s) return s;
  std::vector<float>& c = impl_->colliders;
  auto e = load_words<ColliderEntry>(c, entry_at(index));
  set_end_pose(e, position, rotation);
  store_words(c, entry_at(index), e);
  impl_->contacts.colliders_dirty = true;
  return {};
}

Status Simulation::set_target(std::size_t index, const std::array<double, 3>& position) {
  constexpr const char* call = "set_target";
  std::vector<float>& targets = impl_->targets;
  if (Status s = check_index(call, "target", index, targets.size() / kTargetFloats); !s) return s;
  if (Status s = check_finite(call, "position", position); !s) return s;
  auto e = load_words<TargetEntry>(targets, index * kTargetFloats);
  e.end_x = static_cast<float>(position[0]);
  e.end_y = static_cast<float>(position[1]);
  e.end_z = static_cast<float>(position[2]);
  store_words(targets, index * kTargetFloats, e);
  impl_->contacts.targets_dirty = true;
  return {};
}

Status Simulation::apply_tool_force(std::size_t index, const std::array<double, 3>& force,
                                    const std::array<double, 3>& torque) {
  constexpr const char* call = "apply_tool_force";
  std::vector<ToolBody>& tools = impl_->contacts.tools;
  if (Status s = check_index(call, "tool", index, tools.size()); !s) return s;
  if (Status s = check_finite(call, "force", force); !s) return s;
  if (Status s = check_finite(call, "torque", torque); !s) return s;
  ToolBody& b = tools[index];
  for (int k = 0; k < 3; ++k) {  // calls before one frame add up
    b.force[k] += force[k];
    b.torque[k] += torque[k];
  }
  return {};
}

Result<Simulation::ToolState> Simulation::tool_state(std::size_t index) const {
  const std::vector<ToolBody>& tools = impl_->contacts.tools;
  if (Status s = check_index("tool_state", "tool", index, tools.size()); !s) return s.error();
  const ToolBody& b = tools[index];
  ToolState state;
  state.position = b.position;
  state.rotation = b.rotation;
  state.velocity = b.velocity;
  state.angular_velocity = b.angular_velocity;
  state.contact_force = b.contact_force;
  state.contact_torque = b.contact_torque;
  return state;
}

}  // namespace sinew
