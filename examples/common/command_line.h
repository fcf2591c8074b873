// command_line.h — the command line every example and report program
// shares (CLI11): `--help` says what the program does and lists every
// option with its default and unit, then exits 0 without running
// anything; an unknown option or a bad value is an error naming it (exit
// status 2); `--backend` and `--out` mean the same everywhere. Parsing
// also makes stdout line-buffered, so piped progress appears as printed.
//
//   sinew::examples::CommandLine cli("tissue_sag", "A block of tissue sagging under gravity.");
//   int frames = 180;
//   cli.app().add_option("--frames", frames, "Frames of 1/60 s")->check(sinew::examples::at_least(1));
//   std::string backend = "auto", out = cli.default_out();
//   cli.add_backend(backend);
//   cli.add_out(out);
//   if (auto exit = cli.parse(argc, argv)) return *exit;
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

namespace sinew::examples {

class CommandLine {
 public:
  /// [in] name: the program's name (in "Usage: NAME [OPTIONS]");
  /// [in] about: what it does, the first lines of --help.
  CommandLine(std::string name, std::string about);

  /// The CLI11 application, for the program's own options.
  CLI::App& app() { return app_; }

  /// "./<name>_out": the default output folder, under the current
  /// directory (never the source tree).
  [[nodiscard]] std::string default_out() const;

  /// --backend auto|cpu|opencl|vulkan into [in,out] backend (its value on
  /// entry is the default).
  void add_backend(std::string& backend);

  /// --out DIR into [in,out] out (its value on entry is the default);
  /// parse() creates the folder.
  void add_out(std::string& out);

  /// --NAME on|off into [in,out] flag (its value on entry is the default).
  void add_switch(const std::string& name, bool& flag, const std::string& description);

  /// Parses the command line and creates the --out folder. Returns nothing
  /// when the program should run; otherwise the exit status: 0 after
  /// printing --help, 2 after printing what is wrong with the command line
  /// (to stderr), 1 when the --out folder cannot be created.
  [[nodiscard]] std::optional<int> parse(int argc, char** argv);

 private:
  std::string name_;
  CLI::App app_;
  const std::string* out_ = nullptr;  // the --out folder, when add_out was called
};

/// A number that is finite and >= min (CLI11's own PositiveNumber and
/// Range let NaN through).
CLI::Validator at_least(double min);
/// A number that is finite and > min.
CLI::Validator greater_than(double min);

}  // namespace sinew::examples
