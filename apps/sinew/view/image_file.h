// image_file.h — the viewer's screenshots (docs/viewer.md) as binary PPM
// (P6: a short text header, then 8-bit RGB rows from the top), which image
// viewers, ImageMagick and Python read without a library.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

#include "sinew/result.h"

namespace sinew::view {

/// Writes [in] rgb (width x height x 3 bytes, top row first) to `path`.
/// Errors (bad_input_file) name the file that cannot be written;
/// bad_parameter for a buffer whose size is not width x height x 3.
Status write_ppm(const std::filesystem::path& path, int width, int height, std::span<const std::uint8_t> rgb);

}  // namespace sinew::view
