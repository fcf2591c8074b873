// script_player.cpp — playing a scene file's script on a Simulation
// (sinew/scene_file.h, ScriptPlayer): each frame's interpolated poses and
// forces, then its actions, through the feature handles.
#include <cmath>

#include "math/vec3.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"

namespace sinew {

ScriptKey interpolate_keys(const std::vector<ScriptKey>& keys, int frame) {
  if (frame <= keys.front().frame) return keys.front();
  if (frame >= keys.back().frame) return keys.back();
  std::size_t i = 1;
  while (keys[i].frame < frame) ++i;
  const ScriptKey& a = keys[i - 1];
  const ScriptKey& b = keys[i];
  if (frame == b.frame) return b;
  const double s = double(frame - a.frame) / double(b.frame - a.frame);
  ScriptKey k;
  k.frame = frame;
  for (int c = 0; c < 3; ++c) {
    k.position[c] = a.position[c] + (b.position[c] - a.position[c]) * s;
    k.torque[c] = a.torque[c] + (b.torque[c] - a.torque[c]) * s;
  }
  // Normalised linear interpolation along the shorter arc (q and -q are one rotation).
  double dot = 0.0;
  for (int c = 0; c < 4; ++c) dot += a.rotation[c] * b.rotation[c];
  const double sign = dot < 0.0 ? -1.0 : 1.0;
  double norm = 0.0;
  for (int c = 0; c < 4; ++c) {
    k.rotation[c] = a.rotation[c] + (sign * b.rotation[c] - a.rotation[c]) * s;
    norm += k.rotation[c] * k.rotation[c];
  }
  norm = std::sqrt(norm);
  if (norm > 0.0)
    for (double& q : k.rotation) q /= norm;
  return k;
}

ScriptPlayer::ScriptPlayer(SceneScript script) : script_(std::move(script)) {}

namespace {

std::string describe(const char* what, const TopologyEvent& e) {
  const std::size_t elements = e.tets_removed.size() + e.triangles_removed.size() + e.segments_removed.size();
  return std::string(what) + ": " + std::to_string(elements) + " elements, " +
         std::to_string(e.vertices_removed.size()) + " vertices, " + std::to_string(e.constraints_removed) +
         " constraints removed";
}

// Where landmark `l` is now: the mean of its vertices (summed in order, in
// double) plus its offset.
Result<std::array<double, 3>> landmark_position(Simulation& sim, const ScriptLandmark& l) {
  const SceneInfo& info = sim.info();
  const auto& firsts = l.body_kind == BodyKind::tet   ? info.tet_body_first_particle
                       : l.body_kind == BodyKind::tri ? info.tri_body_first_particle
                                                      : info.line_body_first_particle;
  if (l.body >= firsts.size() || l.vertices.empty())
    return Error(ErrorCode::bad_parameter, "a landmark names body " + std::to_string(l.body) +
                                               " of a kind the scene has " + std::to_string(firsts.size()) +
                                               " of, or no vertex");
  std::vector<float> x;
  if (Status s = sim.read_positions(x); !s) return s.error();
  std::array<double, 3> mean{0.0, 0.0, 0.0};
  for (std::uint32_t v : l.vertices) {
    const std::size_t at = 4 * (std::size_t{firsts[l.body]} + v);
    if (at + 3 > x.size()) return Error(ErrorCode::bad_parameter, "a landmark's vertex " + std::to_string(v) + " is past the scene's particles");
    for (int c = 0; c < 3; ++c) mean[c] += x[at + c];
  }
  for (int c = 0; c < 3; ++c) mean[c] = mean[c] / static_cast<double>(l.vertices.size()) + l.offset[c];
  return mean;
}

// A relative grasper key on the pose the jaws closed at (ScriptTrack::relative).
Pose relative_pose(const Pose& closed, const ScriptKey& k) {
  return {math::add(closed.position, k.position), math::qmul(k.rotation, closed.rotation)};
}

Status pose_track(Simulation& sim, const ScriptTrack& track, const ScriptKey& k, const std::vector<bool>& closed,
                  const std::vector<Pose>& closed_at) {
  switch (track.subject) {
    case ScriptSubject::collider: {
      auto id = sim.tools().collider(track.index);
      if (!id) return id.error();
      return sim.tools().set_pose(*id, k.position, k.rotation);
    }
    case ScriptSubject::target: {
      auto id = sim.tools().target(track.index);
      if (!id) return id.error();
      return sim.tools().set_position(*id, k.position);
    }
    case ScriptSubject::grasper: {
      // Moving open jaws moves nothing: only a closed grasper is moved.
      if (track.index >= closed.size() || !closed[track.index]) return {};
      auto id = sim.graspers().grasper(track.index);
      if (!id) return id.error();
      return sim.graspers().move(*id, track.relative ? relative_pose(closed_at[track.index], k)
                                                     : Pose{k.position, k.rotation});
    }
    case ScriptSubject::needle: {
      auto id = sim.needles().needle(track.index);
      if (!id) return id.error();
      return sim.needles().set_pose(*id, k.position, k.rotation);
    }
    case ScriptSubject::tool: break;
  }
  return Error(ErrorCode::bad_parameter, "a pose track cannot drive a tool (tools are driven by forces)");
}

Status force_track(Simulation& sim, const ScriptTrack& track, const ScriptKey& k) {
  if (track.subject == ScriptSubject::tool) {
    auto id = sim.tools().tool(track.index);
    if (!id) return id.error();
    return sim.tools().apply_force(*id, k.position, k.torque);
  }
  auto id = sim.needles().needle(track.index);
  if (!id) return id.error();
  return sim.needles().apply_force(*id, k.position, k.torque);
}

Result<TopologyEvent> topology_action(Simulation& sim, const ScriptAction& a) {
  Topology topology = sim.topology();
  if (a.kind == ScriptActionKind::remove) {
    if (a.body_kind == BodyKind::tet) {
      auto id = topology.tet_body(a.index);
      if (!id) return id.error();
      return topology.remove_tets(*id, a.elements);
    }
    if (a.body_kind == BodyKind::tri) {
      auto id = topology.tri_body(a.index);
      if (!id) return id.error();
      return topology.remove_triangles(*id, a.elements);
    }
    auto id = topology.line_body(a.index);
    if (!id) return id.error();
    return topology.remove_segments(*id, a.elements);
  }
  Blade from{a.a_from, a.b_from}, to{a.a_to, a.b_to};
  std::array<double, 3> centre = a.centre;
  if (a.at) {
    auto p = landmark_position(sim, *a.at);
    if (!p) return p.error();
    if (a.kind == ScriptActionKind::cauterize) centre = *p;
    for (auto* point : {&from.a, &from.b, &to.a, &to.b})  // a cut's blade is relative to the landmark
      for (int c = 0; c < 3; ++c) (*point)[c] = (*p)[c] + (*point)[c];
  }
  if (a.body_kind == BodyKind::tet) {
    auto id = topology.tet_body(a.index);
    if (!id) return id.error();
    if (a.kind == ScriptActionKind::cut) return topology.cut(*id, from, to);
    return topology.cauterize(*id, centre, a.radius, a.seconds, a.dwell_time);
  }
  auto id = topology.tri_body(a.index);
  if (!id) return id.error();
  if (a.kind == ScriptActionKind::cut) return topology.cut(*id, from, to);
  return topology.cauterize(*id, centre, a.radius, a.seconds, a.dwell_time);
}

}  // namespace

Status ScriptPlayer::before_frame(Simulation& sim, int frame, std::vector<std::string>* events) {
  std::vector<ScriptEvent> done;
  if (Status s = before_frame(sim, frame, done); !s) return s;
  if (events)
    for (ScriptEvent& e : done)
      if (!e.text.empty()) events->push_back(std::move(e.text));
  return {};
}

Status ScriptPlayer::before_frame(Simulation& sim, int frame, std::vector<ScriptEvent>& events) {
  if (grasper_closed_.size() < sim.graspers().count()) {
    grasper_closed_.resize(sim.graspers().count(), false);
    grasper_closed_at_.resize(sim.graspers().count());
  }
  for (const ScriptTrack& t : script_.poses)
    if (Status s = pose_track(sim, t, interpolate_keys(t.keys, frame), grasper_closed_, grasper_closed_at_); !s)
      return s;
  for (const ScriptTrack& t : script_.forces)
    if (Status s = force_track(sim, t, interpolate_keys(t.keys, frame)); !s) return s;
  while (next_action_ < script_.actions.size() && script_.actions[next_action_].frame <= frame) {
    const ScriptAction& a = script_.actions[next_action_++];
    if (a.frame < frame) continue;  // a frame skipped by the caller
    const std::string at = "frame " + std::to_string(frame) + ": ";
    ScriptEvent event;
    event.frame = frame, event.kind = a.kind, event.index = a.index;
    switch (a.kind) {
      case ScriptActionKind::close_grasper:
      case ScriptActionKind::open_grasper: {
        auto id = sim.graspers().grasper(a.index);
        if (!id) return id.error();
        Pose jaws = a.pose;
        if (a.kind == ScriptActionKind::close_grasper && a.at) {
          auto p = landmark_position(sim, *a.at);
          if (!p) return p.error();
          jaws.position = *p;
        }
        auto held = a.kind == ScriptActionKind::close_grasper ? sim.graspers().close(*id, jaws, a.half_extents)
                                                              : sim.graspers().open(*id);
        if (!held) return held.error();
        grasper_closed_[a.index] = a.kind == ScriptActionKind::close_grasper;
        if (a.kind == ScriptActionKind::close_grasper) grasper_closed_at_[a.index] = jaws;
        event.text = at + (a.kind == ScriptActionKind::close_grasper ? "grasper closed on " : "grasper released ") +
                     std::to_string(held->size()) + " vertices";
        event.particles = std::move(*held);
        break;
      }
      case ScriptActionKind::cut:
      case ScriptActionKind::cauterize:
      case ScriptActionKind::remove: {
        auto e = topology_action(sim, a);
        if (!e) return e.error();
        const char* what = a.kind == ScriptActionKind::cut ? "cut" : a.kind == ScriptActionKind::cauterize ? "cautery" : "removal";
        event.text = at + describe(what, *e);
        event.topology = std::move(*e);
        break;
      }
      case ScriptActionKind::cut_collider: {
        auto id = sim.tools().collider(a.index);
        if (!id) return id.error();
        auto r = sim.tools().cut(*id, a.cutter, a.from, a.to);
        if (!r) return r.error();
        event.text = at + "collider cut, " + std::to_string(r->removed_volume * 1e9) + " mm^3 removed";
        event.collider_cut = *r;
        break;
      }
      case ScriptActionKind::set_emitter:
        if (Status s = sim.fluid().set_emitter(a.index, a.emitter); !s) return s;
        break;
      case ScriptActionKind::set_sink:
        if (Status s = sim.fluid().set_sink(a.index, a.sink); !s) return s;
        break;
    }
    events.push_back(std::move(event));
  }
  return {};
}

}  // namespace sinew
