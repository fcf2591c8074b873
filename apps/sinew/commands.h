// commands.h — the sinew command-line program's commands (apps/sinew;
// docs/runner.md): run a scene file, check one, list backends and devices,
// and view one as it runs (docs/viewer.md; built with GLFW, OpenGL and Dear ImGui).
#pragma once

#include <string>
#include <vector>

namespace sinew::cli {

/// `sinew run` options; zero or empty: the scene file's "run" section.
struct RunOptions {
  std::string scene;     ///< the scene file
  std::string backend;   ///< "auto", "cpu", "opencl", "vulkan"; empty: the file's
  std::string device;    ///< a device index or name substring (DeviceOptions::device)
  int frames = 0;        ///< frames to run; 0: the file's
  int every = 0;         ///< output every N frames; 0: the file's
  std::string out;       ///< VTU folder; empty: no VTU output
  int threads = 0;       ///< cpu backend's worker threads; 0: all
  bool quiet = false;    ///< no per-output lines (the summary and profile only)
  /// After the last frame, every particle's position and inverse mass as
  /// raw float32 x, y, z, w (little-endian, in read_positions' order) to
  /// this file; empty: none. For bitwise comparisons with other front ends
  /// (the C API, Python).
  std::string positions;
};

/// `sinew view` options (docs/viewer.md).
struct ViewOptions {
  std::string scene;    ///< the scene file
  std::string backend;  ///< as RunOptions::backend
  std::string device;   ///< as RunOptions::device
  int threads = 0;      ///< cpu backend's worker threads; 0: all but one (left to the renderer)
  bool probe = true;    ///< a scene without a tool gets a probe for the mouse to drive
  int width = 1280, height = 720;  ///< the window [pixels]
  bool vsync = true;    ///< wait for the display's refresh between frames
  /// Multisample antialiasing samples (0: none; a software renderer such as
  /// Mesa's llvmpipe pays for each sample in every pixel).
  int msaa = 0;
  bool no_panel = false;  ///< start with the ImGui panel hidden
  bool paused = false;    ///< start with the physics paused (space runs it)
  int frames = 0;       ///< close after this many rendered frames (0: when the window is closed)
  std::string screenshot;  ///< with frames: the last frame as a PPM image to this file
  /// A headless test: screenshots into this folder before and after moving
  /// the handle by move_tool, then close (view/scripted_run.h).
  std::string script_test;
  std::string move_tool = "0.02,-0.01,0";  ///< the script's handle offset "dx,dy,dz" [m]
};

/// Runs the scene; returns the process's exit status (0, or 1 on an error).
int run_scene(const RunOptions& options);
/// Reads and checks the scene file without running it; prints what it holds.
int check_scene_file(const std::string& scene);
/// Prints the version, the backends built in and the devices each finds;
/// then each haptic device plug-in of `haptic_plugins` (paths), loaded, with
/// its devices. Returns 1 when a plug-in does not load or list, else 0.
int print_info(const std::vector<std::string>& haptic_plugins = {});
/// Opens a window onto the scene as it runs (docs/viewer.md); returns the
/// exit status (0, or 1 on an error: the scene, the backend, no display).
int view_scene(const ViewOptions& options);

}  // namespace sinew::cli
