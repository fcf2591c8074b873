// narrow_phase.h — contacts between triangles of deformable surfaces
// (issue 12, part 2: deformable against deformable, and self-collision):
// for each candidate pair of the broad phase, every vertex of one triangle
// against the other triangle and every edge against every edge, kept when
// closer than the thickness. Closest points: kernels/math/proximity_math.h
// (Ericson 2005, 5.1.5 and 5.1.9).
//
// Broad phase to narrow phase: boxes inflated by thickness / 2 on every
// side overlap whenever two primitives are closer than the thickness (the
// gap along any axis is at most the distance), so no contact is lost
// between the two phases (tests/narrow_phase_test.cpp checks it against
// all pairs of a real surface).
//
// Normals are two-sided, from the closest points (the second primitive
// towards the first): right for thin tissue and for surfaces that have not
// yet passed through each other; a vertex already deep inside another body
// is pushed the way it is nearest to, which CCD (issue 13) prevents.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "collision/bvh.h"

namespace sinew::collision {

struct Contact {
  enum class Kind : std::uint8_t { vertex_triangle, edge_edge, capsule_triangle, shape_face };
  Kind kind = Kind::vertex_triangle;
  /// vertex_triangle: the vertex, then the triangle's three; edge_edge: the
  /// first edge's two vertices, then the second's; capsule_triangle: the
  /// capsule's index (0 for a single one), then the triangle's three;
  /// shape_face (a triangle or segment against a collider's shape, whose
  /// surface point is no particle): a triangle's first vertex twice, then
  /// the other two; a segment's vertices twice each.
  std::array<std::uint32_t, 4> v{};
  /// The weights that place the two closest points on the primitives:
  /// vertex_triangle (1, wa, wb, wc); edge_edge (1 - s, s, 1 - t, t);
  /// capsule_triangle (s along the capsule's axis, wa, wb, wc); shape_face
  /// (0, wa, wb, wc) or (0, 1 - s, 0, s).
  std::array<float, 4> w{};
  /// Unit, from the second primitive towards the first; capsule_triangle:
  /// from the capsule's axis towards the triangle (the way the tissue is
  /// pushed).
  std::array<float, 3> normal{};
  /// Between the closest points [m], < thickness; capsule_triangle: the gap
  /// between the capsule's surface and the triangle, negative when the
  /// triangle reaches inside the capsule.
  float distance = 0.0f;
  /// shape_face: thickness - n . (the shape's surface point) [m], the
  /// constant of its constraint (mesh_contact_params.h); 0 otherwise.
  float offset = 0.0f;
  /// shape_face of a moving shape: the offset at the frame's start minus
  /// `offset` (at its end) [m] (mesh_contact_params.h: the plane's motion).
  float motion = 0.0f;
  /// shape_face: which shape, in the caller's numbering (the solver: the
  /// rigid tool whose reaction it is, or kNoShape for a collider).
  std::uint32_t shape = kNoShape;
  static constexpr std::uint32_t kNoShape = 0xffffffffu;
};

/// cos 25.8 degrees: how far a contact's normal may turn from the direction
/// its primitives face for facing() to hold.
inline constexpr float kFacingCos = 0.9f;

/// Whether a vertex-triangle or edge-edge contact's normal is the direction
/// its primitives face each other across, at `positions` (xyzw per vertex):
/// within kFacingCos of the triangle's normal (vertex-triangle) or of the
/// two edges' common perpendicular (edge-edge), either sign. The others are
/// a vertex beside a triangle or two edges that meet end-on, whose normal
/// from the closest points is the way round the corner. False for parallel
/// edges and zero-area triangles (no direction to face).
bool facing(const Contact& contact, std::span<const float> positions);

/// Sorts contacts by kind, then particles, and keeps the first of each
/// (kind, particles): one contact per (vertex, triangle) and per pair of
/// edges, in a fixed order (what every function below returns).
void sort_unique_contacts(std::vector<Contact>& contacts);

/// The distance between triangles a and b (three vertex indices each into
/// `positions`, xyzw per vertex, finite) [m]: every edge of each against
/// the other (proximity::closest_segment_triangle), so 0 where they cross.
float triangle_distance(std::span<const float> positions, const std::uint32_t* a, const std::uint32_t* b);

/// A quick, conservative reject of the narrow phase: true only when
/// triangles a and b (as in triangle_distance) are farther apart than
/// `gap` [m], shown by a separating axis among their normals and their
/// edges' in-plane normals (false says nothing: the pair may still be far).
/// Widened against float rounding, so a pair within `gap` never gets true.
/// (The liver's surface, self pairs skipping the rest-close ones: 89% of
/// them rejected, the narrow phase 3x faster on one thread.)
bool triangles_apart(std::span<const float> positions, const std::uint32_t* a, const std::uint32_t* b, float gap);

/// Which triangle owns each vertex and edge of a triangle list: the first
/// (lowest index) that has it. triangle_contacts tests a vertex against a
/// triangle B only from the candidate pair (owner, B), and an edge against
/// an edge only from the pair of their owners, so each test runs once
/// instead of once per pair of triangles around them (about 6 times for a
/// vertex, 4 for an edge pair on a closed surface). Nothing is lost: a
/// vertex (edge) within the contact distance d of B lies in its owner's
/// box, so the owner's box, inflated by d / 2, overlaps B's, and the broad
/// phase pairs them, unless the owner shares a vertex with B (such pairs
/// are skipped): then every pair around it tests it, as without owners.
/// A broad phase that leaves out more pairs leaves out their owners' tests
/// with them: the normal cones (normal_cones.h) drop only pairs whose
/// vertex-triangle contacts cannot face each other, and the solver's
/// rest-close pairs (rest_close.h) take the contacts of their owners'
/// features with them, even when another pair around the feature is not
/// rest-close (the rule is per pair of owners, not per feature).
struct TriangleOwnership {
  /// Per triangle: the owner of its corners 0-2, then of its edges from
  /// corner c to c + 1 (mod 3).
  std::vector<std::array<std::uint32_t, 6>> owner;
};
TriangleOwnership triangle_ownership(std::span<const std::uint32_t> triangles);

/// Contacts of the candidate triangle pairs `pairs` (indices into
/// `triangles`, three vertex indices each, into `positions`, xyzw per
/// vertex) closer than `thickness` [m] (> 0, finite). Vertex-triangle
/// contacts skip a vertex of the triangle itself, edge-edge contacts skip
/// edges that share a vertex; each (vertex, triangle) and each pair of
/// edges appears once however many candidate pairs find it. [out]
/// contacts, sorted by kind then vertices. Errors: a bad thickness, a
/// non-finite position, a zero-area triangle in a pair (it has no normal to
/// push along), each named.
Status triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                         std::span<const Pair> pairs, float thickness, std::vector<Contact>& contacts);
/// Which contacts a caller keeps (called from several threads at once):
/// those it drops are never stored or sorted. The solver keeps few of the
/// contacts within a reach swollen by fast motion, and sorting the rest
/// took most of a frame's detection when a pressed organ jittered.
using ContactFilter = std::function<bool(const Contact&)>;

/// The same with the triangles' ownership computed once (triangle_ownership
/// of the same `triangles`), for callers that run it every frame, and only
/// the contacts `keep` accepts (all when empty).
Status triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                         const TriangleOwnership& ownership, std::span<const Pair> pairs, float thickness,
                         std::vector<Contact>& contacts, const ContactFilter& keep = {});

/// Contacts of candidate segment pairs (indices into `segments`, two vertex
/// indices each) closer than `thickness` [m]: edge-edge contacts between
/// segments that share no vertex (a thread against itself or another line
/// mesh). Each pair of segments appears once; touching parallel segments
/// (no direction to push along) make none. [out] contacts, sorted. Errors:
/// a bad thickness, a non-finite position or a bad index, named.
Status segment_contacts(std::span<const float> positions, std::span<const std::uint32_t> segments,
                        std::span<const Pair> pairs, float thickness, std::vector<Contact>& contacts,
                        const ContactFilter& keep = {});

/// Contacts of candidate (segment, triangle) pairs closer than `thickness`:
/// each segment end against the triangle (vertex_triangle, the segment's
/// vertex first) and the segment against each triangle edge (edge_edge, the
/// segment first), skipping what shares a vertex (a thread attached to the
/// surface at a vertex). [out] contacts, sorted. Errors as triangle_contacts.
Status segment_triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> segments,
                                 std::span<const std::uint32_t> triangles, std::span<const Pair> pairs,
                                 float thickness, std::vector<Contact>& contacts, const ContactFilter& keep = {});

/// A capsule (axis from `p0` to `p1`, xyzw, and `radius` [m] > 0) against
/// the candidate triangles `candidates` (indices into `triangles`): one
/// capsule_triangle contact per triangle whose gap to the capsule's surface
/// is below `thickness` (closest points by proximity::closest_segment_triangle).
/// A tool's faces against tissue faces, where a tool's contacts with the
/// tissue's vertices alone let its vertices slip past (README, heavy tool).
/// [out] contacts, sorted by triangle. Errors as triangle_contacts, and a
/// bad radius or a non-finite axis, named.
Status capsule_triangle_contacts(std::span<const float> positions, std::span<const std::uint32_t> triangles,
                                 std::span<const std::uint32_t> candidates, const std::array<float, 4>& p0,
                                 const std::array<float, 4>& p1, float radius, float thickness,
                                 std::vector<Contact>& contacts);

}  // namespace sinew::collision
