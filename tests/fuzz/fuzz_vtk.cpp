// fuzz_vtk.cpp — libFuzzer target for read_vtk (legacy VTK, ASCII and
// BINARY). Input: the file's bytes. See fuzz_support.h for what is checked.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const auto path = fuzz::scratch_file("m.vtk", {reinterpret_cast<const char*>(data), size});
  fuzz::check_tet_mesh_result(read_vtk(path), "read_vtk");
  return 0;
}
