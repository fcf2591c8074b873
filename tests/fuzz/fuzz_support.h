// fuzz_support.h — what the fuzz targets under tests/fuzz share: a scratch
// folder for the files the readers take (the readers read paths, so each
// input is written to a file first), the contract checks every target runs
// on a reader's answer, and the failure that libFuzzer (or the corpus
// replay, replay_main.cpp) reports as a crash.
//
// A reader's contract, checked on every input:
//  - it returns, without crashing, hanging, leaking or throwing (an escaped
//    exception is a crash too: nothing here catches it);
//  - an error has one of the codes its documentation names, and a message;
//  - a result passes the checks a user would run next (check_tet_mesh,
//    extract_boundary_surface + check_closed_surface, ...).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <string_view>

#include "sinew/mesh.h"
#include "sinew/result.h"

namespace sinew::fuzz {

/// Reports a broken contract and aborts: a crash to libFuzzer and to the
/// replay test.
[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "sinew fuzz: contract broken: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

/// With $SINEW_FUZZ_VERBOSE set, each input's outcome is printed (to see
/// what a corpus file exercises).
inline bool verbose() {
  static const bool on = std::getenv("SINEW_FUZZ_VERBOSE") != nullptr;
  return on;
}

inline void note(const std::string& what) {
  if (verbose()) std::fprintf(stderr, "sinew fuzz: %s\n", what.c_str());
}

/// A folder of this process's own (fuzzers and ctest run in parallel),
/// removed at exit: $SINEW_FUZZ_TMP, else the system's temporary folder.
inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      const char* env = std::getenv("SINEW_FUZZ_TMP");
      const std::filesystem::path base =
          env && *env ? std::filesystem::path(env) : std::filesystem::temp_directory_path();
      path = base / ("sinew_fuzz_" + std::to_string(::getpid()));
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// Writes `bytes` to `path` (replacing it); a failure to write is the
/// harness's, not the reader's, so it aborts.
inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  out.close();
  if (!out) fail("cannot write the scratch file " + path.string());
}

/// The scratch file `name`, holding `bytes`.
inline std::filesystem::path scratch_file(const std::string& name, std::string_view bytes) {
  std::filesystem::path path = scratch_dir() / name;
  write_file(path, bytes);
  return path;
}

/// An error must carry a documented code and a message.
inline void check_error(const Error& error, std::initializer_list<ErrorCode> allowed, const char* reader) {
  bool ok = false;
  for (ErrorCode code : allowed) ok = ok || error.code() == code;
  if (!ok) fail(std::string(reader) + " returned an undocumented error code " + std::to_string(int(error.code())) +
                ": " + error.message());
  if (error.message().empty()) fail(std::string(reader) + " returned an error without a message");
  note(std::string(reader) + ": error: " + error.message());
}

/// What a user does with a surface: is it closed? The check is bounded
/// (capacity_exceeded names the bound); anything else it says is an answer.
inline void check_surface(const TriMesh& surface, const char* reader) {
  for (const auto& t : surface.triangles)
    for (std::uint32_t v : t)
      if (v >= surface.vertices.size()) fail(std::string(reader) + ": a triangle's vertex index is out of range");
  const Result<SurfaceReport> report = check_closed_surface(surface);
  if (!report) {
    check_error(report.error(), {ErrorCode::capacity_exceeded}, "check_closed_surface");
    return;
  }
  note(std::string(reader) + ": " + std::to_string(surface.triangles.size()) + " surface triangles, " +
       (report->closed() ? "closed" : "not closed"));
}

/// What a user does with a tet mesh a reader returned: the reader promises
/// it passes check_tet_mesh; then its boundary, and whether that is closed.
inline void check_tet_mesh_result(const Result<TetMesh>& mesh, const char* reader) {
  if (!mesh) {
    check_error(mesh.error(), {ErrorCode::bad_input_file, ErrorCode::out_of_memory}, reader);
    return;
  }
  if (const Status s = check_tet_mesh(*mesh, reader); !s)
    fail(std::string(reader) + " returned a mesh that fails check_tet_mesh: " + s.error().message());
  check_surface(extract_boundary_surface(*mesh), reader);
}

}  // namespace sinew::fuzz
