/* cl_math.h — transitional: the OpenCL kernels not yet moved to kernels/gpu
 * take dot3 and cross3 from kernels/gpu/vec_math.h, so that the one OpenCL
 * program defines them once. */
#ifndef SINEW_CL_MATH_H
#define SINEW_CL_MATH_H

#include "gpu_lang.h"
#include "vec_math.h"

#endif /* SINEW_CL_MATH_H */
