// sph_solver.h — weakly compressible SPH on a device (issue 15, part 2):
// fluid particles and fixed boundary particles on the neighbour grid, one
// program per step (the grid, the density, the velocities gathered into
// the grid's order, the pressure and viscosity forces and the symplectic
// Euler step). The method and its papers: kernels/shared/sph_params.h.
//
// Particles keep an id (their index in the fluid given to create()); their
// storage is re-sorted along the grid every step, so read() returns them by
// id. Boundary particles (Akinci et al. 2012) get their volume on the
// device at create(): V_b = 1 / sum_k W_bk over the boundary particles.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "backends/backend.h"
#include "neighbours/neighbour_grid.h"
#include "sph_params.h"

namespace sinew {

struct SphSettings {
  double spacing = 1e-3;        ///< the fluid's particle spacing [m], > 0
  double support = 2.0;         ///< the kernels' support radius h in spacings, >= 1
  double rest_density = 1000.0; ///< rho0 [kg/m^3], > 0
  double speed_of_sound = 10.0; ///< c0 [m/s], > 0: about 10x the fastest flow keeps density within 1%
  double viscosity = 0.1;       ///< Monaghan's alpha between fluid particles, >= 0
  double boundary_viscosity = 0.1;  ///< ... against boundary particles, >= 0 (0: free-slip walls)
  double time_step = 5e-5;      ///< [s], > 0, at most 0.4 h / c0 (the CFL condition; an error beyond)
  std::array<double, 3> gravity{0.0, -9.81, 0.0};  ///< [m/s^2]
};

/// One particle as read back.
struct SphParticle {
  std::array<float, 3> position{}, velocity{};  ///< [m], [m/s]
  float density = 0.0f, pressure = 0.0f;        ///< [kg/m^3], [Pa]
};

class SphSolver {
 public:
  /// Fluid particles of mass rho0 spacing^3 at `fluid` [m] (at rest) and
  /// boundary particles at `boundary` [m]. Errors (bad_parameter): a
  /// setting out of range or a step beyond the CFL bound (naming both
  /// numbers), a non-finite position, no fluid particle.
  static Result<std::unique_ptr<SphSolver>> create(Device& device, const SphSettings& settings,
                                                   std::span<const std::array<double, 3>> fluid,
                                                   std::span<const std::array<double, 3>> boundary);
  ~SphSolver();
  SphSolver(const SphSolver&) = delete;
  SphSolver& operator=(const SphSolver&) = delete;

  /// Advances `steps` time steps (one program run each), then checks the
  /// CFL condition with the particles' speed: an error (bad_parameter)
  /// when dt > 0.4 h / (c0 + v_max), naming both (the steps were taken;
  /// shorten the step or raise c0). last_max_speed() and mach() report it.
  Status step(int steps);
  /// The fastest fluid particle after the last step() [m/s].
  [[nodiscard]] double last_max_speed() const { return max_speed_; }
  /// last_max_speed() / c0: above about 0.1 the density varies more than
  /// about 1% (weak compressibility no longer holds).
  [[nodiscard]] double mach() const { return max_speed_ / speed_of_sound_; }
  /// [out] the fluid particles by id (their index in create()'s `fluid`),
  /// as the last step left them (density and pressure from its start).
  Status read(std::vector<SphParticle>& fluid);

  [[nodiscard]] std::uint32_t fluid_count() const { return fluid_; }
  [[nodiscard]] std::uint32_t boundary_count() const { return boundary_; }
  [[nodiscard]] const kernels::SphParams& params() const { return params_; }

 private:
  explicit SphSolver(Device& device) : device_(device) {}
  Device& device_;
  std::unique_ptr<NeighbourGrid> grid_;
  BufferHandle velocity_, sorted_velocity_, density_, pressure_, speed2_, scratch_;
  std::uint32_t max_word_ = 0;  // the scratch word that holds the maximum |v|^2 after a step
  double max_speed_ = 0.0, speed_of_sound_ = 0.0, cfl_step_ = 0.0, h_ = 0.0;
  ProgramHandle program_{};
  bool have_program_ = false;
  kernels::SphParams params_{};
  std::uint32_t fluid_ = 0, boundary_ = 0;
};

}  // namespace sinew
