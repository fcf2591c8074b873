// simulation_topology.cpp — Simulation's topology changes: remove_tets,
// remove_triangles, remove_segments, cut_body, cauterize and the tears after
// each frame (topology_editor.h patches the constraints, topology_queries.h
// finds the elements).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "math/xpbd_math.h"
#include "program/stats_program.h"
#include "runtime/simulation_impl.h"
#include "runtime/simulation_internals.h"
#include "runtime/topology_queries.h"

// cut_body and cauterize by BodyKind are deprecated for users; the tet
// overloads here forward to them.
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"

namespace sinew {

namespace {

Status need_topology(const std::unique_ptr<TopologyEditor>& editor, const char* call) {
  if (editor) return {};
  return Error(ErrorCode::bad_parameter,
               std::string(call) + " needs SceneDesc::topology_changes = true when the Simulation is made");
}

// A tet or tri body of the scene.
Status check_body(const TopologyEditor& editor, BodyKind kind, std::size_t body) {
  if (kind == BodyKind::line)
    return Error(ErrorCode::bad_parameter, "a line body has no tets or triangles (remove_segments breaks threads)");
  if (body < editor.bodies(kind)) return {};
  return Error(ErrorCode::bad_parameter, std::string(kind == BodyKind::tri ? "tri body " : "tet body ") +
                                             std::to_string(body) + " does not exist (the scene has " +
                                             std::to_string(editor.bodies(kind)) + ")");
}

}  // namespace

Result<TopologyEvent> Simulation::Impl::apply_removal(BodyKind kind, std::size_t body,
                                                                 std::span<const std::uint32_t> elements, bool burn,
                                                                 std::chrono::steady_clock::time_point start) {
  return edit({kind, body, burn, {elements.begin(), elements.end()}}, start);
}

Result<TopologyEvent> Simulation::Impl::edit(TopologyRecord record, std::chrono::steady_clock::time_point start) {
  auto event = record.kind == BodyKind::line
                   ? topology->remove_segments(*device, buffers, program_shape, record.body, record.elements)
                   : topology->remove(*device, buffers, program_shape, record.kind, record.body, record.elements,
                                      record.burn);
  const bool changed = event.ok() && !record.elements.empty();
  if (changed) topology_log.push_back(std::move(record));
  return finish_change(std::move(event), changed, start);
}

Result<TopologyEvent> Simulation::Impl::finish_change(Result<TopologyEvent> event,
                                                                  bool changed,
                                                                  std::chrono::steady_clock::time_point start) {
  if (!event) return event.error();
  if (changed) {
    ++shape_generation;
    positions_mirror.changed();  // a removal hands mass on: the positions' w
    TopologyChange change{*event};
    for (const auto& stage : stages)  // each feature follows (FrameStage::topology_changed)
      if (Status s = stage->topology_changed(*device, change); !s) return s.error();
    const auto rebuild = std::chrono::steady_clock::now();
    if (replaying) {
      program_ready = false;  // a restore's replay rebuilds once, after its last change
    } else if (Status s = rebuild_program(); !s) {
      return s.error();
    }
    event->rebuild_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - rebuild).count();
  }
  // Between frames the changed scene is the one to roll back to; a tear,
  // inside a frame, waits for the frame's verdict; a restore's replay is
  // followed by the restored state.
  if (changed && !stepping && !replaying && divergence.on_divergence == OnDivergence::roll_back) checkpoint();
  event->wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return event;
}

Status Simulation::Impl::refresh_volume(const TopologyEvent& event) {
  const TetMesh& mesh = topology->mesh(event.body);
  std::vector<std::uint32_t> removed;  // in the statistics' tet list: no longer counted as inverted
  for (std::uint32_t t : event.tets_removed) removed.push_back(stats_tet_first[event.body] + t);
  if (Status s = clear_stats_tets(*device, stats_plan, removed); !s) return s;
  for (std::uint32_t t : event.tets_removed) {  // as create sums the rest volume
    const auto at = [&](int k) {
      const Vec3d& p = mesh.vertices[mesh.tets[t][k]];
      return kernels::double4{p[0], p[1], p[2], 0.0};
    };
    rest_volume -= kernels::tet_volume(at(0), at(1), at(2), at(3));
  }
  std::vector<std::array<std::uint32_t, 4>> faces;
  for (std::size_t b = 0; b < topology->bodies(); ++b) {
    const auto& boundary = topology->boundary(b);
    const std::uint32_t first = info.tet_body_first_particle[b];
    for (const auto& f : boundary)
      faces.push_back({order.device_of[first + f[0]], order.device_of[first + f[1]], order.device_of[first + f[2]],
                       order.device_of[first + boundary.front()[0]]});
  }
  // Within the plan's room (twice the faces the scene started with, or
  // had when it last grew) only the faces and their count are written.
  bool fitted = false;
  if (Status s = set_stats_faces(*device, stats_plan, faces, fitted); !s || fitted) return s;
  if (Status s = release_stats_plan(*device, stats_plan); !s) return s;
  auto plan = make_stats_plan(*device, program_shape, faces, true, static_cast<std::uint32_t>(contacts.tools.size()),
                              2 * static_cast<std::uint32_t>(faces.size()), stats_plan.tet_list);
  if (!plan) return plan.error();
  stats_plan = std::move(*plan);
  return {};
}

Result<TopologyEvent> Simulation::remove_tets(std::size_t body, std::span<const std::uint32_t> tets) {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = need_topology(impl_->topology, "remove_tets"); !s) return s.error();
  return impl_->apply_removal(BodyKind::tet, body, tets, false, start);
}

Result<TopologyEvent> Simulation::remove_triangles(std::size_t body,
                                                               std::span<const std::uint32_t> triangles) {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = need_topology(impl_->topology, "remove_triangles"); !s) return s.error();
  return impl_->apply_removal(BodyKind::tri, body, triangles, false, start);
}

Result<TopologyEvent> Simulation::remove_segments(std::size_t body,
                                                              std::span<const std::uint32_t> segments) {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = need_topology(impl_->topology, "remove_segments"); !s) return s.error();
  return impl_->edit({BodyKind::line, body, false, {segments.begin(), segments.end()}}, start);
}

Result<TopologyEvent> Simulation::cut_body(std::size_t body, const Blade& from, const Blade& to) {
  return cut_body(BodyKind::tet, body, from, to);
}

Result<TopologyEvent> Simulation::cut_body(BodyKind kind, std::size_t body, const Blade& from,
                                                       const Blade& to) {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = need_topology(impl_->topology, "cut_body"); !s) return s.error();
  if (Status s = check_body(*impl_->topology, kind, body); !s) return s.error();
  for (const auto& [p, name] : {std::pair{&from.a, "from.a"}, {&from.b, "from.b"}, {&to.a, "to.a"}, {&to.b, "to.b"}})
    for (double c : *p)
      if (!std::isfinite(c)) return Error(ErrorCode::bad_parameter, std::string("cut_body: blade ") + name + " is not finite");
  std::vector<float> x;
  if (Status s = read_positions(x); !s) return s.error();
  const TopologyEditor& e = *impl_->topology;
  const auto cut = elements_cut(e.view(kind, body), {x, e.first_particle(kind, body)}, from.a, from.b, to.a, to.b);
  return impl_->apply_removal(kind, body, cut, false, start);
}

Result<TopologyEvent> Simulation::cauterize(std::size_t body, const std::array<double, 3>& centre,
                                                        double radius, double seconds, double dwell_time) {
  return cauterize(BodyKind::tet, body, centre, radius, seconds, dwell_time);
}

Result<TopologyEvent> Simulation::cauterize(BodyKind kind, std::size_t body,
                                                        const std::array<double, 3>& centre, double radius,
                                                        double seconds, double dwell_time) {
  const auto start = std::chrono::steady_clock::now();
  if (Status s = need_topology(impl_->topology, "cauterize"); !s) return s.error();
  if (Status s = check_body(*impl_->topology, kind, body); !s) return s.error();
  for (double c : centre)
    if (!std::isfinite(c)) return Error(ErrorCode::bad_parameter, "cauterize: centre is not finite");
  if (!(radius > 0.0) || !std::isfinite(radius))
    return Error(ErrorCode::bad_parameter, "cauterize: radius must be > 0 [m] (got " + std::to_string(radius) + ")");
  if (!(seconds > 0.0) || !std::isfinite(seconds))
    return Error(ErrorCode::bad_parameter, "cauterize: seconds must be > 0 (got " + std::to_string(seconds) + ")");
  if (!(dwell_time > 0.0) || !std::isfinite(dwell_time))
    return Error(ErrorCode::bad_parameter, "cauterize: dwell_time must be > 0 [s] (got " + std::to_string(dwell_time) + ")");
  std::vector<float> x;
  if (Status s = read_positions(x); !s) return s.error();
  TopologyEditor& e = *impl_->topology;
  const auto burned = elements_burned(e.view(kind, body), {x, e.first_particle(kind, body)}, centre, radius, seconds,
                                      dwell_time, e.heat(kind, body));
  return impl_->apply_removal(kind, body, burned, true, start);
}

Status Simulation::Impl::tear() {
  tears.clear();
  if (!topology || !topology->tears()) return {};
  auto start = std::chrono::steady_clock::now();  // each event's time: its query and change (the first's: the read-back too)
  std::vector<float> x;
  if (Status s = positions_in_user_order(x); !s) return s;
  for (BodyKind kind : {BodyKind::tet, BodyKind::tri})
    for (std::size_t b = 0; b < topology->bodies(kind); ++b) {
      const double strain = topology->tear_strain(kind, b);
      if (!(strain > 0.0)) continue;
      const auto torn = elements_torn(topology->view(kind, b), topology->edges(kind, b),
                                      {x, topology->first_particle(kind, b)}, strain);
      if (torn.empty()) continue;
      auto event = apply_removal(kind, b, torn, false, start);
      if (!event) return event.error();
      tears.push_back(std::move(*event));
      start = std::chrono::steady_clock::now();
    }
  for (std::size_t b = 0; b < topology->line_bodies(); ++b) {
    const double strain = topology->line(b).tear_strain;
    if (!(strain > 0.0)) continue;
    const auto torn = segments_torn(topology->line(b), topology->whole(b), {x, topology->line_first_particle(b)}, strain);
    if (torn.empty()) continue;
    auto event = edit({BodyKind::line, b, false, torn}, start);
    if (!event) return event.error();
    tears.push_back(std::move(*event));
    start = std::chrono::steady_clock::now();
  }
  return {};
}

const std::vector<TopologyEvent>& Simulation::last_tears() const { return impl_->tears; }

Result<std::vector<std::array<std::uint32_t, 4>>> Simulation::current_tets(std::size_t body) const {
  if (Status s = need_topology(impl_->topology, "current_tets"); !s) return s.error();
  if (Status s = check_body(*impl_->topology, BodyKind::tet, body); !s) return s.error();
  return impl_->topology->live_tets(body);
}

Result<std::vector<std::array<std::uint32_t, 3>>> Simulation::current_triangles(std::size_t body) const {
  if (Status s = need_topology(impl_->topology, "current_triangles"); !s) return s.error();
  if (Status s = check_body(*impl_->topology, BodyKind::tri, body); !s) return s.error();
  return impl_->topology->live_triangles(body);
}

Result<SimulationInternals::ColorCheck> SimulationInternals::check_colors(const Simulation& sim) {
  const Simulation::Impl& impl = *sim.impl_;
  if (Status s = need_topology(impl.topology, "check_colors"); !s) return s.error();
  Device& device = *impl.device;
  std::vector<kernels::float4> x(impl.program_shape.positions.size());
  if (Status s = device.read_buffer(impl.buffers.position, 0, x.data(), x.size() * 16); !s) return s.error();
  ColorCheck out;
  std::vector<std::uint32_t> owner(x.size(), UINT32_MAX);  // the last colour that moved each particle
  std::uint32_t colour_id = 0;
  for (std::size_t k = 0; k < impl.program_shape.blocks.size(); ++k) {
    const ConstraintBlock& block = impl.program_shape.blocks[k];
    std::vector<std::uint32_t> particles(std::size_t{block.size()} * block.arity);
    if (Status s = device.read_buffer(impl.buffers.blocks[k].particles, 0, particles.data(), particles.size() * 4); !s)
      return s.error();
    for (std::size_t c = 0; c < block.colors(); ++c, ++colour_id) {
      ++out.colors;
      for (std::uint32_t i = block.color_offsets[c]; i < block.color_offsets[c] + block.color_count(c); ++i) {
        ++out.constraints;
        std::vector<std::uint32_t> users;
        for (std::uint32_t a = 0; a < block.arity; ++a) {
          const std::uint32_t d = particles[std::size_t{i} * block.arity + a];
          users.push_back(impl.order.user_of.empty() ? d : impl.order.user_of[d]);
        }
        std::sort(users.begin(), users.end());
        out.in_use.emplace_back(block.kernel, std::move(users));
        // Each particle once per constraint: a body attachment repeats its
        // side's first particle in its unused slots (weight 0), which is no
        // conflict with another constraint.
        std::vector<std::uint32_t> own(particles.begin() + std::size_t{i} * block.arity,
                                       particles.begin() + (std::size_t{i} + 1) * block.arity);
        std::sort(own.begin(), own.end());
        own.erase(std::unique(own.begin(), own.end()), own.end());
        for (const std::uint32_t p : own) {
          if (!(x[p].w > 0.0f)) continue;  // immovable particles may be shared
          if (owner[p] == colour_id) ++out.conflicts;
          owner[p] = colour_id;
        }
      }
    }
  }
  for (const auto& p : x) out.total_mass += p.w > 0.0f ? 1.0 / double(p.w) : 0.0;
  std::sort(out.in_use.begin(), out.in_use.end());
  return out;
}

Result<std::vector<std::uint32_t>> SimulationInternals::constraint_words(const Simulation& sim) {
  const Simulation::Impl& impl = *sim.impl_;
  std::vector<std::uint32_t> out;
  for (std::size_t k = 0; k < impl.program_shape.blocks.size(); ++k) {
    const ConstraintBlock& block = impl.program_shape.blocks[k];
    std::vector<std::uint32_t> particles(std::size_t{block.size()} * block.arity),
        data(std::size_t{block.size()} * block.data_stride);
    if (Status s = impl.device->read_buffer(impl.buffers.blocks[k].particles, 0, particles.data(), particles.size() * 4); !s)
      return s.error();
    if (Status s = impl.device->read_buffer(impl.buffers.blocks[k].data, 0, data.data(), data.size() * 4); !s)
      return s.error();
    out.insert(out.end(), block.color_counts.begin(), block.color_counts.end());
    out.insert(out.end(), particles.begin(), particles.end());
    out.insert(out.end(), data.begin(), data.end());
  }
  return out;
}

}  // namespace sinew
