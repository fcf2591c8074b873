// device_level_set.h — a level set on a device (issue 14, part 2): its
// NanoVDB grid uploaded to a buffer and sampled (value and gradient) by the
// level_set_sample kernel (kernels/shared/level_set_params.h) on any
// backend. The CPU backend's reference reads the same bytes with
// PNanoVDB.h's C mode, the GPU kernels with its GLSL mode or the OpenCL
// layer of kernels/gpu/nanovdb_lang.h.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "backends/backend.h"
#include "sinew/level_set.h"

namespace sinew {

/// A level set's grid in a device buffer. Owns the buffer: destroy() it
/// on the device that made it.
struct DeviceLevelSet {
  BufferHandle grid{};
  std::size_t bytes = 0;    ///< of the NanoVDB grid
  float inv_voxel = 0.0f;   ///< 1 / voxel_size [1/m]
  float inv_two_voxel = 0.0f;
  Status destroy(Device& device);
};

/// Uploads `level_set`'s NanoVDB grid. Errors: a level set without a grid
/// (a build without OpenVDB), device errors.
Result<DeviceLevelSet> upload_level_set(Device& device, const LevelSet& level_set);

/// Brings a device's copy up to date after `level_set.cut` by writing only
/// the byte ranges the cut changed (CutReport::changed_bytes, adjacent ones
/// merged). [out] written: the bytes written, when not null.
Status update_level_set(Device& device, const DeviceLevelSet& grid, const LevelSet& level_set, const CutReport& cut,
                        std::uint64_t* written = nullptr);

/// The value [m] and gradient at each point [m] (level set frame), as
/// (value, gx, gy, gz), by one dispatch of level_set_sample. Errors (bad
/// parameter): a non-finite point; device errors pass through.
Result<std::vector<std::array<float, 4>>> sample_level_set(Device& device, const DeviceLevelSet& level_set,
                                                          std::span<const std::array<float, 3>> points);

}  // namespace sinew
