// SPDX-License-Identifier: MIT
#include "json_read.hpp"

#include <cmath>

#include <fmt/format.h>

namespace vkcloth::scene_detail {

std::string join(std::string_view path, std::string_view key) {
  if (path.empty())
    return std::string(key);
  return fmt::format("{}.{}", path, key);
}

std::string show(const json& v) {
  // dump() would print inf as null; say what the parser really produced.
  if (v.is_number_float() && !std::isfinite(v.get<double>()))
    return fmt::format("{}", v.get<double>());
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace); // invalid UTF-8 -> U+FFFD
  if (s.size() > 60)
    s = s.substr(0, 57) + "...";
  return s;
}

Error shape_error(std::string message) {
  return make_error(ErrorCode::parse, std::move(message));
}

namespace {

Error type_error(std::string_view path, std::string_view expected, const json& v) {
  return shape_error(fmt::format("{} must be {}, got {} ({})", path, expected, show(v), v.type_name()));
}

std::string list(std::initializer_list<std::string_view> keys) {
  std::string s;
  for (std::string_view k : keys)
    s += (s.empty() ? "" : ", ") + std::string(k);
  return s;
}

} // namespace

Result<void> check_keys(const json& obj, std::string_view path,
                        std::initializer_list<std::string_view> allowed) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool known = false;
    for (std::string_view a : allowed)
      known = known || it.key() == a;
    if (!known)
      return shape_error(fmt::format("unknown key {} (known keys{}: {})", join(path, it.key()),
                                     path.empty() ? "" : fmt::format(" in {}", path), list(allowed)));
  }
  return {};
}

Result<void> require_keys(const json& obj, std::string_view path,
                          std::initializer_list<std::string_view> keys, std::string_view what) {
  for (std::string_view k : keys)
    if (!obj.contains(std::string(k)))
      return shape_error(fmt::format("{} is required for {}", join(path, k), what));
  return {};
}

Result<const json*> read_object(const json& obj, std::string_view path, const char* key) {
  auto it = obj.find(key);
  if (it == obj.end())
    return static_cast<const json*>(nullptr);
  if (!it->is_object())
    return type_error(join(path, key), "an object", *it);
  return &*it;
}

Result<const json*> read_array(const json& obj, std::string_view path, const char* key) {
  auto it = obj.find(key);
  if (it == obj.end())
    return static_cast<const json*>(nullptr);
  if (!it->is_array())
    return type_error(join(path, key), "an array", *it);
  return &*it;
}

Result<double> as_number(const json& v, std::string_view path) {
  if (!v.is_number())
    return type_error(path, "a number", v);
  const double d = v.get<double>();
  if (!std::isfinite(d))
    return shape_error(fmt::format("{} must be a finite number, got {} (out of the double range)", path, d));
  return d;
}

Result<std::uint64_t> as_integer(const json& v, std::string_view path, std::uint64_t max, std::uint64_t min) {
  const auto range = [&] {
    return shape_error(fmt::format("{} must be an integer in {}..{}, got {}", path, min, max, show(v)));
  };
  if (v.is_number_unsigned()) {
    const auto u = v.get<std::uint64_t>();
    if (u < min || u > max)
      return range();
    return u;
  }
  if (v.is_number_integer())
    return range(); // negative
  if (v.is_number_float()) {
    const double d = v.get<double>();
    // 1e3 is a JSON float; accept it when it is a whole number.
    if (!std::isfinite(d) || d < static_cast<double>(min) || d != std::floor(d) ||
        d > static_cast<double>(max))
      return range();
    return static_cast<std::uint64_t>(d);
  }
  return type_error(path, "an integer", v);
}

Result<glm::dvec3> as_vec3(const json& v, std::string_view path) {
  if (!v.is_array() || v.size() != 3)
    return type_error(path, "an array of 3 numbers", v);
  glm::dvec3 out{0.0};
  for (int k = 0; k < 3; ++k) {
    auto x = as_number(v[k], fmt::format("{}[{}]", path, k));
    if (!x)
      return x.error();
    out[k] = *x;
  }
  return out;
}

Result<void> read(const json& obj, std::string_view path, const char* key, double& out) {
  auto it = obj.find(key);
  if (it == obj.end())
    return {};
  auto x = as_number(*it, join(path, key));
  if (!x)
    return x.error();
  out = *x;
  return {};
}

Result<void> read(const json& obj, std::string_view path, const char* key, std::string& out) {
  auto it = obj.find(key);
  if (it == obj.end())
    return {};
  if (!it->is_string())
    return type_error(join(path, key), "a string", *it);
  out = it->get<std::string>();
  return {};
}

Result<void> read(const json& obj, std::string_view path, const char* key, bool& out) {
  auto it = obj.find(key);
  if (it == obj.end())
    return {};
  if (!it->is_boolean())
    return type_error(join(path, key), "true or false", *it);
  out = it->get<bool>();
  return {};
}

Result<void> read(const json& obj, std::string_view path, const char* key, glm::dvec3& out) {
  auto it = obj.find(key);
  if (it == obj.end())
    return {};
  auto v = as_vec3(*it, join(path, key));
  if (!v)
    return v.error();
  out = *v;
  return {};
}

Result<void> read(const json& obj, std::string_view path, const char* key, glm::dvec2& out) {
  auto it = obj.find(key);
  if (it == obj.end())
    return {};
  const std::string p = join(path, key);
  if (!it->is_array() || it->size() != 2)
    return type_error(p, "an array of 2 numbers", *it);
  for (int k = 0; k < 2; ++k) {
    auto x = as_number((*it)[k], fmt::format("{}[{}]", p, k));
    if (!x)
      return x.error();
    out[k] = *x;
  }
  return {};
}

Result<void> read_transform(const json& obj, std::string_view path, const char* key, glm::dvec3& translate,
                            glm::dvec3& rotate_deg, double& scale) {
  auto t = read_object(obj, path, key);
  if (!t)
    return t.error();
  if (!*t)
    return {};
  const std::string p = join(path, key);
  VKCLOTH_TRY(check_keys(**t, p, {"translate", "rotate_deg", "scale"}));
  VKCLOTH_TRY(read(**t, p, "translate", translate));
  VKCLOTH_TRY(read(**t, p, "rotate_deg", rotate_deg));
  return read(**t, p, "scale", scale);
}

Result<void> read(const json& obj, std::string_view path, const char* key, std::vector<double>& out) {
  auto it = obj.find(key);
  if (it == obj.end())
    return {};
  const std::string p = join(path, key);
  if (it->is_number()) {
    auto x = as_number(*it, p);
    if (!x)
      return x.error();
    out.assign(1, *x);
    return {};
  }
  if (!it->is_array())
    return type_error(p, "a number or an array of numbers", *it);
  out.clear();
  out.reserve(it->size());
  for (std::size_t k = 0; k < it->size(); ++k) {
    auto x = as_number((*it)[k], fmt::format("{}[{}]", p, k));
    if (!x)
      return x.error();
    out.push_back(*x);
  }
  return {};
}

} // namespace vkcloth::scene_detail
