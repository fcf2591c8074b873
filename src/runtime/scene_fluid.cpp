// scene_fluid.cpp — a scene's fluid on the Simulation's device
// (runtime/scene_fluid.h): made from SceneDesc::fluid, one frame of it
// before the tissue's, and the public handle sinew/scene_fluid.h.
//
// The coupling is the one of Akinci et al. (TOG 31(4), 2012) as the host
// used to run it between a Fluid and a Simulation: the same samples, the
// same floats in the same order (kernels/shared/fluid_coupling_params.h),
// now in two dispatches that read and write the device's buffers, so a
// frame reads back only the fluid's counts.
#include "runtime/scene_fluid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

#include "fluid_coupling_params.h"

namespace sinew {
namespace {

std::string surface_name(std::size_t i) { return "fluid.surfaces[" + std::to_string(i) + "]"; }  // as check_scene_fluid's

// The surface's rest vertices and triangles, and its body's first particle.
struct SurfaceMesh {
  const std::vector<Vec3d>* vertices = nullptr;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::uint32_t first_particle = 0;
};

SurfaceMesh surface_mesh(const SceneDesc& scene, const CompiledScene& compiled, const FluidSurfaceDesc& s) {
  SurfaceMesh out;
  if (s.body_kind == BodyKind::tet) {
    const TetMesh& mesh = scene.tet_bodies[s.body].mesh;
    out.vertices = &mesh.vertices;
    out.triangles = s.triangles.empty() ? extract_boundary_surface(mesh).triangles : s.triangles;
    out.first_particle = compiled.tet_body_first_particle[s.body];
  } else {
    const TriMesh& mesh = scene.tri_bodies[s.body].mesh;
    out.vertices = &mesh.vertices;
    out.triangles = s.triangles.empty() ? mesh.triangles : s.triangles;
    out.first_particle = compiled.tri_body_first_particle[s.body];
  }
  return out;
}

}  // namespace

Result<std::unique_ptr<SceneFluid::State>> SceneFluid::State::create(const SceneDesc& scene,
                                                                     const CompiledScene& compiled, Device& device,
                                                                     const XpbdBuffers& buffers) {
  FluidDesc desc = scene.fluid->fluid;
  std::unique_ptr<State> state(new State(device));
  state->info.steps_per_frame =
      static_cast<std::uint32_t>(std::lround(scene.solver.time_step / desc.settings.time_step));
  state->info.fixed_boundary = static_cast<std::uint32_t>(desc.boundary.size());
  std::vector<SurfaceSamples> samples;
  for (std::size_t i = 0; i < scene.fluid->surfaces.size(); ++i) {
    const SurfaceMesh mesh = surface_mesh(scene, compiled, scene.fluid->surfaces[i]);
    auto sampled = sample_surface(*mesh.vertices, mesh.triangles, desc.settings.spacing);
    if (!sampled) return Error(sampled.error().code(), surface_name(i) + ": " + sampled.error().message());
    if (sampled->points.empty())
      return Error(ErrorCode::bad_parameter, surface_name(i) + " gives no boundary particle (no triangles?)");
    desc.boundary.insert(desc.boundary.end(), sampled->points.begin(), sampled->points.end());
    samples.push_back(std::move(*sampled));
  }
  state->coupled_ = !samples.empty();
  desc.moving_boundary = desc.moving_boundary || state->coupled_;
  desc.boundary_forces = desc.boundary_forces || state->coupled_;
  auto solver = SphSolver::create(device, desc);
  if (!solver) return solver.error();
  state->solver = std::move(*solver);
  state->info.coupled_boundary = static_cast<std::uint32_t>(desc.boundary.size()) - state->info.fixed_boundary;
  state->info.capacity = state->solver->capacity();
  state->info.particle_mass = state->solver->particle_mass();
  if (state->coupled_) {
    if (Status s = state->make_coupling(scene, compiled, buffers, samples); !s) return s.error();
  } else if (const BufferHandle impulse = state->solver->impulse_buffer(); impulse.valid()) {
    // Boundary forces on the fixed boundary only: each frame's start zeroes them.
    FrameProgram zero;
    zero.fill(impulse, 0, 4 * state->info.fixed_boundary, 0u);
    auto made = device.create_program(zero);
    if (!made) return made.error();
    state->follow_ = *made;
  }
  return state;
}

// The samples' particles and weights, the tissue particles' lists of
// (sample, weight) in the samples' order, and the two programs.
Status SceneFluid::State::make_coupling(const SceneDesc& scene, const CompiledScene& compiled,
                                        const XpbdBuffers& buffers, std::vector<SurfaceSamples>& samples) {
  std::vector<std::uint32_t> particles;  // uint4 per sample
  std::vector<float> weights;            // float4 per sample
  std::vector<std::uint32_t> entry_slot, entry_sample;
  std::vector<float> entry_weight;
  std::uint32_t sample = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::uint32_t first = surface_mesh(scene, compiled, scene.fluid->surfaces[i]).first_particle;
    for (std::size_t k = 0; k < samples[i].points.size(); ++k, ++sample) {
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t slot = compiled.order.device_of[first + samples[i].vertices[k][c]];
        particles.push_back(slot);
        weights.push_back(samples[i].weights[k][c]);
        entry_slot.push_back(slot);
        entry_sample.push_back(sample);
        entry_weight.push_back(samples[i].weights[k][c]);
      }
      particles.push_back(0);
      weights.push_back(0.0f);
    }
  }
  // Entries grouped by particle, each group in the samples' order (a
  // stable sort by slot): the order SurfaceSamples::spread_to_vertices adds in.
  std::vector<std::uint32_t> by_slot(entry_slot.size());
  std::iota(by_slot.begin(), by_slot.end(), 0u);
  std::stable_sort(by_slot.begin(), by_slot.end(), [&](std::uint32_t a, std::uint32_t b) { return entry_slot[a] < entry_slot[b]; });
  std::vector<std::uint32_t> vertex_particle, offsets{0}, sorted_sample;
  std::vector<float> sorted_weight;
  for (std::size_t e = 0; e < by_slot.size(); ++e) {
    const std::uint32_t j = by_slot[e];
    if (e == 0 || entry_slot[j] != vertex_particle.back()) {
      if (e > 0) offsets.push_back(static_cast<std::uint32_t>(e));
      vertex_particle.push_back(entry_slot[j]);
    }
    sorted_sample.push_back(entry_sample[j]);
    sorted_weight.push_back(entry_weight[j]);
  }
  offsets.push_back(static_cast<std::uint32_t>(by_slot.size()));
  const auto upload = [&](const auto& data, const char* label) -> Result<BufferHandle> {
    const std::size_t bytes = data.size() * sizeof(data[0]);
    auto buffer = device.create_buffer(bytes, label);
    if (!buffer) return buffer.error();
    owned_.push_back(*buffer);
    if (Status s = device.write_buffer(*buffer, 0, data.data(), bytes); !s) return s.error();
    return *buffer;
  };
  auto sample_particles = upload(particles, "fluid sample particles");
  if (!sample_particles) return sample_particles.error();
  auto sample_weights = upload(weights, "fluid sample weights");
  if (!sample_weights) return sample_weights.error();
  auto vertex_buffer = upload(vertex_particle, "fluid coupled particles");
  if (!vertex_buffer) return vertex_buffer.error();
  auto offset_buffer = upload(offsets, "fluid coupled offsets");
  if (!offset_buffer) return offset_buffer.error();
  auto sample_buffer = upload(sorted_sample, "fluid coupled samples");
  if (!sample_buffer) return sample_buffer.error();
  auto weight_buffer = upload(sorted_weight, "fluid coupled weights");
  if (!weight_buffer) return weight_buffer.error();

  kernels::FluidCouplingParams params{};
  params.boundary = info.fixed_boundary + info.coupled_boundary;
  params.first = info.fixed_boundary;
  params.vertices = static_cast<std::uint32_t>(vertex_particle.size());
  params.inv_frame = float(1.0 / scene.solver.time_step);
  FrameProgram follow;
  follow.dispatch(Kernel::fluid_boundary_follow, params.boundary,
                  {*sample_particles, *sample_weights, buffers.position, buffers.velocity,
                   solver->boundary_position_buffer(), solver->boundary_velocity_buffer(), solver->impulse_buffer()},
                  params);
  auto made = device.create_program(follow);
  if (!made) return made.error();
  follow_ = *made;
  for (std::uint32_t add : {0u, 1u}) {
    params.add = add;
    FrameProgram forces;
    forces.dispatch(Kernel::fluid_forces_on_tissue, params.vertices,
                    {*vertex_buffer, *offset_buffer, *sample_buffer, *weight_buffer, solver->impulse_buffer(),
                     buffers.external_force},
                    params);
    made = device.create_program(forces);
    if (!made) return made.error();
    (add ? forces_added_ : forces_) = *made;
  }
  return {};
}

SceneFluid::State::~State() {
  solver.reset();
  for (ProgramHandle p : {follow_, forces_, forces_added_})
    if (p.id != UINT32_MAX) (void)device.destroy_program(p);
  for (BufferHandle b : owned_) (void)device.destroy_buffer(b);
}

Status SceneFluid::State::run_frame(bool add_to_host_forces) {
  pending = {};
  if (follow_.id != UINT32_MAX)
    if (Status s = device.run_program(follow_); !s) return s;
  Status stepped = solver->step(static_cast<int>(info.steps_per_frame));
  // What fits was made: the frame goes on, and the error waits for its end.
  if (!stepped && stepped.error().code() != ErrorCode::capacity_exceeded) return stepped;
  pending = stepped;
  if (coupled_) return device.run_program(add_to_host_forces ? forces_added_ : forces_);
  return {};
}

// ---- The public handle (sinew/scene_fluid.h)

namespace {
Error no_fluid() {
  return Error(ErrorCode::bad_parameter, "the scene has no fluid (SceneDesc::fluid)");
}
}  // namespace

Status SceneFluid::read(std::vector<FluidParticle>& particles) const {
  if (!state_) return no_fluid();
  return state_->solver->read(particles);
}

Result<FluidStats> SceneFluid::stats() const {
  if (!state_) return no_fluid();
  return state_->solver->stats();
}

Result<SceneFluidInfo> SceneFluid::info() const {
  if (!state_) return no_fluid();
  return state_->info;
}

Status SceneFluid::set_emitter(std::size_t index, const FluidEmitter& emitter) {
  if (!state_) return no_fluid();
  return state_->solver->set_emitter(index, emitter);
}

Status SceneFluid::set_sink(std::size_t index, const FluidSink& sink) {
  if (!state_) return no_fluid();
  return state_->solver->set_sink(index, sink);
}

Result<FluidImpulses> SceneFluid::last_impulses() const {
  if (!state_) return no_fluid();
  FluidImpulses out;
  const BufferHandle impulse = state_->solver->impulse_buffer();
  if (!impulse.valid()) return out;  // no coupled boundary, no boundary forces asked for
  const std::uint32_t n = state_->info.fixed_boundary + state_->info.coupled_boundary;
  std::vector<float> words(4 * std::size_t{n});
  if (Status s = state_->device.read_buffer(impulse, 0, words.data(), 4 * words.size()); !s) return s.error();
  for (std::uint32_t b = 0; b < n; ++b)
    for (int a = 0; a < 3; ++a) (b < state_->info.fixed_boundary ? out.fixed : out.tissue)[a] += words[4 * b + a];
  return out;
}

}  // namespace sinew
