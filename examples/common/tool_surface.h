// tool_surface.h — the examples that keep their frames and write them after
// a run (haptic_drag, bone_burr) write their tools with these: the shapes
// of sinew/display_surfaces.h at a pose, as binary VTU files. Examples that
// write as they run use sinew::SceneOutput (sinew/vtk_output.h) instead.
#pragma once

#include <array>
#include <filesystem>

#include "sinew/display_surfaces.h"
#include "sinew/result.h"

namespace sinew::examples {

/// Writes capsule_surface(radius, half_height, pose) to [in] path. Errors:
/// the file's (write_vtu_triangles).
Status write_capsule_vtu(const std::filesystem::path& path, double radius, double half_height, const Pose& pose);

}  // namespace sinew::examples
