// fem_kernels.h — CPU reference kernels of the FEM tet materials (stable
// Neo-Hookean, St. Venant-Kirchhoff, corotational linear). The models'
// constraints and their derivatives are in kernels/math/fem_math.h; the
// per-tet data layout in kernels/shared/fem_params.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"  // the kernel entry points, declared from the registry
#include "math/fem_math.h"

