// SPDX-License-Identifier: MIT
// OBJ reader: v, vt and f lines; everything else (vn, o, g, s, usemtl, mtllib, l, p, ...) is ignored.
//
// tinyobjloader is lenient: it reads "nan" or "abc" as 0, drops faces with fewer than 3 vertices,
// checks face indices only against the whole file, and its errors do not always name the line. So a
// pre-scan of our own checks every v, vt and f line first, with errors naming the file and the line,
// and tinyobjloader then reads the faces, comments stripped, through its streaming callback API
// (never triangulates, no 255-vertex cap on a face, no allocation per face). The coordinates are the
// pre-scan's (std::from_chars, correctly rounded, so what format_obj writes reads back exactly;
// tinyobjloader's own number parser is off by a few ulps): tinyobjloader only counts v and vt lines.
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <streambuf>
#include <string>

#include <tiny_obj_loader.h>

#include "mesh_io.hpp"

namespace vkcloth {
namespace {

constexpr double max_abs_coordinate = 1e30;

/// One line of the text without its end of line and its comment; `number` is 1-based.
struct Line {
  std::size_t number = 0;
  std::string_view text;
};

/// Position of the first character of `s` at or after `from` for which `pred` holds, or s.size().
/// (string_view::find_first_of calls memchr on the set for every character: far slower here.)
template <typename Pred> std::size_t find_if(std::string_view s, std::size_t from, Pred pred) {
  while (from < s.size() && !pred(s[from]))
    ++from;
  return from;
}

bool is_end_of_line(char c) {
  return c == '\n' || c == '\r';
}
bool is_blank(char c) {
  return c == ' ' || c == '\t';
}

/// The lines of an OBJ text, split where tinyobjloader splits them: "\n", "\r\n" or "\r".
class Lines {
public:
  explicit Lines(std::string_view text) : rest_(text) {}

  bool next(Line& line) {
    if (done_)
      return false;
    const std::size_t end = find_if(rest_, 0, is_end_of_line);
    line.number = ++number_;
    line.text = rest_.substr(0, end);
    if (end == rest_.size()) {
      done_ = true;
    } else {
      rest_.remove_prefix(end + (rest_.substr(end, 2) == "\r\n" ? 2 : 1));
      done_ = rest_.empty();
    }
    line.text = line.text.substr(0, line.text.find('#'));
    return true;
  }

private:
  std::string_view rest_;
  std::size_t number_ = 0;
  bool done_ = false;
};

/// The words of a line, separated by spaces and tabs (as tinyobjloader separates them).
class Words {
public:
  explicit Words(std::string_view text) : rest_(text) {}

  bool next(std::string_view& word) {
    const std::size_t begin = find_if(rest_, 0, [](char c) { return !is_blank(c); });
    if (begin == rest_.size())
      return false;
    const std::size_t end = find_if(rest_, begin, is_blank);
    word = rest_.substr(begin, end - begin);
    rest_.remove_prefix(end);
    return true;
  }

private:
  std::string_view rest_;
};

enum class NumberKind { ok, not_a_number, too_large };

/// A decimal number, correctly rounded; "1e-400" underflows to 0, "1e400" is too large.
NumberKind parse_number(std::string_view word, double& value) {
  if (word.size() > 1 && word[0] == '+' && word[1] != '-')
    word.remove_prefix(1); // from_chars refuses the '+' that OBJ writers may put
  const char* end = word.data() + word.size();
  const auto [ptr, ec] = std::from_chars(word.data(), end, value);
  if (ptr != end || word.empty())
    return NumberKind::not_a_number;
  if (ec == std::errc::result_out_of_range) {
    const std::size_t e = word.find_first_of("eE");
    const bool underflow = e != std::string_view::npos && word.substr(e + 1).starts_with('-');
    value = 0.0;
    return underflow ? NumberKind::ok : NumberKind::too_large;
  }
  return ec == std::errc{} ? NumberKind::ok : NumberKind::not_a_number;
}

/// The numbers after a v or vt keyword.
struct Numbers {
  double values[8] = {};
  std::size_t count = 0;
};

Error line_error(std::string_view source, std::size_t line, std::string_view what) {
  return make_error(ErrorCode::parse, fmt::format("{}:{}: {}", source, line, what));
}

/// Which v or vt line a message is about: "vertex 5", "texture coordinate 2" (numbered from 1, as
/// faces refer to them). Formatted only for a message.
struct Element {
  std::string_view kind;
  std::size_t number = 0;
};

/// Reads the numbers of a v or vt line; the first ones, named by `axes` ("xyz", "uv"), must be
/// finite and within +-1e30.
Result<Numbers> read_numbers(Words& words, std::string_view axes, std::string_view source, std::size_t line,
                             Element what) {
  Numbers n;
  std::string_view word;
  while (words.next(word)) {
    if (n.count == std::size(n.values))
      return line_error(source, line,
                        fmt::format("{} {} has more than {} values", what.kind, what.number, n.count));
    double& v = n.values[n.count];
    const NumberKind kind = parse_number(word, v);
    const bool checked = n.count < axes.size();
    if (kind == NumberKind::not_a_number)
      return line_error(
          source, line,
          fmt::format("{} {}: {} is not a number", what.kind, what.number, mesh_detail::in_quotes(word)));
    if (checked && kind == NumberKind::too_large)
      return line_error(source, line,
                        fmt::format("{} {}: {} = {} is out of range (|coordinate| > 1e30)", what.kind,
                                    what.number, axes[n.count], mesh_detail::in_quotes(word)));
    if (checked && !std::isfinite(v))
      return line_error(
          source, line,
          fmt::format("{} {}: {} = {} is not finite", what.kind, what.number, axes[n.count], v));
    if (checked && std::abs(v) > max_abs_coordinate)
      return line_error(source, line,
                        fmt::format("{} {}: {} = {} is out of range (|coordinate| > 1e30)", what.kind,
                                    what.number, axes[n.count], v));
    ++n.count;
  }
  return n;
}

/// What the first pass reads: the v and vt lines.
struct ObjVertices {
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec2> texcoords;
};

Result<void> read_vertex(Words& words, std::string_view source, std::size_t line, ObjVertices& out) {
  const std::size_t k = out.positions.size() + 1; // OBJ numbers vertices from 1
  auto n = read_numbers(words, "xyz", source, line, {"vertex", k});
  if (!n)
    return n.error();
  // x y z, x y z w, or x y z r g b (a common vertex colour extension)
  if (n->count != 3 && n->count != 4 && n->count != 6)
    return line_error(
        source, line,
        fmt::format("vertex {} has {} values, expected 3 (v x y z), 4 (x y z w) or 6 (x y z r g b)", k,
                    n->count));
  out.positions.emplace_back(n->values[0], n->values[1], n->values[2]);
  return {};
}

Result<void> read_texcoord(Words& words, std::string_view source, std::size_t line, ObjVertices& out) {
  const std::size_t k = out.texcoords.size() + 1;
  auto n = read_numbers(words, "uv", source, line, {"texture coordinate", k});
  if (!n)
    return n.error();
  if (n->count < 1 || n->count > 3)
    return line_error(
        source, line,
        fmt::format("texture coordinate {} has {} values, expected 1 to 3 (vt u [v [w]])", k, n->count));
  out.texcoords.emplace_back(n->values[0], n->values[1]); // a missing v is 0, as in tinyobjloader
  return {};
}

/// The keyword of a line: "v", "vt", "f", ... or empty.
std::string_view keyword_of(std::string_view line) {
  std::string_view word;
  Words(line).next(word);
  return word;
}

/// More vertices than a ParticleSystem holds are refused before any is read.
Result<void> check_vertex_count(std::string_view text, std::string_view source) {
  std::size_t vertices = 0;
  Lines lines(text);
  for (Line line; lines.next(line);)
    if (keyword_of(line.text) == "v" && ++vertices > max_particles)
      return line_error(source, line.number,
                        fmt::format("more than {} vertices (max_particles)", max_particles));
  return {};
}

/// Pass 1: every v and vt line, checked and read.
Result<ObjVertices> read_vertices(std::string_view text, std::string_view source) {
  VKCLOTH_TRY(check_vertex_count(text, source));
  ObjVertices out;
  Lines lines(text);
  for (Line line; lines.next(line);) {
    Words words(line.text);
    std::string_view keyword;
    if (!words.next(keyword))
      continue;
    if (keyword == "v")
      VKCLOTH_TRY(read_vertex(words, source, line.number, out));
    else if (keyword == "vt")
      VKCLOTH_TRY(read_texcoord(words, source, line.number, out));
  }
  return out;
}

/// An OBJ index as written: 1-based from the start of the file, or negative: relative to the
/// elements defined before the line (-1 is the last one). 0 is not an index.
std::optional<std::int64_t> parse_index(std::string_view word) {
  std::int64_t v = 0;
  const char* end = word.data() + word.size();
  const auto [ptr, ec] = std::from_chars(word.data(), end, v);
  if (word.empty() || ptr != end || ec != std::errc{} || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max())
    return std::nullopt; // tinyobjloader reads indices as int
  return v;
}

/// The 0-based element an index refers to, or nullopt when it is out of range. Positive indices may
/// refer to elements defined later in the file (tinyobjloader accepts that too).
std::optional<std::uint32_t> resolve_index(std::int64_t index, std::size_t defined_before,
                                           std::size_t total) {
  const std::int64_t i = index > 0 ? index - 1 : static_cast<std::int64_t>(defined_before) + index;
  if (index == 0 || i < 0 || i >= static_cast<std::int64_t>(total))
    return std::nullopt;
  return static_cast<std::uint32_t>(i);
}

/// One corner of a face as written: v, v/vt, v//vn or v/vt/vn.
struct CornerRef {
  std::int64_t vertex = 0;
  std::optional<std::int64_t> texcoord;
};

std::optional<CornerRef> parse_corner(std::string_view word) {
  const std::size_t slash1 = word.find('/');
  const std::size_t slash2 = slash1 == std::string_view::npos ? slash1 : word.find('/', slash1 + 1);
  CornerRef ref;
  const auto vertex = parse_index(word.substr(0, slash1));
  if (!vertex)
    return std::nullopt;
  ref.vertex = *vertex;
  if (slash1 == std::string_view::npos)
    return ref;
  const std::string_view vt = word.substr(slash1 + 1, slash2 - slash1 - 1);
  const bool has_vn = slash2 != std::string_view::npos;
  if (!vt.empty() || !has_vn) { // "v/", "v/vt/" and "v//" are incomplete
    ref.texcoord = parse_index(vt);
    if (!ref.texcoord)
      return std::nullopt;
  }
  if (has_vn && !parse_index(word.substr(slash2 + 1))) // normals are not read, but must be indices
    return std::nullopt;
  return ref;
}

/// How many of each element precede a line, and the totals of the file.
struct ElementCounts {
  std::size_t vertices_before = 0, texcoords_before = 0;
  std::size_t vertices = 0, texcoords = 0;
};

/// Pass 2 state: the first face, for the message when faces disagree on having texture coordinates.
struct FaceScan {
  std::size_t faces = 0;
  std::size_t first_face_line = 0;
  bool first_face_has_uv = false;
};

/// Returns whether the corner has a texture coordinate.
Result<bool> check_corner(std::string_view word, const ElementCounts& counts, std::string_view source,
                          std::size_t line) {
  const auto ref = parse_corner(word);
  if (!ref)
    return line_error(
        source, line,
        fmt::format("{} is not a vertex reference (v, v/vt, v//vn or v/vt/vn with integer indices)",
                    mesh_detail::in_quotes(word)));
  if (ref->vertex == 0 || (ref->texcoord && *ref->texcoord == 0))
    return line_error(source, line, "face index 0 is invalid (OBJ indices start at 1)");
  if (!resolve_index(ref->vertex, counts.vertices_before, counts.vertices))
    return line_error(source, line,
                      ref->vertex > 0
                          ? fmt::format("face index {} is out of range (the file has {} vertices)",
                                        ref->vertex, counts.vertices)
                          : fmt::format("face index {} is out of range ({} vertices precede this line)",
                                        ref->vertex, counts.vertices_before));
  if (ref->texcoord && !resolve_index(*ref->texcoord, counts.texcoords_before, counts.texcoords))
    return line_error(
        source, line,
        *ref->texcoord > 0
            ? fmt::format("texture index {} is out of range (the file has {} texture coordinates)",
                          *ref->texcoord, counts.texcoords)
            : fmt::format("texture index {} is out of range ({} texture coordinates precede "
                          "this line)",
                          *ref->texcoord, counts.texcoords_before));
  return ref->texcoord.has_value();
}

Result<void> check_face(Words& words, const ElementCounts& counts, std::string_view source, std::size_t line,
                        FaceScan& scan) {
  const std::size_t face = ++scan.faces;
  std::size_t corners = 0, corners_with_uv = 0;
  for (std::string_view word; words.next(word); ++corners) {
    const auto has_uv = check_corner(word, counts, source, line);
    if (!has_uv)
      return has_uv.error();
    corners_with_uv += *has_uv;
  }
  if (corners < 3)
    return line_error(source, line,
                      fmt::format("face {} has {} vertices; a face needs at least 3", face, corners));
  if (corners_with_uv != 0 && corners_with_uv != corners)
    return line_error(source, line,
                      fmt::format("face {} has texture coordinates on {} of its {} corners; give them to all "
                                  "corners or to none",
                                  face, corners_with_uv, corners));
  const bool has_uv = corners_with_uv != 0;
  if (face == 1) {
    scan.first_face_line = line;
    scan.first_face_has_uv = has_uv;
  } else if (has_uv != scan.first_face_has_uv) {
    return line_error(source, line,
                      fmt::format("face {} {} texture coordinates, but face 1 (line {}) {}", face,
                                  has_uv ? "has" : "has no", scan.first_face_line,
                                  scan.first_face_has_uv ? "has" : "has none"));
  }
  return {};
}

/// What pass 2 hands to tinyobjloader: the f lines (comments stripped), a placeholder for each v
/// and vt line, each at its own line number, other lines blank; and what it found.
struct CheckedText {
  std::string text;
  FaceScan faces;
};

/// Pass 2: every f line checked against the vertices and texture coordinates.
Result<CheckedText> check_faces(std::string_view text, const ObjVertices& vertices, std::string_view source) {
  CheckedText out;
  out.text.reserve(text.size());
  ElementCounts counts;
  counts.vertices = vertices.positions.size();
  counts.texcoords = vertices.texcoords.size();
  Lines lines(text);
  for (Line line; lines.next(line);) {
    Words words(line.text);
    std::string_view keyword;
    words.next(keyword);
    if (keyword == "f")
      VKCLOTH_TRY(check_face(words, counts, source, line.number, out.faces));
    counts.vertices_before += keyword == "v";
    counts.texcoords_before += keyword == "vt";
    // tinyobjloader only counts v and vt lines (their values are the pre-scan's): zeros parse fastest.
    if (keyword == "v")
      out.text += "v 0 0 0";
    else if (keyword == "vt")
      out.text += "vt 0 0";
    else if (keyword == "f")
      out.text += line.text;
    out.text += '\n';
  }
  if (out.faces.faces == 0)
    return make_error(ErrorCode::parse,
                      fmt::format("{}: no faces (f lines); a mesh needs at least one", source));
  return out;
}

/// A read-only streambuf over a string, so tinyobjloader reads it without a copy.
class ViewBuffer : public std::streambuf {
public:
  explicit ViewBuffer(std::string& text) { setg(text.data(), text.data(), text.data() + text.size()); }
};

/// Builds the faces from tinyobjloader's callbacks, resolving indices as the pre-scan did.
struct FaceBuilder {
  const ObjVertices* vertices = nullptr;
  bool with_uvs = false;
  Mesh mesh;
  std::vector<bool> uv_set;
  std::size_t vertex_lines = 0, texcoord_lines = 0;
  bool consistent = true; ///< false if tinyobjloader read something the pre-scan did not

  static void on_vertex(void* self, tinyobj::real_t, tinyobj::real_t, tinyobj::real_t, tinyobj::real_t) {
    ++static_cast<FaceBuilder*>(self)->vertex_lines;
  }
  static void on_texcoord(void* self, tinyobj::real_t, tinyobj::real_t, tinyobj::real_t) {
    ++static_cast<FaceBuilder*>(self)->texcoord_lines;
  }
  static void on_face(void* self, tinyobj::index_t* corners, int count) {
    static_cast<FaceBuilder*>(self)->add_face(std::span<const tinyobj::index_t>(corners, std::size_t(count)));
  }

  void add_face(std::span<const tinyobj::index_t> corners) {
    for (const tinyobj::index_t& c : corners) {
      const auto v = resolve_index(c.vertex_index, vertex_lines, vertices->positions.size());
      const auto vt = resolve_index(c.texcoord_index, texcoord_lines, vertices->texcoords.size());
      if (!v || (with_uvs && !vt)) {
        consistent = false;
        return;
      }
      mesh.indices.push_back(*v);
      if (with_uvs && !uv_set[*v]) { // the first corner that references a vertex gives its uv
        uv_set[*v] = true;
        // OBJ's v goes up from the image's bottom row; vkcloth's (glTF's, Vulkan's) goes down from its top.
        const glm::dvec2 vt_uv = vertices->texcoords[*vt];
        mesh.uvs[*v] = glm::dvec2(vt_uv.x, 1.0 - vt_uv.y);
      }
    }
    mesh.face_offsets.push_back(static_cast<std::uint32_t>(mesh.indices.size()));
  }
};

Result<Mesh> build_mesh(CheckedText& checked, ObjVertices& vertices, std::string_view source) {
  FaceBuilder builder;
  builder.vertices = &vertices;
  builder.with_uvs = checked.faces.first_face_has_uv;
  if (builder.with_uvs) {
    builder.mesh.uvs.assign(vertices.positions.size(), glm::dvec2(0.0));
    builder.uv_set.assign(vertices.positions.size(), false);
  }
  tinyobj::callback_t callbacks;
  callbacks.vertex_cb = &FaceBuilder::on_vertex;
  callbacks.texcoord_cb = &FaceBuilder::on_texcoord;
  callbacks.index_cb = &FaceBuilder::on_face;
  ViewBuffer buffer(checked.text);
  std::istream stream(&buffer);
  std::string warn, err;
  const bool loaded = tinyobj::LoadObjWithCallback(stream, callbacks, &builder, nullptr, &warn, &err);
  if (!loaded || !builder.consistent || builder.vertex_lines != vertices.positions.size() ||
      builder.texcoord_lines != vertices.texcoords.size() || builder.mesh.face_count() != checked.faces.faces)
    return make_error(
        ErrorCode::parse,
        fmt::format("{}: tinyobjloader read {} vertices and {} faces where the pre-scan found {} "
                    "and {}{}",
                    source, builder.vertex_lines, builder.mesh.face_count(), vertices.positions.size(),
                    checked.faces.faces, err.empty() ? "" : ": " + err));
  builder.mesh.positions = std::move(vertices.positions);
  return std::move(builder.mesh);
}

} // namespace

Result<Mesh> parse_obj(std::string_view text, std::string_view source_name) {
  return mesh_detail::guarded_parse(source_name, [&]() -> Result<Mesh> {
    VKCLOTH_TRY(mesh_detail::check_mesh_size(text.size(), source_name));
    auto vertices = read_vertices(text, source_name);
    if (!vertices)
      return vertices.error();
    auto checked = check_faces(text, *vertices, source_name);
    if (!checked)
      return checked.error();
    return build_mesh(*checked, *vertices, source_name);
  });
}

Result<Mesh> read_obj(const std::filesystem::path& path) {
  auto bytes = mesh_detail::read_mesh_file(path);
  if (!bytes)
    return bytes.error();
  const std::string_view text(reinterpret_cast<const char*>(bytes->data()), bytes->size());
  return parse_obj(text, path.string());
}

} // namespace vkcloth
