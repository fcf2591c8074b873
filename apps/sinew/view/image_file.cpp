// image_file.cpp — see image_file.h.
#include "view/image_file.h"

#include <cstdio>
#include <string>

namespace sinew::view {

Status write_ppm(const std::filesystem::path& path, int width, int height, std::span<const std::uint8_t> rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3)
    return Error{ErrorCode::bad_parameter, path.string() + ": image of " + std::to_string(rgb.size()) +
                                               " bytes is not " + std::to_string(width) + " x " +
                                               std::to_string(height) + " RGB pixels"};
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return Error{ErrorCode::bad_input_file, path.string() + ": cannot be written"};
  const bool header = std::fprintf(f, "P6\n%d %d\n255\n", width, height) > 0;
  const bool body = std::fwrite(rgb.data(), 1, rgb.size(), f) == rgb.size();
  const bool closed = std::fclose(f) == 0;
  if (!header || !body || !closed) return Error{ErrorCode::bad_input_file, path.string() + ": write failed"};
  return {};
}

}  // namespace sinew::view
