// sinew/log.h — where the library's messages go.
//
// sinew never writes to stdout or stderr itself: every message it has (a
// backend falling back to the CPU, a Vulkan validation message, a frame
// that diverged) goes to one process-wide callback. The default callback
// writes warnings and errors to stderr, one line each ("sinew: warning:
// ..."), and drops debug and info messages; replace it to send them to an
// engine's console or a log file, or to silence them.
//
//   sinew::set_log_callback([](sinew::LogLevel level, std::string_view text) {
//     my_engine_log(sinew::log_level_name(level), text);
//   });
#pragma once

#include <functional>
#include <string_view>

namespace sinew {

enum class LogLevel {
  debug,    ///< details for whoever debugs sinew
  info,     ///< what sinew did that needs no action
  warning,  ///< a result may be wrong or degraded (a diverged frame, a missing validation layer,
            ///< backend "auto" falling back to the CPU)
  error,    ///< a failure that also comes back as an Error where a call can return one
};

/// The level's name: "debug", "info", "warning" or "error".
constexpr const char* log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::debug: return "debug";
    case LogLevel::info: return "info";
    case LogLevel::warning: return "warning";
    case LogLevel::error: return "error";
  }
  return "unknown";
}

/// [in] level, text: one message, a single line without its newline. The
/// text is valid only during the call.
using LogCallback = std::function<void(LogLevel level, std::string_view text)>;

/// Replaces the process-wide callback; an empty callback restores the
/// default (warnings and errors to stderr). Thread-safe: messages may come
/// from any thread (the Vulkan validation layer calls from the driver's),
/// and the callback must be safe to call from several at once. A callback
/// must not call set_log_callback.
void set_log_callback(LogCallback callback);

/// Sends one message through the callback (sinew's own messages come this
/// way; an application may use it too).
void log_message(LogLevel level, std::string_view text);

}  // namespace sinew
