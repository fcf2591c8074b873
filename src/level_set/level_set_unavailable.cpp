// level_set_unavailable.cpp — LevelSet in a build without OpenVDB (the
// CMake option SINEW_OPENVDB off, or its packages missing): every way to
// make one fails, naming the option, so nothing else can be called.
#include "sinew/level_set.h"

#include "level_set/level_set_values.h"

namespace sinew {
namespace {

Error unavailable(const char* call) {
  return Error(ErrorCode::backend_unavailable,
               std::string(call) + ": sinew was built without level sets (SINEW_OPENVDB off or OpenVDB/NanoVDB "
                                   "missing: apt-get install libopenvdb-dev libnanovdb-dev libboost-dev, reconfigure)");
}

}  // namespace

struct LevelSet::Impl {};

LevelSet::LevelSet(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}
Result<LevelSet> LevelSet::from_mesh(const TriMesh&, const LevelSetSettings&) {
  return unavailable("LevelSet::from_mesh");
}
Result<LevelSet> LevelSet::sphere(const std::array<double, 3>&, double, const LevelSetSettings&) {
  return unavailable("LevelSet::sphere");
}
Result<LevelSet> LevelSet::box(const std::array<double, 3>&, const std::array<double, 3>&, const LevelSetSettings&) {
  return unavailable("LevelSet::box");
}
double LevelSet::voxel_size() const { return 0.0; }
double LevelSet::exterior_band() const { return 0.0; }
double LevelSet::interior_band() const { return 0.0; }
std::array<double, 6> LevelSet::bounds() const { return {}; }
std::uint64_t LevelSet::voxels() const { return 0; }
double LevelSet::value(const std::array<double, 3>&) const { return 0.0; }
std::array<double, 3> LevelSet::gradient(const std::array<double, 3>&) const { return {}; }
std::span<const std::byte> LevelSet::nanovdb_bytes() const { return {}; }
Result<CutReport> LevelSet::cut(const CutterShape&, const Pose&, const Pose&) { return unavailable("LevelSet::cut"); }
TriMesh LevelSet::surface() const { return {}; }
Result<TriMesh> LevelSet::surface_in(const std::array<double, 6>&) const { return unavailable("LevelSet::surface_in"); }

Status set_level_set_values(const LevelSet&, std::span<const std::byte>, const std::string&,
                            std::vector<std::array<std::uint64_t, 2>>&) {
  return unavailable("set_level_set_values");
}

}  // namespace sinew
