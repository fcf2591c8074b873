// data_folder.cpp — the folder a scene file's "data:" names are found in.
// The packed meshes (kidney_57k, liver_382k, Armadillo13K) exist only
// unpacked in a build's data folder, never beside the scene files, so a
// scene names them relative to that folder rather than to itself. Only this
// file carries the build's path (SINEW_DATA_DIR, a compile definition), so
// changing it recompiles one file.
#include <cstdlib>

#include "scene_file/readers.h"

#ifndef SINEW_DATA_DIR
#error "SINEW_DATA_DIR (the build's data folder) must be defined for data_folder.cpp"
#endif

namespace sinew::scene_file {

DataFolder data_folder() {
  // The environment wins: an installed runner, or a data folder elsewhere.
  if (const char* env = std::getenv("SINEW_DATA_DIR"); env != nullptr && *env != '\0') return {env, true};
  return {SINEW_DATA_DIR, false};
}

}  // namespace sinew::scene_file
