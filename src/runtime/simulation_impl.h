// simulation_impl.h — the state behind sinew::Simulation, shared by the
// files that implement it: simulation.cpp (create, step, read-back, error
// measurement) and simulation_contacts.cpp (colliders, targets, tools).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "compiler/scene_compiler.h"
#include "program/xpbd_program.h"
#include "runtime/contact_state.h"
#include "sinew/simulation.h"

namespace sinew {

struct Simulation::Impl {
  std::unique_ptr<Device> device;
  XpbdBuffers buffers;
  FrameProgram program;
  ProgramHandle prepared;
  SceneInfo info;
  FrameStats stats;
  double time_step = 0.0;
  bool measure_errors = true;
  std::vector<std::uint32_t> block_sizes;             // constraints per block, for the residual read-back
  std::vector<std::array<std::uint32_t, 4>> tets;    // every tet body's tets, as particle indices
  double rest_volume = 0.0;                           // their total rest volume [m^3]

  Status measure(FrameStats& stats) const;

  // simulation_contacts.cpp: host copies of the collider and target
  // buffers (rewritten before each frame) and the tools' rigid state.
  std::vector<float> colliders;
  std::vector<float> targets;
  ContactState contacts;
  Status init_contacts(const SceneDesc& scene, const CompiledScene& compiled);
  Status before_frame();  ///< integrates the tools (rigid_tool.h), uploads what moved
  Status after_frame();   ///< settles what moved, reduces the tissue's reaction on each tool
};


}  // namespace sinew
