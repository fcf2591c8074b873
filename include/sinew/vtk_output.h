// vtk_output.h — binary VTK XML output for ParaView: unstructured grids
// (.vtu) whose arrays are appended raw binary compressed with zlib,
// multiblock files (.vtm) that group one frame's grids, and SceneOutput,
// which writes every body, tool, collider, needle and the fluid of a
// running Simulation with their fields, one .vtm per frame and one .pvd
// for the whole run (docs/runner.md, "Output").
//
// Format: "VTK File Formats" (docs.vtk.org, XML file formats): every
// DataArray is format="appended"; the AppendedData section (encoding
// "raw") holds, per array, a header of UInt64 words [number of blocks,
// block size, size of the last partial block (0: none), compressed size
// of each block] and then the blocks, each compressed with zlib
// (compressor="vtkZLibDataCompressor"). The same input gives the same
// bytes.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sinew/level_set.h"
#include "sinew/mesh.h"
#include "sinew/result.h"
#include "sinew/scene.h"
#include "sinew/scene_file.h"

namespace sinew {

class Simulation;

/// VTK's cell type numbers for the cells this writer uses.
enum class VtkCellType : std::uint8_t {
  empty = 0,      ///< a removed element: keeps the cell numbering, draws nothing
  vertex = 1,     ///< one point
  line = 3,       ///< two points
  poly_line = 4,  ///< a chain of points
  triangle = 5,   ///< three points
  tetra = 10,     ///< four points
};

/// An unstructured grid for write_vtu. Fields use VertexField (1 or 3
/// float components): a point field has point_count * components values,
/// a cell field cell_count * components.
struct VtkGrid {
  std::span<const float> positions;             ///< xyz per point [m], `stride` floats apart
  int stride = 3;                               ///< 3, or 4 (xyzw: w is skipped)
  std::span<const std::uint32_t> connectivity;  ///< the cells' points, one cell after the other
  std::span<const std::uint32_t> offsets;       ///< per cell: the end of its points in connectivity (non-decreasing)
  std::span<const VtkCellType> types;           ///< per cell (types.size() == offsets.size())
  std::span<const VertexField> point_fields;    ///< per point
  std::span<const VertexField> cell_fields;     ///< per cell
};

/// Writes `grid` to [in] path (.vtu, binary appended, zlib), creating
/// missing folders. Errors (bad_parameter, nothing written): a stride other
/// than 3 or 4, positions not a multiple of it, offsets and types of
/// different lengths or decreasing, a cell's point past the points, a
/// field with an empty name, components other than 1 or 3, or the wrong
/// number of values (each named); bad_input_file: the file cannot be
/// written.
Status write_vtu(const std::filesystem::path& path, const VtkGrid& grid);

/// One dataset of a .vtm file.
struct VtkBlock {
  std::string name;            ///< shown in ParaView's block list
  std::filesystem::path file;  ///< a .vtu file; written relative to the .vtm's folder
};

/// Writes a multiblock file (.vtm) of [in] blocks to [in] path.
Status write_vtm(const std::filesystem::path& path, std::span<const VtkBlock> blocks);

/// What SceneOutput writes besides the bodies.
struct SceneOutputSettings {
  /// The bodies' names (e.g. SceneFile::bodies): the blocks and files are
  /// "<name>_<frame>.vtu". A body without one is "tet0", "tri1", "line0", ...
  std::vector<SceneBodyName> bodies;
  /// The .pvd's and the .vtm files' name: "<name>.pvd", "<name>_<frame>.vtm".
  std::string name = "scene";
  /// Level-set colliders' and tools' surfaces (LevelSet::surface, redone
  /// each frame written, so a cut shows): its cost grows with the surface.
  bool level_set_surfaces = true;
  /// Half the side [m] of the square drawn for a plane collider (0: the
  /// scene's rest bounding box's largest side).
  double plane_half_size = 0.0;
};

/// Writes a Simulation's state frame by frame into a folder, for ParaView
/// (open "<name>.pvd") or scripts/render_frames.py. Blocks, each
/// "<block>_<frame>.vtu":
///  - tet bodies: their tets (removed ones as empty cells); point fields
///    displacement [m] (from the rest shape) and velocity [m/s]; cell fields
///    green_strain (the Frobenius norm of the Green strain E = (F^T F - I)/2
///    against the rest shape, 0 for a removed tet) and alive (1, or 0 once removed);
///  - tri bodies (membranes): their triangles, the same point fields, alive;
///  - line bodies (threads): their segments as lines, the same point fields;
///  - colliders "collider<i>": plane (a square), sphere, capsule, box,
///    cylinder and level-set surfaces at their current pose (implicit
///    colliders are not drawn);
///  - tools "tool<i>": capsule or level-set surface at their pose, with
///    point fields velocity and contact_force [N] (ToolState, the same on
///    every point);
///  - needles "needle<i>": the curve as a poly line at its pose, with
///    contact_force (NeedleState::reaction_force);
///  - "fluid": the fluid's particles as vertices with density [kg/m^3],
///    pressure [Pa] and velocity [m/s];
///  - shapes added with add_surface or add_polyline for that frame.
/// "<name>_<frame>.vtm" groups a frame's blocks and "<name>.pvd" lists every
/// frame written with its time, rewritten after each write (an interrupted
/// run leaves a readable series).
class SceneOutput {
 public:
  /// Prepares output of `scene` into [in] folder (created if missing).
  /// Errors: the folder cannot be made (bad_input_file); a setting's body
  /// past the scene's bodies, an empty or repeated block name, an empty
  /// name (bad_parameter).
  static Result<SceneOutput> create(const SceneDesc& scene, std::filesystem::path folder,
                                    SceneOutputSettings settings = {});
  SceneOutput(SceneOutput&&) noexcept;
  SceneOutput& operator=(SceneOutput&&) noexcept;
  ~SceneOutput();

  /// A display shape for the next write only: a closed or open surface [m]
  /// (e.g. an example's grasper jaws, from box_surface), or a polyline
  /// (a blade's edge). Its block is [in] name, which must not be a body's.
  ///@{
  void add_surface(const std::string& name, const TriMesh& surface);
  void add_polyline(const std::string& name, std::span<const std::array<double, 3>> points);
  ///@}

  /// Writes frame number [in] frame of [in] sim (created from this scene):
  /// its blocks, the frame's .vtm, and the .pvd with the time
  /// sim.last_frame().time (0 before the first step: write frame 0 then).
  /// Errors: a file that cannot be written, a device read error, an added
  /// shape named like another block.
  Status write(Simulation& sim, int frame);

 private:
  struct State;
  explicit SceneOutput(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace sinew
