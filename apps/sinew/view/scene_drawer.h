// scene_drawer.h — draws a ViewSnapshot (docs/viewer.md): the tet bodies'
// live boundaries, membranes, threads, tools, colliders, needles and the
// fluid; the virtual device's handle, its spring to the tool and the force
// on the hand as an arrow; the tools' contact forces. Needs a current
// OpenGL context.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "sinew/scene.h"
#include "view/gl_renderer.h"
#include "view/view_snapshot.h"

namespace sinew::view {

/// What the viewer shows (the panel's toggles).
struct DrawOptions {
  bool colour_by_speed = false;  ///< bodies coloured by their particles' speed instead of one colour each
  bool contacts = true;          ///< the tools' contact forces and the needles' reactions as arrows
  bool fluid = true;             ///< the fluid's particles
  bool colliders = true;         ///< the colliders
};

/// The virtual device as drawn: its handle, the tool it drives, the force on the hand.
struct HandleView {
  int tool = -1;          ///< the driven tool (-1: none; nothing drawn)
  V3 position;            ///< the handle [m]
  V3 force;               ///< on the hand [N]
};

class SceneDrawer {
 public:
  /// Makes the static meshes of the scene's shapes.
  explicit SceneDrawer(const SceneDesc& scene);
  /// Uploads the snapshot's particles (and its elements when they changed).
  void update(const ViewSnapshot& snap, const DrawOptions& options);
  /// Draws the last update()'s scene, and the handle.
  void draw(Renderer& renderer, const ViewSnapshot& snap, const DrawOptions& options, const HandleView& handle);
  /// The box around every particle and tool [m] (the camera frames it).
  static void bounds(const ViewSnapshot& snap, V3& lo, V3& hi);
  /// Metres per newton of the force arrows (a tenth of the scene per newton).
  [[nodiscard]] float arrow_scale() const { return arrow_scale_; }

 private:
  struct Body {
    GpuMesh surface;    // triangles (or the thread's segments)
    MeshData cpu;       // its vertices, rebuilt each update
    V3 colour;
  };
  void upload_elements(const ViewSnapshot& snap);
  void draw_arrow(Renderer& r, V3 from, V3 vector, V3 colour);

  const SceneDesc& scene_;
  std::vector<Body> tets_, tris_, lines_;
  std::vector<std::optional<GpuMesh>> tool_meshes_, collider_meshes_;
  std::vector<GpuMesh> needle_meshes_;
  GpuMesh sphere_, box_, square_, arrow_, fluid_, spring_;
  std::vector<float> colours_;
  std::uint64_t elements_generation_ = 0, elements_version_ = UINT64_MAX;
  std::shared_ptr<const std::vector<TriMesh>> level_set_surfaces_;  // the ones collider_meshes_ show
  float extent_ = 0.1f, arrow_scale_ = 0.01f;
  V3 centre_;
};

}  // namespace sinew::view
