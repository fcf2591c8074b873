// solve_order.h — the order of the constraint kinds within an iteration:
// the scene compiler lays the blocks out in this order (compile_scene) and
// the frame program sweeps them in it (src/program/xpbd_program.cpp).
//
// An xPBD iteration is Gauss-Seidel across blocks: each block is solved
// with the positions the blocks before it left, so where constraints
// disagree, the one solved last holds exactly at the end of the sweep.
// Hence:
//  - the bodies' own constraints first: edges and tet volumes, the FEM
//    materials, then thin bodies and threads. Their order among themselves
//    is the one the Kernel enum used to impose; it is kept because any other
//    order gives other bits, not because one is physically better;
//  - attachments between bodies after them (they couple bodies, as a
//    body's own constraints couple its particles), before the graspers;
//  - attachments (a grasper holding a vertex) after them, so a held vertex
//    ends each sweep at its target however the tissue pulls on it;
//  - contacts last, so a sweep ends with no particle inside a collider or a
//    tool: non-penetration wins over elasticity and over a grasp.
// Changing this table changes every result that has more than one kind of
// constraint.
#pragma once

#include <cstddef>
#include <iterator>
#include <string_view>

#include "backends/kernel.h"
#include "kernel_list.h"

namespace sinew {

/// The constraint-solve kernels, in the order they are solved.
inline constexpr Kernel kSolveOrder[] = {
    Kernel::xpbd_solve_distance,      // tet and triangle edges, thread segments
    Kernel::xpbd_solve_volume,        // tet volumes
    Kernel::xpbd_solve_neo_hookean,   // FEM tets
    Kernel::xpbd_solve_stvk,
    Kernel::xpbd_solve_corotational,
    Kernel::xpbd_solve_area,          // thin bodies
    Kernel::xpbd_solve_dihedral,
    Kernel::xpbd_solve_line_bending,  // threads
    Kernel::xpbd_solve_body_attachment,  // bodies attached to each other: between bodies, before graspers
    Kernel::xpbd_solve_attachment,    // graspers: after the bodies
    Kernel::xpbd_solve_point_attachment,  // graspers' points inside triangles
    Kernel::xpbd_solve_contacts,      // colliders and tools: last, they win
};

/// solve_rank's answer for a kernel that is not in kSolveOrder.
inline constexpr std::size_t kNotSolved = std::size(kSolveOrder);

/// The position of `kernel` in kSolveOrder, or kNotSolved.
constexpr std::size_t solve_rank(Kernel kernel) {
  for (std::size_t i = 0; i < std::size(kSolveOrder); ++i)
    if (kSolveOrder[i] == kernel) return i;
  return kNotSolved;
}

namespace detail {

// True when kSolveOrder holds every constraint-solve kernel of the registry
// (kernels/kernel_list.h: those whose parameters are SolveParams) once, and
// nothing else; a solve kernel added to the registry fails the build here
// until it is given its place.
constexpr bool solve_order_is_complete() {
  struct Entry {
    Kernel kernel;
    std::string_view params;
  };
  constexpr Entry registry[] = {
#define SINEW_SOLVE_ORDER_ENTRY(name, bindings, params, group) {Kernel::name, #params},
      SINEW_KERNELS(SINEW_SOLVE_ORDER_ENTRY)
#undef SINEW_SOLVE_ORDER_ENTRY
  };
  std::size_t solves = 0;
  for (const Entry& e : registry) {
    const bool solve = e.params == "SolveParams";
    if (solve != (solve_rank(e.kernel) != kNotSolved)) return false;
    solves += solve ? 1 : 0;
  }
  return solves == std::size(kSolveOrder);  // and so no kernel twice
}

}  // namespace detail

static_assert(detail::solve_order_is_complete(),
              "kSolveOrder must list every kernel of kernels/kernel_list.h that takes SolveParams, once");

}  // namespace sinew
