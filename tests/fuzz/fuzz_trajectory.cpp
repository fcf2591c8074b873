// fuzz_trajectory.cpp — libFuzzer target for haptics::read_trajectory_csv
// (a recorded device trajectory). Input: the file's bytes. Checked: a
// documented error, or samples that ReplayDevice::create accepts (what
// ReplayDevice::load does next) and that replay to finite readings.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.h"
#include "sinew/haptics/replay_device.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const auto path = fuzz::scratch_file("t.csv", {reinterpret_cast<const char*>(data), size});
  auto samples = haptics::read_trajectory_csv(path);
  if (!samples) {
    fuzz::check_error(samples.error(), {ErrorCode::bad_input_file}, "read_trajectory_csv");
    return 0;
  }
  fuzz::note("read_trajectory_csv: " + std::to_string(samples->size()) + " samples");
  const double t0 = samples->front().time, t1 = samples->back().time;
  auto device = haptics::ReplayDevice::create(std::move(*samples), 0, /*loop=*/true);
  if (!device) fuzz::fail("ReplayDevice::create refused what read_trajectory_csv returned: " + device.error().message());
  // Sample before, inside and past the trajectory (looping), in nanoseconds.
  const double span_ns = (t1 - t0) * 1e9;
  for (double f : {-1.0, 0.0, 0.25, 0.5, 0.999, 1.0, 2.5}) {
    const double at = f * span_ns;
    if (!(std::fabs(at) < 9e18)) continue;  // past the int64 clock
    haptics::DeviceSample s;
    device->sample(std::int64_t(at), s);
    for (double c : s.position)
      if (!std::isfinite(c)) fuzz::fail("ReplayDevice::sample returned a non-finite position");
    for (double c : s.rotation)
      if (!std::isfinite(c)) fuzz::fail("ReplayDevice::sample returned a non-finite rotation");
  }
  return 0;
}
