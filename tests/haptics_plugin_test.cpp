// Haptic device plug-ins: the C test plug-in (plugins/circle_plugin.c) loaded
// with dlopen, listed, opened, and driven by a real HapticLoop — on a
// virtual clock, ticked by hand, and on its own thread — with the poses it
// samples reaching the loop and the forces the loop renders reaching the
// plug-in (read back through the plug-in's own record); the library's
// lifetime; each loader error by name.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "circle_plugin_record.h"
#include "haptics_test_support.h"
#include "sinew/haptics/device_plugin.h"
#include "support/allocation_counter.h"

namespace {

using namespace sinew::test;
using sinew::ErrorCode;
using sinew::haptics::DevicePlugin;
using sinew::haptics::PluginDevice;
using sinew::support::allocation_count;

constexpr double kPi = 3.14159265358979323846;

// Whether the library at `path` is loaded in this process now.
bool loaded(const char* path) {
  void* h = dlopen(path, RTLD_NOW | RTLD_NOLOAD);
  if (h) dlclose(h);  // NOLOAD counts a reference too
  return h != nullptr;
}

// Device `index`'s record in the loaded circle plug-in (which must stay loaded).
sinew_test_plugin_record record_of(std::uint32_t index) {
  sinew_test_plugin_record record{};
  void* h = dlopen(TEST_PLUGIN_CIRCLE, RTLD_NOW | RTLD_NOLOAD);
  EXPECT_NE(h, nullptr) << "the circle plug-in is not loaded";
  if (!h) return record;
  void* symbol = dlsym(h, SINEW_TEST_PLUGIN_RECORD_NAME);
  EXPECT_NE(symbol, nullptr);
  if (symbol) {
    sinew_test_plugin_record_fn fn = nullptr;
    std::memcpy(&fn, &symbol, sizeof fn);
    EXPECT_EQ(fn(index, &record), 0);
  }
  dlclose(h);
  return record;
}

std::unique_ptr<DevicePlugin> load_circle() {
  auto plugin = DevicePlugin::load(TEST_PLUGIN_CIRCLE);
  EXPECT_TRUE(plugin.ok()) << (plugin.ok() ? "" : plugin.error().message());
  return plugin.ok() ? std::move(*plugin) : nullptr;
}

// The error of loading `path`; fails the test when it loads.
sinew::Error load_error(const std::string& path) {
  auto plugin = DevicePlugin::load(path);
  EXPECT_FALSE(plugin.ok()) << path << " loaded";
  return plugin.ok() ? sinew::Error(ErrorCode::internal, "loaded") : plugin.error();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(HapticsPlugin, LoadsListsAndOpensByNameOrIndex) {
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  EXPECT_EQ(plugin->name(), "circle");
  EXPECT_EQ(plugin->path(), TEST_PLUGIN_CIRCLE);
  EXPECT_EQ(plugin->abi_version(), SINEW_HAPTIC_PLUGIN_ABI_VERSION);
  EXPECT_EQ(plugin->struct_size(), sizeof(sinew_haptic_plugin_v1));
  auto devices = plugin->devices();
  ASSERT_TRUE(devices.ok()) << devices.error().message();
  EXPECT_EQ(*devices, (std::vector<std::string>{"circle", "circle-3dof"}));

  auto three = plugin->open("circle-3dof");
  ASSERT_TRUE(three.ok()) << three.error().message();
  EXPECT_EQ((*three)->name(), "circle: circle-3dof");
  EXPECT_EQ((*three)->degrees_of_freedom(), 3u);
  EXPECT_EQ((*three)->update_rate_hz(), 1000.0);
  auto six = plugin->open("0", "radius=0.02");
  ASSERT_TRUE(six.ok()) << six.error().message();
  EXPECT_EQ((*six)->name(), "circle: circle");
  EXPECT_EQ((*six)->degrees_of_freedom(), 6u);
  EXPECT_EQ(record_of(0).opens, 1u);
  EXPECT_EQ(record_of(1).opens, 1u);
  EXPECT_EQ(record_of(0).started, 0u) << "opened, not started";
  six->reset();
  EXPECT_EQ(record_of(0).open, 0u);
  EXPECT_EQ(record_of(0).closes, 1u);
  EXPECT_EQ(record_of(0).stops, 0u) << "never started, never stopped";
}

// A full loop on the plug-in device, ticked by hand on a virtual clock: the
// device's circle reaches the loop's telemetry, the coupling's forces and
// torques reach the plug-in, and no tick allocates.
TEST(HapticsPlugin, LoopOnAVirtualClockSamplesAndCommandsThePlugin) {
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  auto device = plugin->open("circle", "hz=2,radius=0.02");
  ASSERT_TRUE(device.ok()) << device.error().message();
  VirtualRig rig(**device);
  ASSERT_TRUE(rig.loop);
  // Manual ticks: the caller starts the device (HapticLoop::tick()).
  ASSERT_TRUE((*device)->start(rig.clock.now_ns()).ok());
  EXPECT_EQ(record_of(0).started, 1u);
  EXPECT_FALSE((*device)->start(rig.clock.now_ns()).ok()) << "started twice";

  const int ticks = 1000;
  const double r = 0.02, w = 2 * kPi * 2.0;
  std::vector<TickRecord> records;
  records.reserve(ticks);
  rig.run(50);  // warm-up
  const std::uint64_t before = allocation_count();
  for (int i = 0; i < ticks; ++i) records.push_back(rig.step());
  EXPECT_EQ(allocation_count() - before, 0u) << "allocations in ticks on the plug-in device";

  double largest = 0.0;
  for (const TickRecord& rec : records) {
    const double t = 1e-9 * double(rec.start_ns);
    EXPECT_NEAR(rec.device_position[0], r * std::cos(w * t), 1e-12);
    EXPECT_EQ(rec.device_position[1], 0.0);
    EXPECT_NEAR(rec.device_position[2], r * std::sin(w * t), 1e-12);
    EXPECT_EQ(rec.device_buttons, t >= 0.5 ? 1u : 0u) << "t = " << t;
    EXPECT_EQ(rec.flags & kNoDeviceSample, 0u);
    largest = std::max(largest, norm3(rec.force));
  }
  const sinew_test_plugin_record plugin_record = record_of(0);
  EXPECT_EQ(plugin_record.samples, std::uint64_t(ticks + 50));
  EXPECT_EQ(plugin_record.commands, std::uint64_t(ticks + 50));
  const TickRecord& last = records.back();
  EXPECT_EQ(plugin_record.last_command_ns, last.start_ns);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(plugin_record.last_force[k], last.force[k]) << k;
  EXPECT_GT(largest, 1.0) << "the coupling pulled the hand to the tool at the origin";
  const double along = last.force[0] * last.device_position[0] + last.force[2] * last.device_position[2];
  EXPECT_LT(along, 0.0) << "the force pulls the device towards the tool";
  // The 6-DOF device gets the coupling's torque (the device turns, the tool does not).
  CouplingFeedback fb;
  ASSERT_TRUE(rig.feedback.try_read(fb));
  EXPECT_GT(norm3(fb.torque), 0.0);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(plugin_record.last_torque[k], fb.torque[k]) << k;

  (*device)->stop();
  EXPECT_EQ(record_of(0).started, 0u);
  EXPECT_EQ(record_of(0).stops, 1u);
}

TEST(HapticsPlugin, ThreeDofDeviceIsHandedZeroTorque) {
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  auto device = plugin->open("circle-3dof");
  ASSERT_TRUE(device.ok()) << device.error().message();
  VirtualRig rig(**device);
  ASSERT_TRUE(rig.loop);
  ASSERT_TRUE((*device)->start(rig.clock.now_ns()).ok());
  rig.run(300);
  CouplingFeedback fb;
  ASSERT_TRUE(rig.feedback.try_read(fb));
  EXPECT_GT(norm3(fb.torque), 0.0) << "the coupling did render a torque";
  const sinew_test_plugin_record rec = record_of(1);
  EXPECT_EQ(rec.commands, 300u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(rec.torque_sum[k], 0.0) << k;
    EXPECT_EQ(rec.last_force[k], fb.force[k]) << k;
  }
}

// The loop's own thread (real clock, no real-time request): start() starts
// the plug-in device, every tick commands it, stop() commands zero force and
// stops it.
TEST(HapticsPlugin, LoopThreadStartsCommandsAndStopsThePlugin) {
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  auto device = plugin->open("circle");
  ASSERT_TRUE(device.ok()) << device.error().message();
  MonotonicClock clock;
  SnapshotChannel snapshots;
  FeedbackChannel feedback;
  HapticSnapshot tool;
  tool.sequence = 1;
  tool.stamp_ns = clock.now_ns();
  snapshots.publish(tool);
  HapticLoopSettings settings;
  settings.realtime = false;
  auto loop = HapticLoop::create(settings, **device, snapshots, feedback, clock);
  ASSERT_TRUE(loop.ok()) << loop.error().message();
  ASSERT_TRUE((*loop)->start().ok());
  EXPECT_EQ(record_of(0).started, 1u);
  // Wait (bounded) for some ticks; how long they take is not the point.
  for (int i = 0; i < 10000 && (*loop)->counters().ticks < 50; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  (*loop)->stop();
  const std::uint64_t ticks = (*loop)->counters().ticks;
  ASSERT_GE(ticks, 50u);
  const sinew_test_plugin_record rec = record_of(0);
  EXPECT_EQ(rec.started, 0u);
  EXPECT_EQ(rec.starts, 1u);
  EXPECT_EQ(rec.stops, 1u);
  EXPECT_EQ(rec.samples, ticks);
  EXPECT_EQ(rec.commands, ticks + 1) << "one per tick, and the zero force of stop()";
  for (int k = 0; k < 3; ++k) EXPECT_EQ(rec.last_force[k], 0.0);
}

// The devices keep the library loaded after the DevicePlugin is gone; the
// last one to go unloads it.
TEST(HapticsPlugin, LibraryLivesUntilTheLastDeviceIsGone) {
  ASSERT_FALSE(loaded(TEST_PLUGIN_CIRCLE)) << "an earlier test left the plug-in loaded";
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  EXPECT_TRUE(loaded(TEST_PLUGIN_CIRCLE));
  auto a = plugin->open("circle");
  auto b = plugin->open("circle-3dof");
  ASSERT_TRUE(a.ok() && b.ok());
  plugin.reset();
  ASSERT_TRUE(loaded(TEST_PLUGIN_CIRCLE));
  ASSERT_TRUE((*a)->start(0).ok());
  DeviceSample s;
  EXPECT_TRUE((*a)->sample(250'000'000, s)) << "the device still works";
  EXPECT_NEAR(s.position[2], 0.01, 1e-15) << "a quarter turn of 1 Hz at r = 1 cm";
  a->reset();
  EXPECT_TRUE(loaded(TEST_PLUGIN_CIRCLE)) << "b still holds it";
  EXPECT_EQ(record_of(0).closes, 1u) << "a was stopped and closed";
  EXPECT_EQ(record_of(0).stops, 1u);
  b->reset();
  EXPECT_FALSE(loaded(TEST_PLUGIN_CIRCLE)) << "the last device unloaded it";
}

// ------------------------------------------------------------------ errors

TEST(HapticsPluginErrors, MissingLibrarySaysDlerror) {
  const sinew::Error e = load_error("/nonexistent/sinew_no_such_plugin.so");
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_TRUE(contains(e.message(), "haptic plug-in /nonexistent/sinew_no_such_plugin.so: cannot load the library: "))
      << e.message();
  EXPECT_TRUE(contains(e.message(), "No such file or directory")) << e.message();
  EXPECT_EQ(load_error("").code(), ErrorCode::bad_parameter);
}

TEST(HapticsPluginErrors, NotASharedLibrary) {
  const sinew::Error e = load_error(SINEW_TEST_PLUGIN_SOURCE);
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_TRUE(contains(e.message(), "cannot load the library")) << e.message();
  EXPECT_TRUE(contains(e.message(), "invalid ELF header")) << e.message();
}

TEST(HapticsPluginErrors, UnresolvedSymbolRefusedAtLoad) {
  const sinew::Error e = load_error(TEST_PLUGIN_UNRESOLVED);
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_TRUE(contains(e.message(), "undefined symbol: sinew_test_plugin_nowhere")) << e.message();
}

TEST(HapticsPluginErrors, MissingEntryPoint) {
  const sinew::Error e = load_error(TEST_PLUGIN_NO_ENTRY);
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_TRUE(contains(e.message(), std::string("haptic plug-in ") + TEST_PLUGIN_NO_ENTRY +
                                        ": no entry point sinew_haptic_plugin_entry"))
      << e.message();
  EXPECT_FALSE(loaded(TEST_PLUGIN_NO_ENTRY)) << "a refused plug-in is unloaded again";
}

TEST(HapticsPluginErrors, WrongAbiVersion) {
  const sinew::Error e = load_error(TEST_PLUGIN_ABI2);
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_EQ(e.message(),
            std::string("haptic plug-in ") + TEST_PLUGIN_ABI2 + " has ABI version 2; this sinew reads version 1");
}

TEST(HapticsPluginErrors, TableTooSmall) {
  const sinew::Error e = load_error(TEST_PLUGIN_SMALL_TABLE);
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_TRUE(contains(e.message(), "struct_size is 16 bytes, smaller than ABI version 1's table (" +
                                        std::to_string(sizeof(sinew_haptic_plugin_v1)) + " bytes)"))
      << e.message();
}

// Append-only within a version: a table larger than this sinew's (a plug-in
// built against a newer header of version 1) loads and works.
TEST(HapticsPlugin, LargerTableOfTheSameVersionLoads) {
  auto plugin = DevicePlugin::load(TEST_PLUGIN_NEWER_TABLE);
  ASSERT_TRUE(plugin.ok()) << plugin.error().message();
  EXPECT_EQ((*plugin)->struct_size(), sizeof(sinew_haptic_plugin_v1) + 16);
  auto device = (*plugin)->open("circle");
  ASSERT_TRUE(device.ok()) << device.error().message();
  ASSERT_TRUE((*device)->start(0).ok());
  DeviceSample s;
  EXPECT_TRUE((*device)->sample(0, s));
  EXPECT_NEAR(s.position[0], 0.01, 1e-15);
}

TEST(HapticsPluginErrors, NullFunctionPointerNamed) {
  const sinew::Error e = load_error(TEST_PLUGIN_NULL_SAMPLE);
  EXPECT_EQ(e.code(), ErrorCode::bad_input_file);
  EXPECT_TRUE(contains(e.message(), "the table's function pointer 'sample' is NULL")) << e.message();
}

TEST(HapticsPluginErrors, OpenFailureCarriesThePluginsMessage) {
  auto plugin = DevicePlugin::load(TEST_PLUGIN_OPEN_FAILS);
  ASSERT_TRUE(plugin.ok()) << plugin.error().message();
  auto device = (*plugin)->open("circle");
  ASSERT_FALSE(device.ok());
  EXPECT_EQ(device.error().code(), ErrorCode::backend_unavailable);
  EXPECT_EQ(device.error().message(), std::string("haptic plug-in ") + TEST_PLUGIN_OPEN_FAILS +
                                          ": cannot open device \"circle\": no circle attached to this machine "
                                          "(simulated failure)");
}

TEST(HapticsPluginErrors, BadConfigAndBusyDeviceAreThePluginsMessages) {
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  auto bad = plugin->open("circle", "radius=abc");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code(), ErrorCode::backend_unavailable);
  EXPECT_TRUE(contains(bad.error().message(), "circle: \"radius=abc\" needs a finite number > 0"))
      << bad.error().message();
  auto unknown = plugin->open("circle", "speed=3");
  ASSERT_FALSE(unknown.ok());
  EXPECT_TRUE(contains(unknown.error().message(), "unknown config item \"speed=3\"")) << unknown.error().message();

  auto first = plugin->open("circle");
  ASSERT_TRUE(first.ok()) << first.error().message();
  auto second = plugin->open("circle");
  ASSERT_FALSE(second.ok());
  EXPECT_TRUE(contains(second.error().message(), "device \"circle\" is already open")) << second.error().message();
}

TEST(HapticsPluginErrors, UnknownDeviceNameOrIndexListsTheDevices) {
  auto plugin = load_circle();
  ASSERT_TRUE(plugin);
  for (const char* which : {"square", "2", "-1", "99999999999", ""}) {
    auto device = plugin->open(which);
    ASSERT_FALSE(device.ok()) << which;
    EXPECT_EQ(device.error().code(), ErrorCode::bad_parameter);
    EXPECT_TRUE(contains(device.error().message(), std::string("no device \"") + which +
                                                       "\" (by name or index); it has devices: 0 \"circle\", 1 "
                                                       "\"circle-3dof\""))
        << device.error().message();
  }
  EXPECT_EQ(record_of(0).opens, 0u) << "the plug-in's open was never called";
}

}  // namespace
