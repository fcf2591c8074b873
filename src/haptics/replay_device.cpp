// src/haptics/replay_device.cpp — trajectory CSV reading and writing, and a
// device replaying a trajectory (linear interpolation between samples).
#include "sinew/haptics/replay_device.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "math/vec3.h"
#include "sinew/haptics/clock.h"

namespace sinew::haptics {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) out.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && errno != ERANGE;
}

Status check_samples(const std::vector<TrajectorySample>& samples, const std::string& origin) {
  if (samples.empty()) return Error(ErrorCode::bad_parameter, origin + ": no samples");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const TrajectorySample& s = samples[i];
    const std::string where = origin + ": sample " + std::to_string(i);
    if (!std::isfinite(s.time) || !math::finite(s.position) || !math::finite(s.rotation))
      return Error(ErrorCode::bad_parameter, where + " has a non-finite value");
    if (math::qdot(s.rotation, s.rotation) < 1e-12)
      return Error(ErrorCode::bad_parameter, where + " has a zero quaternion");
    if (i > 0 && !(s.time > samples[i - 1].time))
      return Error(ErrorCode::bad_parameter,
                   where + ": time " + std::to_string(s.time) + " s is not after the previous sample's " +
                   std::to_string(samples[i - 1].time) + " s");
  }
  return {};
}

}  // namespace

Result<std::vector<TrajectorySample>> read_trajectory_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return Error(ErrorCode::bad_input_file, "cannot open trajectory " + path.string());
  const std::string file = path.string();
  std::vector<TrajectorySample> samples;
  std::string line;
  std::size_t columns = 0;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    const std::string where = file + ":" + std::to_string(line_no) + ": ";
    const std::vector<std::string> cells = split(t);
    if (columns == 0) {  // the header
      static const char* kNames[] = {"time", "x", "y", "z", "qw", "qx", "qy", "qz", "buttons"};
      if (cells.size() != 4 && cells.size() != 8 && cells.size() != 9)
        return Error(ErrorCode::bad_input_file,
                     where + "header must be time,x,y,z[,qw,qx,qy,qz[,buttons]] (got " + std::to_string(cells.size()) +
                     " columns)");
      for (std::size_t c = 0; c < cells.size(); ++c)
        if (cells[c] != kNames[c])
          return Error(ErrorCode::bad_input_file,
                       where + "header column " + std::to_string(c + 1) + " must be '" + kNames[c] + "' (got '" +
                       cells[c] + "')");
      columns = cells.size();
      continue;
    }
    if (cells.size() != columns)
      return Error(ErrorCode::bad_input_file,
                   where + "expected " + std::to_string(columns) + " values, got " + std::to_string(cells.size()));
    double v[9] = {0, 0, 0, 0, 1, 0, 0, 0, 0};
    for (std::size_t c = 0; c < columns; ++c)
      if (!parse_double(cells[c], v[c]) || !std::isfinite(v[c]))
        return Error(ErrorCode::bad_input_file,
                     where + "column " + std::to_string(c + 1) + " is not a finite number ('" + cells[c] + "')");
    TrajectorySample s;
    s.time = v[0];
    s.position = {v[1], v[2], v[3]};
    const Quat q{v[4], v[5], v[6], v[7]};
    if (math::qdot(q, q) < 1e-12) return Error(ErrorCode::bad_input_file, where + "quaternion is zero");
    s.rotation = math::normalize(q);
    if (columns == 9) {
      if (v[8] < 0 || v[8] != std::floor(v[8]) || v[8] > 4294967295.0)
        return Error(ErrorCode::bad_input_file, where + "buttons must be a non-negative integer ('" + cells[8] + "')");
      s.buttons = static_cast<std::uint32_t>(v[8]);
    }
    if (!samples.empty() && !(s.time > samples.back().time))
      return Error(ErrorCode::bad_input_file,
                   where + "time " + cells[0] + " s is not after the previous row's " +
                   std::to_string(samples.back().time) + " s");
    samples.push_back(s);
  }
  if (columns == 0)
    return Error(ErrorCode::bad_input_file, file + ": no header line (time,x,y,z[,qw,qx,qy,qz[,buttons]])");
  if (samples.empty()) return Error(ErrorCode::bad_input_file, file + ": no samples after the header");
  return samples;
}

Status write_trajectory_csv(const std::filesystem::path& path, std::span<const TrajectorySample> samples) {
  std::FILE* f = std::fopen(path.string().c_str(), "w");
  if (!f) return Error(ErrorCode::bad_input_file, "cannot write trajectory " + path.string());
  std::fprintf(f, "time,x,y,z,qw,qx,qy,qz,buttons\n");
  for (const TrajectorySample& s : samples)
    std::fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u\n", s.time, s.position[0], s.position[1],
                 s.position[2], s.rotation[0], s.rotation[1], s.rotation[2], s.rotation[3], s.buttons);
  if (std::fclose(f) != 0) return Error(ErrorCode::bad_input_file, "cannot write trajectory " + path.string());
  return {};
}

Result<ReplayDevice> ReplayDevice::create(std::vector<TrajectorySample> samples, std::int64_t origin_ns, bool loop,
                                          std::string name) {
  if (auto s = check_samples(samples, name); !s) return s.error();
  ReplayDevice d;
  for (TrajectorySample& s : samples) s.rotation = math::normalize(s.rotation);
  d.samples_ = std::move(samples);
  d.origin_ns_ = origin_ns;
  d.loop_ = loop;
  d.name_ = std::move(name);
  const double span = d.samples_.back().time - d.samples_.front().time;
  d.rate_hz_ = span > 0.0 ? double(d.samples_.size() - 1) / span : 0.0;
  return d;
}

Result<ReplayDevice> ReplayDevice::load(const std::filesystem::path& path, std::int64_t origin_ns, bool loop) {
  auto samples = read_trajectory_csv(path);
  if (!samples) return samples.error();
  auto device = create(std::move(*samples), origin_ns, loop, "replay " + path.string());
  if (!device) return Error(ErrorCode::bad_input_file, device.error().message());  // the samples came from the file
  return device;
}

bool ReplayDevice::sample(std::int64_t now_ns, DeviceSample& out) noexcept {
  const std::size_t n = samples_.size();
  const double t0 = samples_.front().time, t1 = samples_.back().time;
  double t = ns_to_seconds(now_ns - origin_ns_) + t0;
  if (loop_ && t1 > t0 && t > t1) t = t0 + std::fmod(t - t0, t1 - t0);
  out.sequence = ++sequence_;
  out.time_ns = now_ns;
  out.velocity = {0.0, 0.0, 0.0};
  out.angular_velocity = {0.0, 0.0, 0.0};
  if (n == 1 || t <= t0 || t >= t1) {  // hold an end
    const TrajectorySample& s = t <= t0 ? samples_.front() : samples_.back();
    out.position = s.position;
    out.rotation = s.rotation;
    out.buttons = s.buttons;
    return true;
  }
  // Segment [cursor, cursor + 1] containing t: moves forward (or back, after
  // a wrap) from the previous one, so a tick costs O(1) in steady replay.
  if (cursor_ + 1 >= n || samples_[cursor_].time > t) cursor_ = 0;
  while (cursor_ + 2 < n && samples_[cursor_ + 1].time <= t) ++cursor_;
  const TrajectorySample& a = samples_[cursor_];
  const TrajectorySample& b = samples_[cursor_ + 1];
  const double dt = b.time - a.time;
  const double u = (t - a.time) / dt;
  out.position = math::lerp(a.position, b.position, u);
  out.rotation = math::nlerp(a.rotation, b.rotation, u);
  out.velocity = math::mul(math::sub(b.position, a.position), 1.0 / dt);
  out.angular_velocity = math::angular_velocity(a.rotation, b.rotation, dt);
  out.buttons = a.buttons;
  return true;
}

void ReplayDevice::command(const Vec3& force, const Vec3&, std::int64_t) noexcept { force_ = force; }

}  // namespace sinew::haptics
