// vtu_reader.h — a reader of the binary VTU files sinew writes (the tests'
// own, independent of the writer): the XML header's DataArray tags, then
// each array's UInt64 header [blocks, block size, last partial block size,
// compressed sizes] and its zlib blocks from the appended section, as the
// VTK file-format spec lays them out.
#pragma once

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace sinew::vtu_test {

/// One array: its values as doubles (exact for Float32, Int32 and UInt8).
struct Array {
  std::string type;
  int components = 1;
  std::vector<double> values;
  template <typename T>
  [[nodiscard]] std::vector<T> as() const {
    return std::vector<T>(values.begin(), values.end());
  }
};

struct Vtu {
  std::string xml;  ///< everything before the appended data
  std::size_t points = 0, cells = 0;
  Array positions, connectivity, offsets, types;
  std::map<std::string, Array> point_data, cell_data;
};

inline std::string attribute(const std::string& tag, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const auto at = tag.find(key);
  if (at == std::string::npos) return "";
  const auto end = tag.find('"', at + key.size());
  return tag.substr(at + key.size(), end - at - key.size());
}

inline std::uint64_t word(const std::string& data, std::size_t at) {
  if (at + 8 > data.size()) throw std::runtime_error("appended data ends inside a header");
  std::uint64_t w = 0;
  for (int k = 0; k < 8; ++k) w |= std::uint64_t(static_cast<unsigned char>(data[at + k])) << (8 * k);
  return w;
}

// The bytes of the array at `offset` in the appended data.
inline std::string decompress(const std::string& data, std::size_t offset) {
  const std::uint64_t blocks = word(data, offset), block = word(data, offset + 8), last = word(data, offset + 16);
  std::size_t at = offset + 24 + 8 * blocks;
  std::string out;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const std::uint64_t size = word(data, offset + 24 + 8 * b);
    uLongf n = (b + 1 == blocks && last != 0) ? last : block;
    std::string chunk(n, '\0');
    if (at + size > data.size() ||
        uncompress(reinterpret_cast<Bytef*>(chunk.data()), &n, reinterpret_cast<const Bytef*>(data.data() + at), size) != Z_OK)
      throw std::runtime_error("a zlib block does not decompress");
    out.append(chunk.data(), n);
    at += size;
  }
  return out;
}

inline Array decode(const std::string& tag, const std::string& data) {
  Array a;
  a.type = attribute(tag, "type");
  const std::string nc = attribute(tag, "NumberOfComponents");
  a.components = nc.empty() ? 1 : std::stoi(nc);
  const std::string bytes = decompress(data, std::stoull(attribute(tag, "offset")));
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  if (a.type == "Float32") {
    for (std::size_t i = 0; i + 4 <= bytes.size(); i += 4) {
      std::uint32_t u = p[i] | (p[i + 1] << 8) | (p[i + 2] << 16) | (std::uint32_t(p[i + 3]) << 24);
      float f;
      std::memcpy(&f, &u, 4);
      a.values.push_back(f);
    }
  } else if (a.type == "Int32") {
    for (std::size_t i = 0; i + 4 <= bytes.size(); i += 4) {
      const std::uint32_t u = p[i] | (p[i + 1] << 8) | (p[i + 2] << 16) | (std::uint32_t(p[i + 3]) << 24);
      a.values.push_back(static_cast<std::int32_t>(u));
    }
  } else if (a.type == "UInt8") {
    for (std::size_t i = 0; i < bytes.size(); ++i) a.values.push_back(p[i]);
  } else {
    throw std::runtime_error("unexpected array type " + a.type);
  }
  return a;
}

/// Reads [in] path; throws std::runtime_error naming what is wrong.
inline Vtu read_vtu(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + " cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string file = ss.str();
  const auto appended = file.find("<AppendedData encoding=\"raw\">");
  if (appended == std::string::npos) throw std::runtime_error("no raw AppendedData");
  const auto underscore = file.find('_', appended);
  Vtu v;
  v.xml = file.substr(0, appended);
  const std::string data = file.substr(underscore + 1);
  if (v.xml.find("compressor=\"vtkZLibDataCompressor\"") == std::string::npos ||
      v.xml.find("header_type=\"UInt64\"") == std::string::npos)
    throw std::runtime_error("not zlib-compressed with UInt64 headers");
  const auto piece = v.xml.find("<Piece");
  v.points = std::stoull(attribute(v.xml.substr(piece, 200), "NumberOfPoints"));
  v.cells = std::stoull(attribute(v.xml.substr(piece, 200), "NumberOfCells"));
  std::string section;
  for (std::size_t at = v.xml.find('<'); at != std::string::npos; at = v.xml.find('<', at + 1)) {
    const std::string tag = v.xml.substr(at, v.xml.find('>', at) - at + 1);
    for (const char* s : {"<PointData", "<CellData", "<Points", "<Cells"})
      if (tag.rfind(s, 0) == 0) section = s;
    if (tag.rfind("<DataArray", 0) != 0) continue;
    Array a = decode(tag, data);
    const std::string name = attribute(tag, "Name");
    if (section == "<PointData") v.point_data[name] = a;
    else if (section == "<CellData") v.cell_data[name] = a;
    else if (section == "<Points") v.positions = a;
    else if (name == "connectivity") v.connectivity = a;
    else if (name == "offsets") v.offsets = a;
    else if (name == "types") v.types = a;
  }
  return v;
}

}  // namespace sinew::vtu_test
