// topology_editor.h — removes tets, triangles and thread segments from a
// running scene (SceneDesc::topology_changes): cuts, tears and cautery all
// end here.
//
// Constraint storage follows Box2D v3's constraint graph (E. Catto,
// box2d/src/constraint_graph.c, 2024): every colour is a range of slots
// with a count in use; a constraint leaves by giving its slot to its
// colour's last one, so no colour ever holds two constraints that share a
// movable particle and nothing is recoloured. Removal never adds a
// conflict, so removals alone need no colouring at all; the slots freed at
// each colour's end are its spare capacity.
//
// The editor keeps a host copy of every block's particles and data (what
// the compile made), finds an element's constraints (a tet's volume and
// FEM ones, a triangle's area one) by their particles (sorted device
// slots), an edge's distance and dihedral constraints by its two, and
// after a
// change uploads only the slots that changed, the masses that changed, and
// the new colour counts into the program's shape; the caller rebuilds the
// frame program from it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

#include "backends/backend.h"
#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "runtime/topology_queries.h"
#include "sinew/simulation.h"

namespace sinew {

class TopologyEditor {
 public:
  /// [in] scene, compiled: the scene and what compile_scene made of it.
  static Result<std::unique_ptr<TopologyEditor>> create(const SceneDesc& scene, const CompiledScene& compiled);

  /// Removes elements of body `body` of `kind` (tet: its tets; tri: its
  /// triangles; checked: alive, no repeats; on an error nothing changed).
  /// Their own constraints go (volume and FEM; area), so do the edges'
  /// distance constraints no live element keeps and, on a tri body, the
  /// dihedral constraints of the hinges they were part of; an edge that
  /// keeps some of its elements is softened by the share it lost (as the
  /// compile would set it). burn: their lumped mass (a tet's density V / 4,
  /// a triangle's density t A / 3, per vertex) leaves the scene (cautery);
  /// otherwise a vertex left with no element hands its mass to the vertices
  /// it shared a removed element with (cuts, tears: the total is
  /// conserved). Patches the device's constraint buffers and inverse
  /// masses, and [in/out] shape's colour counts; the caller rebuilds the
  /// program. Fills the event but its wall_ms.
  Result<TopologyEvent> remove(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                           BodyKind kind, std::size_t body, std::span<const std::uint32_t> elements,
                                           bool burn);

  /// Breaks segments of line body `body` (checked: whole, no repeats; on
  /// an error nothing changed): their distance constraints and the bending
  /// constraints across them. Patches the device and shape as remove does;
  /// masses stay (a piece of thread keeps its beads).
  Result<TopologyEvent> remove_segments(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                                    std::size_t body, std::span<const std::uint32_t> segments);
  [[nodiscard]] std::size_t line_bodies() const { return lines_.size(); }
  /// Line body `body`'s rest vertices and segments, which are whole, its
  /// first particle (user order) and tear strain.
  [[nodiscard]] const LineBodyDesc& line(std::size_t body) const { return lines_[body].desc; }
  [[nodiscard]] const std::vector<std::uint8_t>& whole(std::size_t body) const { return lines_[body].whole; }
  [[nodiscard]] std::uint32_t line_first_particle(std::size_t body) const { return lines_[body].first; }

  /// Tet bodies (tets()) and tri bodies (sheets()): how many.
  [[nodiscard]] std::size_t bodies() const { return tets_.size(); }
  [[nodiscard]] std::size_t sheets() const { return sheets_.size(); }
  [[nodiscard]] std::size_t bodies(BodyKind kind) const { return kind == BodyKind::tri ? sheets() : bodies(); }
  /// Tet body `body`'s rest mesh and which of its tets are alive.
  [[nodiscard]] const TetMesh& mesh(std::size_t body) const { return tet_meshes_[body]; }
  [[nodiscard]] const std::vector<std::uint8_t>& alive(std::size_t body) const { return tets_[body].alive; }
  /// A tet or tri body's elements, for topology_queries.h.
  [[nodiscard]] ElementView view(BodyKind kind, std::size_t body) const;
  /// Tet body `body`'s live tets and tri body `body`'s live triangles (the
  /// mesh's vertex indices, in mesh order).
  [[nodiscard]] std::vector<std::array<std::uint32_t, 4>> live_tets(std::size_t body) const {
    return live_of(tet_meshes_[body].tets, tets_[body].alive);
  }
  [[nodiscard]] std::vector<std::array<std::uint32_t, 3>> live_triangles(std::size_t body) const {
    return live_of(tri_meshes_[body].triangles, sheets_[body].alive);
  }
  /// The user-order particle of the body's vertex 0.
  [[nodiscard]] std::uint32_t first_particle(BodyKind kind, std::size_t body) const { return of(kind, body).first; }
  [[nodiscard]] double tear_strain(BodyKind kind, std::size_t body) const { return of(kind, body).tear_strain; }
  /// A body's edges, once each (empty unless it tears: tear_strain > 0).
  [[nodiscard]] const EdgeList& edges(BodyKind kind, std::size_t body) const { return of(kind, body).edges; }
  /// Whether any tet, tri or line body tears (tear_strain > 0).
  [[nodiscard]] bool tears() const;
  /// Keeps each tet body's boundary surface through removals from now on
  /// (boundary()); what FrameStats::volume_change measures inside.
  void track_boundaries();
  /// Tet body `body`'s live boundary faces, wound outward (body vertex
  /// indices), in no particular order; empty unless track_boundaries().
  [[nodiscard]] const std::vector<std::array<std::uint32_t, 3>>& boundary(std::size_t body) const {
    return tets_[body].boundary;
  }
  /// Seconds each element has been touched by a cautery tip (cauterize).
  [[nodiscard]] std::vector<double>& heat(BodyKind kind, std::size_t body) { return of(kind, body).heat; }

 private:
  template <class Element>
  static std::vector<Element> live_of(const std::vector<Element>& elements, const std::vector<std::uint8_t>& alive) {
    std::vector<Element> out;
    for (std::size_t e = 0; e < elements.size(); ++e)
      if (alive[e]) out.push_back(elements[e]);
    return out;
  }
  struct Block {
    Kernel kernel = Kernel::count_;
    std::uint32_t arity = 0, data_stride = 0, lambda_stride = 0;
    std::vector<std::uint32_t> particles;  // arity per slot
    std::vector<float> data;               // data_stride per slot
    std::vector<std::uint32_t> offsets;    // colour k: slots [offsets[k], offsets[k + 1])
    std::vector<std::uint32_t> counts;     // in use at the colour's start
    std::vector<std::uint32_t> dirty;      // slots to upload (particles, data, lambda 0)
    std::vector<std::uint32_t> freed;      // slots left unused (residual 0)
  };
  struct Slot {
    std::uint32_t block, slot;
  };
  // An element's sorted device slots (a triangle's fourth is kNone).
  using ElementKey = std::array<std::uint32_t, 4>;
  static constexpr std::uint32_t kNone = UINT32_MAX;
  struct ElementKeyHash {
    std::size_t operator()(const ElementKey& k) const noexcept;
  };
  // A tet body (arity 4: tets, volumes, a vertex's share of a tet V/4, an
  // edge's V/6) or a tri body (arity 3: triangles, areas, A/3 and A/3).
  struct Body {
    std::uint32_t arity = 4;
    std::vector<Vec3d> rest;                 // rest vertices [m]
    std::vector<std::uint32_t> corners;      // arity per element
    std::uint32_t first = 0;                 // user particle of vertex 0
    std::vector<std::uint32_t> device;       // device slot of each vertex
    std::vector<std::uint8_t> alive;         // per element
    std::vector<float> rest_measure;         // per element: volume [m^3] or area [m^2], as the compile computed it
    std::vector<std::uint32_t> live;         // per vertex: alive elements using it
    std::vector<std::uint32_t> offsets;      // per vertex: its elements (CSR, rest mesh)
    std::vector<std::uint32_t> list;
    std::vector<double> heat;                // cautery (per element) [s]
    double mass_density = 0.0;               // per unit measure: density (tets), density x thickness (triangles)
    double edge_depth = 1.0;                 // alpha_e = c_d L^2 / (share x edge_depth): 1 (tets), thickness (triangles)
    double distance_compliance = 0.0, tear_strain = 0.0;
    // Calibrated tet bodies (TetBodyDesc::set_elastic): per tet, its six
    // springs [N/m] (kTetEdgePairs order); an edge's alpha is 1 / (the sum
    // over its live tets). Empty: alpha_e = c_d L^2 / (share x edge_depth).
    std::vector<std::array<double, 6>> edge_stiffness;
    EdgeList edges;                          // its edges once each (bodies that tear)
    // Tet bodies with track_boundaries(): the boundary faces, wound
    // outward from their live tet, and each one's index there by its
    // sorted vertices (a face leaves by giving its index to the last).
    std::vector<std::array<std::uint32_t, 3>> boundary;
    std::unordered_map<ElementKey, std::uint32_t, ElementKeyHash> boundary_index;
    [[nodiscard]] const std::uint32_t* of(std::size_t e) const { return &corners[e * arity]; }
  };
  static Body make_body(std::uint32_t arity, const std::vector<Vec3d>& rest, std::span<const std::uint32_t> corners,
                        std::uint32_t first, const CompiledScene& compiled);
  Body& of(BodyKind kind, std::size_t body) { return kind == BodyKind::tri ? sheets_[body] : tets_[body]; }
  const Body& of(BodyKind kind, std::size_t body) const { return kind == BodyKind::tri ? sheets_[body] : tets_[body]; }

  struct Line {
    LineBodyDesc desc;                  // its vertices and segments (rest)
    std::uint32_t first = 0;            // user particle of vertex 0
    std::vector<std::uint32_t> device;  // device slot of each vertex
    std::vector<std::uint8_t> whole;    // per segment
  };

  ElementKey element_key(const Body& b, std::uint32_t e) const;
  static ElementKey sorted_key(const std::uint32_t* particles, std::uint32_t arity);
  // Writes what changed to the device and the new counts into shape.
  Status commit(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                std::span<const std::uint32_t> mass_changed);
  static std::uint64_t edge_key(std::uint32_t a, std::uint32_t b);
  // Enters slot `slot` of block `k` (b) in the index its kernel uses.
  void index(std::uint32_t k, const Block& b, std::uint32_t slot);
  // Gives slot `slot` of block `k` to its colour's last constraint.
  void swap_remove(std::uint32_t k, std::uint32_t slot);
  // The share of the live elements' measure an edge (vertices a, v of body)
  // holds: V_e [m^3] (a sixth of each tet's volume) or A_e [m^2] (a third
  // of each triangle's area), summed in element order as the compile does;
  // for a calibrated tet body, the sum of its live tets' springs k_e [N/m].
  double edge_share(const Body& b, std::uint32_t a, std::uint32_t v) const;
  // After `removed` tets of tet body b died: each of their faces is on the
  // boundary when exactly one live tet has it (extract_boundary_surface's
  // rule), wound outward from that tet.
  void update_boundary(Body& b, std::span<const std::uint32_t> removed);
  // Hands the mass of `v` (left with no element) to its movable neighbours
  // through the removed elements, else to the body's nearest live movable
  // vertex; returns what it could not place. [out] changed: the slots.
  double hand_off(const Body& b, std::uint32_t v, std::span<const std::uint32_t> removed,
                  std::vector<std::uint32_t>& changed, double& moved);
  Status upload(Device& device, const XpbdBuffers& buffers, std::span<const std::uint32_t> mass_changed);

  std::vector<Block> blocks_;
  std::vector<Body> tets_, sheets_;
  std::vector<TetMesh> tet_meshes_;  // the tet bodies' rest meshes (collision, current_tets)
  std::vector<TriMesh> tri_meshes_;  // the tri bodies'
  std::unordered_map<ElementKey, std::vector<Slot>, ElementKeyHash> element_slots_;  // volume, FEM, area constraints
  std::unordered_map<std::uint64_t, Slot> edge_slots_;                   // distance constraints
  std::unordered_map<std::uint64_t, Slot> hinge_slots_;                  // dihedral constraints, by their edge
  std::unordered_map<std::uint32_t, Slot> bend_slots_;                   // line bending, by its middle particle
  std::vector<Line> lines_;
  std::vector<double> mass_;                                             // per device slot [kg] (0: immovable)
  bool warm_start_ = false;
  bool tracking_ = false;  // track_boundaries()                                              // SolverSettings::warm_start
};

}  // namespace sinew
