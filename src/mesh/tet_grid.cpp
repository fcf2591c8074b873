// make_tet_grid: a box of nx*ny*nz cells, each split into 5 or 6 tets.
//
// Both splits are built from a per-cell template of local corner ids
// (corner c = dx + 2*dy + 4*dz for the cell corner at offset (dx, dy, dz)).
// Each template tet is oriented once on the unit cube; scaling the axes by
// positive cell sizes is a linear map with positive determinant, so the
// orientation carries over to every cell of every grid.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "math/vec3.h"
#include "sinew/mesh.h"

namespace sinew {
namespace {

using LocalTet = std::array<int, 4>;

Vec3d unit_corner(int c) {
  return {static_cast<double>(c & 1), static_cast<double>((c >> 1) & 1), static_cast<double>((c >> 2) & 1)};
}

double unit_orientation(const LocalTet& t) {
  const Vec3d a = unit_corner(t[0]), b = unit_corner(t[1]), c = unit_corner(t[2]), d = unit_corner(t[3]);
  return math::dot(math::sub(b, a), math::cross(math::sub(c, a), math::sub(d, a)));
}

// Swaps two vertices of every negatively oriented template tet.
template <std::size_t N>
std::array<LocalTet, N> oriented(std::array<LocalTet, N> tets) {
  for (LocalTet& t : tets) {
    if (unit_orientation(t) < 0.0) std::swap(t[2], t[3]);
  }
  return tets;
}

// Kuhn/Freudenthal split: one tet per axis order, walking from corner 0 to
// corner 7 one axis step at a time. Every cell uses the same main diagonal,
// so each shared face is cut by the same face diagonal from both sides.
std::array<LocalTet, 6> six_tet_template() {
  const std::array<std::array<int, 3>, 6> axis_orders{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::array<LocalTet, 6> tets{};
  for (std::size_t t = 0; t < 6; ++t) {
    const int first = 1 << axis_orders[t][0];
    const int second = first | (1 << axis_orders[t][1]);
    tets[t] = {0, first, second, 7};
  }
  return oriented(tets);
}

// Five-tet split: a central tet on four alternating corners plus the four
// corner tets cut off around it. `mirrored` picks the other set of
// alternating corners; alternating it with cell parity makes the face
// diagonals of neighbouring cells coincide.
std::array<LocalTet, 5> five_tet_template(bool mirrored) {
  // Corners 0, 3, 5, 6 have an even number of set bits; 1, 2, 4, 7 odd.
  const std::array<int, 4> even{0, 3, 5, 6};
  const std::array<int, 4> odd{1, 2, 4, 7};
  const std::array<int, 4>& central = mirrored ? odd : even;
  const std::array<int, 4>& tips = mirrored ? even : odd;
  std::array<LocalTet, 5> tets{};
  tets[0] = {central[0], central[1], central[2], central[3]};
  for (std::size_t t = 0; t < 4; ++t) {
    // The three central corners adjacent to a tip differ from it in one bit.
    LocalTet tet{tips[t], 0, 0, 0};
    int n = 1;
    for (int bit = 0; bit < 3; ++bit) tet[static_cast<std::size_t>(n++)] = tips[t] ^ (1 << bit);
    tets[t + 1] = tet;
  }
  return oriented(tets);
}

std::string number_text(double v) {
  // to_string prints fixed-point; a short %g style reads better for 1e-300 or nan.
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

Status validate(const TetGridDesc& d) {
  const std::array<std::pair<const char*, int>, 3> counts{{{"nx", d.nx}, {"ny", d.ny}, {"nz", d.nz}}};
  for (const auto& [name, n] : counts) {
    if (n < 1) {
      return Error(ErrorCode::bad_parameter,
                   "make_tet_grid: " + std::string(name) + " must be >= 1 (got " + std::to_string(n) + ")");
    }
  }
  for (int a = 0; a < 3; ++a) {
    const double h = d.cell_size[static_cast<std::size_t>(a)];
    if (!std::isfinite(h) || !(h > 0.0)) {
      return Error(ErrorCode::bad_parameter,
                   "make_tet_grid: cell_size[" + std::to_string(a) + "] must be finite and > 0 (got " +
                   number_text(h) + ")");
    }
    const double o = d.origin[static_cast<std::size_t>(a)];
    if (!std::isfinite(o)) {
      return Error(ErrorCode::bad_parameter,
                   "make_tet_grid: origin[" + std::to_string(a) + "] must be finite (got " + number_text(o) +
                   ")");
    }
    const double far = o + static_cast<double>(counts[static_cast<std::size_t>(a)].second) * h;
    if (!std::isfinite(far)) {
      return Error(ErrorCode::bad_parameter,
                   "make_tet_grid: origin[" + std::to_string(a) + "] + n * cell_size[" + std::to_string(a) +
                   "] overflows a double");
    }
  }
  if (d.split != TetsPerCell::five && d.split != TetsPerCell::six) {
    return Error(ErrorCode::bad_parameter, "make_tet_grid: split must be TetsPerCell::five or TetsPerCell::six");
  }
  // Vertex indices are uint32; the product of three ints needs checking in
  // steps because it can overflow even 64 bits.
  const std::uint64_t limit = std::numeric_limits<std::uint32_t>::max();
  std::uint64_t vertices = 1;
  for (const auto& [name, n] : counts) {
    vertices *= static_cast<std::uint64_t>(n) + 1;  // <= 2^32 * 2^31 before the check below
    if (vertices > limit) {
      return Error(ErrorCode::bad_parameter,
                   "make_tet_grid: (nx+1)*(ny+1)*(nz+1) vertices exceed the 32-bit index limit " +
                   std::to_string(limit) + " (nx=" + std::to_string(d.nx) + ", ny=" + std::to_string(d.ny) +
                   ", nz=" + std::to_string(d.nz) + ")");
    }
  }
  return {};
}

struct GridIndexer {
  std::uint32_t sx, sy;  // vertices per row and rows per layer
  std::uint32_t operator()(int i, int j, int k) const {
    return static_cast<std::uint32_t>(i) +
           sx * (static_cast<std::uint32_t>(j) + sy * static_cast<std::uint32_t>(k));
  }
};

std::vector<Vec3d> grid_vertices(const TetGridDesc& d) {
  std::vector<Vec3d> vertices;
  vertices.reserve(static_cast<std::size_t>(d.nx + 1) * static_cast<std::size_t>(d.ny + 1) *
                   static_cast<std::size_t>(d.nz + 1));
  for (int k = 0; k <= d.nz; ++k) {
    for (int j = 0; j <= d.ny; ++j) {
      for (int i = 0; i <= d.nx; ++i) {
        vertices.push_back({d.origin[0] + i * d.cell_size[0], d.origin[1] + j * d.cell_size[1],
                            d.origin[2] + k * d.cell_size[2]});
      }
    }
  }
  return vertices;
}

template <std::size_t N>
void emit_cell(const std::array<LocalTet, N>& templ, const std::array<std::uint32_t, 8>& corner,
               std::vector<std::array<std::uint32_t, 4>>& tets) {
  for (const LocalTet& t : templ) {
    tets.push_back({corner[static_cast<std::size_t>(t[0])], corner[static_cast<std::size_t>(t[1])],
                    corner[static_cast<std::size_t>(t[2])], corner[static_cast<std::size_t>(t[3])]});
  }
}

std::vector<std::array<std::uint32_t, 4>> grid_tets(const TetGridDesc& d) {
  const auto six = six_tet_template();
  const std::array<std::array<LocalTet, 5>, 2> five{five_tet_template(false), five_tet_template(true)};
  const std::size_t per_cell = d.split == TetsPerCell::six ? 6 : 5;
  std::vector<std::array<std::uint32_t, 4>> tets;
  tets.reserve(per_cell * static_cast<std::size_t>(d.nx) * static_cast<std::size_t>(d.ny) *
               static_cast<std::size_t>(d.nz));
  const GridIndexer index{static_cast<std::uint32_t>(d.nx + 1), static_cast<std::uint32_t>(d.ny + 1)};
  for (int k = 0; k < d.nz; ++k) {
    for (int j = 0; j < d.ny; ++j) {
      for (int i = 0; i < d.nx; ++i) {
        std::array<std::uint32_t, 8> corner{};
        for (int c = 0; c < 8; ++c) {
          corner[static_cast<std::size_t>(c)] = index(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2));
        }
        if (d.split == TetsPerCell::six) {
          emit_cell(six, corner, tets);
        } else {
          emit_cell(five[static_cast<std::size_t>((i + j + k) & 1)], corner, tets);
        }
      }
    }
  }
  return tets;
}

}  // namespace

Result<TetMesh> make_tet_grid(const TetGridDesc& desc) {
  if (Status s = validate(desc); !s) return s.error();
  try {
    TetMesh mesh;
    mesh.vertices = grid_vertices(desc);
    mesh.tets = grid_tets(desc);
    return mesh;
  } catch (const std::bad_alloc&) {
    // A grid within the uint32 vertex limit can still need more memory than
    // the machine has (up to ~25e9 tets); report it instead of throwing.
    return Error(ErrorCode::out_of_memory,
                 "make_tet_grid: out of memory for a " + std::to_string(desc.nx) + " x " +
                 std::to_string(desc.ny) + " x " + std::to_string(desc.nz) + " grid");
  } catch (const std::length_error&) {
    return Error(ErrorCode::out_of_memory,
                 "make_tet_grid: grid of " + std::to_string(desc.nx) + " x " + std::to_string(desc.ny) +
                 " x " + std::to_string(desc.nz) + " cells is too large");
  }
}

}  // namespace sinew

namespace sinew {

TetMesh drop_unused_vertices(const TetMesh& mesh) {
  TetMesh out;
  std::vector<std::uint32_t> renumber(mesh.vertices.size(), ~0u);
  out.tets.reserve(mesh.tets.size());
  for (const auto& tet : mesh.tets) {
    std::array<std::uint32_t, 4> kept{};
    for (int k = 0; k < 4; ++k) {
      std::uint32_t& to = renumber[tet[k]];
      if (to == ~0u) {
        to = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[tet[k]]);
      }
      kept[k] = to;
    }
    out.tets.push_back(kept);
  }
  return out;
}

}  // namespace sinew
