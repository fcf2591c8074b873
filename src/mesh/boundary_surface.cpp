// extract_boundary_surface: the faces used by exactly one tet, wound outward.
//
// Faces are matched by their sorted vertex triple, grouped by smallest
// vertex. A single counting sort by smallest vertex scatters the 4*T face
// entries to random places and is dominated by cache misses (~120 ms for
// liver_382k), so the grouping is done in two levels: a scatter into at most
// 1024 coarse buckets by the high bits of the smallest vertex (few write
// streams, cache friendly), then a counting sort inside each coarse bucket,
// which fits in cache; the few faces per vertex are sorted directly. About
// 70 ms for liver_382k (1.5 M faces) on one core.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "mesh/tet_faces.h"
#include "sinew/mesh.h"

namespace sinew {
namespace {

using Tri = std::array<std::uint32_t, 3>;

Tri face_of(const std::array<std::uint32_t, 4>& tet, int f) {
  const auto& local = kOutwardFaces[static_cast<std::size_t>(f)];
  return {tet[static_cast<std::size_t>(local[0])], tet[static_cast<std::size_t>(local[1])],
          tet[static_cast<std::size_t>(local[2])]};
}

Tri sorted(Tri t) {
  // Three compare-swaps; std::sort is slower for three elements.
  if (t[0] > t[1]) std::swap(t[0], t[1]);
  if (t[1] > t[2]) std::swap(t[1], t[2]);
  if (t[0] > t[1]) std::swap(t[0], t[1]);
  return t;
}

struct FaceEntry {
  std::uint64_t rest;  // the two larger vertices, (mid << 32) | high
  std::uint64_t face;  // 4 * tet + local face
  std::uint32_t low;   // the smallest vertex
};

FaceEntry entry(const Tri& key, std::uint64_t face) {
  return {(std::uint64_t{key[1]} << 32) | key[2], face, key[0]};
}

// Number of low bits of the smallest vertex that stay inside one coarse bucket.
int coarse_shift(std::uint32_t max_index) {
  int bits = 0;
  while (bits < 32 && (max_index >> bits) != 0) ++bits;
  constexpr int kCoarseBits = 10;  // at most 1024 coarse buckets
  return std::max(0, bits - kCoarseBits);
}

// All faces grouped by coarse bucket: start[b] .. start[b + 1] in entries.
int bucket_faces(const TetMesh& mesh, std::vector<std::size_t>& start, std::vector<FaceEntry>& entries) {
  std::uint32_t max_index = 0;
  for (const auto& tet : mesh.tets) {
    for (std::uint32_t v : tet) max_index = std::max(max_index, v);
  }
  const int shift = coarse_shift(max_index);
  start.assign((static_cast<std::size_t>(max_index) >> shift) + 2, 0);
  for (const auto& tet : mesh.tets) {
    for (int f = 0; f < 4; ++f) ++start[(sorted(face_of(tet, f))[0] >> shift) + 1];
  }
  for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  entries.resize(mesh.tets.size() * 4);
  std::vector<std::size_t> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (int f = 0; f < 4; ++f) {
      const Tri key = sorted(face_of(mesh.tets[t], f));
      entries[fill[key[0] >> shift]++] =
          entry(key, 4 * static_cast<std::uint64_t>(t) + static_cast<std::uint64_t>(f));
    }
  }
  return shift;
}

// Marks the faces of one group with the same smallest vertex whose key occurs once.
void mark_single(std::vector<FaceEntry>::iterator first, std::vector<FaceEntry>::iterator last,
                 std::vector<std::uint8_t>& single) {
  std::sort(first, last, [](const FaceEntry& a, const FaceEntry& b) { return a.rest < b.rest; });
  for (auto run = first; run != last;) {
    auto end = run + 1;
    while (end != last && end->rest == run->rest) ++end;
    if (end - run == 1) single[run->face] = 1;
    run = end;
  }
}

// Splits one coarse bucket by smallest vertex (a counting sort that stays in
// cache) and marks the faces that occur once.
void mark_coarse_bucket(std::vector<FaceEntry>::iterator first, std::vector<FaceEntry>::iterator last,
                        int shift, std::vector<FaceEntry>& scratch, std::vector<std::size_t>& fine,
                        std::vector<std::uint8_t>& single) {
  const std::uint32_t mask = (std::uint32_t{1} << shift) - 1;
  fine.assign(static_cast<std::size_t>(mask) + 2, 0);
  for (auto it = first; it != last; ++it) ++fine[(it->low & mask) + 1];
  for (std::size_t v = 1; v < fine.size(); ++v) fine[v] += fine[v - 1];
  scratch.resize(static_cast<std::size_t>(last - first));
  std::vector<std::size_t> fill(fine.begin(), fine.end() - 1);
  for (auto it = first; it != last; ++it) scratch[fill[it->low & mask]++] = *it;
  for (std::size_t v = 0; v + 1 < fine.size(); ++v) {
    mark_single(scratch.begin() + static_cast<std::ptrdiff_t>(fine[v]),
                scratch.begin() + static_cast<std::ptrdiff_t>(fine[v + 1]), single);
  }
}

// Marks the faces whose key occurs exactly once.
std::vector<std::uint8_t> single_faces(const TetMesh& mesh) {
  std::vector<std::size_t> start;
  std::vector<FaceEntry> entries;
  const int shift = bucket_faces(mesh, start, entries);
  std::vector<std::uint8_t> single(entries.size(), 0);
  std::vector<FaceEntry> scratch;
  std::vector<std::size_t> fine;
  for (std::size_t b = 0; b + 1 < start.size(); ++b) {
    mark_coarse_bucket(entries.begin() + static_cast<std::ptrdiff_t>(start[b]),
                       entries.begin() + static_cast<std::ptrdiff_t>(start[b + 1]), shift, scratch, fine,
                       single);
  }
  return single;
}

}  // namespace

TriMesh extract_boundary_surface(const TetMesh& mesh) {
  TriMesh surface;
  surface.vertices = mesh.vertices;
  const std::vector<std::uint8_t> single = single_faces(mesh);
  // Output in (tet, local face) order so the result does not depend on the
  // bucket sort above.
  for (std::size_t id = 0; id < single.size(); ++id) {
    if (single[id]) surface.triangles.push_back(face_of(mesh.tets[id / 4], static_cast<int>(id % 4)));
  }
  return surface;
}

}  // namespace sinew
