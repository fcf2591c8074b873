// test_support.h — helpers shared by the test files: the backends to run
// every test body on, and small scene builders.
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "backends/kernel_table.h"
#include "sinew/mesh.h"
#include "sinew/simulation.h"

namespace sinew::test {

/// Every backend built into this library; a test body is run on each.
inline std::vector<std::string> backends() { return built_backends(); }

/// Names parameterised tests after their backend ("Backends/Xpbd.Name/opencl").
inline std::string backend_name(const ::testing::TestParamInfo<std::string>& info) { return info.param; }

/// Why `backend` has no device here ("" when it has one); probed once.
inline std::string missing_device(const std::string& backend) {
  static std::map<std::string, std::string> known;
  if (auto it = known.find(backend); it != known.end()) return it->second;
  auto device = create_device({.backend = backend, .quiet = true});
  return known[backend] = device.ok() ? "" : device.error().message();
}

/// Fixture of every test body run on each backend: a backend that is built
/// but has no device on this machine (no GPU, no driver) skips the test.
class BackendTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (const std::string why = missing_device(GetParam()); !why.empty())
      GTEST_SKIP() << "backend " << GetParam() << " has no device here: " << why;
  }
};

/// Creates a simulation on `backend`, skipping the test when the backend is
/// built but has no device here (e.g. no GPU), failing it on any other error.
inline Result<Simulation> create_or_skip(const SceneDesc& scene, const std::string& backend, int threads = 0) {
  return Simulation::create(scene, {.backend = backend, .threads = threads, .quiet = true});
}

/// One dispatch of `kernel` over one item, every binding on `buffer`,
/// parameters zeroed: enough for create_program to look the kernel up and
/// build it (not meant to be run).
inline FrameProgram single_dispatch_program(Kernel kernel, BufferHandle buffer) {
  Dispatch d;
  d.kernel = kernel;
  d.count = 1;  // count-0 dispatches are dropped
  d.binding_count = kernel_signature(kernel).bindings;
  for (std::uint32_t b = 0; b < d.binding_count; ++b) d.bindings[b] = buffer;
  d.params_bytes = kernel_signature(kernel).params_bytes;
  FrameProgram p;
  p.dispatch_raw(d);
  return p;
}

inline std::string data_path(const std::string& relative) { return std::string(SINEW_DATA_DIR) + "/" + relative; }

/// A box of nx*ny*nz cells of edge `cell` [m], 6 tets per cell.
inline TetMesh box_mesh(int nx, int ny, int nz, double cell) {
  auto mesh = make_tet_grid({.nx = nx, .ny = ny, .nz = nz, .origin = {0, 0, 0}, .cell_size = {cell, cell, cell}});
  EXPECT_TRUE(mesh.ok()) << (mesh.ok() ? "" : mesh.error().message());
  return mesh.ok() ? *mesh : TetMesh{};
}

}  // namespace sinew::test

#define SINEW_ASSERT_OK(expr)                                       \
  do {                                                              \
    const auto& sinew_status_ = (expr);                             \
    ASSERT_TRUE(sinew_status_.ok()) << sinew_status_.error().message(); \
  } while (0)
