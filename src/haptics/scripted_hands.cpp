// scripted_hands.cpp — scripted hands ticked on a virtual clock between the
// physics frames (sinew/haptics/scripted_hands.h).
#include "sinew/haptics/scripted_hands.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "sinew/simulation.h"

namespace sinew::haptics {
namespace {

Error named(const std::string& hand, const Error& e) { return Error(e.code(), hand + ": " + e.message()); }

}  // namespace

Result<std::unique_ptr<ScriptedHands>> ScriptedHands::create(std::vector<ScriptedHandDesc> hands, Simulation& sim,
                                                             double frame_seconds) {
  if (!std::isfinite(frame_seconds) || frame_seconds <= 0.0)
    return Error(ErrorCode::bad_parameter, "frame_seconds: must be finite and > 0");
  std::unique_ptr<ScriptedHands> self(new ScriptedHands());
  self->frame_s_ = frame_seconds;
  for (std::size_t i = 0; i < hands.size(); ++i) {
    ScriptedHandDesc& d = hands[i];
    const std::string name = "hands[" + std::to_string(i) + "]";
    if (auto tool = sim.tools().tool(d.tool); !tool) return named(name + ".tool", tool.error());
    for (std::size_t j = 0; j < i; ++j)
      if (hands[j].tool == d.tool)
        return Error(ErrorCode::bad_parameter, name + ".tool: tool " + std::to_string(d.tool) +
                                                   " is driven by hands[" + std::to_string(j) + "] already");
    auto hand = std::make_unique<Hand>();
    hand->rate_hz = d.loop.rate_hz;
    // Ticked here, on the caller's thread: no real-time thread to ask for.
    d.loop.realtime = false;
    d.loop.cpu = -1;
    d.loop.zero_cpu_latency = false;
    hand->device = std::make_unique<ScriptedDevice>(d.path.script(), 0, d.loop.rate_hz);
    auto loop = HapticLoop::create(d.loop, *hand->device, hand->snapshots, hand->feedback, self->clock_);
    if (!loop) return named(name + ".loop", loop.error());
    hand->loop = std::move(*loop);
    if (auto s = hand->device->start(0); !s) return named(name, s.error());
    hand->bridge = std::make_unique<HapticToolBridge>(d.tool, hand->snapshots, hand->feedback, self->clock_);
    if (auto s = hand->bridge->set_damping(d.tool_damping, d.tool_angular_damping); !s)
      return named(name + ".tool_damping", s.error());
    if (auto s = hand->bridge->publish(sim); !s) return named(name, s.error());
    self->hands_.push_back(std::move(hand));
  }
  return self;
}

Status ScriptedHands::before_step(Simulation& sim) {
  // The coming frame's end, from the frames the Simulation has done (so
  // frames stepped without the hands leave no lag: their ticks run now).
  const std::uint64_t frame = sim.last_frame().frame + 1;
  const auto end = static_cast<std::int64_t>(std::llround(double(frame) * frame_s_ * 1e9));
  // Tick k of a hand at round(k 1e9 / rate): each loop at its own rate, as
  // its device's servo scheduler would call it over this frame, all in the
  // order of time (the clock never goes back).
  const auto next = [](const Hand& h) {
    return static_cast<std::int64_t>(std::llround(double(h.ticks + 1) * 1e9 / h.rate_hz));
  };
  for (;;) {
    std::int64_t t = end + 1;
    for (const auto& h : hands_) t = std::min(t, next(*h));
    if (t > end) break;
    clock_.set(t);
    for (auto& h : hands_)
      if (next(*h) == t) {
        (void)h->loop->tick();
        ++h->ticks;
      }
  }
  clock_.set(end);
  for (std::size_t i = 0; i < hands_.size(); ++i)
    if (auto s = hands_[i]->bridge->apply_feedback(sim); !s)
      return named("hands[" + std::to_string(i) + "]", s.error());
  return {};
}

Status ScriptedHands::after_step(const Simulation& sim) {
  for (std::size_t i = 0; i < hands_.size(); ++i)
    if (auto s = hands_[i]->bridge->publish(sim); !s) return named("hands[" + std::to_string(i) + "]", s.error());
  return {};
}

}  // namespace sinew::haptics
