// read_stl: binary STL surfaces (issue 14).
//
// Format (3D Systems, "StereoLithography Interface Specification", 1989;
// the binary form): an 80-byte header, a little-endian uint32 triangle
// count, then per triangle 50 bytes: a normal (3 float32, ignored: the
// vertices' order says which way the triangle faces), its three vertices
// (3 x 3 float32) and a uint16 "attribute byte count". The file's size is
// therefore exactly 84 + 50 n. An ASCII STL starts with "solid" and does
// not match that size (a binary header may start with "solid" too, so the
// size decides).
//
// STL repeats every vertex in each triangle that uses it; vertices with
// bitwise equal coordinates are welded into one, so the surface's edges
// are shared and its closedness can be checked (check_closed_surface).
//
// Hostile headers (issue 39): the header's count is checked against the
// file's size, and against the 32-bit vertex indices, before anything is
// allocated (a sparse file can be as large as its header claims without
// taking disk space); an allocation that fails anyway is out_of_memory.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <string>
#include <unordered_map>
#include <vector>

#include "sinew/mesh.h"
#include "text_scan.h"

namespace sinew {
namespace {

static_assert(std::endian::native == std::endian::little, "read_stl assumes a little-endian host");

struct KeyHash {
  std::size_t operator()(const std::array<std::uint32_t, 3>& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t v : k) h = (h ^ v) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

// The header's triangle count, once it has been checked against the file's
// size: an error if the file is no binary STL of that many triangles.
Result<std::uint32_t> checked_count(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return Error(ErrorCode::bad_input_file, name + ": cannot open file (it does not exist)");
  if (!std::filesystem::is_regular_file(path, ec)) return Error(ErrorCode::bad_input_file, name + ": not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return Error(ErrorCode::bad_input_file, name + ": cannot read file size (" + ec.message() + ")");
  if (size < 84)
    return Error(ErrorCode::bad_input_file,
                 name + ": " + std::to_string(size) + " bytes, too short for a binary STL (84-byte header)");
  char header[84];
  std::ifstream in(path, std::ios::binary);
  if (!in.read(header, 84)) return Error(ErrorCode::bad_input_file, name + ": cannot read its 84-byte header");
  std::uint32_t count = 0;
  std::memcpy(&count, header + 80, 4);
  const std::uint64_t expected = 84 + 50 * std::uint64_t{count};
  if (size != expected) {
    if (std::memcmp(header, "solid", 5) == 0)
      return Error(ErrorCode::bad_input_file, name + ": an ASCII STL (it starts with \"solid\" and its size does not "
                                                     "fit a binary one); only binary STL is read");
    return Error(ErrorCode::bad_input_file, name + ": " + std::to_string(size) + " bytes, but its header says " +
                                                std::to_string(count) + " triangles, which take " +
                                                std::to_string(expected) + " (84 + 50 per triangle)");
  }
  if (count == 0) return Error(ErrorCode::bad_input_file, name + ": no triangles");
  // Up to 3 welded vertices per triangle, numbered in 32 bits.
  constexpr std::uint32_t kMaxTriangles = std::numeric_limits<std::uint32_t>::max() / 3;
  if (count > kMaxTriangles)
    return Error(ErrorCode::bad_input_file, name + ": its header says " + std::to_string(count) +
                                                " triangles, more than the " + std::to_string(kMaxTriangles) +
                                                " whose vertices 32-bit indices can number");
  return count;
}

Result<TriMesh> read_welded(const std::filesystem::path& path, std::uint32_t count) {
  auto bytes = detail::read_whole_file(path);
  if (!bytes) return bytes.error();
  const std::string& data = *bytes;
  const std::string name = path.string();
  if (data.size() != 84 + 50 * std::uint64_t{count})  // changed since checked_count read it
    return Error(ErrorCode::bad_input_file, name + ": the file changed while it was read");
  TriMesh mesh;
  mesh.triangles.reserve(count);
  std::unordered_map<std::array<std::uint32_t, 3>, std::uint32_t, KeyHash> welded;
  welded.reserve(count);
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* record = data.data() + 84 + 50 * std::size_t{t};
    std::array<std::uint32_t, 3> triangle{};
    for (int v = 0; v < 3; ++v) {
      std::array<std::uint32_t, 3> bits{};
      std::memcpy(bits.data(), record + 12 + 12 * v, 12);
      Vec3d p{};
      for (int k = 0; k < 3; ++k) {
        const float c = std::bit_cast<float>(bits[k]);
        if (!std::isfinite(c))
          return Error(ErrorCode::bad_input_file, name + ": triangle " + std::to_string(t) + ", vertex " +
                                                      std::to_string(v) + " has a non-finite coordinate");
        p[k] = c;
        if (c == 0.0f) bits[k] = 0;  // -0 and +0 are one position
      }
      const auto [it, added] = welded.try_emplace(bits, static_cast<std::uint32_t>(mesh.vertices.size()));
      if (added) mesh.vertices.push_back(p);
      triangle[v] = it->second;
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

}  // namespace

Result<TriMesh> read_stl(const std::filesystem::path& path) {
  const Result<std::uint32_t> count = checked_count(path);
  if (!count) return count.error();
  try {
    return read_welded(path, *count);
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::out_of_memory, path.string() + ": out of memory reading " + std::to_string(*count) +
                                               " triangles");
  }
}

}  // namespace sinew
