// embree_broad_phase.cpp — Embree 3 scenes of user-geometry boxes and
// rtcCollide (see embree_broad_phase.h). Embree calls the collision
// callback from its own worker threads; each gathers into its own list.
#include "collision/embree_broad_phase.h"

#include <embree3/rtcore.h>

#include <tbb/enumerable_thread_specific.h>

#include <string>

namespace sinew::collision {

struct EmbreeBoxes::Handles {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  RTCGeometry geometry = nullptr;
  std::uint32_t count = 0;
};

namespace {

Status device_error(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e == RTC_ERROR_NONE) return {};
  return Error(ErrorCode::internal, std::string("Embree: ") + what + " failed (error " + std::to_string(int(e)) + ")");
}

void bounds_of(const RTCBoundsFunctionArguments* args) {
  const auto* boxes = static_cast<const Aabb*>(args->geometryUserPtr);
  const Aabb& b = boxes[args->primID];
  RTCBounds* o = args->bounds_o;
  o->lower_x = b.lo[0], o->lower_y = b.lo[1], o->lower_z = b.lo[2];
  o->upper_x = b.hi[0], o->upper_y = b.hi[1], o->upper_z = b.hi[2];
}

// Candidates per Embree worker thread, merged after rtcCollide: a lock per
// callback cost ~4x the whole traversal (Embree passes few pairs per call).
struct Gather {
  tbb::enumerable_thread_specific<std::vector<Pair>> local;
};

void gather(void* user, RTCCollision* collisions, unsigned int count) {
  std::vector<Pair>& out = static_cast<Gather*>(user)->local.local();
  for (unsigned int k = 0; k < count; ++k) out.push_back({collisions[k].primID0, collisions[k].primID1});
}

}  // namespace

Result<std::unique_ptr<EmbreeBoxes>> EmbreeBoxes::create() {
  auto set = std::unique_ptr<EmbreeBoxes>(new EmbreeBoxes());
  set->handles_ = std::make_unique<Handles>();
  set->handles_->device = rtcNewDevice(nullptr);
  if (!set->handles_->device) return Error(ErrorCode::backend_unavailable, "Embree: rtcNewDevice failed");
  return set;
}

EmbreeBoxes::~EmbreeBoxes() {
  if (!handles_) return;
  if (handles_->scene) rtcReleaseScene(handles_->scene);
  if (handles_->device) rtcReleaseDevice(handles_->device);
}

Status EmbreeBoxes::commit(bool rebuild) {
  Handles& h = *handles_;
  if (rebuild) {
    if (h.scene) rtcReleaseScene(h.scene);
    h.scene = rtcNewScene(h.device);
    // Dynamic and refittable: the boxes move every substep.
    rtcSetSceneFlags(h.scene, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(h.scene, RTC_BUILD_QUALITY_LOW);
    h.geometry = rtcNewGeometry(h.device, RTC_GEOMETRY_TYPE_USER);
    h.count = static_cast<std::uint32_t>(boxes_.size());
    rtcSetGeometryUserPrimitiveCount(h.geometry, h.count);
    rtcSetGeometryBuildQuality(h.geometry, RTC_BUILD_QUALITY_REFIT);
    rtcSetGeometryBoundsFunction(h.geometry, bounds_of, nullptr);
    rtcAttachGeometry(h.scene, h.geometry);
    rtcReleaseGeometry(h.geometry);  // the scene holds it
  }
  rtcSetGeometryUserData(h.geometry, const_cast<Aabb*>(boxes_.data()));
  rtcCommitGeometry(h.geometry);
  rtcCommitScene(h.scene);
  return device_error(h.device, rebuild ? "building the scene" : "refitting the scene");
}

Status EmbreeBoxes::build(std::span<const Aabb> boxes) {
  boxes_ = boxes;
  return commit(true);
}

Status EmbreeBoxes::refit(std::span<const Aabb> boxes) {
  if (!handles_->scene || boxes.size() != handles_->count)
    return Error(ErrorCode::bad_parameter, "Embree refit: " + std::to_string(boxes.size()) + " boxes for a scene built over " +
                                               std::to_string(handles_->count) + " (build again)");
  boxes_ = boxes;
  return commit(false);
}

Status EmbreeBoxes::collide(const EmbreeBoxes& a, const EmbreeBoxes& b, std::vector<Pair>& candidates) {
  candidates.clear();
  if (a.boxes_.empty() || b.boxes_.empty()) return {};
  Gather g;
  rtcCollide(a.handles_->scene, b.handles_->scene, gather, &g);
  for (const std::vector<Pair>& part : g.local) candidates.insert(candidates.end(), part.begin(), part.end());
  return device_error(a.handles_->device, "rtcCollide");
}

Status embree_pairs(const EmbreeBoxes& a, const EmbreeBoxes& b, std::vector<Pair>& pairs) {
  std::vector<Pair> candidates;
  if (Status s = EmbreeBoxes::collide(a, b, candidates); !s) return s;
  pairs.clear();
  for (const auto& [i, j] : candidates)
    if (overlap(a.boxes()[i], b.boxes()[j])) pairs.push_back({i, j});
  detail::sort_unique(pairs);
  return {};
}

}  // namespace sinew::collision
