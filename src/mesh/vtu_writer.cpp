// write_vtu, write_vtu_lines, write_vtu_triangles, write_vtu_points and
// write_pvd (mesh.h): each checks its cells by kind (errors name the tet,
// segment or triangle), then writes a binary VTU through write_vtu(VtkGrid)
// (vtk_output.h: appended raw data, zlib-compressed).
//
// Format reference: "VTK File Formats", docs.vtk.org, "XML File Formats"
// (cell type 10 = VTK_TETRA, 3 = VTK_LINE, 5 = VTK_TRIANGLE, 1 = VTK_VERTEX)
// and the ParaView Data (.pvd) Collection format.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "output/vtk_files.h"
#include "sinew/mesh.h"
#include "sinew/vtk_output.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;

void append_double(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// Names the first cell that refers to a missing vertex; the rest (stride,
// fields) is checked by write_vtu(VtkGrid).
template <std::size_t N>
Status check_cells(const fs::path& path, std::span<const float> positions, int stride,
                   std::span<const std::array<std::uint32_t, N>> cells, const char* cell) {
  if ((stride != 3 && stride != 4) || positions.size() % static_cast<std::size_t>(stride) != 0) return {};
  const std::size_t n = positions.size() / static_cast<std::size_t>(stride);
  for (std::size_t t = 0; t < cells.size(); ++t)
    for (std::uint32_t v : cells[t])
      if (v >= n)
        return Error(ErrorCode::bad_parameter, path.string() + ": " + cell + " " + std::to_string(t) +
                                                   " refers to vertex " + std::to_string(v) + ", but there are only " +
                                                   std::to_string(n) + " vertices");
  return {};
}

// Cells of N vertices each, all of type `type`, through write_vtu(VtkGrid).
template <std::size_t N>
Status write_cells(const fs::path& path, std::span<const float> positions, int stride,
                   std::span<const std::array<std::uint32_t, N>> cells, std::span<const VertexField> fields,
                   VtkCellType type, const char* cell) {
  if (Status s = check_cells<N>(path, positions, stride, cells, cell); !s) return s;
  std::vector<std::uint32_t> connectivity;
  connectivity.reserve(N * cells.size());
  for (const auto& c : cells) connectivity.insert(connectivity.end(), c.begin(), c.end());
  std::vector<std::uint32_t> offsets(cells.size());
  for (std::size_t c = 0; c < cells.size(); ++c) offsets[c] = static_cast<std::uint32_t>(N * (c + 1));
  const std::vector<VtkCellType> types(cells.size(), type);
  return write_vtu(path, VtkGrid{.positions = positions, .stride = stride, .connectivity = connectivity,
                                 .offsets = offsets, .types = types, .point_fields = fields, .cell_fields = {}});
}

}  // namespace

Status write_vtu(const std::filesystem::path& path, std::span<const float> positions, int stride,
                 std::span<const std::array<std::uint32_t, 4>> tets, std::span<const VertexField> fields) {
  return write_cells<4>(path, positions, stride, tets, fields, VtkCellType::tetra, "tet");
}

Status write_vtu_lines(const std::filesystem::path& path, std::span<const float> positions, int stride,
                       std::span<const std::array<std::uint32_t, 2>> segments) {
  return write_cells<2>(path, positions, stride, segments, {}, VtkCellType::line, "segment");
}

Status write_vtu_triangles(const std::filesystem::path& path, std::span<const float> positions, int stride,
                           std::span<const std::array<std::uint32_t, 3>> triangles) {
  return write_cells<3>(path, positions, stride, triangles, {}, VtkCellType::triangle, "triangle");
}

Status write_vtu_points(const std::filesystem::path& path, std::span<const float> positions, int stride,
                        std::span<const VertexField> fields) {
  // One vertex cell per point, so ParaView shows and colours every point.
  std::vector<std::array<std::uint32_t, 1>> points(stride > 0 ? positions.size() / std::size_t(stride) : 0);
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = {static_cast<std::uint32_t>(i)};
  return write_cells<1>(path, positions, stride, points, fields, VtkCellType::vertex, "point");
}

Status write_pvd(const std::filesystem::path& path, std::span<const std::filesystem::path> vtu_files,
                 std::span<const double> times) {
  if (vtu_files.size() != times.size()) {
    return Error(ErrorCode::bad_parameter,
                 path.string() + ": " + std::to_string(vtu_files.size()) + " files but " +
                 std::to_string(times.size()) + " times");
  }
  for (std::size_t i = 0; i < times.size(); ++i) {
    if (!std::isfinite(times[i]))
      return Error(ErrorCode::bad_parameter, path.string() + ": time " + std::to_string(i) + " is not finite");
  }
  std::string out = "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
  const fs::path folder = path.parent_path();
  for (std::size_t i = 0; i < vtu_files.size(); ++i) {
    out += "    <DataSet timestep=\"";
    append_double(out, times[i]);
    out += "\" group=\"\" part=\"0\" file=\"" + vtk_files::xml_attribute(vtk_files::relative_name(vtu_files[i], folder)) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  return vtk_files::write_file(path, out);
}

}  // namespace sinew
