// vtk_files.h — what the VTK XML writers share: attribute escaping, file
// names relative to a collection's folder, and writing a file whole.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "sinew/result.h"

namespace sinew::vtk_files {

/// [in] s escaped for an XML attribute value in double quotes.
std::string xml_attribute(std::string_view s);

/// The name to write for [in] file in a collection (.pvd, .vtm) in [in]
/// folder: relative when possible, else absolute.
std::string relative_name(const std::filesystem::path& file, const std::filesystem::path& folder);

/// Creates missing parent folders, then writes [in] bytes to [in] path.
/// Errors (bad_input_file) name the file and the reason.
Status write_file(const std::filesystem::path& path, std::string_view bytes);

}  // namespace sinew::vtk_files
