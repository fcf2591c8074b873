// write_vtu and write_pvd: VTK XML files for ParaView.
//
// Format reference: "VTK File Formats", VTK User's Guide / docs.vtk.org,
// section "XML File Formats" (UnstructuredGrid: Piece, PointData, Points,
// Cells with connectivity/offsets/types; cell type 10 = VTK_TETRA) and the
// ParaView Data (.pvd) Collection format.
//
// Floats are written with std::to_chars' shortest round-trip form: at most
// max_digits10 (9) significant digits and exactly the stored float when read
// back. The whole file is formatted in memory and written in one go.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "sinew/mesh.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;

constexpr int kVtkTetra = 10;
constexpr int kVtkLine = 3;
constexpr int kVtkTriangle = 5;
constexpr int kVtkVertex = 1;

void append_float(std::string& out, float v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void append_double(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

void append_uint(std::string& out, std::uint64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// Escapes text for an XML attribute value in double quotes.
std::string xml_attribute(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Creates missing parent folders, then writes `text` to `path`.
Status write_text_file(const fs::path& path, const std::string& text) {
  std::error_code ec;
  const fs::path parent = path.parent_path();
  if (!parent.empty()) {
    fs::create_directories(parent, ec);
    if (ec)
      return Error(ErrorCode::bad_input_file,
                   path.string() + ": cannot create folder " + parent.string() + " (" + ec.message() + ")");
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    return Error(ErrorCode::bad_input_file,
                 path.string() + ": cannot open file for writing (" + std::strerror(errno) + ")");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) return Error(ErrorCode::bad_input_file, path.string() + ": write failed (disk full?)");
  return {};
}

template <std::size_t N>
Status check_vtu_input(const fs::path& path, std::span<const float> positions, int stride,
                       std::span<const std::array<std::uint32_t, N>> tets,
                       std::span<const VertexField> fields, const char* cell = "tet") {
  const std::string where = path.string() + ": ";
  if (stride != 3 && stride != 4) {
    return Error(ErrorCode::bad_parameter, where + "stride must be 3 or 4 (got " + std::to_string(stride) + ")");
  }
  const auto s = static_cast<std::size_t>(stride);
  if (positions.size() % s != 0) {
    return Error(ErrorCode::bad_parameter,
                 where + "positions holds " + std::to_string(positions.size()) +
                 " floats, not a multiple of stride " + std::to_string(stride));
  }
  const std::size_t n = positions.size() / s;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    for (std::uint32_t v : tets[t]) {
      if (v >= n) {
        return Error(ErrorCode::bad_parameter,
                     where + cell + " " + std::to_string(t) + " refers to vertex " + std::to_string(v) +
                     ", but there are only " + std::to_string(n) + " vertices");
      }
    }
  }
  for (const VertexField& f : fields) {
    const std::string name = "field '" + f.name + "'";
    if (f.name.empty()) return Error(ErrorCode::bad_parameter, where + "a field has an empty name");
    if (f.components != 1 && f.components != 3) {
      return Error(ErrorCode::bad_parameter,
                   where + name + ": components must be 1 or 3 (got " + std::to_string(f.components) + ")");
    }
    const std::size_t expected = n * static_cast<std::size_t>(f.components);
    if (f.values.size() != expected) {
      return Error(ErrorCode::bad_parameter,
                   where + name + " has " + std::to_string(f.values.size()) + " values, expected " +
                   std::to_string(expected) + " (" + std::to_string(n) + " vertices x " +
                   std::to_string(f.components) + " components)");
    }
  }
  return {};
}

void append_field(std::string& out, const VertexField& f) {
  out += "        <DataArray type=\"Float32\" Name=\"" + xml_attribute(f.name) + "\" NumberOfComponents=\"" +
         std::to_string(f.components) + "\" format=\"ascii\">\n";
  const auto c = static_cast<std::size_t>(f.components);
  for (std::size_t i = 0; i < f.values.size(); i += c) {
    out += "          ";
    for (std::size_t k = 0; k < c; ++k) {
      if (k) out += ' ';
      append_float(out, f.values[i + k]);
    }
    out += '\n';
  }
  out += "        </DataArray>\n";
}

void append_points(std::string& out, std::span<const float> positions, std::size_t stride) {
  out += "      <Points>\n";
  out += "        <DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < positions.size(); i += stride) {
    out += "          ";
    append_float(out, positions[i]);
    out += ' ';
    append_float(out, positions[i + 1]);
    out += ' ';
    append_float(out, positions[i + 2]);
    out += '\n';
  }
  out += "        </DataArray>\n      </Points>\n";
}

// Cells of N vertices each, all of VTK type `type`.
template <std::size_t N>
void append_cells(std::string& out, std::span<const std::array<std::uint32_t, N>> cells, int type) {
  out += "      <Cells>\n";
  out += "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : cells) {
    out += "          ";
    for (std::size_t k = 0; k < N; ++k) {
      if (k) out += ' ';
      append_uint(out, t[k]);
    }
    out += '\n';
  }
  out += "        </DataArray>\n";
  out += "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < cells.size(); ++t) {
    out += "          ";
    append_uint(out, N * (t + 1));
    out += '\n';
  }
  out += "        </DataArray>\n";
  out += "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < cells.size(); ++t) out += "          " + std::to_string(type) + "\n";
  out += "        </DataArray>\n      </Cells>\n";
}

// The whole file: points, their fields and the cells.
template <std::size_t N>
Status write_cells(const fs::path& path, std::span<const float> positions, int stride,
                   std::span<const std::array<std::uint32_t, N>> cells, std::span<const VertexField> fields, int type,
                   const char* cell) {
  if (Status s = check_vtu_input<N>(path, positions, stride, cells, fields, cell); !s) return s;
  const auto s = static_cast<std::size_t>(stride);
  std::string out;
  // About 12 bytes per number keeps reallocation out of the formatting loop.
  out.reserve(64 + 12 * (positions.size() + cells.size() * (N + 2)) + 12 * positions.size() / s * fields.size() * 3);
  out += "<?xml version=\"1.0\"?>\n";
  out +=
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n";
  out += "  <UnstructuredGrid>\n";
  out += "    <Piece NumberOfPoints=\"" + std::to_string(positions.size() / s) + "\" NumberOfCells=\"" +
         std::to_string(cells.size()) + "\">\n";
  out += "      <PointData>\n";
  for (const VertexField& f : fields) append_field(out, f);
  out += "      </PointData>\n";
  append_points(out, positions, s);
  append_cells<N>(out, cells, type);
  out += "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return write_text_file(path, out);
}

// The name to write for `file` in a .pvd in `folder`: relative when possible.
std::string relative_name(const fs::path& file, const fs::path& folder) {
  std::error_code ec;
  const fs::path abs_file = fs::absolute(file, ec).lexically_normal();
  if (ec) return file.generic_string();
  const fs::path abs_folder = fs::absolute(folder.empty() ? fs::path(".") : folder, ec).lexically_normal();
  if (ec) return file.generic_string();
  const fs::path rel = abs_file.lexically_relative(abs_folder);
  // Empty when the two have no common root (e.g. other drives): keep it absolute.
  return rel.empty() ? abs_file.generic_string() : rel.generic_string();
}

}  // namespace

Status write_vtu(const std::filesystem::path& path, std::span<const float> positions, int stride,
                 std::span<const std::array<std::uint32_t, 4>> tets, std::span<const VertexField> fields) {
  return write_cells<4>(path, positions, stride, tets, fields, kVtkTetra, "tet");
}

Status write_vtu_lines(const std::filesystem::path& path, std::span<const float> positions, int stride,
                       std::span<const std::array<std::uint32_t, 2>> segments) {
  return write_cells<2>(path, positions, stride, segments, {}, kVtkLine, "segment");
}

Status write_vtu_triangles(const std::filesystem::path& path, std::span<const float> positions, int stride,
                           std::span<const std::array<std::uint32_t, 3>> triangles) {
  return write_cells<3>(path, positions, stride, triangles, {}, kVtkTriangle, "triangle");
}

Status write_vtu_points(const std::filesystem::path& path, std::span<const float> positions, int stride,
                        std::span<const VertexField> fields) {
  // One vertex cell per point, so ParaView shows and colours every point.
  std::vector<std::array<std::uint32_t, 1>> points(stride > 0 ? positions.size() / std::size_t(stride) : 0);
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = {static_cast<std::uint32_t>(i)};
  return write_cells<1>(path, positions, stride, points, fields, kVtkVertex, "point");
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
    out += "\" group=\"\" part=\"0\" file=\"" + xml_attribute(relative_name(vtu_files[i], folder)) + "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  return write_text_file(path, out);
}

}  // namespace sinew
