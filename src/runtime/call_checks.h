// call_checks.h — the argument checks the Simulation's calls share: an
// index in range, finite vectors, unit quaternions. Each error names the
// call and the argument.
#pragma once

#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>

#include "math/vec3.h"
#include "sinew/result.h"

namespace sinew::call_checks {

inline std::string str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

inline Status check_index(const char* call, const char* what, std::size_t index, std::size_t count) {
  if (index < count) return {};
  return Error(ErrorCode::bad_parameter,
               std::string(call) + ": index " + std::to_string(index) + " is not a " + what + " (the scene has " +
               std::to_string(count) + ")");
}

inline Status check_finite(const char* call, const char* name, const math::Vec3& v) {
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(v[k]))
      return Error(ErrorCode::bad_parameter,
                   std::string(call) + ": " + name + "[" + std::to_string(k) + "] must be finite (got " + str(v[k]) +
                   ")");
  return {};
}

inline Status check_rotation(const char* call, const math::Quat& q) {
  const double n = math::qnorm(q);
  if (!std::isfinite(n) || std::abs(n - 1.0) > 1e-6)
    return Error(ErrorCode::bad_parameter,
                 std::string(call) + ": rotation must be a unit quaternion (w, x, y, z) (its norm is " + str(n) + ")");
  return {};
}

}  // namespace sinew::call_checks
