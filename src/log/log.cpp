// log.cpp — the process-wide log callback (sinew/log.h). The callback is
// held by a shared_ptr copied under a mutex, so a message runs its callback
// without holding the lock (a slow callback does not serialise the threads
// that log) and a replacement never destroys a callback still running.
#include "sinew/log.h"

#include <cstdio>
#include <memory>
#include <mutex>
#include <string>

namespace sinew {
namespace {

// The documented default: warnings and errors on stderr, one line each.
void default_callback(LogLevel level, std::string_view text) {
  if (level < LogLevel::warning) return;
  std::fprintf(stderr, "sinew: %s: %.*s\n", log_level_name(level), static_cast<int>(text.size()), text.data());
}

std::mutex& callback_mutex() {
  static std::mutex m;
  return m;
}

std::shared_ptr<const LogCallback>& current() {
  static std::shared_ptr<const LogCallback> callback = std::make_shared<const LogCallback>(default_callback);
  return callback;
}

}  // namespace

void set_log_callback(LogCallback callback) {
  auto next = std::make_shared<const LogCallback>(callback ? std::move(callback) : LogCallback(default_callback));
  const std::lock_guard lock(callback_mutex());
  current() = std::move(next);
}

void log_message(LogLevel level, std::string_view text) {
  std::shared_ptr<const LogCallback> callback;
  {
    const std::lock_guard lock(callback_mutex());
    callback = current();
  }
  (*callback)(level, text);
}

}  // namespace sinew
