// gl_renderer.h — the viewer's OpenGL 3.3 core drawing (docs/viewer.md):
// one shader program (Phong lighting from a head light, two-sided, a
// uniform or per-vertex colour; unlit for lines and points), meshes in
// vertex and index buffers, and reading the frame back for a screenshot.
// Needs a current OpenGL context (GLFW's).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sinew/result.h"
#include "view/shape_meshes.h"
#include "view/view_math.h"

namespace sinew::view {

/// What a GpuMesh's indices draw.
enum class Primitive { triangles, lines, points };

/// A mesh in OpenGL buffers: interleaved vertices (MeshData's layout) and indices.
class GpuMesh {
 public:
  GpuMesh() = default;
  explicit GpuMesh(const MeshData& data, Primitive primitive = Primitive::triangles);
  ~GpuMesh();
  GpuMesh(GpuMesh&& o) noexcept;
  GpuMesh& operator=(GpuMesh&& o) noexcept;
  GpuMesh(const GpuMesh&) = delete;
  GpuMesh& operator=(const GpuMesh&) = delete;

  /// Replaces the vertices (MeshData's 9 floats each); the buffer grows as needed.
  void set_vertices(std::span<const float> vertices);
  /// Replaces the indices.
  void set_indices(std::span<const std::uint32_t> indices);
  void set_primitive(Primitive p) { primitive_ = p; }
  /// Draws the whole index list (the program bound by Renderer::draw).
  void draw() const;
  [[nodiscard]] bool empty() const { return count_ == 0; }

 private:
  void make();
  unsigned vao_ = 0, vbo_ = 0, ebo_ = 0;
  std::size_t vbo_bytes_ = 0, ebo_bytes_ = 0;
  int count_ = 0;
  Primitive primitive_ = Primitive::triangles;
};

/// How a mesh is drawn.
struct DrawStyle {
  V3 colour{0.8f, 0.8f, 0.8f};
  bool lit = true;             ///< Phong; false: the flat colour (lines, points)
  bool vertex_colours = false; ///< the vertices' colours instead of `colour`
  float alpha = 1.0f;          ///< < 1: blended (drawn after the opaque ones)
  float point_size = 4.0f;     ///< [pixels], points only
  bool on_top = false;         ///< drawn over everything (no depth test): the handle inside its tool
};

/// The shader program and the frame's camera.
class Renderer {
 public:
  /// Compiles the program. Errors: the driver's compile or link log.
  Status init();
  ~Renderer();
  /// Starts a frame of [in] width x height pixels with [in] view and projection matrices, the eye [m].
  void begin(int width, int height, const M4& view, const M4& projection, V3 eye, V3 background);
  /// Draws `mesh` placed by `model`.
  void draw(const GpuMesh& mesh, const M4& model, const DrawStyle& style);
  /// Reads the frame drawn so far: [out] rgb, width x height x 3 bytes, top row first.
  void read_pixels(int width, int height, std::vector<std::uint8_t>& rgb) const;

 private:
  unsigned program_ = 0;
  int u_model_ = -1, u_view_proj_ = -1, u_colour_ = -1, u_lit_ = -1, u_vertex_colours_ = -1, u_eye_ = -1,
      u_point_size_ = -1;
};

}  // namespace sinew::view
