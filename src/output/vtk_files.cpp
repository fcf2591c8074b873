// vtk_files.cpp — the VTK XML writers' shared helpers (vtk_files.h).
#include "output/vtk_files.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace sinew::vtk_files {

namespace fs = std::filesystem;

std::string xml_attribute(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string relative_name(const fs::path& file, const fs::path& folder) {
  std::error_code ec;
  const fs::path abs_file = fs::absolute(file, ec).lexically_normal();
  if (ec) return file.generic_string();
  const fs::path abs_folder = fs::absolute(folder.empty() ? fs::path(".") : folder, ec).lexically_normal();
  if (ec) return file.generic_string();
  const fs::path rel = abs_file.lexically_relative(abs_folder);
  // Empty when the two have no common root (e.g. other drives): keep it absolute.
  return rel.empty() ? abs_file.generic_string() : rel.generic_string();
}

Status write_file(const fs::path& path, std::string_view bytes) {
  std::error_code ec;
  const fs::path parent = path.parent_path();
  if (!parent.empty()) {
    fs::create_directories(parent, ec);
    if (ec)
      return Error(ErrorCode::bad_input_file,
                   path.string() + ": cannot create folder " + parent.string() + " (" + ec.message() + ")");
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    return Error(ErrorCode::bad_input_file,
                 path.string() + ": cannot open file for writing (" + std::strerror(errno) + ")");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return Error(ErrorCode::bad_input_file, path.string() + ": write failed (disk full?)");
  return {};
}

}  // namespace sinew::vtk_files
