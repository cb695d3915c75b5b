// SPDX-License-Identifier: MIT
// What the vkcloth tool's commands share (commands.hpp): the options' number checks, exit codes from
// errors, the exit codes' help text, and the scene options every scene command takes.
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace vkcloth::cli {

namespace {
/// A check of an option's text: an empty string when it holds, else what is wrong.
CLI::Validator text_check(std::string description, std::string (*check)(const std::string&)) {
  return CLI::Validator([check](std::string& text) { return check(text); }, std::move(description));
}
/// The whole of `text` as a number of type T (std::from_chars: no sign for unsigned, no spaces).
template <typename T> bool parse_all(const std::string& text, T& value) {
  const char* end = text.data() + text.size();
  const auto [at, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc{} && at == end;
}
} // namespace

const CLI::Validator whole_number_at_least_one = text_check("N>=1", [](const std::string& text) {
  std::uint64_t n = 0;
  return parse_all(text, n) && n >= 1 ? std::string{} : "must be a whole number >= 1, got " + text;
});
const CLI::Validator positive_number = text_check("X>0", [](const std::string& text) {
  double x = 0.0;
  return parse_all(text, x) && std::isfinite(x) && x > 0.0 ? std::string{}
                                                           : "must be a finite number > 0, got " + text;
});
const CLI::Validator non_negative_number = text_check("X>=0", [](const std::string& text) {
  double x = 0.0;
  return parse_all(text, x) && std::isfinite(x) && x >= 0.0 ? std::string{}
                                                            : "must be a finite number >= 0, got " + text;
});

int exit_code(const Error& e) {
  switch (e.code) {
  case ErrorCode::invalid_argument:
  case ErrorCode::io:
  case ErrorCode::parse:
    return exit_bad_input;
  case ErrorCode::diverged:
    return exit_diverged;
  case ErrorCode::no_device:
  case ErrorCode::unsupported:
    return exit_no_device;
  case ErrorCode::vulkan:
  case ErrorCode::out_of_memory:
    return exit_failure;
  }
  return exit_failure;
}

int report(const Error& e) {
  fmt::print(stderr, "vkcloth: {}\n", e.message);
  return exit_code(e);
}

const char* const exit_codes_footer = R"(Exit codes:
  0  success
  1  unexpected runtime failure (Vulkan error, out of memory), or Vulkan validation messages
     were reported with --validate / VKCLOTH_VALIDATION=1
  2  bad input or usage: command line, scene file (the message names the key), output file
  3  the simulation diverged (the message names the step and time; --trace keeps the rows before it)
  4  no usable Vulkan device
  5  compare: the backends differ by more than the tolerance
Scene format and CSV outputs: docs/scene-format.md)";

std::vector<std::string> SceneArgs::overrides() const {
  std::vector<std::string> out = sets;
  if (steps)
    out.push_back(fmt::format("integrator.steps={}", *steps));
  if (dt)
    out.push_back(fmt::format("integrator.dt={:.17g}", *dt));
  if (integrator)
    out.push_back(fmt::format("integrator.method={}", *integrator));
  return out;
}

Result<Scene> SceneArgs::load() const {
  auto loaded = load_scene_file(scene, overrides());
  if (loaded)
    for (const std::string& w : loaded->warnings)
      fmt::print(stderr, "vkcloth: warning: {}\n", w);
  return loaded;
}

void add_scene_options(CLI::App& cmd, SceneArgs& args, bool sugar) {
  cmd.add_option("scene", args.scene, "Scene file (JSON)")->required();
  cmd.add_option("--set", args.sets,
                 "Override a scene key before validation: key.path=value (value is JSON, or a plain string), "
                 "e.g. cloth.stiffness.bend=15, wind.direction=[0,1,0], colliders.0.radius=0.3. Repeatable.")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  if (!sugar)
    return;
  cmd.add_option("--steps", args.steps, "Number of steps (sugar for --set integrator.steps=N)")
      ->type_name("N");
  cmd.add_option("--dt", args.dt, "Time step in seconds (sugar for --set integrator.dt=X)");
  cmd.add_option("--integrator", args.integrator,
                 "explicit_euler | semi_implicit_euler | rk4 | implicit_euler | vbd (sugar for --set "
                 "integrator.method=NAME)");
}

} // namespace vkcloth::cli
