/* thin_apply.h — the xPBD step shared by the thin-body GLSL kernels, twin of
 * kernels/cpu/thin_kernels.cpp's apply<N> (and thin_apply in
 * kernels/opencl/thin_math.h): the same sums in the same order, every result
 * `precise`. A kernel includes it after declaring its Position buffer `x`
 * and Lambda buffer `lambda`, which it writes (GLSL cannot pass buffers).
 * Without a usable step (see thin_step_usable) it stores lambda unchanged
 * and moves nothing; immovable particles are never written (several
 * constraints of a colour may share one). */
#ifndef SINEW_GLSL_THIN_APPLY_H
#define SINEW_GLSL_THIN_APPLY_H

void thin_apply(uint i, uint ids[4], vec4 xs[4], vec3 g[4], int n, float c, float alpha_t, float lambda_i) {
  precise float w = 0.0;
  for (int k = 0; k < n; ++k) w += xs[k].w * dot3(g[k], g[k]);
  precise float total = w + alpha_t;
  if (!thin_step_usable(total)) {  // positive inside: NaN gives false, so it lands here
    lambda[i] = lambda_i;
    return;
  }
  precise float dlambda = (-c - alpha_t * lambda_i) / total;
  for (int k = 0; k < n; ++k) {
    if (xs[k].w > 0.0) {
      precise vec3 y = xs[k].xyz + (xs[k].w * dlambda) * g[k];
      x[ids[k]] = vec4(y, xs[k].w);
    }
  }
  precise float lambda_n = lambda_i + dlambda;
  lambda[i] = lambda_n;
}

#endif /* SINEW_GLSL_THIN_APPLY_H */
