// vtu_binary_writer.cpp — write_vtu(VtkGrid) and write_vtm (vtk_output.h):
// VTK XML with every array appended as raw binary, compressed with zlib.
//
// Format reference: "VTK File Formats" (docs.vtk.org), XML formats,
// "Appended data" and compressed data: with header_type="UInt64" each
// array starts at its offset (from the byte after the '_' that opens the
// AppendedData section) with UInt64 words [blocks, block size, last
// partial block's size (0 when the last block is full), compressed size of
// each block], then the compressed blocks. zlib at one fixed level and the
// XML formatted by hand make the same input give the same bytes.
#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "output/vtk_files.h"
#include "sinew/vtk_output.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;

// VTK's default block size: large enough for zlib, small enough that a
// reader can decompress one block at a time.
constexpr std::size_t kBlockSize = 1 << 15;
// zlib's level: level 1 keeps output at run speed; higher levels gain
// little on float data (most of the bytes).
constexpr int kZlibLevel = 1;

// The appended section: each array's header and blocks, one after the other.
class Appended {
 public:
  // Compresses `size` bytes at `data` as the next array; returns its offset.
  Result<std::size_t> add(const void* data, std::size_t size) {
    const std::size_t offset = bytes_.size();
    const auto* in = static_cast<const unsigned char*>(data);
    const std::size_t blocks = (size + kBlockSize - 1) / kBlockSize;
    const std::size_t header_at = bytes_.size();
    bytes_.resize(bytes_.size() + 8 * (3 + blocks));
    std::vector<std::uint64_t> header{blocks, kBlockSize, size % kBlockSize};
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t n = std::min(kBlockSize, size - b * kBlockSize);
      uLongf out_size = compressBound(static_cast<uLong>(n));
      const std::size_t at = bytes_.size();
      bytes_.resize(at + out_size);
      if (compress2(bytes_.data() + at, &out_size, in + b * kBlockSize, static_cast<uLong>(n), kZlibLevel) != Z_OK)
        return Error(ErrorCode::bad_parameter, "zlib could not compress a block");
      bytes_.resize(at + out_size);
      header.push_back(out_size);
    }
    // Little-endian words (the file says byte_order="LittleEndian").
    for (std::size_t w = 0; w < header.size(); ++w)
      for (int k = 0; k < 8; ++k) bytes_[header_at + 8 * w + k] = static_cast<unsigned char>(header[w] >> (8 * k));
    return offset;
  }
  [[nodiscard]] const std::vector<unsigned char>& bytes() const { return bytes_; }

 private:
  std::vector<unsigned char> bytes_;
};

template <typename T>
std::vector<unsigned char> little_endian(std::span<const T> values) {
  std::vector<unsigned char> out(values.size() * sizeof(T));
  for (std::size_t i = 0; i < values.size(); ++i)
    for (std::size_t k = 0; k < sizeof(T); ++k) {
      std::make_unsigned_t<T> u;
      std::memcpy(&u, &values[i], sizeof(T));
      out[i * sizeof(T) + k] = static_cast<unsigned char>(u >> (8 * k));
    }
  return out;
}

std::vector<unsigned char> float_bytes(std::span<const float> values) {
  std::vector<std::uint32_t> words(values.size());
  std::memcpy(words.data(), values.data(), values.size() * sizeof(float));
  return little_endian<std::uint32_t>(words);
}

Status check_fields(const std::string& where, std::span<const VertexField> fields, std::size_t count, const char* of) {
  for (const VertexField& f : fields) {
    const std::string name = "field '" + f.name + "'";
    if (f.name.empty()) return Error(ErrorCode::bad_parameter, where + "a field has an empty name");
    if (f.components != 1 && f.components != 3)
      return Error(ErrorCode::bad_parameter,
                   where + name + ": components must be 1 or 3 (got " + std::to_string(f.components) + ")");
    const std::size_t expected = count * static_cast<std::size_t>(f.components);
    if (f.values.size() != expected)
      return Error(ErrorCode::bad_parameter, where + name + " has " + std::to_string(f.values.size()) +
                                                 " values, expected " + std::to_string(expected) + " (" +
                                                 std::to_string(count) + " " + of + " x " +
                                                 std::to_string(f.components) + " components)");
  }
  return {};
}

Status check_grid(const std::string& where, const VtkGrid& g) {
  if (g.stride != 3 && g.stride != 4)
    return Error(ErrorCode::bad_parameter, where + "stride must be 3 or 4 (got " + std::to_string(g.stride) + ")");
  const auto s = static_cast<std::size_t>(g.stride);
  if (g.positions.size() % s != 0)
    return Error(ErrorCode::bad_parameter, where + "positions holds " + std::to_string(g.positions.size()) +
                                               " floats, not a multiple of stride " + std::to_string(g.stride));
  const std::size_t points = g.positions.size() / s;
  if (g.offsets.size() != g.types.size())
    return Error(ErrorCode::bad_parameter, where + std::to_string(g.offsets.size()) + " cell offsets but " +
                                               std::to_string(g.types.size()) + " cell types");
  std::uint32_t previous = 0;
  for (std::size_t c = 0; c < g.offsets.size(); ++c) {
    if (g.offsets[c] < previous || g.offsets[c] > g.connectivity.size())
      return Error(ErrorCode::bad_parameter, where + "cell " + std::to_string(c) + " ends at " +
                                                 std::to_string(g.offsets[c]) + ", before the previous cell or past the " +
                                                 std::to_string(g.connectivity.size()) + " connectivity entries");
    previous = g.offsets[c];
  }
  for (std::size_t i = 0; i < g.connectivity.size(); ++i)
    if (g.connectivity[i] >= points)
      return Error(ErrorCode::bad_parameter, where + "connectivity entry " + std::to_string(i) + " refers to point " +
                                                 std::to_string(g.connectivity[i]) + ", but there are only " +
                                                 std::to_string(points) + " points");
  if (Status st = check_fields(where, g.point_fields, points, "points"); !st) return st;
  return check_fields(where, g.cell_fields, g.offsets.size(), "cells");
}

// One DataArray element pointing into the appended section.
void array_tag(std::string& xml, std::string_view indent, std::string_view type, const std::string& name, int components,
               std::size_t offset) {
  xml += indent;
  xml += "<DataArray type=\"";
  xml += type;
  xml += "\"";
  if (!name.empty()) xml += " Name=\"" + vtk_files::xml_attribute(name) + "\"";
  if (components > 1) xml += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  xml += " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
}

Result<std::string> field_tags(Appended& data, std::span<const VertexField> fields) {
  std::string xml;
  for (const VertexField& f : fields) {
    const auto bytes = float_bytes(f.values);
    auto at = data.add(bytes.data(), bytes.size());
    if (!at) return at.error();
    array_tag(xml, "        ", "Float32", f.name, f.components, *at);
  }
  return xml;
}

}  // namespace

Status write_vtu(const std::filesystem::path& path, const VtkGrid& g) {
  if (Status st = check_grid(path.string() + ": ", g); !st) return st;
  const auto s = static_cast<std::size_t>(g.stride);
  const std::size_t points = g.positions.size() / s;
  Appended data;
  std::string xml = "<?xml version=\"1.0\"?>\n";
  xml +=
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
      "compressor=\"vtkZLibDataCompressor\">\n";
  xml += "  <UnstructuredGrid>\n";
  xml += "    <Piece NumberOfPoints=\"" + std::to_string(points) + "\" NumberOfCells=\"" +
         std::to_string(g.offsets.size()) + "\">\n";
  auto point_tags = field_tags(data, g.point_fields);
  if (!point_tags) return point_tags.error();
  xml += "      <PointData>\n" + *point_tags + "      </PointData>\n";
  auto cell_tags = field_tags(data, g.cell_fields);
  if (!cell_tags) return cell_tags.error();
  xml += "      <CellData>\n" + *cell_tags + "      </CellData>\n";
  std::vector<float> xyz(3 * points);
  for (std::size_t p = 0; p < points; ++p)
    for (std::size_t k = 0; k < 3; ++k) xyz[3 * p + k] = g.positions[s * p + k];
  const auto xyz_bytes = float_bytes(xyz);
  auto at = data.add(xyz_bytes.data(), xyz_bytes.size());
  if (!at) return at.error();
  xml += "      <Points>\n";
  array_tag(xml, "        ", "Float32", "Points", 3, *at);
  xml += "      </Points>\n      <Cells>\n";
  // Int32 indices: VTK reads any integer type, and meshes stay far below 2^31 points.
  std::vector<std::int32_t> words(g.connectivity.begin(), g.connectivity.end());
  const auto connectivity = little_endian<std::int32_t>(words);
  if (!(at = data.add(connectivity.data(), connectivity.size()))) return at.error();
  array_tag(xml, "        ", "Int32", "connectivity", 1, *at);
  words.assign(g.offsets.begin(), g.offsets.end());
  const auto offsets = little_endian<std::int32_t>(words);
  if (!(at = data.add(offsets.data(), offsets.size()))) return at.error();
  array_tag(xml, "        ", "Int32", "offsets", 1, *at);
  if (!(at = data.add(g.types.data(), g.types.size()))) return at.error();
  array_tag(xml, "        ", "UInt8", "types", 1, *at);
  xml += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
  const auto& bytes = data.bytes();
  xml.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  xml += "\n  </AppendedData>\n</VTKFile>\n";
  return vtk_files::write_file(path, xml);
}

Status write_vtm(const std::filesystem::path& path, std::span<const VtkBlock> blocks) {
  std::string xml = "<?xml version=\"1.0\"?>\n";
  xml += "<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n";
  xml += "  <vtkMultiBlockDataSet>\n";
  const fs::path folder = path.parent_path();
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    if (blocks[i].name.empty())
      return Error(ErrorCode::bad_parameter, path.string() + ": block " + std::to_string(i) + " has an empty name");
    xml += "    <DataSet index=\"" + std::to_string(i) + "\" name=\"" + vtk_files::xml_attribute(blocks[i].name) +
           "\" file=\"" + vtk_files::xml_attribute(vtk_files::relative_name(blocks[i].file, folder)) + "\"/>\n";
  }
  xml += "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
  return vtk_files::write_file(path, xml);
}

}  // namespace sinew
