// view_command.cpp — `sinew view` (docs/viewer.md): a window onto a scene
// file as it runs. The physics steps on its own thread at the scene's rate
// (view/physics_thread.h); this thread draws the newest snapshot, runs the
// ImGui panel, and turns the mouse into a virtual haptic device whose
// handle the haptic loop couples to the picked tool (view/mouse_device.h).
#include <sys/resource.h>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "sinew/scene_file.h"
#include "view/gl_renderer.h"
#include "view/image_file.h"
#include "view/orbit_camera.h"
#include "view/physics_thread.h"
#include "view/scene_drawer.h"
#include "view/scripted_run.h"
#include "view/view_panel.h"

namespace sinew::cli {
namespace {

using namespace sinew::view;

int fail(const std::string& what) {
  std::fprintf(stderr, "sinew view: %s\n", what.c_str());
  return 1;
}

std::string glfw_error;  // the last GLFW error, for the message when a window cannot be made

// A probe for scenes without a tool: a vertical capsule above the middle
// of the bodies, carried by the hand (no gravity), as in haptic_drag.
ToolDesc make_probe(const SceneDesc& scene) {
  V3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  const auto grow = [&](const Vec3d& p) {
    const V3 v(p);
    lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
    hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
  };
  for (const TetBodyDesc& b : scene.tet_bodies) for (const Vec3d& p : b.mesh.vertices) grow(p);
  for (const TriBodyDesc& b : scene.tri_bodies) for (const Vec3d& p : b.mesh.vertices) grow(p);
  for (const LineBodyDesc& b : scene.line_bodies) for (const Vec3d& p : b.vertices) grow(p);
  if (lo.x > hi.x) lo = {0, 0, 0}, hi = {0, 0, 0};
  const double size = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 0.02f});
  ToolDesc probe;
  probe.radius = 0.05 * size;
  probe.half_height = 0.15 * size;
  probe.mass = 0.5;  // [kg]
  const double r2 = probe.radius * probe.radius, l2 = 4 * probe.half_height * probe.half_height;
  probe.inertia = {probe.mass * (3 * r2 + l2) / 12, probe.mass * r2 / 2, probe.mass * (3 * r2 + l2) / 12};
  probe.position = {0.5 * (lo.x + hi.x), hi.y + 0.25 * size + probe.radius + probe.half_height, 0.5 * (lo.z + hi.z)};
  probe.gravity = false;  // the hand carries the instrument
  return probe;
}

// "dx,dy,dz" [m].
std::optional<V3> parse_offset(const std::string& text) {
  float v[3];
  char tail = 0;
  if (std::sscanf(text.c_str(), "%f,%f,%f%c", &v[0], &v[1], &v[2], &tail) != 3) return std::nullopt;
  for (float x : v)
    if (!std::isfinite(x)) return std::nullopt;
  return V3{v[0], v[1], v[2]};
}

// The window's mouse, between two frames.
struct MouseState {
  double scroll = 0.0;                 // wheel clicks since the last frame
  double x = 0, y = 0;                 // the cursor [window pixels]
  bool left = false, right = false, middle = false;
  double press_x = 0, press_y = 0;     // where the left button went down
  bool dragged = false;                // the left button moved since it went down
};

void on_scroll(GLFWwindow* window, double, double dy) {
  static_cast<MouseState*>(glfwGetWindowUserPointer(window))->scroll += dy;
}

// The tool whose centre is drawn within 40 pixels of (x, y), nearest first; -1: none.
int tool_at(const ViewSnapshot& snap, const M4& view_proj, double x, double y, int width, int height) {
  int best = -1;
  double best_d2 = 40.0 * 40.0;
  for (std::size_t t = 0; t < snap.tools.size(); ++t) {
    float w = 0;
    const V3 ndc = transform_point(view_proj, V3(snap.tools[t].position), &w);
    if (w <= 0) continue;
    const double sx = (ndc.x * 0.5 + 0.5) * width, sy = (0.5 - ndc.y * 0.5) * height;
    const double d2 = (sx - x) * (sx - x) + (sy - y) * (sy - y);
    if (d2 < best_d2) best_d2 = d2, best = static_cast<int>(t);
  }
  return best;
}

}  // namespace

int view_scene(const ViewOptions& o) {
  auto file = load_scene_file(o.scene);
  if (!file) return fail(file.error().message());
  std::optional<V3> move;
  if (!o.script_test.empty()) {
    move = parse_offset(o.move_tool);
    if (!move) return fail("--move-tool " + o.move_tool + ": expected three finite numbers dx,dy,dz [m]");
    std::error_code ec;
    std::filesystem::create_directories(o.script_test, ec);
    if (ec) return fail(o.script_test + ": cannot be made (" + ec.message() + ")");
  }
  bool added_probe = false;
  if (file->scene.tools.empty() && o.probe) {
    file->scene.tools.push_back(make_probe(file->scene));
    added_probe = true;
  }
  const std::string title = "sinew view " + o.scene;

  glfwSetErrorCallback([](int, const char* description) { glfw_error = description; });
  if (!glfwInit())
    return fail("cannot open a window: " + glfw_error + " (no display? xvfb-run runs it on a virtual one)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, o.msaa);
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, title.c_str(), nullptr, nullptr);
  if (!window) {
    glfwTerminate();
    return fail("cannot open an OpenGL 3.3 window: " + glfw_error);
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(o.vsync ? 1 : 0);
  MouseState mouse_state;
  glfwSetWindowUserPointer(window, &mouse_state);
  glfwSetScrollCallback(window, on_scroll);  // before ImGui's backend, which chains to it

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the working folder
  ImGui::StyleColorsDark();
  int status = 0;
  if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 330 core"))
    status = fail("Dear ImGui's GLFW or OpenGL 3 backend could not start");
  {
    Renderer renderer;
    if (status == 0)
      if (Status s = renderer.init(); !s) status = fail(s.error().message());
    MouseDevice device;
    // The CPU backend leaves one hardware thread to this one: a software
    // OpenGL (Mesa's llvmpipe) draws on the CPU too, and a thread team
    // sharing its cores with the renderer waits at every barrier.
    const int threads = o.threads > 0 ? o.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()) - 1);
    PhysicsThread physics(*file, DeviceOptions{.backend = o.backend.empty() ? file->run.backend : o.backend,
                                               .device = o.device, .threads = threads, .quiet = true},
                          device);
    physics.set_paused(o.paused);
    if (status == 0)
      if (Status s = physics.start(); !s) status = fail(s.error().message());
    if (status == 0) {
      std::printf("sinew view %s on %s%s\n", o.scene.c_str(), physics.device_name().c_str(),
                  added_probe ? "; the scene has no tool: a probe was added for the mouse to drive" : "");
      if (!physics.haptic_description().empty()) std::printf("%s\n", physics.haptic_description().c_str());
      std::fflush(stdout);
      SceneDrawer drawer(physics.file().scene);
      DrawOptions options;
      OrbitCamera camera;
      TripleBuffer<ViewSnapshot>& snapshots = physics.snapshots();
      snapshots.update();
      {
        V3 lo, hi;
        SceneDrawer::bounds(snapshots.front(), lo, hi);
        camera.frame_box(lo, hi);
      }
      std::optional<ScriptedRun> script;
      if (move) script.emplace(o.script_test, *move);
      bool show_panel = !o.no_panel;
      std::uint64_t generation_seen = snapshots.front().generation;
      std::vector<std::uint8_t> pixels;
      using clock = std::chrono::steady_clock;
      const auto start = clock::now();
      auto fps_start = start;
      int fps_frames = 0, rendered = 0;
      double fps = 0.0;
      // Physics frames seen, over resets (each new Simulation counts from 0).
      std::uint64_t physics_frames = 0, counted_frame = snapshots.front().frame;
      while (!glfwWindowShouldClose(window)) {
        glfwPollEvents();
        snapshots.update();
        const ViewSnapshot& snap = snapshots.front();
        physics_frames += snap.generation == generation_seen ? snap.frame - counted_frame : snap.frame;
        counted_frame = snap.frame;
        // A new Simulation (reset): the handle goes to the driven tool.
        if (snap.generation != generation_seen) {
          generation_seen = snap.generation;
          const int t = physics.driven_tool();
          if (t >= 0 && static_cast<std::size_t>(t) < snap.tools.size()) device.place(snap.tools[static_cast<std::size_t>(t)].position);
        }
        const auto pick = [&](int t) {
          if (t < 0 || static_cast<std::size_t>(t) >= snap.tools.size()) return;
          device.place(snap.tools[static_cast<std::size_t>(t)].position);
          physics.drive_tool(t);
        };

        int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
        glfwGetFramebufferSize(window, &fb_w, &fb_h);
        glfwGetWindowSize(window, &win_w, &win_h);
        const float aspect = fb_h > 0 ? static_cast<float>(fb_w) / fb_h : 1.0f;
        const M4 view = camera.view(), projection = camera.projection(aspect);

        // ---- the mouse and keys (unless the panel has them)
        ImGuiIO& io = ImGui::GetIO();
        double mx = 0, my = 0;
        glfwGetCursorPos(window, &mx, &my);
        const double dx = mx - mouse_state.x, dy = my - mouse_state.y;
        mouse_state.x = mx, mouse_state.y = my;
        const bool ctrl = glfwGetKey(window, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS ||
                          glfwGetKey(window, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
        const bool shift = glfwGetKey(window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                           glfwGetKey(window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
        const bool left = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
        const bool right = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
        const bool middle = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
        if (!io.WantCaptureMouse) {
          if (left && !mouse_state.left) mouse_state.press_x = mx, mouse_state.press_y = my, mouse_state.dragged = false;
          if (left && std::hypot(mx - mouse_state.press_x, my - mouse_state.press_y) > 3) mouse_state.dragged = true;
          const bool handle_drag = right || (left && ctrl);
          if (handle_drag && physics.driven_tool() >= 0 && (dx != 0 || dy != 0)) {
            const V3 goal(device.goal());
            const V3 step = shift ? camera.drag_in_depth(goal, static_cast<float>(dy), static_cast<float>(win_h))
                                  : camera.drag_in_plane(goal, static_cast<float>(dx), static_cast<float>(dy),
                                                         static_cast<float>(win_h));
            device.move_to((goal + step).to_double());
          } else if (left && mouse_state.dragged) {
            camera.orbit(static_cast<float>(dx), static_cast<float>(dy));
          } else if (middle) {
            camera.pan(static_cast<float>(dx), static_cast<float>(dy), static_cast<float>(win_h));
          }
          if (!left && mouse_state.left && !mouse_state.dragged && !ctrl)
            pick(tool_at(snap, projection * view, mx, my, win_w, win_h));
          if (mouse_state.scroll != 0) camera.zoom(static_cast<float>(mouse_state.scroll));
        }
        mouse_state.scroll = 0;
        mouse_state.left = left, mouse_state.right = right, mouse_state.middle = middle;
        PanelActions act;
        if (!io.WantCaptureKeyboard) {
          act.toggle_pause = ImGui::IsKeyPressed(GLFW_KEY_SPACE);
          act.step = ImGui::IsKeyPressed(GLFW_KEY_N);
          act.reset = ImGui::IsKeyPressed(GLFW_KEY_R);
          if (ImGui::IsKeyPressed(GLFW_KEY_C)) options.contacts = !options.contacts;
          if (ImGui::IsKeyPressed(GLFW_KEY_V)) options.colour_by_speed = !options.colour_by_speed;
          if (ImGui::IsKeyPressed(GLFW_KEY_H)) show_panel = !show_panel;
          if (ImGui::IsKeyPressed(GLFW_KEY_TAB) && !snap.tools.empty())
            act.pick_tool = (physics.driven_tool() + 1) % static_cast<int>(snap.tools.size());
          if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(window, GLFW_TRUE);
        }

        // ---- the script (a headless test) and the frame limit
        ScriptedRun::Step scripted;
        if (script) scripted = script->next(snap, physics.driven_tool());
        if (scripted.move) device.move_to((V3(device.goal()) + *move).to_double());
        const bool last = scripted.done || (o.frames > 0 && rendered + 1 >= o.frames);
        std::string shot = scripted.screenshot;
        if (shot.empty() && last && !o.screenshot.empty()) shot = o.screenshot;

        // ---- the scene
        haptics::CouplingFeedback feedback{};
        const bool have_feedback = physics.read_feedback(feedback);
        HandleView handle{.tool = physics.driven_tool(),
                          .position = have_feedback ? V3(feedback.device_position) : V3(device.goal()),
                          .force = have_feedback ? V3(feedback.force) : V3{}};
        drawer.update(snap, options);
        renderer.begin(fb_w, fb_h, view, projection, camera.eye(), {0.13f, 0.14f, 0.17f});
        drawer.draw(renderer, snap, options, handle);

        // ---- the panel (left out of the script's pictures: the scene alone)
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        if (show_panel && !(script && !shot.empty())) {
          const PanelInfo info{.scene = o.scene, .device = physics.device_name(), .haptics = physics.haptic_description(),
                               .render_fps = fps, .frame_time = physics.file().scene.solver.time_step,
                               .driven_tool = physics.driven_tool(), .hand_force = handle.force, .handle = handle.position};
          const PanelActions panel = draw_panel(snap, info, options);
          act.toggle_pause |= panel.toggle_pause, act.step |= panel.step, act.reset |= panel.reset;
          if (panel.pick_tool >= 0) act.pick_tool = panel.pick_tool;
          if (handle.tool >= 0) {  // the force's number beside the handle
            float w = 0;
            const V3 ndc = transform_point(projection * view, handle.position, &w);
            if (w > 0) {
              char text[32];
              std::snprintf(text, sizeof text, "%.2f N", length(handle.force));
              ImGui::GetForegroundDrawList()->AddText(
                  ImVec2(static_cast<float>((ndc.x * 0.5 + 0.5) * win_w) + 12, static_cast<float>((0.5 - ndc.y * 0.5) * win_h)),
                  IM_COL32(255, 120, 90, 255), text);
            }
          }
        }
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        if (!shot.empty()) {
          renderer.read_pixels(fb_w, fb_h, pixels);
          if (Status s = write_ppm(shot, fb_w, fb_h, pixels); !s) {
            status = fail(s.error().message());
            break;
          }
        }
        glfwSwapBuffers(window);

        if (act.toggle_pause) physics.set_paused(!physics.paused());
        if (act.step) physics.step_once();
        if (act.reset) physics.reset();
        if (act.pick_tool >= 0) pick(act.pick_tool);

        ++rendered, ++fps_frames;
        const auto now = clock::now();
        const double since = std::chrono::duration<double>(now - fps_start).count();
        if (since >= 0.5) fps = fps_frames / since, fps_start = now, fps_frames = 0;
        if (script && std::chrono::duration<double>(now - start).count() > 300) {
          status = fail("--script-test: the physics did not reach its frames within 300 s");
          break;
        }
        if (!snap.error.empty() && script) {
          status = fail(snap.error);
          break;
        }
        if (last) break;
      }
      const double seconds = std::chrono::duration<double>(clock::now() - start).count();
      // The process's CPU time (physics, haptic loop, this thread and a
      // software OpenGL's threads): how many cores the view needs.
      rusage usage{};
      getrusage(RUSAGE_SELF, &usage);
      const double cpu = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
      std::printf("rendered %d frames in %.2f s: %.1f frames per second; physics %llu frames: %.1f Hz (the scene's rate %.1f Hz); "
                  "CPU time %.2f s (%.2f cores)\n",
                  rendered, seconds, rendered / seconds, static_cast<unsigned long long>(physics_frames),
                  physics_frames / seconds, 1.0 / physics.file().scene.solver.time_step, cpu, cpu / seconds);
      if (script && status == 0) std::printf("%s", script->report().c_str());
      std::fflush(stdout);
      physics.stop();
    }
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return status;
}

}  // namespace sinew::cli
