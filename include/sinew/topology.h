// sinew/topology.h — a running scene's topology changes
// (SceneDesc::topology_changes; runtime/topology_editor.h), reached
// through Simulation::topology(): removing elements, cuts, cautery, tears,
// and the live elements for a renderer.
//
// Elements (a tet body's tets, a tri body's triangles) are removed, never
// split: what is left is whole original elements, so no sliver is ever
// made (the smallest element keeps its rest volume or area). A removed
// element's own constraints go (volume and FEM; area), and so do the
// distance constraints of edges no remaining element has and, on a tri
// body, the dihedral (bending) constraints of the hinges it was part of;
// an edge that keeps some of its elements is made softer by the share it
// lost (alpha_e = c_d L^2 / V_e, TetBodyDesc; c_d L^2 / (A_e t),
// TriBodyDesc). Each removed constraint's colour gives its last
// constraint the slot, so every colour stays valid and only the changed
// slots are uploaded; the frame program is rebuilt with the new counts.
// A vertex left with no element is fixed (inverse mass 0) and its mass
// handed to the movable vertices it shared a removed element with, or
// else to the nearest live movable vertex of its body; cuts and tears
// conserve the total mass unless nothing movable is left to take it
// (then it is mass_removed). Cautery burns its elements' mass away.
// Events are returned, for a renderer to update its meshes
// (current_tets, current_triangles). Elements are never renumbered or
// reused: naming one that was removed is an error ("was removed
// already"). Errors in the arguments change nothing. A device error
// during a change is returned by name and the Simulation steps on (its
// program is rebuilt at the next step), but the change may be partly
// applied on the device.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "sinew/ids.h"
#include "sinew/result.h"
#include "sinew/scene.h"

namespace sinew {

class Simulation;

/// What one change did to body `body` (a tet body, a tri body, or a line
/// body whose segments broke: body_kind).
struct TopologyEvent {
  BodyKind body_kind = BodyKind::tet;  ///< the kind of body changed
  std::size_t body = 0;                ///< its index among the scene's bodies of that kind
  std::vector<std::uint32_t> tets_removed;      ///< a tet body's: indices into its mesh.tets
  std::vector<std::uint32_t> triangles_removed; ///< a tri body's: indices into its mesh.triangles
  std::vector<std::uint32_t> segments_removed;  ///< a line body's: indices into its segments
  std::vector<std::uint32_t> vertices_removed;  ///< movable vertices left with no element (now fixed and massless)
  std::uint32_t constraints_removed = 0;  ///< volume, FEM, area, distance and bending constraints taken out
  std::uint32_t edges_softened = 0;       ///< distance constraints whose compliance grew
  double mass_moved = 0.0;    ///< [kg] handed from removed vertices to their neighbours
  double mass_removed = 0.0;  ///< [kg] that left the scene (burned, or no neighbour left)
  double wall_ms = 0.0;       ///< host and device time of the change, the program rebuilt included
  double rebuild_ms = 0.0;    ///< of which rebuilding the frame program
};

/// A blade: the segment from `a` to `b` [m].
struct Blade {
  std::array<double, 3> a{};  ///< one end [m]
  std::array<double, 3> b{};  ///< the other end [m]
};

/// A handle on a Simulation's topology changes; a view of the Simulation,
/// valid while it is neither destroyed nor moved. Every call on a scene
/// made without SceneDesc::topology_changes is an error naming it, as is
/// a null id or one of another Simulation.
class Topology {
 public:
  /// The id of tet body `index` (SceneDesc::tet_bodies), tri body, line
  /// body. Errors: an index past the scene's bodies of that kind.
  ///@{
  [[nodiscard]] Result<TetBodyId> tet_body(std::size_t index) const;
  [[nodiscard]] Result<TriBodyId> tri_body(std::size_t index) const;
  [[nodiscard]] Result<LineBodyId> line_body(std::size_t index) const;
  ///@}

  /// Removes tets of `body` (indices into its mesh.tets, each alive, no
  /// repeats). Errors: a tet that does not exist or was removed (named); on
  /// an error nothing changed.
  Result<TopologyEvent> remove_tets(TetBodyId body, std::span<const std::uint32_t> tets);
  /// Removes triangles of `body` (indices into its mesh.triangles). Errors as remove_tets'.
  Result<TopologyEvent> remove_triangles(TriBodyId body, std::span<const std::uint32_t> triangles);
  /// Breaks segments of thread `body` (indices into its segments, each
  /// whole, no repeats): their distance constraints go, with the bending
  /// constraints across them (a thread cut with scissors).
  Result<TopologyEvent> remove_segments(LineBodyId body, std::span<const std::uint32_t> segments);
  /// Cuts `body` with a blade swept from `from` to `to` (the quad they
  /// span, two triangles): every live tet the swept quad touches at the
  /// body's current positions is removed (mass as above). The query sees
  /// the tissue where it is now: tissue moving across the blade's path
  /// between strokes can slip past uncut, so strokes along a line should
  /// overlap (examples/cholecystectomy.cpp).
  Result<TopologyEvent> cut(TetBodyId body, const Blade& from, const Blade& to);
  /// A sheet: every live triangle the swept quad touches; a sheet cut in
  /// its own plane loses the triangles the quad overlaps.
  Result<TopologyEvent> cut(TriBodyId body, const Blade& from, const Blade& to);
  /// A heated tip (a ball of `radius` [m] at `centre` [m]) touching `body`
  /// for `seconds` [s] (> 0): a live element whose current centroid lies
  /// in the ball accumulates that time, and is burned (removed with its
  /// mass) once it has been touched for dwell_time [s] (> 0) in all. The
  /// rate: the ball's volume inside a tet body (its disc's area across a
  /// sheet) goes every dwell_time.
  ///@{
  Result<TopologyEvent> cauterize(TetBodyId body, const std::array<double, 3>& centre, double radius,
                                  double seconds, double dwell_time);
  Result<TopologyEvent> cauterize(TriBodyId body, const std::array<double, 3>& centre, double radius,
                                  double seconds, double dwell_time);
  ///@}
  /// What tore in the last step() (the bodies' tear_strain), one event per
  /// body that tore (none on a scene without topology changes).
  [[nodiscard]] const std::vector<TopologyEvent>& last_tears() const;
  /// The live tets of `body` (as tets of its mesh's vertices), for extract_boundary_surface.
  [[nodiscard]] Result<std::vector<std::array<std::uint32_t, 4>>> current_tets(TetBodyId body) const;
  /// The live triangles of `body`: its current surface, for a renderer.
  [[nodiscard]] Result<std::vector<std::array<std::uint32_t, 3>>> current_triangles(TriBodyId body) const;

  /// A view of `sim` (Simulation::topology() makes one).
  explicit Topology(Simulation* sim) : sim_(sim) {}

 private:
  Simulation* sim_;
};

}  // namespace sinew
