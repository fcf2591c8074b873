// fuzz_tetgen.cpp — libFuzzer target for read_tetgen (.node + .ele).
// Input: the .node file's bytes, a NUL byte, the .ele file's bytes (no NUL:
// the whole input is the .node and the .ele is empty). See fuzz_support.h
// for what is checked.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sinew;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find('\0');
  const std::string_view node = input.substr(0, split);
  const std::string_view ele = split == std::string_view::npos ? std::string_view() : input.substr(split + 1);
  fuzz::scratch_file("m.node", node);
  fuzz::scratch_file("m.ele", ele);
  fuzz::check_tet_mesh_result(read_tetgen(fuzz::scratch_dir() / "m"), "read_tetgen");
  return 0;
}
