// voxel_bounds.h — the range checks every level-set call that loops over
// voxels makes first (issue 39): voxel indices that fit in int32 with room
// to spare, and a bound on how many voxels one call may visit, so that a
// shape far from the origin or a very fine voxel is a named error instead
// of an int overflow (undefined behaviour) or a loop of hours.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "sinew/result.h"

namespace sinew::level_set {

/// The largest |voxel index| a level set may use: 2^30, half of int32's
/// range, so that neighbours (+-1), OpenVDB's node origins (multiples of
/// 4096) and sums of two indices never overflow.
constexpr double kMaxVoxelIndex = 1073741824.0;
/// The most voxels one factory or cut may visit: 2^30 (a cube of 1024^3;
/// at the default 0.5 mm voxel, a box of about 0.5 m a side).
constexpr double kMaxVisitedVoxels = 1073741824.0;
/// The smallest voxel: OpenVDB's linear transform refuses a voxel whose
/// volume is below 3e-15 m^3 (about 14.4 um a side).
constexpr double kMinVoxelSize = 1.5e-5;

/// The voxels (first .. last, inclusive, per axis) of the world box
/// [lo - margin, hi + margin] on a grid of voxel `h` [m].
struct VoxelBox {
  std::array<int, 3> first{};
  std::array<int, 3> last{};
  [[nodiscard]] double count() const {
    return (double(last[0]) - first[0] + 1) * (double(last[1]) - first[1] + 1) * (double(last[2]) - first[2] + 1);
  }
};

/// [in] call: the public call, for messages; lo, hi [m], finite; margin,
/// h [m], finite and > 0. Errors (bad_parameter, naming `what`): an index
/// beyond +-kMaxVoxelIndex.
Result<VoxelBox> voxel_box(const std::string& call, const std::string& what, const std::array<double, 3>& lo,
                           const std::array<double, 3>& hi, double margin, double h);

/// Errors (capacity_exceeded, naming `what`): `voxels` (those a call would
/// visit) more than kMaxVisitedVoxels.
Status check_visited(const std::string& call, const std::string& what, double voxels, double h);

/// `v` as the level-set calls' messages print it ("%g").
std::string number_text(double v);

/// Errors (bad_parameter, naming `what`): a value whose magnitude a float
/// cannot hold (the device samples the grid in float32).
Status float_finite(const std::string& call, const std::string& what, double value);

}  // namespace sinew::level_set
