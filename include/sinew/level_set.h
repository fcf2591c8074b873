// level_set.h — signed distance fields on a sparse grid (docs/level_sets.md): bone and
// tools as narrow-band level sets built from closed triangle surfaces or
// analytic shapes, sampled (value and gradient, trilinear) on the host and
// inside every backend's kernels.
//
// Built on OpenVDB (the host grid; Museth, "VDB: High-resolution sparse
// volumes with dynamic topology", TOG 32(3), 2013) and NanoVDB (the
// read-only copy the kernels sample; Museth, "NanoVDB: A GPU-friendly and
// portable VDB data structure for real-time rendering and simulation",
// SIGGRAPH 2021 Talks); neither appears in this header. Built without
// OpenVDB (the CMake option SINEW_OPENVDB off, or the packages missing),
// every call returns ErrorCode::backend_unavailable naming the option.
//
// Conventions. Units: metres. The distance is negative inside the surface
// and positive outside (a closed surface's inside is the side its outward
// normals, counter-clockwise triangles seen from outside, point away from).
// A narrow band: the values are exact distances (up to the grid's
// discretisation) within `exterior_band` outside and `interior_band`
// inside the surface; beyond, value() returns +exterior_band outside and
// -interior_band inside (the background) and the gradient is zero there.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sinew/mesh.h"
#include "sinew/result.h"

namespace sinew {

/// What a level set is built with.
struct LevelSetSettings {
  double voxel_size = 5e-4;     ///< edge of a cubic voxel [m], >= 1.5e-5 (OpenVDB's smallest) and within float32
  double exterior_band = 1.5e-3;  ///< exact distances this far outside the surface [m], >= voxel_size
  /// ... and this far inside [m], >= voxel_size; +infinity fills the whole
  /// inside (every voxel inside is stored: a solid that will be cut).
  double interior_band = 1.5e-3;
};

/// A cutting tool (LevelSet::cut), in its own frame: a burr (sphere of
/// `radius` about the origin), a drill (capsule: the segment +-half_height
/// along y swollen by `radius`) or a saw (box of `half_extents`).
struct CutterShape {
  /// burr, drill, saw
  enum class Kind { sphere, capsule, box };
  Kind kind = Kind::sphere;                  ///< which shape
  double radius = 1.5e-3;                               ///< sphere, capsule [m], > 0
  double half_height = 0.0;                             ///< capsule [m], >= 0
  std::array<double, 3> half_extents{1e-3, 1e-3, 1e-3};  ///< box [m], > 0
};

/// A rigid pose: the frame's origin [m] and its rotation, a unit quaternion
/// (w, x, y, z), in the level set's frame.
struct Pose {
  std::array<double, 3> position{0.0, 0.0, 0.0};       ///< the origin [m]
  std::array<double, 4> rotation{1.0, 0.0, 0.0, 0.0};  ///< unit quaternion (w, x, y, z)
};

/// What one cut changed.
struct CutReport {
  double removed_volume = 0.0;      ///< [m^3], measured on the grid (see LevelSet::cut)
  std::uint64_t changed_voxels = 0;  ///< voxels whose value changed
  std::uint32_t changed_leaves = 0;  ///< 8^3-voxel blocks of the grid
  /// Byte ranges (offset, size) of the NanoVDB grid that changed: what a
  /// device's copy needs (update_level_set, src/level_set/device_level_set.h).
  std::vector<std::array<std::uint64_t, 2>> changed_bytes;
};

/// A signed distance field on a sparse grid, in its own frame (the frame of
/// the surface or shape it was built from). Copies share the grid (cheap).
///
/// Bounds every factory and cut checks first, so that no input
/// overflows or runs without end: every length and coordinate within
/// float32's range (the device samples in float; e.g. a cube of 1e39 m is
/// bad_parameter); every voxel index, the shape's box grown by the
/// exterior band over voxel_size, within +-2^30 (bad_parameter: move the
/// shape nearer the origin or use a larger voxel); at most 2^30 voxels
/// visited by one call (capacity_exceeded): a sphere's or box's whole
/// grown box, a surface's bands (about its area / h^2 voxels per layer) or
/// its whole box when the inside is filled, a cut's swept box; a cut
/// places a capsule or box at most 2^20 times and makes at most 2^30
/// distance evaluations, its swept box's voxels x those poses
/// (capacity_exceeded).
/// Whatever OpenVDB still throws becomes an error (bad_parameter, or
/// out_of_memory for an allocation): no call throws.
class LevelSet {
 public:
  /// From a closed triangle surface [m]. Errors (bad_parameter): settings
  /// out of range, a surface that is not closed (check_closed_surface; the
  /// message gives the counts), an empty surface, a non-finite vertex;
  /// capacity_exceeded from check_closed_surface's pair bound; and the
  /// bounds above.
  static Result<LevelSet> from_mesh(const TriMesh& surface, const LevelSetSettings& settings);
  /// A sphere of `radius` [m] > 0 about `centre` [m].
  static Result<LevelSet> sphere(const std::array<double, 3>& centre, double radius, const LevelSetSettings& settings);
  /// An axis-aligned box [lo, hi] [m], hi > lo on every axis.
  static Result<LevelSet> box(const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                              const LevelSetSettings& settings);

  [[nodiscard]] double voxel_size() const;     ///< the voxels' edge [m]
  [[nodiscard]] double exterior_band() const;  ///< how far outside distances are exact [m]
  [[nodiscard]] double interior_band() const;  ///< how far inside distances are exact [m] (infinity: the whole inside)
  /// The box of the stored voxels [m] (lo then hi).
  [[nodiscard]] std::array<double, 6> bounds() const;
  /// Stored voxels (active and inactive, in allocated leaves).
  [[nodiscard]] std::uint64_t voxels() const;

  /// The signed distance at p [m], trilinear between voxel centres
  /// (OpenVDB's BoxSampler; the background beyond the band).
  [[nodiscard]] double value(const std::array<double, 3>& p) const;
  /// Its gradient at p: the trilinear interpolation of the 8 surrounding
  /// voxels' central differences (second-order accurate: off unit length by
  /// about 0.5 (h / r)^2 at r voxels from the medial axis, so within 1e-3
  /// from about 23 voxels on, where all 32 voxels it reads are in the band;
  /// zero in the background).
  [[nodiscard]] std::array<double, 3> gradient(const std::array<double, 3>& p) const;

  /// The NanoVDB copy the kernels sample (a float grid, 32-byte aligned):
  /// its bytes, as uploaded to a device.
  [[nodiscard]] std::span<const std::byte> nanovdb_bytes() const;

  /// Removes the material `shape` sweeps moving from pose `from` to `to`
  /// (a CSG difference: every stored voxel becomes max(its value, minus
  /// the swept tool's distance), at most exterior_band). The sweep is the
  /// exact capsule for a sphere; a capsule or box is placed at poses along
  /// the motion (positions lerped, rotations nlerped) no more than half a
  /// voxel apart at its farthest point, so the union lies within h / 8 of
  /// the true sweep. Voxels within exterior_band of the tool's reach are
  /// updated (the solid's distances near the new face: a voxel deeper keeps
  /// its old, larger depth, so the field is exact within the bands of every
  /// surface, as a narrow band is). The host grid and its NanoVDB copy change in place
  /// (for every copy of this LevelSet), neither's layout: only values.
  /// removed_volume sums, over the changed voxels, h^3 times the drop of
  /// clamp(1/2 - value / h, 0, 1) (the voxel's inside fraction, a linear
  /// ramp across the surface). Errors (bad_parameter, nothing changed): a
  /// level set whose inside is not all stored (interior_band must be
  /// +infinity: a cut makes surface anywhere inside), a bad shape, a
  /// non-finite pose or a rotation that is not a unit quaternion.
  /// The NanoVDB leaves' statistics (their minimum, maximum, average) are
  /// not updated: the kernels never read them. Not safe against sampling
  /// the same grid on another thread at the same time.
  Result<CutReport> cut(const CutterShape& shape, const Pose& from, const Pose& to);

  /// The zero level as triangles [m], counter-clockwise seen from outside
  /// (OpenVDB's volume to mesh; quads split in two). For display: its cost
  /// grows with the surface (measure it before calling it per frame).
  [[nodiscard]] TriMesh surface() const;
  /// The part of the solid inside `box` [m] (lo then hi, in the level
  /// set's frame), as a closed surface: the zero level within the box and
  /// caps where the box's faces cut the solid (on the grid's voxels: within
  /// a voxel outside the box's face). For displaying the region a
  /// tool works on at a lower rate (the whole of a bone at 0.25 mm is
  /// about a million triangles). Errors (bad_parameter): a box not finite
  /// or with hi <= lo on an axis.
  [[nodiscard]] Result<TriMesh> surface_in(const std::array<double, 6>& box) const;

  struct Impl;  ///< opaque outside sinew (src/level_set/level_set_impl.h)
  explicit LevelSet(std::shared_ptr<Impl> impl);
  /// The library's own view of the grid (opaque outside sinew).
  [[nodiscard]] const Impl& internals() const { return *impl_; }

 private:
  std::shared_ptr<Impl> impl_;
};

/// Points spread over a surface, each with the area it stands for: a
/// triangle mesh's vertices, each given a third of its triangles' areas.
struct SurfacePoints {
  std::vector<std::array<double, 3>> points;  ///< [m]
  std::vector<double> areas;                  ///< [m^2]
};
/// [in] mesh, e.g. LevelSet::surface() of a tool. Unused vertices get no area.
SurfacePoints surface_points(const TriMesh& mesh);

/// What a solid level set does to a tool's surface points pressed into it,
/// as a penalty (the voxmap-pointshell idea of McNeely, Neff and Troy,
/// "Six degree-of-freedom haptic rendering using voxel sampling", SIGGRAPH
/// 1999): a point at depth d = -value > 0 is pushed along the solid's
/// normalised gradient with stiffness * d * its area, a pressure growing
/// with depth. A sphere of radius R pressed delta deep into a flat face
/// feels stiffness * pi * R * delta^2. Points where the gradient is zero
/// (beyond the solid's interior band) push nothing: keep the band deeper
/// than the tool goes.
struct PenaltyContact {
  std::array<double, 3> force{};   ///< on the tool [N], in the solid's frame
  std::array<double, 3> torque{};  ///< on the tool about its origin [N m], in the solid's frame
  double deepest = 0.0;            ///< the deepest point's depth [m]
  std::uint32_t touching = 0;      ///< points inside the solid
};
/// [in] tool: its surface points in its own frame; tool_pose: that frame in
/// the solid's; stiffness: pressure per depth [N/m^3], > 0. Errors
/// (bad_parameter): a stiffness not finite and > 0, a non-finite pose or a
/// rotation that is not a unit quaternion, points and areas of different
/// counts.
Result<PenaltyContact> penalty_contact(const LevelSet& solid, const SurfacePoints& tool, const Pose& tool_pose,
                                       double stiffness);

}  // namespace sinew
