// SPDX-License-Identifier: MIT
// Helpers of the CLI tests: run the built `vkcloth` as a separate process and read its outputs.
#pragma once

#include <doctest/doctest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace vkcloth::test {

namespace fs = std::filesystem;

struct Outcome {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline fs::path tmp_dir() {
  fs::path d(VKCLOTH_TEST_TMP);
  fs::create_directories(d);
  return d;
}

/// Runs `[env] vkcloth <args>`; `tag` keeps the captured output of concurrent tests apart.
inline Outcome run_cli(const std::string& tag, const std::string& args, const std::string& env = "") {
  const fs::path out = tmp_dir() / (tag + ".stdout"), err = tmp_dir() / (tag + ".stderr");
  const std::string cmd = env + " '" + VKCLOTH_CLI_PATH + "' " + args + " >'" + out.string() + "' 2>'" +
                          err.string() + "' </dev/null";
  const int status = std::system(cmd.c_str());
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.out = slurp(out);
  o.err = slurp(err);
  return o;
}

/// run_cli for input that must be refused: exit 2 with `needle` in stderr.
inline Outcome run_cli_refused(const std::string& tag, const std::string& args, const std::string& needle) {
  Outcome o = run_cli(tag, args);
  CHECK_MESSAGE(o.code == 2, "vkcloth " << args << ": exit " << o.code);
  CHECK_MESSAGE(o.err.find(needle) != std::string::npos, "'" << needle << "' not in: " << o.err);
  return o;
}

/// Single-quoted for the shell. (Appending avoids a g++ 12 -Wrestrict false positive on "'" + s.)
inline std::string quote(const std::string& s) {
  std::string q;
  q.reserve(s.size() + 2);
  q.append(1, '\'').append(s).append(1, '\'');
  return q;
}

inline std::string write_scene(const std::string& name, const std::string& text) {
  const fs::path p = tmp_dir() / name;
  std::ofstream(p) << text;
  return quote(p.string());
}

inline std::string sample(const std::string& name) {
  return quote(std::string(VKCLOTH_SCENES_DIR) + "/" + name);
}

inline std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');)
      cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

/// True when a Vulkan device is there. On CI (CI=true) its absence fails the calling test.
inline bool have_vulkan_device() {
  const Outcome o = run_cli("devices", "devices");
  if (o.code == 0)
    return true;
  const char* ci = std::getenv("CI");
  if (ci && std::string(ci) == "true")
    FAIL("CI=true but `vkcloth devices` found no usable Vulkan device (exit ", o.code, "): ", o.err);
  MESSAGE("skipped: no Vulkan device (", o.err, ")");
  return false;
}

inline const std::string validate = "VKCLOTH_VALIDATION=1";

} // namespace vkcloth::test
