// simulation.cpp — a compiled scene on a device: upload once, run the frame
// program every step, read back on request.
#include "sinew/simulation.h"
#include "runtime/simulation_internals.h"

#include <atomic>
#include <chrono>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "compiler/device_ranges.h"
#include "compiler/scene_compiler.h"
#include "math/xpbd_math.h"
#include "program/xpbd_program.h"
#include "runtime/simulation_impl.h"
#include "runtime/stages/stages.h"

namespace sinew {

// The errors of the frame from the device's reductions (stats_program.h):
// the same numbers on every backend.
void Simulation::Impl::measure(FrameStats& out) const {
  const DeviceStats& d = device_stats;
  out.residual_rms = d.constraints ? std::sqrt(d.residual_sum_squares / double(d.constraints)) : 0.0;
  out.max_residual = d.residual_max;
  out.kinetic_energy = d.kinetic_energy;
  out.volume_change = rest_volume > 0.0 ? d.volume / rest_volume - 1.0 : 0.0;
  out.inverted_tets = d.inverted_tets;
}

Simulation::Simulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;
Simulation::~Simulation() = default;

Result<Simulation> Simulation::create(const SceneDesc& scene, const DeviceOptions& device_options) {
  // The scene is checked before a device is made: a bad scene costs no driver start.
  auto compiled = compile_scene(scene);
  if (!compiled) return compiled.error();
  auto device = create_device(device_options);
  if (!device) return device.error();
  auto sim = SimulationInternals::assemble(scene, *compiled, std::move(*device));
  if (sim) sim->impl_->device_options = device_options;  // to make it again (SimulationInternals::restore)
  return sim;
}

Result<Simulation> SimulationInternals::create(const SceneDesc& scene, std::unique_ptr<Device> device) {
  if (!device) return Error(ErrorCode::bad_parameter, "Simulation::create: no device");
  auto compiled = compile_scene(scene);
  if (!compiled) return compiled.error();
  return assemble(scene, *compiled, std::move(device));
}

Result<Simulation> SimulationInternals::assemble(const SceneDesc& scene, CompiledScene& compiled_scene,
                                                 std::unique_ptr<Device> device) {
  using Impl = Simulation::Impl;
  warn_about_scene(scene);
  CompiledScene* const compiled = &compiled_scene;  // as the Result it was
  auto impl = std::make_unique<Impl>();
  impl->device = std::move(device);
  static std::atomic<std::uint32_t> simulations{0};  // ids name their Simulation by this
  impl->serial = ++simulations;
  auto buffers = upload_scene(*impl->device, *compiled);
  if (!buffers) return buffers.error();
  impl->buffers = *buffers;
  if (scene.solver.method == SolverMethod::vbd) {
    auto vbd = upload_vbd(*impl->device, *compiled);
    if (!vbd) return vbd.error();
    impl->vbd = std::move(*vbd);
  }
  if (compiled->external_forces) {
    impl->force_scratch.resize(compiled->positions.size());
    for (const kernels::float4& p : compiled->positions) impl->force_inverse_mass.push_back(p.w);
  }
  if (Status s = impl->init_contacts(scene, *compiled); !s) return s.error();
  impl->order = compiled->order;
  impl->scene_targets = scene.targets.size();
  impl->time_step = scene.solver.time_step;
  impl->measure_errors = scene.solver.measure_errors;
  impl->substeps = scene.solver.substeps;
  impl->iterations = scene.solver.iterations;
  // Every tet body's boundary (wound outward) with one particle of the body
  // as the reference point: its volume on the device (stats_surface_volume).
  std::vector<std::array<std::uint32_t, 4>> faces;
  // Every tet, wound with a positive rest volume: the inverted tets' count
  // (stats_inverted_tets; FrameStats::inverted_tets).
  std::vector<std::array<std::uint32_t, 4>> tets;
  for (std::size_t b = 0; b < scene.tet_bodies.size(); ++b) {
    const TetMesh& mesh = scene.tet_bodies[b].mesh;
    const std::uint32_t first = compiled->tet_body_first_particle[b];
    impl->stats_tet_first.push_back(static_cast<std::uint32_t>(tets.size()));
    for (const auto& t : mesh.tets) {
      const auto at = [&](int k) {
        const Vec3d& p = mesh.vertices[t[k]];
        return kernels::double4{p[0], p[1], p[2], 0.0};
      };
      const double volume = kernels::tet_volume(at(0), at(1), at(2), at(3));
      impl->rest_volume += volume;
      if (!impl->measure_errors) continue;
      std::array<std::uint32_t, 4> d;
      for (int k = 0; k < 4; ++k) d[k] = compiled->order.device_of[first + t[k]];
      if (volume < 0.0) std::swap(d[2], d[3]);
      tets.push_back(d);
    }
    if (!impl->measure_errors) continue;
    const TriMesh boundary = extract_boundary_surface(mesh);
    for (const auto& f : boundary.triangles)
      faces.push_back({compiled->order.device_of[first + f[0]], compiled->order.device_of[first + f[1]],
                       compiled->order.device_of[first + f[2]],
                       compiled->order.device_of[first + boundary.triangles.front()[0]]});
  }
  // With topology changes, room for twice the faces: cuts add faces
  // (refresh_volume writes them without making the plan again).
  auto plan = make_stats_plan(*impl->device, *compiled, faces, impl->measure_errors,
                              static_cast<std::uint32_t>(impl->contacts.tools.size()),
                              scene.topology_changes ? 2 * static_cast<std::uint32_t>(faces.size()) : 0u,
                              std::move(tets));
  if (!plan) return plan.error();
  impl->stats_plan = std::move(*plan);
  impl->solver = scene.solver;
  impl->gravity = scene.gravity;
  if (scene.fluid) {
    auto fluid = SceneFluid::State::create(scene, *compiled, *impl->device, impl->buffers);
    if (!fluid) return fluid.error();
    impl->fluid = std::move(*fluid);
  }
  if (scene.mesh_collision.enabled) {
    auto mesh_collision = MeshCollision::create(scene, *compiled, *impl->device);
    if (!mesh_collision) return mesh_collision.error();
    impl->mesh_collision = std::move(*mesh_collision);
  }
  if (scene.topology_changes) {
    auto editor = TopologyEditor::create(scene, *compiled);
    if (!editor) return editor.error();
    impl->topology = std::move(*editor);
    if (impl->measure_errors) impl->topology->track_boundaries();  // volume_change after cuts (refresh_volume)
    impl->source_scene = std::make_shared<const SceneDesc>(scene);  // a restore may make it again
  }
  if (impl->topology && impl->mesh_collision) {
    impl->collision_scene = std::make_unique<SceneDesc>(scene);
    impl->collision_scene->attachments.clear();  // what MeshCollision does not read
    impl->collision_scene->targets.clear();
  }
  if (!scene.graspers.empty()) impl->graspers = std::make_unique<GrasperHolds>(scene, *compiled);
  if (impl->mesh_collision || impl->topology || impl->graspers) {  // programs rebuilt while the scene runs start from this
    impl->program_shape = *compiled;
    for (ConstraintBlock& block : impl->program_shape.blocks) block.data = {};
  }
  if (!scene.needles.empty()) {
    auto sutures = Sutures::create(scene, *compiled, *impl->device);
    if (!sutures) return sutures.error();
    impl->sutures = std::move(*sutures);
  }
  const bool continuous = scene.mesh_collision.enabled && scene.mesh_collision.continuous;
  if (continuous)
    impl->continuous = std::make_unique<ContinuousCollision>(
        impl->mesh_collision->segments(), impl->mesh_collision->triangles(), *impl->mesh_collision, impl->buffers,
        scene.mesh_collision, scene.solver.substeps);
  if (impl->mesh_collision) impl->mesh_collision->set_positions_mirror(&impl->positions_mirror);
  if (impl->sutures) impl->sutures->set_positions_mirror(&impl->positions_mirror);
  if (impl->sutures) {  // a thread runs through its punctures: no contacts may push it out there
    if (impl->mesh_collision) impl->mesh_collision->set_suture_exemption(impl->sutures->exemption());
    if (impl->continuous) impl->continuous->set_suture_exemption(impl->sutures->exemption());
  }
  if (!impl->vbd && SolveStepper::needed(scene.solver, continuous)) {
    impl->program = build_xpbd_program(*compiled, impl->buffers, scene.solver, scene.gravity);
    append_stats(impl->program, impl->stats_plan, impl->buffers);
    auto stepper = SolveStepper::create(*impl->device, *compiled, impl->buffers, scene.solver, scene.gravity,
                                        impl->stats_plan, impl->sweep_extras(), continuous);
    if (!stepper) return stepper.error();
    impl->stepper = std::move(*stepper);
    impl->program = impl->stepper->frame_program();
  } else if (Status s = impl->prepare_program(*compiled); !s) {
    return s.error();
  }

  // The frame's stages, in the order they run: one line per feature.
  Impl& im = *impl;
  if (compiled->external_forces) im.add_stage(make_forces_stage(im));
  if (im.fluid) im.add_stage(make_fluid_stage(im));
  if (auto cuts = make_tool_cuts_stage(im, scene.tools)) im.add_stage(std::move(cuts));
  im.add_stage(make_tools_stage(im));
  if (im.mesh_collision) im.add_stage(make_mesh_collision_stage(im));
  if (im.sutures) im.add_stage(make_sutures_stage(im));
  if (im.continuous) im.add_stage(make_continuous_stage(im));
  im.add_stage(make_solve_stage(im));
  im.add_stage(make_statistics_stage(im));
  if (im.topology && im.topology->tears()) im.add_stage(make_tearing_stage(im));

  impl->init_state_buffers(*compiled);

  SceneInfo& info = impl->info;
  info.particles = static_cast<std::uint32_t>(compiled->positions.size());
  for (const ConstraintBlock& block : compiled->blocks) {
    if (block.kernel == Kernel::xpbd_solve_distance) {
      info.distance_constraints += block.size();
      info.distance_colors += block.colors();
    } else if (block.kernel == Kernel::xpbd_solve_volume) {
      info.volume_constraints += block.size();
      info.volume_colors += block.colors();
    } else {
      info.other_constraints += block.size();
    }
    info.colors += block.colors();
  }
  info.dispatches_per_frame = static_cast<std::uint32_t>(impl->program.dispatch_count());
  info.barriers_per_frame = static_cast<std::uint32_t>(impl->program.barrier_count());
  info.tet_body_first_particle = compiled->tet_body_first_particle;
  info.tri_body_first_particle = compiled->tri_body_first_particle;
  info.line_body_first_particle = compiled->line_body_first_particle;
  if (impl->mesh_collision) info.rest_close_triangle_pairs = impl->mesh_collision->rest_close_pairs();
  return Simulation(std::move(impl));
}

Status Simulation::Impl::prepare_program(const CompiledScene& compiled) {
  program = vbd ? build_vbd_program(compiled, buffers, *vbd, solver, gravity)
               : build_xpbd_program(compiled, buffers, solver, gravity, sweep_extras());
  append_stats(program, stats_plan, buffers);
  auto made = device->create_program(program);  // made before the old one goes: a failure leaves it whole
  if (!made) return made.error();
  if (prepared.id != UINT32_MAX)
    if (Status s = device->destroy_program(prepared); !s) {
      (void)device->destroy_program(*made);
      return s;
    }
  prepared = *made;
  info.dispatches_per_frame = static_cast<std::uint32_t>(program.dispatch_count());
  info.barriers_per_frame = static_cast<std::uint32_t>(program.barrier_count());
  return {};
}

Status Simulation::Impl::rebuild_program() {
  // Not ready until rebuilt: after a failure (a device error) the next
  // step() rebuilds before it runs anything.
  program_ready = false;
  if (Status s = rebuild_programs(); !s) return s;
  program_ready = true;
  return {};
}

Status Simulation::Impl::rebuild_programs() {
  stats_plan.in_use.clear();  // the residuals' RMS divides by the constraints in use
  for (const ConstraintBlock& block : program_shape.blocks) stats_plan.in_use.push_back(block.in_use());
  if (!stepper) return prepare_program(program_shape);
  if (Status s = stepper->rebuild(*device, program_shape, buffers, gravity, stats_plan, sweep_extras()); !s) return s;
  program = stepper->frame_program();
  info.dispatches_per_frame = static_cast<std::uint32_t>(program.dispatch_count());
  info.barriers_per_frame = static_cast<std::uint32_t>(program.barrier_count());
  return {};
}

void Simulation::Impl::add_stage(std::unique_ptr<FrameStage> stage) {
  stats.stages.push_back({std::string(stage->name()), 0.0, {}});
  stages.push_back(std::move(stage));
}

// A frame: every stage's hooks, phase by phase (runtime/frame_stage.h), each
// phase in the stages' order, each stage timed.
Status Simulation::step() {
  Impl& im = *impl_;
  const auto start = std::chrono::steady_clock::now();
  if (!im.program_ready)  // a rebuild failed (topology change, contacts that grew)
    if (Status s = im.rebuild_program(); !s) return s;
  FrameContext frame{*im.device, im.stats, {}};
  for (StageProfile& p : im.stats.stages) p.ms = 0.0;
  im.positions_mirror.begin_frame();
  // The device counts what the host reads and how often it waits; each
  // stage is given what its own hooks did.
  const HostTransfers& device = im.device->transfers();
  const HostTransfers frame_start = device;
  im.stage_transfers.assign(im.stages.size(), {});
  using Hook = Status (FrameStage::*)(FrameContext&);
  im.stepping = true;
  for (Hook hook : {&FrameStage::before_frame, &FrameStage::solve, &FrameStage::after_solve, &FrameStage::after_frame})
    for (std::size_t i = 0; i < im.stages.size(); ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const HostTransfers before = device;
      if (Status s = (im.stages[i].get()->*hook)(frame); !s) {
        im.stepping = false;
        return im.after_failed_frame(s.error());
      }
      im.stats.stages[i].ms += ms_since(t0);
      im.stage_transfers[i].read_bytes += device.read_bytes - before.read_bytes;
      im.stage_transfers[i].waits += device.waits - before.waits;
    }
  im.stepping = false;
  for (std::size_t i = 0; i < im.stages.size(); ++i) {
    im.stages[i]->report(im.stats.stages[i]);
    im.stats.stages[i].set("read_bytes", static_cast<double>(im.stage_transfers[i].read_bytes));
    im.stats.stages[i].set("host_waits", static_cast<double>(im.stage_transfers[i].waits));
  }
  im.stats.read_back_bytes = device.read_bytes - frame_start.read_bytes;
  im.stats.host_reads = static_cast<std::uint32_t>(device.reads - frame_start.reads);
  im.stats.host_waits = static_cast<std::uint32_t>(device.waits - frame_start.waits);
  im.stats.position_reads = im.positions_mirror.reads();
  const auto end = std::chrono::steady_clock::now();
  im.stats.frame += 1;
  im.stats.time = static_cast<double>(im.stats.frame) * im.time_step;
  im.stats.wall_ms = std::chrono::duration<double, std::milli>(end - start).count();
  im.warnings.after_frame(im.stats);
  if (Status s = im.check_divergence(); !s) return s;
  if (im.pending_roll_back) {  // back before this frame's tears: the Simulation made again
    const Impl::PendingRollBack pending = std::move(*im.pending_roll_back);
    im.pending_roll_back.reset();
    const SavedState good = im.last_good;
    if (Status s = SimulationInternals::restore(*this, good, "step (rolling back)"); !s) return s;
    impl_->report_roll_back(pending.diverged, pending.message);  // im is gone
  }
  return frame.deferred;
}

Status Simulation::set_particle_forces(std::span<const float> xyz) {
  constexpr const char* call = "set_particle_forces";
  Impl& im = *impl_;
  if (!im.buffers.external_force.valid())
    return Error(ErrorCode::bad_parameter, std::string(call) +
                                               ": the scene was created without SceneDesc::external_forces "
                                               "(set it to true to apply forces to particles)");
  const std::size_t n = im.order.device_of.size();
  if (xyz.size() != 3 * n)
    return Error(ErrorCode::bad_parameter, std::string(call) + ": xyz holds " + std::to_string(xyz.size()) +
                                               " floats; the scene has " + std::to_string(n) +
                                               " particles, so it needs " + std::to_string(3 * n) +
                                               " (x, y, z per particle)");
  // Checked and staged before anything is uploaded: on an error the forces
  // set before stay. force_energy: sum |f|^2 / (2 m), the divergence
  // check's bound on the energy they add (sinew/divergence.h).
  double force_energy = 0.0;
  for (std::size_t u = 0; u < n; ++u) {
    const float* f = &xyz[3 * u];
    if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2])) {
      std::ostringstream message;
      message << call << ": the force on particle " << u << " must be finite (got " << f[0] << ", " << f[1] << ", "
              << f[2] << " N)";
      return Error(ErrorCode::bad_parameter, message.str());
    }
    // What the device makes of it in float (issue 39): the velocity a
    // frame's substeps add, dt f / m (h f / m each), and the move it makes,
    // dt^2 f / m, bounded as gravity's is (compiler/device_ranges.h).
    const std::uint32_t slot = im.order.device_of[u];
    const float dt = static_cast<float>(im.time_step), w = im.force_inverse_mass[slot];
    for (int k = 0; k < 3; ++k) {
      const float dv = dt * (f[k] * w);
      if (!std::isfinite(dv) || !(std::abs(dt * dv) <= kMaxFrameMove)) {
        std::ostringstream message;
        message << call << ": the force on particle " << u << " (" << f[0] << ", " << f[1] << ", " << f[2]
                << " N) is too large: the velocity h f / m it adds over a frame (inverse mass " << w
                << " 1/kg, time_step " << im.time_step << " s) must be finite in float32, the device's precision, "
                << "and the move time_step^2 f / m at most " << kMaxFrameMove << " m";
        return Error(ErrorCode::bad_parameter, message.str());
      }
    }
    im.force_scratch[slot] = kernels::float4{f[0], f[1], f[2], 0.0f};
    if (w > 0.0f) force_energy += (double(f[0]) * f[0] + double(f[1]) * f[1] + double(f[2]) * f[2]) * w / 2.0;
  }
  if (n == 0) return {};
  if (Status s = im.device->write_buffer(im.buffers.external_force, 0, im.force_scratch.data(),
                                         n * sizeof(kernels::float4));
      !s)
    return s;
  im.forces_for_next_frame = true;
  im.forces_on_device = true;
  im.history.next_force_speed = im.time_step * std::sqrt(force_energy);
  return {};
}

// Forces act for one frame. They are reset lazily, at the start of the
// first frame without a call: a host that sets them every frame (two-way
// coupling) pays one upload per frame, not two, one that stops pays one
// upload of zeros, and one that never calls pays nothing. (A fill in the
// frame program would cost every frame of every such scene.)
Status Simulation::Impl::begin_frame_forces() {
  const bool stale = forces_on_device && !forces_for_next_frame;
  host_forces_this_frame = forces_for_next_frame;
  history.force_speed = forces_for_next_frame ? history.next_force_speed : 0.0;
  forces_for_next_frame = false;  // this frame consumes them
  if (!stale) return {};
  std::fill(force_scratch.begin(), force_scratch.end(), kernels::float4{0.0f, 0.0f, 0.0f, 0.0f});
  if (Status s = device->write_buffer(buffers.external_force, 0, force_scratch.data(),
                                      force_scratch.size() * sizeof(kernels::float4));
      !s)
    return s;
  forces_on_device = false;
  return {};
}

Status Simulation::Impl::read_in_user_order(BufferHandle buffer, std::vector<float>& xyzw) const {
  const std::size_t n = order.user_of.size();
  xyzw.resize(n * 4);
  std::vector<float>& slots = device_order_scratch;
  slots.resize(n * 4);
  if (Status s = device->read_buffer(buffer, 0, slots.data(), slots.size() * sizeof(float)); !s) return s;
  for (std::size_t slot = 0; slot < n; ++slot)
    std::copy_n(&slots[slot * 4], 4, &xyzw[std::size_t{order.user_of[slot]} * 4]);
  return {};
}

Status Simulation::Impl::positions_in_user_order(std::vector<float>& xyzw) {
  const std::size_t n = order.user_of.size();
  xyzw.resize(n * 4);
  std::vector<float>& slots = device_order_scratch;
  if (Status s = positions_mirror.copy_to(*device, buffers.position, n * 4, slots); !s) return s;
  for (std::size_t slot = 0; slot < n; ++slot)
    std::copy_n(&slots[slot * 4], 4, &xyzw[std::size_t{order.user_of[slot]} * 4]);
  return {};
}

void StageProfile::set(std::string_view counter, double value) {
  for (Counter& c : counters)
    if (c.name == counter) {
      c.value = value;
      return;
    }
  counters.push_back({std::string(counter), value});
}

double FrameStats::counter(std::string_view stage, std::string_view counter) const {
  for (const StageProfile& p : stages)
    if (p.name == stage)
      for (const StageProfile::Counter& c : p.counters)
        if (c.name == counter) return c.value;
  return 0.0;
}

double FrameStats::stage_ms(std::string_view name) const {
  for (const StageProfile& stage : stages)
    if (stage.name == name) return stage.ms;
  return 0.0;
}

SceneFluid Simulation::fluid() { return SceneFluid(impl_->fluid.get()); }

Status Simulation::read_positions(std::vector<float>& xyzw) const {
  return impl_->read_in_user_order(impl_->buffers.position, xyzw);
}

Status Simulation::read_velocities(std::vector<float>& xyzw) const {
  if (Status s = impl_->read_in_user_order(impl_->buffers.velocity, xyzw); !s) return s;
  for (std::size_t p = 3; p < xyzw.size(); p += 4) xyzw[p] = 0.0f;  // the device keeps the damping factor there
  return {};
}

const SceneInfo& Simulation::info() const { return impl_->info; }
const FrameStats& Simulation::last_frame() const { return impl_->stats; }
std::string Simulation::backend_name() const { return impl_->device->backend_name(); }
std::string Simulation::device_name() const { return impl_->device->device_name(); }

const Device& SimulationInternals::device(const Simulation& sim) { return *sim.impl_->device; }
const FrameProgram& SimulationInternals::program(const Simulation& sim) { return sim.impl_->program; }
double SimulationInternals::frame_length(const Simulation& sim) { return sim.impl_->solver.time_step; }
void SimulationInternals::add_stage(Simulation& sim, std::unique_ptr<FrameStage> stage) {
  sim.impl_->add_stage(std::move(stage));
}
BufferHandle SimulationInternals::velocity_buffer(const Simulation& sim) { return sim.impl_->buffers.velocity; }

}  // namespace sinew
