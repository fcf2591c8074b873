// device_ccd.h — continuous collision queries on a device (issue 13): the
// single-precision kernel of kernels/shared/ccd_params.h, whose float error
// bound keeps it free of false negatives on any device (it relies only on
// correctly rounded adds, subtracts and multiplies). One work item per
// query; the double-precision CPU queries of sinew/ccd.h remain the
// reference (the kernel's answers may differ from them only by more false
// positives, never by a miss: tests/device_ccd_test.cpp).
#pragma once

#include <array>
#include <span>
#include <vector>

#include "backends/backend.h"
#include "sinew/ccd.h"

namespace sinew::ccd {

struct DeviceQuery {
  bool vertex_face = true;  ///< else edge-edge
  /// In sinew/ccd.h's order: vertex-face p, a, b, c at the step's start,
  /// then at its end; edge-edge a0, a1, b0, b1, then at the end [m].
  std::array<Point, 8> points{};
};

/// Answers `queries` on `device` (uploads them, runs the kernel, reads the
/// hits back; Hit::u and v are not computed there and stay 0).
/// `settings.min_separation` is rounded up to float, so no touch within
/// the asked separation is lost. Errors (bad_parameter): a coordinate not
/// finite or beyond 1e15 (the float kernel's range: products of
/// coordinates must not overflow), a bad setting; device errors pass
/// through.
Result<std::vector<Hit>> device_queries(Device& device, std::span<const DeviceQuery> queries,
                                        const Settings& settings = {});

}  // namespace sinew::ccd
