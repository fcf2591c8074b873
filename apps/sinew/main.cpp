// main.cpp — the `sinew` program (docs/runner.md): `sinew run`, `sinew
// check`, `sinew info`, each with --help (CLI11).
#include <CLI/CLI.hpp>

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

  CLI::App* info_cmd = app.add_subcommand("info", "List the backends built in and the devices each finds");

  CLI11_PARSE(app, argc, argv);
  if (*run_cmd) return sinew::cli::run_scene(run);
  if (*check_cmd) return sinew::cli::check_scene_file(check_path);
  if (*info_cmd) return sinew::cli::print_info();
  return 2;
}
