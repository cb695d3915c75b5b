// SPDX-License-Identifier: MIT
#include "internal/json_parse.hpp"

#include <string>
#include <unordered_set>
#include <vector>

#include <fmt/format.h>

namespace vkcloth::scene_detail {
namespace {

using json = nlohmann::json;

/// nlohmann's DOM builder plus a key-path stack, so a failure can say where it happened.
class PathTrackingSax {
public:
  PathTrackingSax(json& root, bool unique_keys)
      : unique_keys_(unique_keys), dom_(root, /*allow_exceptions=*/false) {}

  bool null() { return value(), dom_.null(); }
  bool boolean(bool v) { return value(), dom_.boolean(v); }
  bool number_integer(json::number_integer_t v) { return value(), dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value(), dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const json::string_t& s) {
    return value(), dom_.number_float(v, s);
  }
  bool string(json::string_t& v) { return value(), dom_.string(v); }
  bool binary(json::binary_t& v) { return value(), dom_.binary(v); }
  bool start_object(std::size_t n) {
    return value(), frames_.push_back({false, 0, {}, {}}), dom_.start_object(n);
  }
  bool key(json::string_t& k) {
    Frame& f = frames_.back();
    if (unique_keys_ && !f.keys.insert(k).second) { // nlohmann gives no position here
      failure.byte = std::string::npos;
      failure.path = path();
      failure.message =
          fmt::format("the key \"{}\" appears twice in this object (each key may appear once)", k);
      return false;
    }
    return f.key = k, dom_.key(k);
  }
  bool end_object() { return frames_.pop_back(), dom_.end_object(); }
  bool start_array(std::size_t n) {
    return value(), frames_.push_back({true, 0, {}, {}}), dom_.start_array(n);
  }
  bool end_array() { return frames_.pop_back(), dom_.end_array(); }

  bool parse_error(std::size_t position, const std::string& /*last_token*/,
                   const nlohmann::detail::exception& ex) {
    failure.byte = position > 0 ? position - 1 : 0; // nlohmann counts the character just read
    failure.overflow = ex.id == 406;
    failure.message = ex.what();
    // Drop "[json.exception.parse_error.101] parse error at line 1, column 2: " style prefixes.
    if (auto at = failure.message.find("] "); at != std::string::npos)
      failure.message.erase(0, at + 2);
    if (auto col = failure.message.find("column "); col != std::string::npos)
      if (auto at = failure.message.find(": ", col); at != std::string::npos)
        failure.message.erase(0, at + 2);
    // The failing value was not started: the innermost array's index is its element count.
    failure.path.clear();
    for (std::size_t k = 0; k < frames_.size(); ++k) {
      const Frame& f = frames_[k];
      if (f.array)
        failure.path += fmt::format("[{}]", k + 1 == frames_.size() ? f.count : f.count - 1);
      else
        failure.path += (failure.path.empty() ? "" : ".") + f.key;
    }
    return false;
  }

  JsonParseFailure failure;

private:
  struct Frame {
    bool array;
    std::size_t count;
    std::string key;
    std::unordered_set<std::string> keys; // with unique_keys: the object's keys so far
  };
  // The key path of the object being read (its enclosing arrays' current elements).
  std::string path() const {
    std::string p;
    for (std::size_t k = 0; k + 1 < frames_.size(); ++k)
      p += frames_[k].array ? fmt::format("[{}]", frames_[k].count - 1)
                            : (p.empty() ? "" : ".") + frames_[k].key;
    return p;
  }
  bool unique_keys_;
  void value() {
    if (!frames_.empty() && frames_.back().array)
      ++frames_.back().count;
  }
  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::vector<Frame> frames_;
};

} // namespace

/// Byte offset of the first '[' or '{' nested deeper than `max_depth` (outside strings), or npos.
/// Checked before parsing so that no recursive code (dump, copy, compare) ever meets a deep document.
std::size_t too_deep_at(std::string_view text, std::size_t max_depth) {
  std::size_t depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"')
      in_string = true;
    else if (c == '[' || c == '{') {
      if (++depth > max_depth)
        return k;
    } else if ((c == ']' || c == '}') && depth > 0)
      --depth;
  }
  return std::string_view::npos;
}

bool parse_json(std::string_view text, json& out, JsonParseFailure& failure, bool unique_keys) {
  if (const std::size_t at = text.find('\0'); at != std::string_view::npos) {
    if (text.find_first_not_of('\0', at) != std::string_view::npos) {
      failure = JsonParseFailure{};
      failure.byte = at;
      failure.message = "a NUL byte before more text (JSON is text; nothing after it would be read)";
      out = json();
      return false;
    }
    text = text.substr(0, at); // trailing NULs: a C string's terminator
  }
  if (const std::size_t at = too_deep_at(text, max_json_depth); at != std::string_view::npos) {
    failure = JsonParseFailure{};
    failure.byte = at;
    failure.message = fmt::format("arrays and objects are nested more than {} levels deep", max_json_depth);
    out = json();
    return false;
  }
  PathTrackingSax sax(out, unique_keys);
  if (json::sax_parse(text, &sax))
    return true;
  failure = std::move(sax.failure);
  out = json();
  return false;
}

std::string describe(const JsonParseFailure& f, std::string_view text, std::string_view where) {
  const std::string at = f.path.empty() ? "" : fmt::format(" at {}", f.path);
  if (f.byte == std::string::npos)
    return fmt::format("{}: invalid JSON{}: {}", where, at, f.message);
  const auto [line, col] = line_col(text, f.byte);
  return fmt::format("{}:{}:{}: invalid JSON{} (byte {}): {}", where, line, col, at, f.byte, f.message);
}

std::pair<std::size_t, std::size_t> line_col(std::string_view text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t k = 0; k < byte && k < text.size(); ++k) {
    if (text[k] == '\n')
      ++line, col = 1;
    else
      ++col;
  }
  return {line, col};
}

} // namespace vkcloth::scene_detail
