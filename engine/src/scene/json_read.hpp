// SPDX-License-Identifier: MIT
// Typed, path-aware reads from a nlohmann::json document. Every error names the full key path
// ("cloth.stiffness.bend", "colliders[1].radius") and the offending JSON value.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "vkcloth/result.hpp"

namespace vkcloth::scene_detail {

using json = nlohmann::json;

/// "a.b" + "c" -> "a.b.c"; "" + "c" -> "c".
std::string join(std::string_view path, std::string_view key);
/// A JSON value as a short string for messages (long values are cut).
std::string show(const json& v);
/// ErrorCode::parse: the document has the wrong shape.
Error shape_error(std::string message);

/// Errors on the first key of `obj` not in `allowed`, naming its full path.
Result<void> check_keys(const json& obj, std::string_view path,
                        std::initializer_list<std::string_view> allowed);
/// Errors on the first of `keys` that `obj` lacks: "colliders[0].radius is required for a sphere"
/// (`what` = "a sphere").
Result<void> require_keys(const json& obj, std::string_view path,
                          std::initializer_list<std::string_view> keys, std::string_view what);

/// Readers: absent key -> `out` keeps its default. Wrong type or non-finite -> error.
/// `obj` must be an object.
Result<const json*> read_object(const json& obj, std::string_view path, const char* key);
Result<const json*> read_array(const json& obj, std::string_view path, const char* key);
Result<void> read(const json& obj, std::string_view path, const char* key, double& out);
Result<void> read(const json& obj, std::string_view path, const char* key, std::string& out);
Result<void> read(const json& obj, std::string_view path, const char* key, bool& out);
Result<void> read(const json& obj, std::string_view path, const char* key, glm::dvec3& out);
Result<void> read(const json& obj, std::string_view path, const char* key, glm::dvec2& out);
/// A placement (docs/scene-format.md `cloth.mesh_transform`): obj[key] = {"translate": [x,y,z],
/// "rotate_deg": [rx,ry,rz], "scale": s}, each optional; absent keys keep `translate`, `rotate_deg`,
/// `scale` as they are. Only shapes and finiteness are checked here (the caller checks scale > 0).
Result<void> read_transform(const json& obj, std::string_view path, const char* key, glm::dvec3& translate,
                            glm::dvec3& rotate_deg, double& scale);
/// A number or an array of numbers (a single number becomes a one-element array).
Result<void> read(const json& obj, std::string_view path, const char* key, std::vector<double>& out);

/// Value readers (the value itself, at `path`).
Result<double> as_number(const json& v, std::string_view path);
/// A whole number in min..max (a JSON float too when it is whole); the message names that range.
Result<std::uint64_t> as_integer(const json& v, std::string_view path, std::uint64_t max,
                                 std::uint64_t min = 0);
Result<glm::dvec3> as_vec3(const json& v, std::string_view path);

} // namespace vkcloth::scene_detail
