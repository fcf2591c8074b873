// fuzz_gmsh.cpp — libFuzzer target for read_gmsh (.msh, ASCII 2.x and 4.x).
// Input: the file's bytes. See fuzz_support.h for what is checked.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const auto path = fuzz::scratch_file("m.msh", {reinterpret_cast<const char*>(data), size});
  fuzz::check_tet_mesh_result(read_gmsh(path), "read_gmsh");
  return 0;
}
