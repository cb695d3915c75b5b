// SPDX-License-Identifier: MIT
#include "overrides.hpp"

#include <cctype>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "internal/json_parse.hpp"
#include "json_read.hpp"

namespace vkcloth::scene_detail {
namespace {

bool is_index(std::string_view s) {
  if (s.empty() || s.size() > 9)
    return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c)))
      return false;
  return true;
}

/// "colliders[0].radius" -> {"colliders", "0", "radius"}; empty segments are kept (and refused).
std::vector<std::string> split_path(std::string_view key) {
  std::string norm;
  for (char c : key) {
    if (c == '[')
      norm += '.';
    else if (c != ']')
      norm += c;
  }
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = norm.find('.', start);
    parts.push_back(norm.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos)
      break;
    start = dot + 1;
  }
  return parts;
}

} // namespace

Result<void> apply_override(nlohmann::json& doc, std::string_view spec) {
  const std::size_t eq = spec.find('=');
  if (eq == std::string_view::npos || eq == 0)
    return shape_error(fmt::format("override '{}' must look like key.path=value", spec));
  const std::string_view key = spec.substr(0, eq), text = spec.substr(eq + 1);
  const std::vector<std::string> parts = split_path(key);
  if (parts.size() > max_override_depth)
    return shape_error(fmt::format("override '{}': the key path has {} parts, more than {}",
                                   spec.substr(0, 200), parts.size(), max_override_depth));
  for (const std::string& p : parts)
    if (p.empty())
      return shape_error(fmt::format("override '{}': the key path '{}' has an empty part", spec, key));

  json value;
  if (JsonParseFailure f; !parse_json(text, value, f)) {
    if (f.overflow)
      return shape_error(fmt::format(
          "override '{}': {} must be a finite number, got {} (out of the double range)", spec, key, text));
    value = std::string(text); // plain words need no quotes
  }

  json* node = &doc;
  std::string walked;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string& part = parts[k];
    const bool last = k + 1 == parts.size();
    json* child = nullptr;
    if (node->is_object()) {
      if (!node->contains(part) && !last)
        (*node)[part] = is_index(parts[k + 1]) ? json::array() : json::object(); // create the way down
      child = &(*node)[part];
      walked = join(walked, part);
    } else if (node->is_array()) {
      if (!is_index(part))
        return shape_error(
            fmt::format("override '{}': {} is an array; '{}' is not an index", spec, walked, part));
      const std::size_t i = std::stoul(part);
      if (i > node->size())
        return shape_error(fmt::format("override '{}': index {} is past the end of {} ({} elements)", spec, i,
                                       walked, node->size()));
      if (i == node->size())
        node->push_back(last ? json() : json::object()); // append
      child = &(*node)[i];
      walked = fmt::format("{}[{}]", walked, i);
    } else {
      return shape_error(
          fmt::format("override '{}': {} is {} ({}), not an object or array, so it has no key '{}'", spec,
                      walked, show(*node), node->type_name(), part));
    }
    node = child;
  }
  *node = std::move(value);
  return {};
}

} // namespace vkcloth::scene_detail
