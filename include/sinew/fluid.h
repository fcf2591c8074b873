// sinew/fluid.h — smoothed-particle hydrodynamics on any backend (issue
// 15): blood and irrigation as weakly compressible SPH (Becker and
// Teschner 2007) against boundary particles (Akinci et al. 2012), with
// sources and suction that change the particle count on the device.
//
//   sinew::FluidDesc desc;
//   desc.settings.spacing = 1e-3;                         // 1 mm particles
//   desc.boundary = *sinew::sample_box_walls(...);        // or sample_surface
//   desc.emitters.push_back({.centre = {0, 0.02, 0}, .direction = {0, -1, 0},
//                            .radius = 2e-3, .flow_rate = 2e-6});  // 2 ml/s
//   desc.sinks.push_back({.centre = {0, 0, 0}, .radius = 3e-3});
//   desc.capacity = 20000;
//   auto fluid = sinew::Fluid::create(desc);
//   for (int frame = 0; ...) { fluid->step(20); fluid->read(particles); }
//
// Units are SI throughout: metres, seconds, kilograms (a flow of 1 ml/s
// is 1e-6 m^3/s). The method, its kernels and the order of their float
// operations: kernels/shared/sph_params.h and sph_flow_params.h.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sinew/device.h"
#include "sinew/level_set.h"
#include "sinew/result.h"

namespace sinew {

/// The solver (docs/fluids.md, "SPH fluid", has the measured comparison).
enum class FluidMethod {
  /// Weakly compressible SPH (Becker and Teschner 2007): pressure from
  /// density by Tait's equation, explicit steps bound by the speed of sound.
  wcsph,
  /// Position-based fluids (Macklin and Müller 2013): density constraints
  /// projected by pbf_iterations Jacobi sweeps a step, steps bound only by
  /// the particles' speed (0.4 h per step). No boundary forces (no coupling
  /// with tissue), no pressure, no viscosity yet.
  pbf,
};

/// The fluid's material and solver: spacing, rest density, speed of sound,
/// viscosity, time step and the solver's own settings (docs/fluids.md).
struct FluidSettings {
  FluidMethod method = FluidMethod::wcsph;  ///< weakly compressible SPH (default) or position-based fluids
  double spacing = 1e-3;        ///< the fluid's particle spacing [m], > 0; a particle's mass is rho0 spacing^3
  double support = 2.0;         ///< the kernels' support radius h in spacings, >= 1
  double rest_density = 1000.0; ///< rho0 [kg/m^3], > 0 (blood: about 1060)
  double speed_of_sound = 10.0; ///< c0 [m/s], > 0: about 10x the fastest flow keeps density within 1% (wcsph)
  double viscosity = 0.1;       ///< Monaghan's alpha between fluid particles, >= 0
  double boundary_viscosity = 0.1;  ///< ... against boundary particles, >= 0 (0: free-slip walls)
  double time_step = 5e-5;      ///< [s], > 0; wcsph: at most 0.4 h / c0 (the CFL condition; an error beyond)
  std::array<double, 3> gravity{0.0, -9.81, 0.0};  ///< [m/s^2]
  /// wcsph: Akinci et al.'s (2013) surface tension coefficient gamma, >= 0
  /// (0: none, and no kernels for it): cohesion between fluid particles and
  /// a curvature term that rounds the surface (kernels/shared/
  /// sph_tension_params.h). Water at 1 mm particles: about 0.05-0.5.
  double surface_tension = 0.0;
  int pbf_iterations = 4;        ///< pbf: Jacobi sweeps of the density constraints per step, >= 1
  /// pbf: epsilon, the softening of every constraint, as a fraction of a
  /// particle's constraint stiffness inside a fluid at rest, > 0.
  double pbf_relaxation = 0.01;
};

/// A source: a disc that lets fluid through at a flow rate, layer after
/// layer of particles on a square lattice of the spacing (those within
/// the radius), each layer leaving one spacing behind the last. A lattice
/// point with a fluid particle within 0.75 spacing of its place makes
/// nothing that layer (FluidStats::blocked): a source under the fluid's
/// surface delivers less than its rate. Only fluid blocks it: a moving
/// boundary that comes to cover a source is not checked after
/// set_emitter. Emitters need support >= 1.25 spacings (the search's reach).
struct FluidEmitter {
  std::array<double, 3> centre{};             ///< the disc's centre [m]
  std::array<double, 3> direction{0, -1, 0};  ///< the flow's direction (normalised; not zero)
  double radius = 0.0;     ///< [m], >= spacing / 2 (the disc must hold a lattice point)
  /// [m^3/s] (1 ml/s = 1e-6), >= 0. The particles leave at speed
  /// flow_rate / (lattice points x spacing^2), so the volume is exact; that
  /// speed may carry a layer at most one spacing per step (an error beyond).
  double flow_rate = 0.0;
};

/// Suction: fluid particles strictly inside the ball are removed each step,
/// after the emitters' layers are made (a particle made inside a sink is
/// counted as emitted and removed in the same step).
struct FluidSink {
  std::array<double, 3> centre{};  ///< [m]
  double radius = 0.0;             ///< [m], > 0
};

/// A fluid to create: its settings, particles at the start, boundary,
/// emitters, sinks, capacity and device (Fluid::create).
struct FluidDesc {
  FluidSettings settings;  ///< material and solver settings
  /// Fluid at the start [m], about a spacing from the boundary particles:
  /// closer, a single layer of them adds more than the missing fluid's
  /// density (their volumes assume that gap) and the first steps push the
  /// fluid away hard.
  std::vector<std::array<double, 3>> particles;
  std::vector<std::array<double, 3>> velocities; ///< their velocities [m/s] (empty: at rest)
  /// Boundary particles [m] (sample_surface, sample_box_walls): what holds
  /// the fluid. Each gets its volume from its neighbours at create().
  std::vector<std::array<double, 3>> boundary;
  /// true: the boundary moves (Fluid::set_boundary). Adds one kernel per step.
  bool moving_boundary = false;
  /// true: the fluid's push on each boundary particle is summed on the
  /// device (Fluid::read_boundary_impulses). Adds one kernel per step.
  bool boundary_forces = false;
  std::vector<FluidEmitter> emitters;  ///< their count is fixed; their poses and rates may change
  std::vector<FluidSink> sinks;        ///< likewise
  /// The most fluid particles there can be at once; 0: the initial
  /// particles' count (with emitters it must be more than that). An
  /// emitter that would pass it makes what fits, and step() finishes its
  /// steps and then reports capacity_exceeded (naming "sph particles").
  std::uint32_t capacity = 0;
  DeviceOptions device;  ///< the backend it runs on
};

/// One fluid particle as read back.
struct FluidParticle {
  /// Its index in FluidDesc::particles, then counting on as emitters make
  /// more (a particle not made for lack of capacity uses up its id too).
  /// Ids are 31 bits: a step() that could pass 2^31 is refused
  /// (capacity_exceeded) before it runs.
  std::uint32_t id = 0;
  std::array<float, 3> position{};  ///< [m]
  std::array<float, 3> velocity{};  ///< [m/s]
  float density = 0.0f;             ///< [kg/m^3], from the last step's start
  float pressure = 0.0f;            ///< [Pa], from the last step's start
};

/// Counts after the last step() (read back with it: 6 words).
struct FluidStats {
  std::uint32_t particles = 0;  ///< fluid particles now
  std::uint64_t emitted = 0;    ///< made by emitters since create()
  std::uint64_t removed = 0;    ///< removed by sinks since create()
  /// Emitter lattice points that made nothing because a fluid particle was
  /// within 0.75 spacing of their place (a submerged source makes only what
  /// it finds room for: a particle on top of another would blow the fluid
  /// apart), since create().
  std::uint64_t blocked = 0;
  std::uint64_t steps = 0;      ///< time steps since create()
  double time = 0.0;            ///< simulated time [s]
  double max_speed = 0.0;       ///< the fastest fluid particle after the last step() [m/s]
  double mass = 0.0;            ///< particles x rho0 spacing^3 [kg]
};

/// An SPH fluid on a device, on its own (a scene's fluid is reached by
/// Simulation::fluid instead): created from a FluidDesc, stepped, read back.
class Fluid {
 public:
  /// Errors (bad_parameter), each naming the field: a setting out of
  /// range or a time step beyond the CFL bound (naming both numbers); a
  /// position that is not finite; neither particles nor an emitter; a bad
  /// emitter or sink; an emitter whose lattice point lies within half a
  /// spacing of a boundary particle (a source inside a collider); more
  /// particles than the capacity. The backend's, when it is not available.
  static Result<Fluid> create(const FluidDesc& desc);
  /// Moves the fluid and its device.
  ///@{
  Fluid(Fluid&&) noexcept;
  Fluid& operator=(Fluid&&) noexcept;
  ///@}
  ~Fluid();

  /// Advances `steps` time steps, each one device program: the boundary
  /// moved, the sinks' particles removed, the emitters' layers made, the
  /// grid, density and forces, symplectic Euler. Then reads the counts and
  /// checks the CFL condition with the particles' speed: an error when dt >
  /// 0.4 h / (c0 + v_max), naming both (the steps were taken). Emitters
  /// that outgrow the capacity: capacity_exceeded after all the steps (what
  /// fits was made in each).
  Status step(int steps = 1);
  /// [out] the fluid particles, by increasing id.
  Status read(std::vector<FluidParticle>& particles) const;
  /// The counts and figures of the last step() call.
  [[nodiscard]] const FluidStats& stats() const;

  /// Moves emitter `index` (its lattice size stays: the radius and spacing
  /// it was created with; a new radius is an error) or changes its rate.
  Status set_emitter(std::size_t index, const FluidEmitter& emitter);
  /// Moves sink `index` or changes its radius.
  Status set_sink(std::size_t index, const FluidSink& sink);
  /// The boundary's positions [m] and velocities [m/s] for the next steps
  /// (FluidDesc::moving_boundary), one per boundary particle. The particles'
  /// volumes stay those of create(): a boundary that stretches by a lot
  /// should be resampled.
  Status set_boundary(std::span<const std::array<float, 3>> positions,
                      std::span<const std::array<float, 3>> velocities);
  /// [out] the impulse [N s] the fluid gave each boundary particle since
  /// the last call (FluidDesc::boundary_forces): divide by the time passed
  /// for a force. The fluid lost exactly what the boundary gained, up to
  /// float rounding: momentum is conserved. Resets them to zero.
  Status read_boundary_impulses(std::vector<std::array<float, 3>>& impulses);

  [[nodiscard]] std::string device_name() const;      ///< the device the fluid runs on
  [[nodiscard]] std::uint32_t boundary_count() const;  ///< boundary particles
  [[nodiscard]] std::uint32_t capacity() const;  ///< fluid particles
  [[nodiscard]] double particle_mass() const;    ///< rho0 spacing^3 [kg]

  struct Impl;  ///< opaque (src/fluid/fluid.cpp)
 private:
  explicit Fluid(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// ---- Boundary sampling (src/fluid/boundary_sampling.cpp)

/// Points on a triangle surface, at most `spacing` apart along every edge
/// and across every face: the vertices, points along each edge (once per
/// edge), and a barycentric lattice inside each face. Each point keeps the
/// triangle and barycentric weights it came from, so it can follow a
/// deforming surface (positions_on) and hand a force back to the vertices
/// (spread_to_vertices).
struct SurfaceSamples {
  std::vector<std::array<double, 3>> points;    ///< [m]
  std::vector<std::array<std::uint32_t, 3>> vertices;  ///< the triangle's vertices per point
  std::vector<std::array<float, 3>> weights;    ///< barycentric, summing to 1
  /// [out] the points on the surface with these vertex positions (xyz per
  /// vertex, `stride` floats apart: 4 for Simulation::read_positions).
  void positions_on(std::span<const float> vertex_xyz, std::size_t stride,
                    std::vector<std::array<float, 3>>& out) const;
  /// [in/out] adds each point's value (force, impulse) to its triangle's
  /// vertices by the weights, xyz per vertex `stride` floats apart: the
  /// total is kept.
  void spread_to_vertices(std::span<const std::array<float, 3>> values, std::span<float> vertex_xyz,
                          std::size_t stride) const;
};

/// Samples triangles (indices into `vertices`, [m]). Errors: spacing <= 0,
/// an index out of range, a coordinate that is not finite.
Result<SurfaceSamples> sample_surface(std::span<const std::array<double, 3>> vertices,
                                      std::span<const std::array<std::uint32_t, 3>> triangles, double spacing);

/// Samples the zero surface of a level set (LevelSet::surface(), in its
/// frame): a bone or organ as a boundary. Errors: as sample_surface.
Result<SurfaceSamples> sample_level_set(const LevelSet& level_set, double spacing);

/// The walls and floor of an open box [lo, hi] (no lid on the +y face),
/// `layers` layers of points `spacing` apart outside it, the first on its
/// faces: a tank for tests and examples. Errors (bad_parameter): hi not
/// above lo on every axis, a spacing that is not finite and > 0 or gives
/// more than 2^24 points, layers < 1.
Result<std::vector<std::array<double, 3>>> sample_box_walls(const std::array<double, 3>& lo,
                                                            const std::array<double, 3>& hi, double spacing,
                                                            int layers = 2);

}  // namespace sinew
