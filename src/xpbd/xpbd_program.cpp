// xpbd_program.cpp — builds the xPBD frame program.
//
// Macklin, Storey, Lu, Terdiman, Chentanez, Jeschke, Müller, "Small Steps in
// Physics Simulation", SCA 2019: a frame is split into substeps of
// h = dt / n; each substep predicts positions, solves the constraints with
// lambda reset to zero, and derives velocities from the position change.
// Within an iteration the constraints are swept colour by colour
// (Gauss-Seidel across colours, Jacobi-free within one since a colour's
// constraints share no movable particle); each colour ends with a barrier.
#include "xpbd/xpbd_program.h"

#include "xpbd_params.h"

namespace sinew {
namespace {

template <class T>
Result<BufferHandle> make_buffer(Device& device, const std::vector<T>& data, std::string_view label) {
  // Empty blocks still get a (small) buffer so every handle is valid.
  auto buffer = device.create_buffer(std::max<std::size_t>(data.size() * sizeof(T), 16), label);
  if (!buffer) return buffer;
  if (!data.empty())
    if (Status s = device.write_buffer(*buffer, 0, data.data(), data.size() * sizeof(T)); !s) return s.error();
  return buffer;
}

void sweep(FrameProgram& program, const ConstraintBlock& block, Kernel kernel, BufferHandle position,
           BufferHandle particles, BufferHandle rest_alpha, BufferHandle lambda, float inv_h2, bool first_iteration) {
  // SolveDistanceParams and SolveVolumeParams have the same fields.
  static_assert(sizeof(kernels::SolveDistanceParams) == sizeof(kernels::SolveVolumeParams));
  for (std::uint32_t c = 0; c < block.colors(); ++c) {
    kernels::SolveDistanceParams p{};
    p.first = block.color_offsets[c];
    p.count = block.color_offsets[c + 1] - block.color_offsets[c];
    p.inv_h2 = inv_h2;
    p.reset_lambda = first_iteration ? 1u : 0u;
    program.dispatch(kernel, p.count, {position, particles, rest_alpha, lambda}, p);
    program.barrier();
  }
}

}  // namespace

Result<XpbdBuffers> upload_scene(Device& device, const CompiledScene& scene) {
  XpbdBuffers b;
  const std::vector<kernels::float4> zeros(scene.positions.size(), kernels::float4{0, 0, 0, 0});
  const std::vector<float> no_lambda_d(scene.distance.size(), 0.0f);
  const std::vector<float> no_lambda_v(scene.volume.size(), 0.0f);
  struct Upload {
    BufferHandle* handle;
    Result<BufferHandle> made;
  };
  Upload uploads[] = {
      {&b.position, make_buffer(device, scene.positions, "position")},
      {&b.previous, make_buffer(device, zeros, "previous position")},
      {&b.velocity, make_buffer(device, zeros, "velocity")},
      {&b.distance_particles, make_buffer(device, scene.distance.particles, "distance particles")},
      {&b.distance_rest_alpha, make_buffer(device, scene.distance.rest_alpha, "distance rest/compliance")},
      {&b.distance_lambda, make_buffer(device, no_lambda_d, "distance lambda")},
      {&b.volume_particles, make_buffer(device, scene.volume.particles, "volume particles")},
      {&b.volume_rest_alpha, make_buffer(device, scene.volume.rest_alpha, "volume rest/compliance")},
      {&b.volume_lambda, make_buffer(device, no_lambda_v, "volume lambda")},
  };
  for (auto& u : uploads) {
    if (!u.made) return u.made.error();
    *u.handle = *u.made;
  }
  return b;
}

FrameProgram build_xpbd_program(const CompiledScene& scene, const XpbdBuffers& buffers, const SolverSettings& solver,
                                const std::array<double, 3>& gravity) {
  const double h = solver.time_step / solver.substeps;
  const auto particles = static_cast<std::uint32_t>(scene.positions.size());
  const auto inv_h2 = static_cast<float>(1.0 / (h * h));

  kernels::PredictParams predict{};
  predict.h = static_cast<float>(h);
  predict.gravity_x = static_cast<float>(gravity[0]);
  predict.gravity_y = static_cast<float>(gravity[1]);
  predict.gravity_z = static_cast<float>(gravity[2]);
  predict.count = particles;
  kernels::UpdateVelocityParams update{};
  update.inv_h = static_cast<float>(1.0 / h);
  update.count = particles;

  FrameProgram program;
  for (int s = 0; s < solver.substeps; ++s) {
    program.dispatch(Kernel::xpbd_predict, particles, {buffers.position, buffers.previous, buffers.velocity}, predict);
    program.barrier();
    for (int it = 0; it < solver.iterations; ++it) {
      sweep(program, scene.distance, Kernel::xpbd_solve_distance, buffers.position, buffers.distance_particles,
            buffers.distance_rest_alpha, buffers.distance_lambda, inv_h2, it == 0);
      sweep(program, scene.volume, Kernel::xpbd_solve_volume, buffers.position, buffers.volume_particles,
            buffers.volume_rest_alpha, buffers.volume_lambda, inv_h2, it == 0);
    }
    program.dispatch(Kernel::xpbd_update_velocity, particles, {buffers.position, buffers.previous, buffers.velocity},
                     update);
    program.barrier();
  }
  return program;
}

}  // namespace sinew
