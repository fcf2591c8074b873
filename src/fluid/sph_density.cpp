// sph_density.cpp — see sph_density.h.
#include "fluid/sph_density.h"

#include <cmath>
#include <numbers>

namespace sinew {

kernels::SphParams sph_params(const NeighbourGrid& grid, double support) {
  kernels::SphParams p{};
  p.count_word = 0;
  p.capacity = grid.capacity();
  p.table_mask = grid.buckets() - 1;
  const double l = 0.5 * support;  // the cubic spline's smoothing length
  p.h2 = float(support) * float(support);
  p.inv_l = float(1.0 / l);
  p.sigma = float(1.0 / (std::numbers::pi * l * l * l));
  p.grad_sigma = float(1.0 / (std::numbers::pi * l * l * l * l));
  return p;
}

void append_sph_density(FrameProgram& program, const NeighbourGrid& grid, const kernels::SphParams& params,
                        BufferHandle density) {
  const NeighbourGridBuffers& b = grid.buffers();
  program.dispatch_indirect(Kernel::sph_density, grid.live_points(program), {b.counts, b.sorted_points, b.sorted_cells, b.ranges, density},
                   params);
  program.barrier();
}

}  // namespace sinew
