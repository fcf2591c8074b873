// capi_errors.cpp — the C API's status codes, the thread-local message of
// the last failing call, the version, and the buffer checks
// (sinew/sinew.h).
#include <string>

#include "capi/capi_internal.h"
#include "sinew/version.h"

namespace sinew::capi {
namespace {

// One per thread: a simulation is used by one thread at a time, and each
// thread reads the message of its own last failing call.
thread_local std::string last_error_message;

sinew_status code_of(ErrorCode code) {
  switch (code) {
    case ErrorCode::bad_parameter: return SINEW_BAD_PARAMETER;
    case ErrorCode::bad_input_file: return SINEW_BAD_INPUT_FILE;
    case ErrorCode::backend_unavailable: return SINEW_BACKEND_UNAVAILABLE;
    case ErrorCode::device_lost: return SINEW_DEVICE_LOST;
    case ErrorCode::out_of_memory: return SINEW_OUT_OF_MEMORY;
    case ErrorCode::capacity_exceeded: return SINEW_CAPACITY_EXCEEDED;
    case ErrorCode::internal: return SINEW_INTERNAL;
    case ErrorCode::diverged: return SINEW_DIVERGED;
  }
  return SINEW_INTERNAL;
}

}  // namespace

sinew_status fail(sinew_status status, std::string message) {
  try {
    last_error_message = std::move(message);
  } catch (...) {
    // No memory for the message: the code still says what happened.
  }
  return status;
}

sinew_status fail(const Error& error) { return fail(code_of(error.code()), error.message()); }

sinew_status check_capacity(const char* call, const void* buffer, std::size_t capacity, std::size_t needed,
                            std::size_t* count) {
  if (sinew_status s = need(count, call, "count"); s != SINEW_OK) return s;
  *count = needed;
  if (!buffer && capacity == 0) return SINEW_OK;  // asking for the count only
  if (sinew_status s = need(buffer, call, "the buffer (with a capacity above 0)"); s != SINEW_OK) return s;
  if (capacity < needed)
    return fail(SINEW_BUFFER_TOO_SMALL, std::string(call) + ": the buffer holds " + std::to_string(capacity) +
                                            " records, " + std::to_string(needed) + " are needed");
  return SINEW_OK;
}

sinew_event topology_event(sinew_event_kind kind, const TopologyEvent& e, std::uint64_t frame) {
  sinew_event out{};
  out.kind = kind;
  out.object = static_cast<std::uint32_t>(e.body);
  out.body_kind = static_cast<std::uint32_t>(e.body_kind);
  out.body = static_cast<std::uint32_t>(e.body);
  out.frame = frame;
  out.count = static_cast<std::uint32_t>(e.tets_removed.size() + e.triangles_removed.size() + e.segments_removed.size());
  out.vertices_removed = static_cast<std::uint32_t>(e.vertices_removed.size());
  out.constraints_removed = e.constraints_removed;
  out.mass_moved = e.mass_moved;
  out.mass_removed = e.mass_removed;
  return out;
}

}  // namespace sinew::capi

// The C layout is part of the ABI (docs/c_api.md): a change here is a change of it.
static_assert(sizeof(sinew_event) == 96, "sinew_event is 96 bytes");
static_assert(offsetof(sinew_event, frame) == 16 && offsetof(sinew_event, weights) == 48, "sinew_event's layout");
static_assert(sizeof(sinew_frame_stats) == 208, "sinew_frame_stats' first version is 208 bytes");
static_assert(sizeof(sinew_status) == 4, "sinew_status is 32 bits");
static_assert(static_cast<int>(sinew::BodyKind::tri) == SINEW_BODY_TRI && static_cast<int>(sinew::BodyKind::line) == SINEW_BODY_LINE,
              "sinew_body_kind mirrors sinew::BodyKind");

extern "C" {

uint32_t sinew_version(void) { return SINEW_VERSION; }

const char* sinew_version_string(void) { return SINEW_VERSION_STRING; }

const char* sinew_last_error(void) { return sinew::capi::last_error_message.c_str(); }

const char* sinew_status_name(sinew_status status) {
  switch (status) {
    case SINEW_OK: return "ok";
    case SINEW_NULL_ARGUMENT: return "null_argument";
    case SINEW_BUFFER_TOO_SMALL: return "buffer_too_small";
    case SINEW_BAD_PARAMETER: return sinew::error_code_name(sinew::ErrorCode::bad_parameter);
    case SINEW_BAD_INPUT_FILE: return sinew::error_code_name(sinew::ErrorCode::bad_input_file);
    case SINEW_BACKEND_UNAVAILABLE: return sinew::error_code_name(sinew::ErrorCode::backend_unavailable);
    case SINEW_DEVICE_LOST: return sinew::error_code_name(sinew::ErrorCode::device_lost);
    case SINEW_OUT_OF_MEMORY: return sinew::error_code_name(sinew::ErrorCode::out_of_memory);
    case SINEW_CAPACITY_EXCEEDED: return sinew::error_code_name(sinew::ErrorCode::capacity_exceeded);
    case SINEW_INTERNAL: return sinew::error_code_name(sinew::ErrorCode::internal);
    case SINEW_DIVERGED: return sinew::error_code_name(sinew::ErrorCode::diverged);
    case SINEW_STATUS_MAX_ENUM: break;
  }
  return "unknown";
}

}  // extern "C"
