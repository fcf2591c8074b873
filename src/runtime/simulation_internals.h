// simulation_internals.h — what the library's tests and benchmarks may see
// of a Simulation beyond the public API: its device and its frame program
// (both internal types; users describe scenes, not dispatches).
#pragma once

#include "backends/backend.h"
#include "sinew/simulation.h"

namespace sinew {

struct SimulationInternals {
  static const Device& device(const Simulation& sim);
  static const FrameProgram& program(const Simulation& sim);
  static double frame_length(const Simulation& sim);  ///< SolverSettings::time_step [s]
};

}  // namespace sinew
