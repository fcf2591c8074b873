// positions_mirror.h — the particles' positions as the device holds them,
// read back at most once between two changes, for every stage that needs
// them on the host (mesh collision, sutures, tearing). Before it each of
// those read the positions on its own: a scene with needles read them
// three times a frame.
//
// Whatever writes positions on the device says so (changed()): the solve
// stage before it runs, and the topology editor (a removal hands mass on,
// and the inverse mass is the positions' w). The first stage that asks
// after a change reads; the others, in this frame and before the next
// change, copy the host's mirror.
#pragma once

#include <cstdint>
#include <vector>

#include "backends/backend.h"

namespace sinew {

class PositionsMirror {
 public:
  /// [out] into: the device's positions (a float4 per particle in device
  /// order, `floats` floats in all), read from `position` only if they
  /// changed since the last read.
  Status copy_to(Device& device, BufferHandle position, std::size_t floats, std::vector<float>& into) {
    if (!valid_ || data_.size() != floats) {
      data_.resize(floats);
      if (Status s = device.read_buffer(position, 0, data_.data(), floats * sizeof(float)); !s) return s;
      ++reads_;
      valid_ = true;
    }
    into.assign(data_.begin(), data_.end());
    return {};
  }
  /// The positions on the device changed (or may have).
  void changed() { valid_ = false; }
  /// Starts a frame's count of reads.
  void begin_frame() { reads_ = 0; }
  [[nodiscard]] std::uint32_t reads() const { return reads_; }   ///< read-backs since begin_frame

 private:
  std::vector<float> data_;
  bool valid_ = false;
  std::uint32_t reads_ = 0;
};

}  // namespace sinew
