// topology_editor.h — removes tets from a running scene (SceneDesc::
// topology_changes): cuts, tears and cautery all end here.
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
// the compile made), finds a tet's constraints by their particles (sorted
// device slots) and an edge's distance constraint likewise, and after a
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
#include "sinew/simulation.h"

namespace sinew {

class TopologyEditor {
 public:
  /// [in] scene, compiled: the scene and what compile_scene made of it.
  static Result<std::unique_ptr<TopologyEditor>> create(const SceneDesc& scene, const CompiledScene& compiled);

  /// Removes tets of tet body `body` (checked: alive, no repeats; on an
  /// error nothing changed). burn: their lumped mass (density V / 4 per
  /// vertex) leaves the scene (cautery); otherwise a vertex left with no
  /// tet hands its mass to the vertices it shared a removed tet with (cuts,
  /// tears: the total is conserved). Patches the device's constraint
  /// buffers and inverse masses, and [in/out] shape's colour counts; the
  /// caller rebuilds the program. Fills the event but its wall_ms.
  Result<Simulation::TopologyEvent> remove(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                           std::size_t body, std::span<const std::uint32_t> tets, bool burn);

  /// Breaks segments of line body `body` (checked: whole, no repeats; on
  /// an error nothing changed): their distance constraints and the bending
  /// constraints across them. Patches the device and shape as remove does;
  /// masses stay (a piece of thread keeps its beads).
  Result<Simulation::TopologyEvent> remove_segments(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                                                    std::size_t body, std::span<const std::uint32_t> segments);
  [[nodiscard]] std::size_t line_bodies() const { return lines_.size(); }
  /// Line body `body`'s rest vertices and segments, which are whole, its
  /// first particle (user order) and tear strain.
  [[nodiscard]] const LineBodyDesc& line(std::size_t body) const { return lines_[body].desc; }
  [[nodiscard]] const std::vector<std::uint8_t>& whole(std::size_t body) const { return lines_[body].whole; }
  [[nodiscard]] std::uint32_t line_first_particle(std::size_t body) const { return lines_[body].first; }

  [[nodiscard]] std::size_t bodies() const { return bodies_.size(); }
  /// Tet body `body`'s rest mesh and which of its tets are alive.
  [[nodiscard]] const TetMesh& mesh(std::size_t body) const { return bodies_[body].mesh; }
  [[nodiscard]] const std::vector<std::uint8_t>& alive(std::size_t body) const { return bodies_[body].alive; }
  /// The user-order particle of the body's vertex 0.
  [[nodiscard]] std::uint32_t first_particle(std::size_t body) const { return bodies_[body].first; }
  [[nodiscard]] double tear_strain(std::size_t body) const { return bodies_[body].tear_strain; }
  /// Whether any tet or line body tears (tear_strain > 0).
  [[nodiscard]] bool tears() const;
  /// Seconds each tet has been touched by a cautery tip (cauterize).
  [[nodiscard]] std::vector<double>& heat(std::size_t body) { return bodies_[body].heat; }


 private:
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
  using TetKey = std::array<std::uint32_t, 4>;  // sorted device slots
  struct TetKeyHash {
    std::size_t operator()(const TetKey& k) const noexcept;
  };
  struct Body {
    TetMesh mesh;
    std::uint32_t first = 0;                 // user particle of vertex 0
    std::vector<std::uint32_t> device;       // device slot of each vertex
    std::vector<std::uint8_t> alive;         // per tet
    std::vector<float> rest_volume;          // per tet, as the compile computed it
    std::vector<std::uint32_t> live_tets;    // per vertex: alive tets using it
    std::vector<std::uint32_t> tet_offsets;  // per vertex: its tets (CSR, rest mesh)
    std::vector<std::uint32_t> tet_list;
    std::vector<double> heat;                // cautery (per tet) [s]
    double density = 0.0, distance_compliance = 0.0, tear_strain = 0.0;
  };

  struct Line {
    LineBodyDesc desc;                  // its vertices and segments (rest)
    std::uint32_t first = 0;            // user particle of vertex 0
    std::vector<std::uint32_t> device;  // device slot of each vertex
    std::vector<std::uint8_t> whole;    // per segment
  };

  TetKey tet_key(const Body& b, std::uint32_t tet) const;
  // Writes what changed to the device and the new counts into shape.
  Status commit(Device& device, const XpbdBuffers& buffers, CompiledScene& shape,
                std::span<const std::uint32_t> mass_changed);
  static std::uint64_t edge_key(std::uint32_t a, std::uint32_t b);
  // Gives slot `slot` of block `k` to its colour's last constraint.
  void swap_remove(std::uint32_t k, std::uint32_t slot);
  // The share V_e of the live tets' volume an edge (vertices a, b of body) holds [m^3].
  double edge_share(const Body& b, std::uint32_t a, std::uint32_t v) const;
  Status upload(Device& device, const XpbdBuffers& buffers, std::span<const std::uint32_t> mass_changed);

  std::vector<Block> blocks_;
  std::vector<Body> bodies_;
  std::unordered_map<TetKey, std::vector<Slot>, TetKeyHash> tet_slots_;  // volume and FEM constraints
  std::unordered_map<std::uint64_t, Slot> edge_slots_;                   // distance constraints
  std::unordered_map<std::uint32_t, Slot> bend_slots_;                   // line bending, by its middle particle
  std::vector<Line> lines_;
  std::vector<double> mass_;                                             // per device slot [kg] (0: immovable)
  bool warm_start_ = false;                                              // SolverSettings::warm_start
};

}  // namespace sinew
