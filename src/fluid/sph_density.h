// sph_density.h — the fluid's density on a device (issue 15, part 2): the
// cubic spline kernel summed over each particle's neighbours on the
// neighbour grid (kernels/shared/sph_params.h; Monaghan 2005).
#pragma once

#include "backends/backend.h"
#include "neighbours/neighbour_grid.h"
#include "sph_params.h"

namespace sinew {

/// The density kernel's parameters for particles on `grid` with support
/// radius `support` [m] (the grid's radius): h^2 in float, 1 / l, sigma and
/// sigma / l of the cubic spline (l = support / 2).
kernels::SphParams sph_params(const NeighbourGrid& grid, double support);

/// Appends the density of every particle of `grid` (xyz and mass in the
/// points' w, [m] and [kg]) to `program`, after the grid's own commands
/// (NeighbourGrid::append_grid): density [kg/m^3], one float per particle in
/// the grid's sorted order (order[s] is the particle).
void append_sph_density(FrameProgram& program, const NeighbourGrid& grid, const kernels::SphParams& params,
                        BufferHandle density);

}  // namespace sinew
