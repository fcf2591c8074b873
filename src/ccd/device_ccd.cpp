// device_ccd.cpp — the host side of the continuous collision kernel (see
// device_ccd.h).
#include "ccd/device_ccd.h"

#include <bit>
#include <cmath>
#include <string>

#include "ccd_params.h"

namespace sinew::ccd {

Result<std::vector<Hit>> device_queries(Device& device, std::span<const DeviceQuery> queries,
                                        const Settings& settings) {
  if (!(settings.min_separation >= 0.0) || !std::isfinite(settings.min_separation) ||
      settings.min_separation > 1e15)
    return Error(ErrorCode::bad_parameter, "device ccd: the minimum separation must be finite, >= 0 and <= 1e15 [m] "
                                           "(got " + std::to_string(settings.min_separation) + ")");
  if (!(settings.tolerance > 0.0) || !std::isfinite(settings.tolerance) || settings.tolerance > 1e15)
    return Error(ErrorCode::bad_parameter,
                 "device ccd: the tolerance must be finite, > 0 and <= 1e15 [m] (got " + std::to_string(settings.tolerance) + ")");
  if (settings.max_boxes == 0) return Error(ErrorCode::bad_parameter, "device ccd: max_boxes must be > 0");
  std::vector<Hit> hits(queries.size());
  if (queries.empty()) return hits;
  std::vector<float> points(queries.size() * 32);
  std::vector<std::uint32_t> kinds(queries.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    kinds[q] = queries[q].vertex_face ? 0u : 1u;
    for (int i = 0; i < 8; ++i)
      for (int k = 0; k < 3; ++k) {
        const double x = queries[q].points[std::size_t(i)][std::size_t(k)];
        if (!std::isfinite(x) || std::abs(x) > 1e15)
          return Error(ErrorCode::bad_parameter, "device ccd: query " + std::to_string(q) + ", point " + std::to_string(i) +
                                                     " has coordinate " + std::to_string(x) +
                                                     ": it must be finite and within 1e15");
        points[32 * q + 4 * std::size_t(i) + std::size_t(k)] = float(x);
      }
  }
  kernels::CcdParams p{};
  p.count = static_cast<std::uint32_t>(queries.size());
  p.max_boxes = settings.max_boxes;
  // Rounded up: a float below the asked separation could miss a touch within it.
  p.min_separation = float(settings.min_separation);
  if (double(p.min_separation) < settings.min_separation) p.min_separation = std::nextafter(p.min_separation, INFINITY);
  p.tolerance = float(settings.tolerance);
  auto point_buffer = device.create_buffer(points.size() * 4, "ccd points");
  if (!point_buffer) return point_buffer.error();
  auto kind_buffer = device.create_buffer(kinds.size() * 4, "ccd kinds");
  if (!kind_buffer) return kind_buffer.error();
  auto hit_buffer = device.create_buffer(queries.size() * 16, "ccd hits");
  if (!hit_buffer) return hit_buffer.error();
  if (Status s = device.write_buffer(*point_buffer, 0, points.data(), points.size() * 4); !s) return s.error();
  if (Status s = device.write_buffer(*kind_buffer, 0, kinds.data(), kinds.size() * 4); !s) return s.error();
  FrameProgram program;
  program.dispatch(Kernel::ccd_queries, p.count, {*point_buffer, *kind_buffer, *hit_buffer}, p);
  auto prepared = device.create_program(program);
  if (!prepared) return prepared.error();
  if (Status s = device.run_program(*prepared); !s) return s.error();
  std::vector<std::uint32_t> words(queries.size() * 4);
  if (Status s = device.read_buffer(*hit_buffer, 0, words.data(), words.size() * 4); !s) return s.error();
  for (std::size_t q = 0; q < queries.size(); ++q) {
    hits[q].touch = words[4 * q] != 0;
    hits[q].time = double(std::bit_cast<float>(words[4 * q + 1]));
    hits[q].gave_up = words[4 * q + 2] != 0;
    hits[q].boxes = words[4 * q + 3];
  }
  return hits;
}

}  // namespace sinew::ccd
