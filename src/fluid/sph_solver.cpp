// sph_solver.cpp — see sph_solver.h.
#include "fluid/sph_solver.h"

#include <bit>
#include <cmath>
#include <cstdio>
#include <string>

#include "fluid/sph_density.h"
#include "program/primitives.h"

namespace sinew {
namespace {

std::string str(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

Status positive(const char* name, double v) {
  if (v > 0.0 && std::isfinite(v)) return {};
  return Error(ErrorCode::bad_parameter, std::string("sph: ") + name + " must be finite and > 0 (got " + str(v) + ")");
}

}  // namespace

SphSolver::~SphSolver() {
  if (have_program_) (void)device_.destroy_program(program_);
  for (BufferHandle h : {velocity_, sorted_velocity_, density_, pressure_, speed2_, scratch_})
    if (h.valid()) (void)device_.destroy_buffer(h);
  grid_.reset();
}

Result<std::unique_ptr<SphSolver>> SphSolver::create(Device& device, const SphSettings& settings,
                                                     std::span<const std::array<double, 3>> fluid,
                                                     std::span<const std::array<double, 3>> boundary) {
  for (const auto& [name, value] : {std::pair{"spacing", settings.spacing}, {"rest_density", settings.rest_density},
                                    {"speed_of_sound", settings.speed_of_sound}, {"time_step", settings.time_step}})
    if (Status s = positive(name, value); !s) return s.error();
  for (const auto& [name, value] : {std::pair{"viscosity", settings.viscosity}, {"boundary_viscosity", settings.boundary_viscosity}})
    if (!(value >= 0.0) || !std::isfinite(value))
      return Error(ErrorCode::bad_parameter, std::string("sph: ") + name + " must be finite and >= 0 (got " + str(value) + ")");
  for (double g : settings.gravity)
    if (!std::isfinite(g)) return Error(ErrorCode::bad_parameter, "sph: gravity must be finite");
  if (!(settings.support >= 1.0) || !std::isfinite(settings.support))
    return Error(ErrorCode::bad_parameter, "sph: support must be finite and >= 1 spacing (got " + str(settings.support) + ")");
  const double h = settings.support * settings.spacing;
  // The CFL condition for the speed of sound (Monaghan 2005): reported, never clamped.
  const double cfl = 0.4 * h / settings.speed_of_sound;
  if (settings.time_step > cfl)
    return Error(ErrorCode::bad_parameter, "sph: time_step " + str(settings.time_step) +
                                               " s is beyond the CFL bound 0.4 h / c0 = " + str(cfl) +
                                               " s (h = " + str(h) + " m, c0 = " + str(settings.speed_of_sound) +
                                               " m/s): shorten it or lower the speed of sound");
  if (fluid.empty()) return Error(ErrorCode::bad_parameter, "sph: no fluid particles");
  for (const auto& [what, points] : {std::pair{"fluid", fluid}, {"boundary", boundary}})
    for (std::size_t i = 0; i < points.size(); ++i)
      for (double x : points[i])
        if (!std::isfinite(x))
          return Error(ErrorCode::bad_parameter, std::string("sph: ") + what + " particle " + std::to_string(i) +
                                                     " has coordinate " + str(x) + ": it must be finite");
  const std::size_t total = fluid.size() + boundary.size();
  if (total > (1u << 24))
    return Error(ErrorCode::bad_parameter, "sph: " + std::to_string(total) + " particles, more than 2^24");
  std::unique_ptr<SphSolver> solver(new SphSolver(device));
  solver->fluid_ = static_cast<std::uint32_t>(fluid.size());
  solver->boundary_ = static_cast<std::uint32_t>(boundary.size());
  const auto n = static_cast<std::uint32_t>(total);
  auto grid = NeighbourGrid::create(device, n, h, 1);  // the solver visits the cells itself: no lists
  if (!grid) return grid.error();
  solver->grid_ = std::move(*grid);
  NeighbourGrid& g = *solver->grid_;
  for (BufferHandle* b : {&solver->velocity_, &solver->sorted_velocity_}) {
    auto made = device.create_buffer(16 * std::size_t{n}, "sph velocities");
    if (!made) return made.error();
    *b = *made;
  }
  for (BufferHandle* b : {&solver->density_, &solver->pressure_, &solver->speed2_}) {
    auto made = device.create_buffer(4 * std::size_t{n}, "sph densities");
    if (!made) return made.error();
    *b = *made;
  }
  auto scratch = device.create_buffer(4 * std::size_t{reduce_scratch_words(n)}, "sph scratch");
  if (!scratch) return scratch.error();
  solver->scratch_ = *scratch;
  solver->speed_of_sound_ = settings.speed_of_sound;
  solver->h_ = h;
  solver->cfl_step_ = settings.time_step;
  kernels::SphParams p = sph_params(g, h);
  const float rho0 = float(settings.rest_density);
  p.rho0 = rho0;
  p.stiffness = float(settings.rest_density * settings.speed_of_sound * settings.speed_of_sound / 7.0);
  p.viscosity = float(settings.viscosity * settings.speed_of_sound * h);
  p.boundary_viscosity = float(settings.boundary_viscosity * settings.speed_of_sound * h);
  p.eta2 = float(0.01 * h * h);
  p.gx = float(settings.gravity[0]);
  p.gy = float(settings.gravity[1]);
  p.gz = float(settings.gravity[2]);
  p.dt = float(settings.time_step);
  solver->params_ = p;

  // The boundary's volumes: its density with "mass" 1 each is sum_k W_bk.
  std::vector<float> xyzw;
  xyzw.reserve(4 * total);
  for (const auto& b : boundary) xyzw.insert(xyzw.end(), {float(b[0]), float(b[1]), float(b[2]), -1.0f});
  std::vector<float> psi(boundary.size());
  if (!boundary.empty()) {
    if (Status s = g.upload(xyzw.data(), solver->boundary_); !s) return s.error();
    FrameProgram volumes;
    g.append_grid(volumes);
    append_sph_density(volumes, g, p, solver->density_);
    auto program = device.create_program(volumes);
    if (!program) return program.error();
    Status ran = device.run_program(*program);
    std::vector<float> sum(boundary.size());
    std::vector<std::uint32_t> order(boundary.size());
    if (ran) ran = device.read_buffer(solver->density_, 0, sum.data(), 4 * boundary.size());
    if (ran) ran = device.read_buffer(g.buffers().order, 0, order.data(), 4 * boundary.size());
    (void)device.destroy_program(*program);
    if (!ran) return ran.error();
    for (std::size_t s = 0; s < boundary.size(); ++s) psi[order[s]] = float(settings.rest_density / double(sum[s]));
  }
  // Fluid first (ids 0 ..), then the boundary (w = -psi).
  const float mass = float(settings.rest_density * std::pow(settings.spacing, 3));
  xyzw.clear();
  std::vector<float> velocity;
  velocity.reserve(4 * total);
  for (std::size_t i = 0; i < fluid.size(); ++i) {
    xyzw.insert(xyzw.end(), {float(fluid[i][0]), float(fluid[i][1]), float(fluid[i][2]), mass});
    velocity.insert(velocity.end(), {0.0f, 0.0f, 0.0f, std::bit_cast<float>(std::uint32_t(i))});
  }
  for (std::size_t b = 0; b < boundary.size(); ++b) {
    xyzw.insert(xyzw.end(), {float(boundary[b][0]), float(boundary[b][1]), float(boundary[b][2]), -psi[b]});
    velocity.insert(velocity.end(), {0.0f, 0.0f, 0.0f, std::bit_cast<float>(std::uint32_t(fluid.size() + b))});
  }
  if (Status s = g.upload(xyzw.data(), n); !s) return s.error();
  if (Status s = device.write_buffer(solver->velocity_, 0, velocity.data(), 4 * velocity.size()); !s) return s.error();

  // One step: the grid, the density, the velocities in the grid's order, the forces and the motion.
  const NeighbourGridBuffers& b = g.buffers();
  FrameProgram step;
  g.append_grid(step);
  append_sph_density(step, g, p, solver->density_);
  step.dispatch(Kernel::sph_gather, n, {b.counts, b.order, solver->velocity_, solver->sorted_velocity_}, p);
  step.barrier();
  step.dispatch(Kernel::sph_step, n,
                {b.counts, b.sorted_points, b.sorted_cells, b.ranges, solver->density_, solver->sorted_velocity_,
                 b.points, solver->velocity_, solver->pressure_, solver->speed2_},
                p);
  step.barrier();
  // The fastest particle, for the CFL check after the steps.
  solver->max_word_ =
      append_reduce(step, {b.counts, 0, n}, ReduceOp::max_f32, {solver->speed2_, 0}, 1, {solver->scratch_, 0});
  auto program = device.create_program(step);
  if (!program) return program.error();
  solver->program_ = *program;
  solver->have_program_ = true;
  return solver;
}

Status SphSolver::step(int steps) {
  for (int k = 0; k < steps; ++k)
    if (Status s = device_.run_program(program_); !s) return s;
  if (steps <= 0) return {};
  float v2 = 0.0f;
  if (Status s = device_.read_buffer(scratch_, 4 * std::size_t{max_word_}, &v2, 4); !s) return s;
  max_speed_ = std::sqrt(double(v2));
  const double bound = 0.4 * h_ / (speed_of_sound_ + max_speed_);
  if (!(cfl_step_ <= bound))
    return Error(ErrorCode::bad_parameter, "sph: time_step " + str(cfl_step_) + " s is beyond the CFL bound 0.4 h / (c0 + "
                                               "v_max) = " + str(bound) + " s with a particle at " + str(max_speed_) +
                                               " m/s (c0 = " + str(speed_of_sound_) + " m/s)");
  return {};
}

Status SphSolver::read(std::vector<SphParticle>& fluid) {
  const std::uint32_t n = fluid_ + boundary_;
  std::vector<float> x(4 * std::size_t{n}), v(4 * std::size_t{n}), rho(n), pressure(n);
  // After a step, points and velocity hold the grid's sorted order of that
  // step, as do density and pressure.
  if (Status s = device_.read_buffer(grid_->buffers().points, 0, x.data(), 4 * x.size()); !s) return s;
  if (Status s = device_.read_buffer(velocity_, 0, v.data(), 4 * v.size()); !s) return s;
  if (Status s = device_.read_buffer(density_, 0, rho.data(), 4 * rho.size()); !s) return s;
  if (Status s = device_.read_buffer(pressure_, 0, pressure.data(), 4 * pressure.size()); !s) return s;
  fluid.assign(fluid_, SphParticle{});
  for (std::uint32_t s = 0; s < n; ++s) {
    const std::uint32_t id = std::bit_cast<std::uint32_t>(v[4 * std::size_t{s} + 3]);
    if (id >= fluid_) continue;  // a boundary particle
    SphParticle& q = fluid[id];
    q.position = {x[4 * std::size_t{s}], x[4 * std::size_t{s} + 1], x[4 * std::size_t{s} + 2]};
    q.velocity = {v[4 * std::size_t{s}], v[4 * std::size_t{s} + 1], v[4 * std::size_t{s} + 2]};
    q.density = rho[s];
    q.pressure = pressure[s];
  }
  return {};
}

}  // namespace sinew
