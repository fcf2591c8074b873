// shape_meshes.h — triangle meshes the viewer draws (docs/viewer.md):
// the tools' and colliders' shapes made from their sizes, and a body's
// surface with smooth normals from its particles. Plain data, no OpenGL.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "sinew/mesh.h"
#include "view/view_math.h"

namespace sinew::view {

/// Interleaved vertices (position [m], normal, colour; 9 floats each) and triangle or line indices.
struct MeshData {
  std::vector<float> vertices;
  std::vector<std::uint32_t> indices;
  /// Appends a vertex; returns its index.
  std::uint32_t add(V3 p, V3 n, V3 c = {1, 1, 1});
};

/// A sphere of radius 1 at the origin.
MeshData unit_sphere(int slices = 24, int stacks = 12);
/// A capsule: the segment +-half_height along y swollen by `radius` [m] (ToolDesc, ColliderShape::capsule).
MeshData capsule(double radius, double half_height, int slices = 24, int stacks = 8);
/// A closed cylinder of `radius` with caps at +-half_height along y [m] (ColliderShape::cylinder).
MeshData cylinder(double radius, double half_height, int slices = 24);
/// A box of half extents 1 (scale it by the half extents).
MeshData unit_box();
/// The square y = 0, -1 <= x, z <= 1, facing +y (a plane collider, scaled to the scene).
MeshData unit_square();
/// An arrow from the origin to (0, 1, 0), its shaft 0.04 and its head 0.12 wide (scale it).
MeshData unit_arrow(int slices = 12);
/// A tube of `radius` [m] along a polyline [m] (a needle's curve), one open cylinder per segment.
MeshData tube(std::span<const Vec3d> polyline, double radius, int slices = 8);
/// A surface given in the shape's frame (a level set's, LevelSet::surface), with smooth normals.
MeshData surface_mesh(const TriMesh& surface);

/// A body's surface: [in] xyzw positions of its particles (4 floats each),
/// its triangles (indices into them), optional per-particle colours (3
/// floats each; empty: white). [out] out's vertices: one per particle,
/// normals the area-weighted mean of the faces around it (so the surface
/// looks smooth); indices are left alone.
void body_vertices(std::span<const float> xyzw, std::span<const std::array<std::uint32_t, 3>> triangles,
                   std::span<const float> colours, MeshData& out);

/// A colour for a speed [m/s] on a blue -> green -> red scale up to `top` [m/s].
V3 speed_colour(float speed, float top);

}  // namespace sinew::view
