// device_level_set.cpp — a level set's grid on a device and its sampling
// kernel's host side (see device_level_set.h).
#include "level_set/device_level_set.h"

#include <cmath>
#include <string>

#include "level_set_params.h"

namespace sinew {

Status DeviceLevelSet::destroy(Device& device) { return device.destroy_buffer(grid); }

Result<DeviceLevelSet> upload_level_set(Device& device, const LevelSet& level_set) {
  const std::span<const std::byte> bytes = level_set.nanovdb_bytes();
  if (bytes.empty())
    return Error(ErrorCode::backend_unavailable, "upload_level_set: the level set has no NanoVDB grid (sinew was "
                                                 "built without OpenVDB)");
  DeviceLevelSet out;
  auto buffer = device.create_buffer(bytes.size(), "level set grid");
  if (!buffer) return buffer.error();
  out.grid = *buffer;
  out.bytes = bytes.size();
  if (Status s = device.write_buffer(out.grid, 0, bytes.data(), bytes.size()); !s) return s.error();
  out.inv_voxel = float(1.0 / level_set.voxel_size());
  out.inv_two_voxel = float(0.5 / level_set.voxel_size());
  return out;
}

Status update_level_set(Device& device, const DeviceLevelSet& grid, const LevelSet& level_set, const CutReport& cut,
                        std::uint64_t* written) {
  const std::span<const std::byte> bytes = level_set.nanovdb_bytes();
  if (bytes.size() != grid.bytes)
    return Error(ErrorCode::bad_parameter, "update_level_set: the device's grid (" + std::to_string(grid.bytes) +
                                               " bytes) is not this level set's (" + std::to_string(bytes.size()) + ")");
  std::uint64_t total = 0;
  for (std::size_t r = 0; r < cut.changed_bytes.size();) {
    std::uint64_t offset = cut.changed_bytes[r][0], end = offset + cut.changed_bytes[r][1];
    for (++r; r < cut.changed_bytes.size() && cut.changed_bytes[r][0] == end; ++r) end += cut.changed_bytes[r][1];
    if (end > bytes.size()) return Error(ErrorCode::bad_parameter, "update_level_set: a changed range past the grid");
    if (Status s = device.write_buffer(grid.grid, offset, bytes.data() + offset, end - offset); !s) return s;
    total += end - offset;
  }
  if (written) *written = total;
  return {};
}

Result<std::vector<std::array<float, 4>>> sample_level_set(Device& device, const DeviceLevelSet& level_set,
                                                          std::span<const std::array<float, 3>> points) {
  std::vector<std::array<float, 4>> samples(points.size());
  if (points.empty()) return samples;
  std::vector<float> xyzw(points.size() * 4, 0.0f);
  for (std::size_t q = 0; q < points.size(); ++q)
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(points[q][k]))
        return Error(ErrorCode::bad_parameter, "sample_level_set: point " + std::to_string(q) + " is not finite");
      xyzw[4 * q + k] = points[q][k];
    }
  auto point_buffer = device.create_buffer(xyzw.size() * 4, "level set points");
  if (!point_buffer) return point_buffer.error();
  auto sample_buffer = device.create_buffer(xyzw.size() * 4, "level set samples");
  if (!sample_buffer) return sample_buffer.error();
  Status status = device.write_buffer(*point_buffer, 0, xyzw.data(), xyzw.size() * 4);
  if (status) {
    kernels::LevelSetSampleParams p{};
    p.count = static_cast<std::uint32_t>(points.size());
    p.inv_voxel = level_set.inv_voxel;
    p.inv_two_voxel = level_set.inv_two_voxel;
    FrameProgram program;
    program.dispatch(Kernel::level_set_sample, p.count, {level_set.grid, *point_buffer, *sample_buffer}, p);
    auto prepared = device.create_program(program);
    if (!prepared) status = prepared.error();
    if (status) status = device.run_program(*prepared);
    if (prepared) (void)device.destroy_program(*prepared);
    if (status) status = device.read_buffer(*sample_buffer, 0, samples.data(), samples.size() * 16);
  }
  (void)device.destroy_buffer(*point_buffer);
  (void)device.destroy_buffer(*sample_buffer);
  if (!status) return status.error();
  return samples;
}

}  // namespace sinew
