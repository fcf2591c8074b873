// voxel_bounds.cpp — index-range and voxel-count checks of the level-set
// calls (voxel_bounds.h; issue 39).
#include "level_set/voxel_bounds.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace sinew::level_set {

std::string number_text(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

namespace {
std::string str(double v) { return number_text(v); }
}  // namespace

Result<VoxelBox> voxel_box(const std::string& call, const std::string& what, const std::array<double, 3>& lo,
                           const std::array<double, 3>& hi, double margin, double h) {
  VoxelBox box;
  for (int k = 0; k < 3; ++k) {
    // In double, before any conversion to int (which would be undefined
    // behaviour out of range).
    const double first = std::floor((lo[k] - margin) / h), last = std::ceil((hi[k] + margin) / h);
    if (!(std::abs(first) <= kMaxVoxelIndex && std::abs(last) <= kMaxVoxelIndex))
      return Error(ErrorCode::bad_parameter,
                   call + ": " + what + " reaches voxel index " + str(std::abs(first) > std::abs(last) ? first : last) +
                       " on axis " + std::to_string(k) + " (voxel_size " + str(h) + " m), beyond the +-2^30 a level " +
                       "set's indices may use: move it nearer the origin or use a larger voxel_size");
    box.first[k] = static_cast<int>(first);
    box.last[k] = static_cast<int>(last);
  }
  return box;
}

Status check_visited(const std::string& call, const std::string& what, double voxels, double h) {
  if (voxels <= kMaxVisitedVoxels) return {};
  return Error(ErrorCode::capacity_exceeded, call + ": " + what + " spans " + str(voxels) + " voxels of " + str(h) +
                                                 " m, more than the 2^30 one call may visit: use a larger voxel_size");
}

Status float_finite(const std::string& call, const std::string& what, double value) {
  if (std::abs(value) <= double(std::numeric_limits<float>::max())) return {};
  return Error(ErrorCode::bad_parameter, call + ": " + what + " (" + str(value) +
                                             ") is beyond float32's range, the precision the device samples in");
}

}  // namespace sinew::level_set
