// sutures.h — needles and the threads they pull through tissue (issue 13,
// part 4; SceneDesc::needles): the host side of the rows that
// kernels/shared/suture_params.h describes and xpbd_sutures solves in every
// sweep.
//
// Every frame, before it: the positions are read back; each needle's tip
// path over the frame (its tip at the frame's start to its tip at the end)
// is tested against the punctureable surfaces (tet bodies' boundaries, tri
// bodies), and the first triangle it meets from outside gets a tip contact
// row (kind 2), which keeps the tissue ahead of the tip. The needles'
// points at the frame's start and end and the rows are uploaded.
// After it: the rows come back. A tip contact whose frame-average push
// passed NeedleDesc::puncture_force, with the tip within
// max_puncture_angle of the inward normal, becomes a puncture (kind 3) at
// the same tissue point; a tip path that left a tet body through its
// surface makes an exit puncture where it crossed. The kernel itself turns
// a puncture the needle's tail has passed into a thread puncture (kind 4).
// Punctures the needle was pulled back out of (their tissue point 0.5 mm
// ahead of the tip) end.
//
// A needle's reaction: each row that joins the tissue or the thread to the
// needle (tie, tip contact, puncture) gave the tissue an impulse (its
// lambda records); the needle takes the opposite, at the row's point on the
// needle at the frame's end, summed into a force and torque about its
// origin. A force-driven needle (NeedleDrive::force) is a rigid body
// integrated before each frame from the force applied to it and the last
// substep's reaction, exactly as a rigid tool is (rigid_tool.h: the
// coupling, its stability bound and its limits), the rows' particles
// standing for the tool's touching particles.
//
// Needle forces (docs/needles.md; Okamura, Simone and O'Leary, IEEE TBME
// 51(10), 2004): a blunt tip (NeedleDesc::tip_radius) adds a row (kind 5)
// for each surface vertex its rounded end meets, made afresh each frame
// with the tip contact and pushing with it; each entering puncture of a tet
// body carries the length of shaft inside that body and, for the body the
// tip is in, the cutting force, for the kernel's Karnopp friction.
//
// Why the detection is on the host: a needle is one polyline and its tip
// path one segment per frame, tested against the surfaces' triangles in a
// linear pass (60,000 triangles: a fraction of a millisecond); the read-back
// of the positions is the cost (16 bytes per particle per frame).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "compiler/scene_compiler.h"
#include "math/vec3.h"
#include "program/xpbd_program.h"
#include "runtime/positions_mirror.h"
#include "runtime/rigid_tool.h"
#include "sinew/simulation.h"

namespace sinew {

namespace state_format {
class Writer;
class Reader;
}  // namespace state_format

class Sutures {
 public:
  /// Most rows a needle may hold (its tie, tip contact and punctures).
  /// (Rows on the thread never end: a running suture of about 15 stitches
  /// fills it; then step() fails naming the needle.)
  static constexpr std::uint32_t kRowsPerNeedle = 64;

  /// [in] scene: its needles (checked), surfaces and threads; compiled: the
  /// particles' device order. Creates the buffers on `device`.
  static Result<std::unique_ptr<Sutures>> create(const SceneDesc& scene, const CompiledScene& compiled, Device& device);

  [[nodiscard]] const SutureBuffers& buffers() const { return buffers_; }

  /// The pose needle `index` reaches at the end of the next frame.
  /// [pre] index < needles(), the pose finite, the rotation a unit
  /// quaternion (Simulation::set_needle_pose checks). Errors: a force-driven
  /// needle; a turn of more than pi/2 from the frame's start.
  Status set_pose(std::size_t index, const math::Vec3& position, const math::Quat& rotation);
  /// Adds a force [N] and torque [N m] (world frame, about its origin) on
  /// force-driven needle `index` for the next frame. [pre] index <
  /// needles(), both finite. Errors: a kinematic needle.
  /// [in] dt: the frame's time step [s] (add_frame_force checks the move it makes).
  Status apply_force(std::size_t index, const math::Vec3& force, const math::Vec3& torque, double dt);

  /// Before a frame: reads the positions, finds the tips' contacts,
  /// uploads the needles and the rows.
  Status before_frame(Device& device, const XpbdBuffers& scene_buffers);
  /// Reads the positions through the frame's shared mirror (null: on its own).
  void set_positions_mirror(PositionsMirror* mirror) { mirror_ = mirror; }
  /// After it: reads the rows back, makes and ends punctures. [in] h: the
  /// substep [s]; frame: the frame's length [s].
  Status after_frame(Device& device, const XpbdBuffers& scene_buffers, double h, double frame);

  [[nodiscard]] NeedleState state(std::size_t index) const;
  /// Per particle (device order), what the sutures exempt from mesh
  /// collision and CCD (suture_exemption.h); updated after every frame.
  [[nodiscard]] const std::vector<std::uint8_t>* exemption() const { return &exempt_; }
  [[nodiscard]] std::size_t needles() const { return needles_.size(); }

  // What a needle keeps between frames (all of it saved in a state: sutures_state.cpp).
  struct Row {
    std::array<std::uint32_t, 8> words{};  // rows binding: (kind, needle, a, b), (c, first slot, vertices, segment)
    std::array<float, 4> weights{};        // (wa, wb, wc, s)
    std::uint32_t surface = kNone, triangle = 0;
    bool exit = false;
    float slip = 0.0f;  // a puncture's slide speed along the shaft at the last frame's end [m/s] (Karnopp's band)
  };
  struct Needle {
    NeedleDesc desc;
    math::Vec3 position_start{}, position_end{};
    math::Quat rotation_start{1, 0, 0, 0}, rotation_end{1, 0, 0, 0};
    std::uint32_t thread_first = 0, thread_vertices = 0;  // into the slots binding (0 vertices: no thread)
    std::vector<Row> rows;                                // tie first, then the tip contact and punctures
    // A force-driven needle's rigid body (its position and rotation are
    // position_start and rotation_start between frames); a kinematic one
    // keeps only the last frame's motion here.
    ToolBody body;
    math::Vec3 reaction_force{}, reaction_torque{};  // the last frame's average [N], [N m]
    double tip_force = 0.0;
    std::uint32_t refused_degenerate = 0, refused_inverted = 0, refused_angle = 0;
  };
  static constexpr std::uint32_t kNone = UINT32_MAX;
  /// Appends each needle's state, its rows with it, to a saved state's payload.
  void save(state_format::Writer& w) const;
  /// [out] out: each needle's state read back from a payload (save's
  /// order), checked against this scene: the rows' kinds, needles,
  /// particles, thread slots, surfaces and triangles. Errors name `what`
  /// and the bad field (bad_parameter; bad_input_file when truncated).
  Status read(state_format::Reader& r, const std::string& what, std::vector<Needle>& out) const;
  void restore_needles(std::vector<Needle> needles);

 private:
  // A surface a tip can puncture: its triangles (device slots), the
  // opposite vertex of each one's tet (tet bodies; kNone for tri bodies,
  // which are two-sided).
  struct Surface {
    BodyKind kind = BodyKind::tet;
    std::uint32_t body = 0;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<std::uint32_t> opposite;
  };
  // The needle's points in the world at its start (end = false) or end pose.
  std::vector<math::Vec3> curve_at(const Needle& n, bool end) const;
  math::Vec3 position_of(std::uint32_t slot) const;
  math::Vec3 point_of(const Row& row) const;
  // Sums each row's impulse on the needle (the opposite of the tissue's)
  // into n's reaction and, for a force-driven needle, its coupling and
  // touching mass (rigid_tool.h). [in] end: the needle at the frame's end;
  // lambda: the rows' records as read back.
  void add_reactions(Needle& n, const std::vector<math::Vec3>& end, const float* lambda, double h, double frame);
  // Where the segment a -> b first crosses a surface triangle in direction
  // `entering` (true: from outside, false: from inside a tet body the needle
  // has entered and not left; tri bodies either
  // way), skipping triangles the needle holds already. [out] row: its
  // triangle and weights. Counts the triangles refused on `needle`.
  bool first_crossing(const math::Vec3& a, const math::Vec3& b, bool entering, Needle& needle, Row& row);
  Status upload(Device& device);
  // A blunt tip (NeedleDesc::tip_radius): adds a row (kind 5) for each
  // surface vertex of surface `surface` its flat end meets this frame.
  // [in] tip_start, tip_end: the tip at the frame's start and end; axis: its
  // unit direction. Errors: more rows than a needle holds.
  Status add_blunt_rows(Needle& n, std::size_t index, std::uint32_t surface, const math::Vec3& tip_start,
                        const math::Vec3& tip_end, const math::Vec3& axis);
  // Sets each puncture's inserted shaft length (weights[3], [m]) and cutting
  // flag (words[7]) for the shaft's friction. [in] curve: the needle at the
  // frame's start.
  void set_shaft_lengths(Needle& n, const std::vector<math::Vec3>& curve);

  std::vector<Surface> surfaces_;
  std::vector<Needle> needles_;
  std::vector<std::uint32_t> slots_;  // the threads' vertices' device slots
  std::vector<float> positions_;      // device order, xyzw, the last read
  PositionsMirror* mirror_ = nullptr;
  Status read_positions(Device& device, const XpbdBuffers& scene_buffers);
  std::vector<std::uint8_t> exempt_;  // per particle: kSutureThread, kSutureHole (suture_exemption.h)
  void mark_exemption();
  SutureBuffers buffers_;
  std::uint32_t rows_capacity_ = 0, curve_points_ = 0;
  double frame_ = 0.0;      // the frame's length [s]
  double stiffness_ = 0.0;  // iterations times substeps squared (integrate_tool)
};

}  // namespace sinew
