// haptics_reader.cpp — a scene file's "haptics": scripted hands, each a
// device on a keyframed path driving one tool through the haptic loop on a
// virtual clock (docs/scene_files.md, "Haptics"; sinew/haptics/scripted_hands.h).
#include <cmath>
#include <string>
#include <utility>

#include "scene_file/readers.h"

namespace sinew::scene_file {
namespace {

void read_path(const Json& v, const std::string& path, Context& ctx, haptics::KeyframePath& out) {
  Object o(v, path, ctx);
  haptics::PathInterpolation interpolation = haptics::PathInterpolation::smooth;
  if (const Json* i = o.find("interpolation"))
    read_enum(*i, o.path("interpolation"), ctx,
              {{"smooth", haptics::PathInterpolation::smooth}, {"linear", haptics::PathInterpolation::linear}},
              interpolation);
  std::vector<haptics::PathKey> keys;
  if (const Json* k = o.find("keys")) {
    read_array(*k, o.path("keys"), ctx, [&](const Json& e, const std::string& p) {
      Object ko(e, p, ctx);
      haptics::PathKey key;
      ko.read("time", key.time, true);
      ko.read("position", key.position, true);
      ko.read("rotation", key.rotation);
      ko.finish();
      keys.push_back(key);
    });
  } else if (!ctx.failed()) {
    ctx.fail(ErrorCode::bad_input_file, o.path("keys"), "is required");
  }
  o.finish();
  if (ctx.failed()) return;
  auto made = haptics::KeyframePath::create(std::move(keys), interpolation);
  if (!made) {
    // "keys[2].time: rule" -> "<path>/keys/2/time: rule"
    std::string m = made.error().message();
    std::string where = o.path("keys");
    if (m.rfind("keys[", 0) == 0) {
      const auto close = m.find(']');
      const auto colon = m.find(':');
      where += "/" + m.substr(5, close - 5);
      if (close + 1 < colon) where += "/" + m.substr(close + 2, colon - close - 2);
      m = m.substr(colon + 2);
    } else if (m.rfind("keys: ", 0) == 0) {
      m = m.substr(6);
    }
    return ctx.fail(ErrorCode::bad_parameter, where, m);
  }
  out = std::move(*made);
}

void read_coupling(const Json& v, const std::string& path, Context& ctx, haptics::CouplingParams& out) {
  Object o(v, path, ctx);
  o.read("stiffness", out.stiffness);
  o.read("damping", out.damping);
  o.read("rotational_stiffness", out.rotational_stiffness);
  o.read("rotational_damping", out.rotational_damping);
  o.read("max_force", out.max_force);
  o.read("max_force_change", out.max_force_change);
  o.read("max_torque", out.max_torque);
  o.read("max_torque_change", out.max_torque_change);
  o.finish();
}

void read_hand(const Json& v, const std::string& path, Context& ctx, haptics::ScriptedHandDesc& out) {
  Object o(v, path, ctx);
  o.read("tool", out.tool, true);
  if (const Json* p = o.find("path")) read_path(*p, o.path("path"), ctx, out.path);
  else if (!ctx.failed()) ctx.fail(ErrorCode::bad_input_file, o.path("path"), "is required");
  o.read("rate_hz", out.loop.rate_hz);
  if (const Json* c = o.find("coupling")) read_coupling(*c, o.path("coupling"), ctx, out.loop.coupling);
  o.read("tool_damping", out.tool_damping);
  o.read("tool_angular_damping", out.tool_angular_damping);
  o.finish();
  if (ctx.failed()) return;
  out.loop.realtime = false;  // ticked by the runner on a virtual clock
  if (!(out.loop.rate_hz >= 1.0 && out.loop.rate_hz <= 1e6))
    return ctx.fail(ErrorCode::bad_parameter, path + "/rate_hz", "must be in [1, 1e6] [Hz]");
  if (Status s = haptics::check(out.loop.coupling); !s) {
    // "coupling.damping must be ..." -> "<hand>/coupling/damping: must be ..."
    const std::string& m = s.error().message();
    const auto space = m.find(' ');
    std::string key = m.substr(0, space);
    for (char& c : key)
      if (c == '.') c = '/';
    return ctx.fail(ErrorCode::bad_parameter, path + "/" + key, m.substr(space + 1));
  }
  // The loop's other settings are not in the file (their defaults hold); ScriptedHands checks them all.
  for (const auto& [key, value] : {std::pair<const char*, double>{"tool_damping", out.tool_damping},
                                    {"tool_angular_damping", out.tool_angular_damping}})
    if (!(value >= 0.0 && std::isfinite(value)))
      return ctx.fail(ErrorCode::bad_parameter, path + "/" + key, "must be finite and >= 0");
}

}  // namespace

void read_haptics(const Json& v, const std::string& path, Context& ctx, std::vector<haptics::ScriptedHandDesc>& out) {
  Object o(v, path, ctx);
  if (const Json* h = o.find("hands")) {
    read_array(*h, o.path("hands"), ctx, [&](const Json& e, const std::string& p) {
      read_hand(e, p, ctx, out.emplace_back());
    });
  } else if (!ctx.failed()) {
    ctx.fail(ErrorCode::bad_input_file, o.path("hands"), "is required");
  }
  o.finish();
}

void check_haptics(const std::vector<haptics::ScriptedHandDesc>& hands, const SceneDesc& scene, Context& ctx) {
  for (std::size_t i = 0; i < hands.size() && !ctx.failed(); ++i) {
    const std::string at = "/haptics/hands/" + std::to_string(i) + "/tool";
    if (hands[i].tool >= scene.tools.size())
      return ctx.fail(ErrorCode::bad_parameter, at,
                      "tool " + std::to_string(hands[i].tool) + " does not exist (the scene has " +
                          std::to_string(scene.tools.size()) + ")");
    for (std::size_t j = 0; j < i; ++j)
      if (hands[j].tool == hands[i].tool)
        return ctx.fail(ErrorCode::bad_parameter, at,
                        "tool " + std::to_string(hands[i].tool) + " is driven by /haptics/hands/" + std::to_string(j) +
                            " already");
  }
}

}  // namespace sinew::scene_file
