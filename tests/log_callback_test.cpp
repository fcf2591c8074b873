// log_callback_test.cpp — sinew/log.h: messages reach the callback with their
// level; the default callback writes warnings and errors (only) to stderr;
// with a callback set the library writes nothing to stdout or stderr.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "robustness_scenes.h"
#include "sinew/log.h"

namespace sinew {
namespace {

class LogHook : public ::testing::Test {
 protected:
  void TearDown() override { set_log_callback({}); }
};

TEST_F(LogHook, DefaultWritesWarningsAndErrorsToStderrOnly) {
  set_log_callback({});
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  log_message(LogLevel::debug, "a debug line");
  log_message(LogLevel::info, "an info line");
  log_message(LogLevel::warning, "a warning line");
  log_message(LogLevel::error, "an error line");
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "sinew: warning: a warning line\nsinew: error: an error line\n");
}

TEST_F(LogHook, ReplacedCallbackGetsEveryLevelAndTheLibraryWritesNothing) {
  std::vector<std::pair<LogLevel, std::string>> got;
  set_log_callback([&](LogLevel level, std::string_view text) { got.emplace_back(level, std::string(text)); });
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  log_message(LogLevel::info, "hello");
  // A frame that diverges logs its warning through the callback, not stderr.
  auto sim = Simulation::create(test::robustness_block(), {.backend = "cpu", .quiet = true});
  ASSERT_TRUE(sim.ok()) << sim.error().message();
  auto target = sim->tools().target(0);
  ASSERT_TRUE(target.ok());
  SINEW_ASSERT_OK(sim->tools().set_position(*target, {10.0, 0.0, 0.0}));
  SINEW_ASSERT_OK(sim->step());
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].first, LogLevel::info);
  EXPECT_EQ(got[0].second, "hello");
  EXPECT_EQ(got[1].first, LogLevel::warning);
  EXPECT_NE(got[1].second.find("diverged"), std::string::npos) << got[1].second;
}

TEST_F(LogHook, ReplacingWhileOtherThreadsLogIsSafe) {
  // Two threads log 2000 messages each while this one keeps replacing the
  // callback: every message reaches exactly one of the callbacks.
  std::atomic<int> a{0}, b{0};
  set_log_callback([&](LogLevel, std::string_view) { ++a; });
  std::vector<std::thread> loggers;
  for (int t = 0; t < 2; ++t)
    loggers.emplace_back([] {
      for (int i = 0; i < 2000; ++i) log_message(LogLevel::debug, "x");
    });
  for (int i = 0; i < 200; ++i)
    set_log_callback(i % 2 ? LogCallback([&](LogLevel, std::string_view) { ++a; })
                           : LogCallback([&](LogLevel, std::string_view) { ++b; }));
  for (std::thread& t : loggers) t.join();
  EXPECT_EQ(a + b, 4000);
}

}  // namespace
}  // namespace sinew
