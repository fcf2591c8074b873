// sinew/mesh.h — tetrahedral and triangle meshes: generation, reading,
// checking, boundary extraction and VTU output for ParaView.
//
// Units: positions are whatever the file holds; sinew is SI throughout, so a
// mesh stored in millimetres (e.g. data/meshes/tet/kidney_57k) is
// scaled with scale_mesh(mesh, 1e-3) before it is used in a scene.
//
// Orientation: a tet {a, b, c, d} is positively oriented when
// dot(b - a, cross(c - a, d - a)) > 0 (six times its signed volume).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "sinew/result.h"

namespace sinew {

using Vec3d = std::array<double, 3>;

/// A tetrahedral mesh: vertex positions and tets as 0-based vertex indices.
struct TetMesh {
  std::vector<Vec3d> vertices;                  ///< positions [m]
  std::vector<std::array<std::uint32_t, 4>> tets;  ///< 0-based, positively oriented
};

/// A triangle mesh. For a boundary surface the vertex indices refer to the
/// tet mesh it came from, and triangles wind counter-clockwise seen from
/// outside (normals point outward).
struct TriMesh {
  std::vector<Vec3d> vertices;                     ///< positions [m]
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< vertex indices, counter-clockwise from outside
};

/// Reads a binary STL file: the triangles, with vertices at equal positions
/// welded into one (bitwise equal coordinates, as STL writers repeat them).
/// Units as in the file (../shared/data's are millimetres: scale them).
/// Errors (bad_input_file, naming the file): missing or unreadable, an
/// ASCII STL, a size that does not match its triangle count (checked
/// before anything is allocated), more than 2^32/3 triangles (their welded
/// vertices could not be numbered in 32 bits), a non-finite coordinate, no
/// triangles; out_of_memory when the file's triangles do not fit in memory.
Result<TriMesh> read_stl(const std::filesystem::path& path);

/// Why a closed surface is needed and what is checked (check_closed_surface).
struct SurfaceReport {
  std::uint64_t open_edges = 0;          ///< edges on one triangle only
  std::uint64_t nonmanifold_edges = 0;   ///< edges on more than two triangles
  std::uint64_t misoriented_edges = 0;   ///< edges both of whose triangles run the same way along them
  std::uint64_t degenerate_triangles = 0;  ///< no area (or a repeated vertex)
  /// Pairs of triangles that share no vertex and cross each other; only
  /// searched for when the counts above are all 0 (crossings_tested).
  std::uint64_t intersecting_pairs = 0;
  /// Whether the crossing search ran: false when the edge and triangle
  /// counts already show the surface does not bound a solid (the search
  /// would only cost time).
  bool crossings_tested = false;
  /// Whether the surface bounds a solid: no open, non-manifold or misoriented edge, no degenerate triangle and
  /// no crossing.
  [[nodiscard]] bool closed() const {
    return open_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0 && degenerate_triangles == 0 &&
           crossings_tested && intersecting_pairs == 0;
  }
};

/// Checks that `surface` bounds a solid: every edge on exactly two
/// triangles running opposite ways along it, no triangle without area, no
/// two triangles crossing (pairs sharing a vertex are not tested). [out]
/// the counts. Work: the edge counts (n log n in the triangles) decide
/// first; a surface they show open, non-manifold, misoriented or
/// degenerate is not searched for crossings (crossings_tested = false);
/// nor is a surface without triangles, which bounds nothing (not closed).
/// The crossing search tests the pairs of triangles whose boxes overlap,
/// at most 64 per triangle (and at least 2^20 in all): the data's organ
/// and bone surfaces test under 0.05 per triangle. Errors: capacity_exceeded when
/// that bound is passed (e.g. many closed shells piled on each other),
/// naming the bound. A non-finite vertex is counted as degenerate.
Result<SurfaceReport> check_closed_surface(const TriMesh& surface);

/// How a box cell of a tet grid is split.
enum class TetsPerCell {
  five,  ///< 5 tets per cell, alternating mirrored cells so faces match
  six,   ///< 6 tets per cell around the cell's main diagonal (Freudenthal/Kuhn)
};

/// A box [origin, origin + (nx, ny, nz) * cell_size] of nx*ny*nz cells.
struct TetGridDesc {
  int nx = 1;                     ///< cells along x, >= 1
  int ny = 1;                     ///< cells along y, >= 1
  int nz = 1;                     ///< cells along z, >= 1
  Vec3d origin{0.0, 0.0, 0.0};    ///< lowest corner [m]
  Vec3d cell_size{1.0, 1.0, 1.0}; ///< cell edge lengths [m], > 0
  TetsPerCell split = TetsPerCell::six;  ///< 5 or 6 tets per cell
};

/// [in] desc: grid size; errors name the bad parameter.
/// [out] (nx+1)(ny+1)(nz+1) vertices, vertex (i,j,k) at index i + (nx+1)*(j + (ny+1)*k);
/// 5 or 6 positively oriented tets per cell, conforming across cells.
Result<TetMesh> make_tet_grid(const TetGridDesc& desc);

/// The mesh without the vertices no tet uses (e.g. after removing tets to
/// carve a cavity out of a tet grid), the others renumbered in the order
/// the tets first use them. [pre] every index < vertices.size().
TetMesh drop_unused_vertices(const TetMesh& mesh);

/// Reads a TetGen mesh: `path` is the .node file, the .ele file or their
/// common stem; both files must exist. Handles 0- and 1-based numbering
/// (detected from the first index in .node), attributes and boundary markers
/// (ignored), `#` comments, and tets with 4 nodes (10-node tets: the first 4).
/// [out] a mesh that passes check_tet_mesh; errors name file:line.
Result<TetMesh> read_tetgen(const std::filesystem::path& path);

/// Reads a Gmsh .msh file, ASCII format 2.x or 4.x, keeping the linear
/// tetrahedra (element type 4) and dropping other element types. Node tags
/// may be sparse; they are renumbered densely, and nodes used by no tet are
/// dropped. [out] a mesh that passes check_tet_mesh; errors name file:line.
Result<TetMesh> read_gmsh(const std::filesystem::path& path);

/// Reads a legacy VTK file (.vtk, first line "# vtk DataFile Version x.y"),
/// ASCII or BINARY (big-endian), DATASET UNSTRUCTURED_GRID: POINTS (float or
/// double), CELLS and CELL_TYPES, keeping the cells of type 10 (VTK_TETRA)
/// and dropping other cell types; POINT_DATA, CELL_DATA and FIELD sections
/// after them are ignored. Points used by no tet are dropped and the others
/// renumbered in the order the tets first use them (drop_unused_vertices).
/// Float coordinates are widened to double. VTK 5.x cells (OFFSETS and
/// CONNECTIVITY arrays) are not read. [out] a mesh that passes
/// check_tet_mesh; errors (bad_input_file) name file:line, or file: byte N
/// past binary data, and the section at fault.
Result<TetMesh> read_vtk(const std::filesystem::path& path);

/// Reads a tet mesh by extension: .msh (Gmsh), .node/.ele (TetGen), .vtk
/// (legacy VTK).
Result<TetMesh> read_tet_mesh(const std::filesystem::path& path);

/// Checks a tet mesh: at least one tet; all coordinates finite; all indices
/// in range; no tet repeats a vertex; every tet has positive volume above
/// 1e-12 of the cube of its own longest edge, a flatness test independent of
/// units, mesh size and grading (zero-volume and inverted tets are errors,
/// naming the tet, its vertices, its signed volume and that minimum).
/// `origin` prefixes the messages (e.g. a file name). Errors are
/// ErrorCode::bad_parameter (a mesh given in code); the readers report the
/// same faults in a file as ErrorCode::bad_input_file.
Status check_tet_mesh(const TetMesh& mesh, const std::string& origin = "mesh");

/// Multiplies every position by `factor` (e.g. 1e-3 for millimetres to metres).
void scale_mesh(TetMesh& mesh, double factor);
void scale_mesh(TriMesh& mesh, double factor);

/// The faces that belong to exactly one tet, wound outward; the returned
/// mesh shares the tet mesh's vertex array and indices (unused vertices are
/// kept so indices match). Deterministic order.
TriMesh extract_boundary_surface(const TetMesh& mesh);

/// A per-vertex (or per-cell: VtkGrid) field written to VTU: 1 (scalar) or 3 (vector) components.
struct VertexField {
  std::string name;               ///< the field's name in the file
  int components = 1;             ///< 1 or 3
  std::span<const float> values;  ///< vertex_count * components values
};

/// Writes a VTK XML unstructured grid (.vtu, binary, zlib: vtk_output.h) of tets with per-vertex
/// fields. [in] positions: xyz per vertex [m], as 3 floats per vertex
/// (stride 3) or 4 (stride 4, the w component is skipped).
/// Errors name the file or the field whose size is wrong.
Status write_vtu(const std::filesystem::path& path, std::span<const float> positions, int stride,
                 std::span<const std::array<std::uint32_t, 4>> tets,
                 std::span<const VertexField> fields = {});

/// Writes a VTU of line cells (VTK_LINE), one per segment: a thread, a
/// needle. [in] positions as for write_vtu. Errors name the file or the
/// segment that refers to a missing vertex.
Status write_vtu_lines(const std::filesystem::path& path, std::span<const float> positions, int stride,
                       std::span<const std::array<std::uint32_t, 2>> segments);

/// Writes a VTU of triangle cells (VTK_TRIANGLE): a surface, e.g. a level
/// set's (LevelSet::surface). [in] positions as for write_vtu. Errors name
/// the file or the triangle that refers to a missing vertex.
Status write_vtu_triangles(const std::filesystem::path& path, std::span<const float> positions, int stride,
                           std::span<const std::array<std::uint32_t, 3>> triangles);

/// Writes a VTU of points (one VTK_VERTEX cell each) with per-point fields:
/// particles, e.g. a fluid's with density, pressure and velocity. [in]
/// positions as for write_vtu. Errors name the file or the field whose size
/// is wrong.
Status write_vtu_points(const std::filesystem::path& path, std::span<const float> positions, int stride,
                        std::span<const VertexField> fields = {});

/// Writes a ParaView collection (.pvd) that lists a series of VTU files with
/// their times [s]; file names are written relative to the .pvd's folder.
Status write_pvd(const std::filesystem::path& path,
                 std::span<const std::filesystem::path> vtu_files, std::span<const double> times);

}  // namespace sinew
