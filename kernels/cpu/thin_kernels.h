// thin_kernels.h — CPU reference kernels of thin bodies (triangle meshes)
// and threads: area, dihedral bending, line bending. Their constraint
// functions are in kernels/math/thin_math.h, which the scene compiler
// shares; data layouts and residuals in kernels/shared/thin_params.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cpu/cpu_kernels.h"  // the kernel entry points, declared from the registry
#include "math/thin_math.h"

