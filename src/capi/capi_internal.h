// capi_internal.h — what the C API's sources (src/capi/*.cpp, sinew/sinew.h)
// share: the handle behind sinew_simulation*, the guard that turns every
// error and exception into a sinew_status with its thread-local message,
// and the checks of the caller's pointers and buffers.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <exception>
#include <new>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sinew/result.h"
#include "sinew/scene_file.h"
#include "sinew/simulation.h"
#include "sinew/sinew.h"

// The opaque handle: the scene file (its meshes give the surfaces), the
// Simulation made from it, the script's player and the events of the
// frames. Global namespace: sinew.h declares it there.
struct sinew_simulation {
  sinew::SceneFile file;
  std::optional<sinew::Simulation> sim;  // always engaged once created (Simulation has no default)
  std::optional<sinew::ScriptPlayer> player;
  std::unique_ptr<sinew::haptics::ScriptedHands> hands;  // the file's scripted hands, played with the script
  bool play_script = true;
  int frames_done = 0;
  // Events of calls and script actions since the last step, and of the last frame.
  std::vector<sinew_event> pending_events;
  std::vector<sinew_event> last_events;
  // Each needle's punctures after the last step (to tell made from ended ones).
  std::vector<std::vector<sinew::Puncture>> punctures;
  // Each tet body's boundary surface of its whole mesh, for scenes without
  // topology changes (whose surface never changes).
  std::vector<std::vector<std::array<std::uint32_t, 3>>> fixed_tet_surfaces;
  std::vector<float> scratch;  // read-back buffer, reused
};

namespace sinew::capi {

// Records `message` as this thread's last error and returns `status`.
sinew_status fail(sinew_status status, std::string message);
// An Error's code as a sinew_status, its message recorded.
sinew_status fail(const Error& error);
// OK, or the Status's error recorded.
inline sinew_status status_of(const Status& s) { return s ? SINEW_OK : fail(s.error()); }

// Runs `body` (returning sinew_status) with every exception turned into a
// code: the C API's functions are wrapped in it, so nothing is thrown
// across the C boundary.
template <class F>
sinew_status guarded(const char* call, F&& body) noexcept {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return fail(SINEW_OUT_OF_MEMORY, std::string(call) + ": out of host memory");
  } catch (const std::exception& e) {
    return fail(SINEW_INTERNAL, std::string(call) + ": " + e.what());
  } catch (...) {
    return fail(SINEW_INTERNAL, std::string(call) + ": an unknown exception");
  }
}

// SINEW_NULL_ARGUMENT naming `what` when `p` is null.
inline sinew_status need(const void* p, const char* call, const char* what) {
  if (p) return SINEW_OK;
  return fail(SINEW_NULL_ARGUMENT, std::string(call) + ": " + what + " is NULL");
}

// A read into the caller's buffer of `capacity` records: writes the count,
// then refuses a too-small non-null buffer (the count is still written).
// SINEW_OK with nothing to copy when buffer is NULL and capacity 0.
sinew_status check_capacity(const char* call, const void* buffer, std::size_t capacity, std::size_t needed,
                            std::size_t* count);

// Copies `full` (a struct whose first field is uint32_t struct_size) into
// the caller's `out`, as much of it as the caller's struct_size holds;
// refuses a struct_size smaller than this version's struct.
template <class T>
sinew_status copy_sized(const char* call, const T& full, T* out) {
  if (sinew_status s = need(out, call, "the struct"); s != SINEW_OK) return s;
  std::uint32_t size = 0;
  std::memcpy(&size, out, sizeof size);
  if (size < sizeof(T))
    return fail(SINEW_BAD_PARAMETER, std::string(call) + ": struct_size is " + std::to_string(size) +
                                         ", less than this version's " + std::to_string(sizeof(T)) +
                                         " (set it to sizeof the struct)");
  T copy = full;
  copy.struct_size = size;
  std::memcpy(out, &copy, sizeof(T));
  return SINEW_OK;
}

// The handle checked, for calls that take one.
inline sinew_status need_sim(const sinew_simulation* sim, const char* call) {
  return need(sim, call, "the simulation handle");
}

// Each public function taking a handle: the handle checked, then `body` run guarded.
template <class Sim, class F>
sinew_status with_sim(const char* call, Sim* sim, F&& body) noexcept {
  return guarded(call, [&]() -> sinew_status {
    if (sinew_status s = need_sim(sim, call); s != SINEW_OK) return s;
    return body();
  });
}

// An array of 3 (or 4) doubles from C as a std::array.
inline std::array<double, 3> vec3(const double* v) { return {v[0], v[1], v[2]}; }
inline std::array<double, 4> quat(const double* q) { return {q[0], q[1], q[2], q[3]}; }

// The topology change `e` of kind `kind` as a C event record of `frame`.
sinew_event topology_event(sinew_event_kind kind, const TopologyEvent& e, std::uint64_t frame);

}  // namespace sinew::capi
