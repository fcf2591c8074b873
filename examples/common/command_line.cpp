// command_line.cpp — the examples' shared command line (command_line.h).
#include "command_line.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <system_error>
#include <utility>

namespace sinew::examples {

namespace {
// --help lists each option as "--frames INT [>= 1] (default 180)".
class Formatter : public CLI::Formatter {
 public:
  std::string make_option_opts(const CLI::Option* opt) const override {
    if (opt->get_type_size() == 0) return "";  // a flag
    std::string type = opt->get_type_name();
    if (!type.empty() && type.front() == ':') type.erase(0, 1);
    for (char& c : type)
      if (c == ':') c = ' ';
    std::string text = " " + type;
    if (!opt->get_default_str().empty()) text += " (default " + opt->get_default_str() + ")";
    if (opt->get_required()) text += " (required)";
    return text;
  }
};
}  // namespace

CommandLine::CommandLine(std::string name, std::string about) : name_(std::move(name)), app_(std::move(about), name_) {
  app_.option_defaults()->always_capture_default();
  auto formatter = std::make_shared<Formatter>();
  formatter->column_width(40);
  app_.formatter(formatter);
}

std::string CommandLine::default_out() const { return "./" + name_ + "_out"; }

void CommandLine::add_backend(std::string& backend) {
  app_.add_option("--backend", backend, "Backend: auto (the best available), cpu, opencl or vulkan")
      ->check(CLI::IsMember({"auto", "cpu", "opencl", "vulkan"}));
}

void CommandLine::add_out(std::string& out) {
  app_.add_option("--out", out, "Folder for everything the program writes (created if missing)")
      ->type_name("DIR")
      ->check([](const std::string& v) { return v.empty() ? std::string("must not be empty") : std::string(); });
  out_ = &out;
}

void CommandLine::add_switch(const std::string& name, bool& flag, const std::string& description) {
  app_.add_option_function<std::string>(
          name, [&flag](const std::string& v) { flag = v == "on"; }, description)
      ->check(CLI::IsMember({"on", "off"}))
      ->default_str(flag ? "on" : "off")
      ->type_name("");
}

std::optional<int> CommandLine::parse(int argc, char** argv) {
  // Line-buffered even into a pipe: progress appears as it is printed.
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    app_.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints the usage to stdout (exit code 0); every other parse
    // error its message and a hint to stderr.
    return app_.exit(e) == 0 ? 0 : 2;
  }
  if (out_) {
    std::error_code error;
    std::filesystem::create_directories(*out_, error);
    if (error) {
      std::fprintf(stderr, "%s: cannot create the --out folder %s: %s\n", name_.c_str(), out_->c_str(),
                   error.message().c_str());
      return 1;
    }
  }
  return std::nullopt;
}

namespace {
CLI::Validator bound(double min, bool strict) {
  const std::string rule = std::string(strict ? "> " : ">= ") + CLI::detail::to_string(min);
  return CLI::Validator(
      [min, strict, rule](const std::string& text) {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v) || (strict ? !(v > min) : !(v >= min)))
          return "must be a finite number " + rule + " (got " + text + ")";
        return std::string();
      },
      "[" + rule + "]");
}
}  // namespace

CLI::Validator at_least(double min) { return bound(min, false); }
CLI::Validator greater_than(double min) { return bound(min, true); }

}  // namespace sinew::examples
