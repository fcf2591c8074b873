// fuzz_stl.cpp — libFuzzer target for read_stl (binary STL; an ASCII STL is
// a named error). Input: the file's bytes. Checked (fuzz_support.h): a
// documented error, or a surface whose indices are in range and whose
// closedness check answers within its bound.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const auto path = fuzz::scratch_file("m.stl", {reinterpret_cast<const char*>(data), size});
  const Result<TriMesh> surface = read_stl(path);
  if (!surface) {
    fuzz::check_error(surface.error(), {ErrorCode::bad_input_file, ErrorCode::out_of_memory}, "read_stl");
    return 0;
  }
  if (surface->triangles.empty()) fuzz::fail("read_stl returned no triangles");
  for (const Vec3d& v : surface->vertices)
    for (double c : v)
      if (!std::isfinite(c)) fuzz::fail("read_stl returned a non-finite coordinate");
  fuzz::check_surface(*surface, "read_stl");
  return 0;
}
