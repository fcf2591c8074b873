// main.cpp — the `sinew` program (docs/runner.md): `sinew run`, `sinew
// check`, `sinew info` and, when built with GLFW, OpenGL and Dear ImGui,
// `sinew view` (docs/viewer.md), each with --help (CLI11).
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

#include "commands.h"
#include "sinew/version.h"

int main(int argc, char** argv) {
  CLI::App app{"sinew " SINEW_VERSION_STRING ": run and check scene files (docs/scene_files.md, docs/runner.md)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SINEW_VERSION_STRING);

  sinew::cli::RunOptions run;
  CLI::App* run_cmd = app.add_subcommand("run", "Run a scene file: progress, statistics, VTU output, stage profile");
  run_cmd->add_option("scene", run.scene, "The scene file (JSON)")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--backend", run.backend, "Backend (default: the file's run.backend, else auto)")
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
  run_cmd->add_option("--device", run.device, "Device index or name substring (opencl, vulkan)");
  run_cmd->add_option("--frames", run.frames, "Frames to run (default: the file's run.frames)")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--out", run.out, "Write VTU files and .pvd series per body (and the fluid) to this folder");
  run_cmd->add_option("--every", run.every, "Statistics line and VTU output every N frames (default: run.every)")
      ->check(CLI::PositiveNumber);
  run_cmd->add_option("--threads", run.threads, "CPU backend worker threads (0: all)")->check(CLI::NonNegativeNumber);
  run_cmd->add_option("--positions", run.positions,
                      "Write the final positions (raw float32 x y z w per particle) to this file");
  run_cmd->add_flag("--quiet", run.quiet, "Only the summary and the profile, no per-output lines");

  std::string check_path;
  CLI::App* check_cmd = app.add_subcommand("check", "Validate a scene file without running it");
  check_cmd->add_option("scene", check_path, "The scene file (JSON)")->required()->check(CLI::ExistingFile);

  std::vector<std::string> haptic_plugins;
  CLI::App* info_cmd = app.add_subcommand("info", "List the backends built in and the devices each finds");
  info_cmd->add_option("--haptic-plugin", haptic_plugins,
                       "Also load this haptic device plug-in and list its devices (repeatable; docs/haptics.md)");

#ifdef SINEW_HAVE_VIEWER
  sinew::cli::ViewOptions view;
  CLI::App* view_cmd = app.add_subcommand("view", "Open a window onto a scene as it runs; the mouse drives a tool (docs/viewer.md)");
  view_cmd->add_option("scene", view.scene, "The scene file (JSON)")->required()->check(CLI::ExistingFile);
  view_cmd->add_option("--backend", view.backend, "Backend (default: the file's run.backend, else auto)")
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
  view_cmd->add_option("--device", view.device, "Device index or name substring (opencl, vulkan)");
  view_cmd->add_option("--threads", view.threads, "CPU backend worker threads (0: all but one, left to the renderer)")->check(CLI::NonNegativeNumber);
  view_cmd->add_flag_callback("--no-probe", [&view] { view.probe = false; },
                              "Add no probe to a scene without tools (nothing for the mouse to drive)");
  view_cmd->add_option("--width", view.width, "Window width [pixels]")->check(CLI::Range(64, 16384));
  view_cmd->add_option("--height", view.height, "Window height [pixels]")->check(CLI::Range(64, 16384));
  view_cmd->add_flag_callback("--no-vsync", [&view] { view.vsync = false; },
                              "Draw as fast as possible instead of at the display's refresh");
  view_cmd->add_option("--msaa", view.msaa, "Antialiasing samples per pixel (0: none)")->check(CLI::Range(0, 16));
  CLI::Option* paused = view_cmd->add_flag("--paused", view.paused, "Start with the physics paused (space runs it)");
  view_cmd->add_flag("--no-panel", view.no_panel, "Start with the panel hidden (h shows it)");
  view_cmd->add_option("--frames", view.frames, "Close after this many rendered frames")->check(CLI::PositiveNumber);
  view_cmd->add_option("--screenshot", view.screenshot, "With --frames: save the last frame to this PPM file")
      ->needs("--frames");
  view_cmd->add_option("--script-test", view.script_test,
                       "Headless test: settle, screenshot, move the handle by --move-tool, screenshot, close; "
                       "images into this folder")
      ->excludes(paused);
  view_cmd->add_option("--move-tool", view.move_tool, "With --script-test: the handle's move dx,dy,dz [m]")
      ->needs("--script-test");
#endif

  CLI11_PARSE(app, argc, argv);
  if (*run_cmd) return sinew::cli::run_scene(run);
  if (*check_cmd) return sinew::cli::check_scene_file(check_path);
  if (*info_cmd) return sinew::cli::print_info(haptic_plugins);
#ifdef SINEW_HAVE_VIEWER
  if (*view_cmd) return sinew::cli::view_scene(view);
#endif
  return 2;
}
