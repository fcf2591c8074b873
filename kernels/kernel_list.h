/* kernel_list.h — the kernel registry: every kernel sinew runs, once.
 *
 * From this one list follow the Kernel enum (backends/backend.h), the
 * signature table create_program checks dispatches against
 * (backends/kernel_table.cpp), the CPU backend's dispatch table
 * (backends/cpu/cpu_device.cpp: the CPU reference function kernels::NAME)
 * and the GPU kernels looked up by name (the OpenCL kernel NAME and the
 * SPIR-V module NAME, both built from kernels/gpu/NAME.gpu). CMake checks
 * that every entry has its kernels/gpu/NAME.gpu and that some
 * kernels/cpu/ *.cpp defines NAME (cmake/CheckKernelRegistry.cmake).
 *
 * SINEW_KERNEL(NAME, BINDINGS, PARAMS, GROUP)
 *   NAME      the kernel's name in every language;
 *   BINDINGS  how many storage buffers it binds, in the order its comment
 *             in kernels/shared lists them;
 *   PARAMS    its parameter struct (kernels/shared), passed by value
 *             (OpenCL argument, Vulkan push constants, CPU pointer);
 *   GROUP     0: independent work items (launched in groups of 64 that
 *             never cooperate; the CPU runs any split of the items);
 *             N > 0: a cooperative kernel of fixed work groups of N items
 *             that share group memory and meet at group barriers. The CPU
 *             reference is then called once per group, with the group's
 *             index range [g, g + 1), and does the group's work in order.
 *
 * Adding a kernel: one line here, its PARAMS struct in kernels/shared, its
 * CPU reference in kernels/cpu and its GPU source kernels/gpu/NAME.gpu. */
#ifndef SINEW_KERNEL_LIST_H
#define SINEW_KERNEL_LIST_H

#define SINEW_KERNELS(SINEW_KERNEL)                                              \
  /* xPBD solver (kernels/shared/xpbd_params.h) */                               \
  SINEW_KERNEL(xpbd_predict, 3, PredictParams, 0)                                \
  SINEW_KERNEL(xpbd_external_force, 3, ExternalForceParams, 0)                   \
  SINEW_KERNEL(xpbd_update_velocity, 3, UpdateVelocityParams, 0)                 \
  SINEW_KERNEL(xpbd_solve_distance, 6, SolveParams, 0)                           \
  SINEW_KERNEL(xpbd_solve_volume, 6, SolveParams, 0)                             \
  /* FEM tets (kernels/shared/fem_params.h) */                                   \
  SINEW_KERNEL(xpbd_solve_neo_hookean, 5, SolveParams, 0)                        \
  SINEW_KERNEL(xpbd_solve_stvk, 5, SolveParams, 0)                               \
  SINEW_KERNEL(xpbd_solve_corotational, 5, SolveParams, 0)                       \
  /* thin tissue and threads (kernels/shared/thin_params.h) */                   \
  SINEW_KERNEL(xpbd_solve_area, 5, SolveParams, 0)                               \
  SINEW_KERNEL(xpbd_solve_dihedral, 5, SolveParams, 0)                           \
  SINEW_KERNEL(xpbd_solve_line_bending, 5, SolveParams, 0)                       \
  /* contacts (kernels/shared/contact_params.h): + targets; + previous position, \
   * colliders, contact impulses, level-set grids */                             \
  SINEW_KERNEL(xpbd_solve_attachment, 6, SolveParams, 0)                         \
  SINEW_KERNEL(xpbd_solve_point_attachment, 6, SolveParams, 0)                   \
  SINEW_KERNEL(xpbd_solve_body_attachment, 5, SolveParams, 0)                    \
  SINEW_KERNEL(xpbd_solve_contacts, 9, SolveParams, 0)                           \
  /* contacts between meshes (kernels/shared/mesh_contact_params.h) */           \
  SINEW_KERNEL(xpbd_solve_mesh_contacts, 10, MeshContactParams, 0)               \
  SINEW_KERNEL(xpbd_mesh_contacts_jacobi, 10, MeshContactParams, 0)              \
  SINEW_KERNEL(xpbd_mesh_contacts_gather, 6, MeshContactParams, 0)               \
  /* needles and sutures (kernels/shared/suture_params.h) */                     \
  SINEW_KERNEL(xpbd_sutures, 9, SutureParams, 0)                                 \
  /* device-side work of data-dependent size (kernels/shared/primitive_params.h) */ \
  SINEW_KERNEL(indirect_args, 2, IndirectArgsParams, 0)                          \
  SINEW_KERNEL(scan_blocks, 4, ScanParams, 256)                                  \
  SINEW_KERNEL(scan_add, 3, ScanParams, 256)                                     \
  SINEW_KERNEL(compact_scatter, 5, CompactParams, 0)                             \
  SINEW_KERNEL(radix_histogram, 3, RadixParams, 256)                             \
  SINEW_KERNEL(radix_scatter, 6, RadixParams, 256)                               \
  SINEW_KERNEL(reduce_blocks, 3, ReduceParams, 256)                              \
  /* per-frame statistics (kernels/shared/stats_params.h) */                     \
  SINEW_KERNEL(stats_kinetic_energy, 3, StatsParams, 0)                          \
  SINEW_KERNEL(stats_surface_volume, 3, StatsParams, 0)                          \
  SINEW_KERNEL(stats_tool_terms, 2, StatsParams, 0)                              \
  SINEW_KERNEL(stats_inverted_tets, 3, StatsParams, 0)                           \
  SINEW_KERNEL(reduce_dd_blocks, 3, ReduceDdParams, 256)                         \
  /* the sweeps' accelerators (kernels/shared/accelerator_params.h) */           \
  SINEW_KERNEL(xpbd_chebyshev, 3, ChebyshevParams, 0)                            \
  SINEW_KERNEL(xpbd_warm_start, 4, WarmStartParams, 0)                          \
  /* Vertex Block Descent (kernels/shared/vbd_params.h) */                       \
  SINEW_KERNEL(vbd_initial_guess, 2, VbdInitParams, 0)                           \
  SINEW_KERNEL(vbd_solve_vertices, 8, VbdSolveParams, 0)                         \
  /* the device BVH (kernels/shared/bvh_params.h) */                             \
  SINEW_KERNEL(bvh_morton_codes, 3, MortonParams, 0)                             \
  SINEW_KERNEL(bvh_karras_nodes, 3, KarrasParams, 0)                             \
  SINEW_KERNEL(bvh_refit_pass, 6, RefitParams, 0)                                \
  SINEW_KERNEL(bvh_self_pairs, 7, SelfPairsParams, 0)                            \
  SINEW_KERNEL(bvh_tree_pairs, 7, TreePairsParams, 0)                            \
  /* the device narrow phase (kernels/shared/narrow_phase_params.h) */           \
  SINEW_KERNEL(narrow_triangle_pairs, 6, TrianglePairsParams, 0)                \
  /* the contacts' colouring (kernels/shared/contact_coloring_params.h) */      \
  SINEW_KERNEL(contact_coloring, 8, ContactColoringParams, 0)                   \
  /* continuous collision queries (kernels/shared/ccd_params.h) */              \
  SINEW_KERNEL(ccd_queries, 3, CcdParams, 0)                                     \
  /* level sets (kernels/shared/level_set_params.h) */                          \
  SINEW_KERNEL(level_set_sample, 3, LevelSetSampleParams, 0)                    \
  /* the fixed-radius neighbour search (kernels/shared/neighbour_params.h) */   \
  SINEW_KERNEL(nbr_cells, 5, NeighbourParams, 0)                                 \
  SINEW_KERNEL(nbr_ranges, 5, NeighbourParams, 0)                                \
  SINEW_KERNEL(nbr_gather, 6, NeighbourParams, 0)                                \
  SINEW_KERNEL(nbr_query, 7, NeighbourParams, 0)                                 \
  /* smoothed-particle hydrodynamics (kernels/shared/sph_params.h) */             \
  SINEW_KERNEL(sph_density, 5, SphParams, 0)                                    \
  SINEW_KERNEL(sph_gather, 4, SphParams, 0)                                     \
  SINEW_KERNEL(sph_step, 10, SphParams, 0)                                      \
  SINEW_KERNEL(sph_fluid_cells, 4, SphParams, 0)                                \
  SINEW_KERNEL(sph_boundary_force, 8, SphParams, 0)                             \
  /* surface tension (kernels/shared/sph_tension_params.h) */                   \
  SINEW_KERNEL(sph_normals, 6, TensionParams, 0)                                \
  SINEW_KERNEL(sph_tension, 8, TensionParams, 0)                                \
  /* particles that come and go (kernels/shared/sph_flow_params.h) */          \
  SINEW_KERNEL(sph_boundary_move, 5, SphFlowParams, 0)                          \
  SINEW_KERNEL(sph_sink_flags, 4, SphFlowParams, 0)                             \
  SINEW_KERNEL(sph_pack, 7, SphFlowParams, 0)                                   \
  SINEW_KERNEL(sph_emit_flags, 8, SphFlowParams, 0)                             \
  SINEW_KERNEL(sph_emit, 7, SphFlowParams, 0)                                   \
  SINEW_KERNEL(sph_emit_commit, 4, SphFlowParams, 0)                            \
  /* position-based fluids (kernels/shared/pbf_params.h) */                     \
  SINEW_KERNEL(pbf_predict, 4, PbfParams, 0)                                    \
  SINEW_KERNEL(pbf_lambda, 6, PbfParams, 0)                                     \
  SINEW_KERNEL(pbf_delta, 6, PbfParams, 0)                                      \
  SINEW_KERNEL(pbf_finish, 9, PbfParams, 0)                                     \
  /* a fluid coupled with its scene's tissue (kernels/shared/fluid_coupling_params.h) */ \
  SINEW_KERNEL(fluid_boundary_follow, 7, FluidCouplingParams, 0)                \
  SINEW_KERNEL(fluid_forces_on_tissue, 6, FluidCouplingParams, 0)

#endif /* SINEW_KERNEL_LIST_H */
