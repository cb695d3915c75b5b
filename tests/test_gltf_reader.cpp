// SPDX-License-Identifier: MIT
// The glTF reader (vkcloth/mesh.hpp): .gltf, .glb and files on disk read exactly (positions, texture
// coordinates, the base-colour texture), and every malformed input refused with the right ErrorCode
// and a message naming the element (accessor, buffer view, buffer, image).
#include "mesh_io_test_util.hpp"

namespace {

// ---- glTF built in the test ----------------------------------------------------------------------

/// A glTF document and its binary buffer, written as .gltf (buffer as a base64 data: URI) or .glb.
struct TestGltf {
  json doc;
  std::vector<std::uint8_t> bin;

  template <typename T> std::size_t append(std::initializer_list<T> values) {
    const std::size_t at = bin.size();
    for (const T v : values) {
      std::uint8_t b[sizeof(T)];
      std::memcpy(b, &v, sizeof v);
      bin.insert(bin.end(), b, b + sizeof b);
    }
    while (bin.size() % 4 != 0)
      bin.push_back(0);
    return at;
  }

  void set_float(std::size_t at, float v) { std::memcpy(bin.data() + at, &v, sizeof v); }

  std::string gltf_text() const {
    json d = doc;
    d["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
    return d.dump();
  }

  std::vector<std::uint8_t> glb() const {
    json d = doc;
    d["buffers"][0].erase("uri");
    std::string text = d.dump();
    while (text.size() % 4 != 0)
      text += ' ';
    std::vector<std::uint8_t> out;
    const auto u32 = [&out](std::uint32_t v) {
      for (int i = 0; i < 4; ++i)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    };
    u32(0x46546C67);
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
    u32(static_cast<std::uint32_t>(text.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), text.begin(), text.end());
    u32(static_cast<std::uint32_t>(bin.size()));
    u32(0x004E4942);
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
  }

  static std::string base64(std::span<const std::uint8_t> b) {
    static constexpr char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < b.size(); i += 3) {
      const std::uint32_t n = (std::uint32_t(b[i]) << 16) |
                              (i + 1 < b.size() ? std::uint32_t(b[i + 1]) << 8 : 0u) |
                              (i + 2 < b.size() ? std::uint32_t(b[i + 2]) : 0u);
      out += abc[(n >> 18) & 63];
      out += abc[(n >> 12) & 63];
      out += i + 1 < b.size() ? abc[(n >> 6) & 63] : '=';
      out += i + 2 < b.size() ? abc[n & 63] : '=';
    }
    return out;
  }
};

constexpr int float_type = 5126, ushort_type = 5123, ubyte_type = 5121;

/// The reference mesh as glTF triangles: the quad split along 0-2, then the triangle.
/// bufferViews: [0] positions (60 bytes), [1] uvs (40 bytes), [2] indices (18 bytes); buffer 120.
TestGltf ref_gltf() {
  TestGltf g;
  const std::size_t pos = g.append<float>({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0.5f});
  const std::size_t uv = g.append<float>({0, 0, 0.5f, 0, 0.5f, 1, 0, 1, 1, 0.25f});
  const std::size_t idx = g.append<std::uint16_t>({0, 1, 2, 0, 2, 3, 1, 4, 2});
  g.doc = {
      {"asset", {{"version", "2.0"}}},
      {"buffers", json::array({{{"byteLength", g.bin.size()}}})},
      {"bufferViews", json::array({{{"buffer", 0}, {"byteOffset", pos}, {"byteLength", 60}},
                                   {{"buffer", 0}, {"byteOffset", uv}, {"byteLength", 40}},
                                   {{"buffer", 0}, {"byteOffset", idx}, {"byteLength", 18}}})},
      {"accessors",
       json::array({{{"bufferView", 0}, {"componentType", float_type}, {"count", 5}, {"type", "VEC3"}},
                    {{"bufferView", 1}, {"componentType", float_type}, {"count", 5}, {"type", "VEC2"}},
                    {{"bufferView", 2}, {"componentType", ushort_type}, {"count", 9}, {"type", "SCALAR"}}})},
      {"meshes",
       json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}},
                                                  {"indices", 2}}})}}})},
  };
  return g;
}

const std::vector<std::uint32_t> ref_triangles = {0, 1, 2, 0, 2, 3, 1, 4, 2};

Result<Mesh> parse_text(const TestGltf& g) {
  const std::string text = g.gltf_text();
  return parse_gltf(bytes_of(text), false, "bad.gltf");
}

Result<Mesh> parse_binary(const TestGltf& g) {
  return parse_gltf(g.glb(), true, "bad.glb");
}

/// Expects the same error, naming the file and `needles`, from the .gltf and the .glb form.
void expect_gltf_error(const TestGltf& g, std::initializer_list<std::string> needles,
                       ErrorCode code = ErrorCode::parse) {
  expect_error(parse_text(g), code, needles);
  CHECK(parse_text(g).error().message.starts_with("bad.gltf: "));
  expect_error(parse_binary(g), code, needles);
  CHECK(parse_binary(g).error().message.starts_with("bad.glb: "));
}

// A 1 x 1 PNG.
const std::vector<std::uint8_t> png = {0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d,
                                       0x49, 0x48, 0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01,
                                       0x08, 0x06, 0x00, 0x00, 0x00, 0x1f, 0x15, 0xc4, 0x89, 0x00, 0x00, 0x00,
                                       0x0d, 0x49, 0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0x64, 0x60, 0xf8, 0x5f,
                                       0x0f, 0x00, 0x02, 0x87, 0x01, 0x80, 0xeb, 0x47, 0xba, 0x92, 0x00, 0x00,
                                       0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

/// The reference glTF with a material whose base-colour texture is images[0] (`image` as given).
TestGltf textured_gltf(const json& image) {
  TestGltf g = ref_gltf();
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  g.doc["textures"] = json::array({{{"source", 0}}});
  g.doc["images"] = json::array({image});
  return g;
}

} // namespace

// ---- glTF ----------------------------------------------------------------------------------------

TEST_CASE("gltf: the same triangles from .gltf (base64 data: buffer), .glb and files on disk") {
  const TestGltf g = ref_gltf();
  auto text = parse_text(g);
  auto binary = parse_binary(g);
  REQUIRE_MESSAGE(text.ok(), text.error().message);
  REQUIRE_MESSAGE(binary.ok(), binary.error().message);
  CHECK(text->positions == ref_positions);
  CHECK(text->uvs == ref_uvs);
  CHECK(text->indices == ref_triangles);
  CHECK(text->face_offsets == std::vector<std::uint32_t>{0, 3, 6, 9});
  CHECK(!text->texture);
  CHECK(binary->positions == text->positions);
  CHECK(binary->uvs == text->uvs);
  CHECK(binary->indices == text->indices);
  CHECK(binary->face_offsets == text->face_offsets);

  const fs::path dir = temp_dir();
  write_file(dir / "flag.gltf", g.gltf_text());
  write_file(dir / "flag.GLB", g.glb());
  auto from_gltf = read_mesh(dir / "flag.gltf");
  auto from_glb = read_mesh(dir / "flag.GLB");
  REQUIRE_MESSAGE(from_gltf.ok(), from_gltf.error().message);
  REQUIRE_MESSAGE(from_glb.ok(), from_glb.error().message);
  CHECK(from_gltf->indices == ref_triangles);
  CHECK(from_glb->positions == ref_positions);
}

TEST_CASE(
    "gltf: primitives merge with offset indices, and no indices means sequential, and other modes skipped") {
  TestGltf g = ref_gltf();
  auto& prims = g.doc["meshes"][0]["primitives"];
  prims.push_back({{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"mode", 1}}); // lines: skipped
  g.doc["accessors"].push_back(
      {{"bufferView", 0}, {"componentType", float_type}, {"count", 3}, {"type", "VEC3"}});
  g.doc["accessors"].push_back(
      {{"bufferView", 1}, {"componentType", float_type}, {"count", 3}, {"type", "VEC2"}});
  prims.push_back({{"attributes", {{"POSITION", 3}, {"TEXCOORD_0", 4}}}, {"mode", 4}});
  auto m = parse_text(g);
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  REQUIRE(m->positions.size() == 8);
  CHECK(m->positions[7] == ref_positions[2]);
  CHECK(m->indices.size() == 12);
  CHECK(std::vector<std::uint32_t>(m->indices.begin() + 9, m->indices.end()) ==
        std::vector<std::uint32_t>{5, 6, 7});
  CHECK(m->face_count() == 4);
}

TEST_CASE("gltf: TEXCOORD_0 as normalized unsigned bytes") {
  TestGltf g = ref_gltf();
  const std::size_t at = g.append<std::uint8_t>({0, 0, 255, 0, 255, 255, 0, 255, 51, 102});
  g.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", 10}});
  g.doc["buffers"][0]["byteLength"] = g.bin.size();
  g.doc["accessors"][1] = {
      {"bufferView", 3}, {"componentType", ubyte_type}, {"normalized", true}, {"count", 5}, {"type", "VEC2"}};
  auto m = parse_text(g);
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->uvs[2] == glm::dvec2(1, 1));
  CHECK(m->uvs[4] == glm::dvec2(0.2, 0.4));
  g.doc["accessors"][1].erase("normalized");
  expect_gltf_error(
      g, {"accessors[1] (TEXCOORD_0) has componentType 5121 (unsigned byte) without \"normalized\""});
}

TEST_CASE("gltf: the base-colour texture keeps the PNG's encoded bytes (data: URI, bufferView, file)") {
  // data: URI in a .gltf
  auto a = parse_text(textured_gltf({{"uri", "data:image/png;base64," + TestGltf::base64(png)}}));
  REQUIRE_MESSAGE(a.ok(), a.error().message);
  REQUIRE(a->texture);
  CHECK(a->texture->encoded == png);
  CHECK(a->texture->source == "bad.gltf images[0]");

  // a bufferView of the .glb's BIN chunk
  TestGltf g = textured_gltf({{"bufferView", 3}, {"mimeType", "image/png"}});
  const std::size_t at = g.bin.size();
  g.bin.insert(g.bin.end(), png.begin(), png.end());
  while (g.bin.size() % 4 != 0)
    g.bin.push_back(0);
  g.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", png.size()}});
  g.doc["buffers"][0]["byteLength"] = g.bin.size();
  auto b = parse_binary(g);
  REQUIRE_MESSAGE(b.ok(), b.error().message);
  REQUIRE(b->texture);
  CHECK(b->texture->encoded == png);

  // a file beside the .gltf
  const fs::path dir = temp_dir() / "beside";
  fs::create_directories(dir);
  write_file(dir / "cotton weave.png", png);
  write_file(dir / "shirt.gltf", textured_gltf({{"uri", "cotton%20weave.png"}}).gltf_text());
  auto c = read_gltf(dir / "shirt.gltf");
  REQUIRE_MESSAGE(c.ok(), c.error().message);
  REQUIRE(c->texture);
  CHECK(c->texture->encoded == png);
}

TEST_CASE("gltf: an external .bin buffer beside the .gltf, and none from memory") {
  const fs::path dir = temp_dir() / "external";
  fs::create_directories(dir);
  TestGltf g = ref_gltf();
  write_file(dir / "flag.bin", g.bin);
  g.doc["buffers"][0]["uri"] = "flag.bin";
  const std::string text = g.doc.dump();
  write_file(dir / "flag.gltf", text);
  auto m = read_gltf(dir / "flag.gltf");
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->indices == ref_triangles);

  expect_error(parse_gltf(bytes_of(text), false, "mem.gltf"), ErrorCode::io,
               {"mem.gltf: buffers[0] is the file 'flag.bin'", "without a base directory"});
  g.doc["buffers"][0]["uri"] = "missing.bin";
  write_file(dir / "missing.gltf", g.doc.dump());
  expect_error(read_gltf(dir / "missing.gltf"), ErrorCode::io,
               {"missing.gltf: buffers[0]: cannot find the file 'missing.bin' in " + dir.string()});
  g.doc["buffers"][0]["uri"] = "flag.bin";
  g.doc["buffers"][0]["byteLength"] = 200;
  write_file(dir / "short.gltf", g.doc.dump());
  expect_error(read_gltf(dir / "short.gltf"), ErrorCode::parse,
               {"short.gltf: buffers[0]: the file 'flag.bin' holds 120 bytes, but byteLength is 200"});
}

TEST_CASE("gltf: URIs are file names, never shell-expanded (tinygltf's default runs wordexp)") {
  const fs::path dir = temp_dir() / "wordexp";
  fs::create_directories(dir);
  const fs::path marker = dir / "expanded";
  fs::remove(marker);
  const std::string uri = "$(touch " + marker.string() + ").png";
  write_file(dir / "evil.gltf", textured_gltf({{"uri", uri}}).gltf_text());
  expect_error(read_gltf(dir / "evil.gltf"), ErrorCode::io, {"evil.gltf: images[0]: cannot read the file"});
  CHECK(!fs::exists(marker));
}

TEST_CASE("gltf errors: accessors and buffer views that reach past their buffer view and buffer") {
  TestGltf g = ref_gltf();
  g.doc["accessors"][0]["count"] = 6;
  expect_gltf_error(g, {"accessors[0] (POSITION) reads bytes 0..72 of bufferViews[0], which holds 60 bytes"});
  g = ref_gltf();
  g.doc["accessors"][1]["byteOffset"] = 4;
  expect_gltf_error(g,
                    {"accessors[1] (TEXCOORD_0) reads bytes 4..44 of bufferViews[1], which holds 40 bytes"});
  g = ref_gltf();
  g.doc["accessors"][0]["count"] = std::uint64_t(1) << 62; // the byte range overflows 64 bits
  g.doc["accessors"][0]["type"] = "VEC3";
  g.doc["accessors"][1]["count"] = std::uint64_t(1) << 62;
  g.doc["meshes"][0]["primitives"][0]["attributes"].erase("POSITION");
  g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 1;
  g.doc["accessors"][1]["type"] = "VEC3";
  g.doc["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_0");
  expect_gltf_error(g, {"accessors[1] (POSITION) has 4611686018427387904 elements, more than max_particles"});
  g = ref_gltf();
  g.doc["bufferViews"][2]["byteLength"] = 100;
  expect_gltf_error(g, {"bufferViews[2] covers bytes 100..200 of buffers[0], which holds 120 bytes"});
  g = ref_gltf();
  g.doc["bufferViews"][0]["byteStride"] = 8;
  expect_gltf_error(
      g, {"bufferViews[0] has byteStride 8, less than one element of accessors[0] (POSITION) (12 bytes)"});
  g = ref_gltf();
  g.doc["accessors"][0]["bufferView"] = 7;
  expect_gltf_error(g, {"accessors[0] (POSITION) refers to bufferViews[7], but the file has 3 buffer views"});
  g = ref_gltf();
  g.doc["bufferViews"][1]["buffer"] = 2;
  expect_gltf_error(g, {"bufferViews[1] refers to buffers[2], but the file has 1 buffer"});
  g = ref_gltf();
  g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9;
  expect_gltf_error(g,
                    {"meshes[0].primitives[0].attributes.POSITION refers to accessors[9], but the file has 3 "
                     "accessors"});
  g = ref_gltf();
  g.doc["accessors"][0]["count"] = max_particles + 1;
  expect_gltf_error(g, {"accessors[0] (POSITION) has 16777217 elements, more than max_particles (16777216)"});
}

TEST_CASE("gltf errors: accessor types, sparse accessors, counts") {
  TestGltf g = ref_gltf();
  g.doc["accessors"][0]["componentType"] = ushort_type;
  expect_gltf_error(
      g, {"accessors[0] (POSITION) has componentType 5123 (unsigned short), expected 5126 (float)"});
  g = ref_gltf();
  g.doc["accessors"][0]["type"] = "VEC2";
  expect_gltf_error(g, {"accessors[0] (POSITION) has type VEC2, expected VEC3"});
  g = ref_gltf();
  g.doc["accessors"][2]["componentType"] = float_type;
  expect_gltf_error(
      g, {"accessors[2] (indices) has componentType 5126 (float), expected 5121 (unsigned byte) or"});
  g = ref_gltf();
  g.doc["accessors"][0]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", 2}, {"componentType", ushort_type}}},
                                     {"values", {{"bufferView", 0}}}};
  expect_gltf_error(g, {"accessors[0] (POSITION) is sparse; sparse accessors are not supported"});
  g = ref_gltf();
  g.doc["accessors"][2]["count"] = 8;
  expect_gltf_error(g, {"accessors[2] (indices) has 8 indices, not a multiple of 3"});
  g = ref_gltf();
  g.doc["accessors"][1]["count"] = 4;
  expect_gltf_error(g, {"accessors[1] (TEXCOORD_0) has 4 elements, but accessors[0] (POSITION) has 5"});
  g = ref_gltf();
  g.doc["meshes"][0]["primitives"][0].erase("indices");
  expect_gltf_error(g, {"meshes[0].primitives[0] has no indices and 5 vertices, not a multiple of 3"});
}

TEST_CASE("gltf errors: index values, coordinates that are not finite or out of range") {
  TestGltf g = ref_gltf();
  g.bin[100 + 2 * 4] = 7; // indices element 4
  expect_gltf_error(g,
                    {"accessors[2] (indices) element 4 is 7, out of range (the primitive has 5 vertices)"});
  g = ref_gltf();
  g.set_float(3 * 12 + 4, std::numeric_limits<float>::quiet_NaN()); // vertex 3, y
  expect_gltf_error(g, {"accessors[0] (POSITION) vertex 3: nan is not finite"});
  g = ref_gltf();
  g.set_float(2 * 12 + 8, std::numeric_limits<float>::infinity()); // what 1e39 becomes in a float
  expect_gltf_error(g, {"accessors[0] (POSITION) vertex 2: inf is not finite"});
  g = ref_gltf();
  g.set_float(1 * 12, -1e35f);
  expect_gltf_error(
      g, {"accessors[0] (POSITION) vertex 1: -1.0000000", "is out of range (|coordinate| > 1e30)"});
  g = ref_gltf();
  g.set_float(60 + 4 * 8, std::numeric_limits<float>::quiet_NaN());
  expect_gltf_error(g, {"accessors[1] (TEXCOORD_0) element 4: nan is not finite"});
}

TEST_CASE("gltf errors: no meshes, no POSITION, no triangles, mixed TEXCOORD_0") {
  TestGltf g = ref_gltf();
  g.doc.erase("meshes");
  expect_gltf_error(g, {"the file has no meshes"});
  g = ref_gltf();
  g.doc["meshes"][0]["primitives"][0]["attributes"].erase("POSITION");
  expect_gltf_error(g, {"meshes[0].primitives[0] has no POSITION attribute"});
  g = ref_gltf();
  g.doc["meshes"][0]["primitives"][0]["mode"] = 1;
  expect_gltf_error(g, {"meshes[0] has no TRIANGLES primitive (modes found: 1)"});
  g = ref_gltf();
  g.doc["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 0}}}, {"indices", 2}});
  expect_gltf_error(g, {"meshes[0].primitives[1] has no TEXCOORD_0, but meshes[0].primitives[0] has"});
}

TEST_CASE("gltf errors: materials, textures and images") {
  TestGltf g = textured_gltf({{"uri", "data:image/png;base64," + TestGltf::base64(png)}});
  g.doc["meshes"][0]["primitives"][0]["material"] = 3;
  expect_gltf_error(g, {"meshes[0].primitives[0].material is 3, but the file has 1 material"});
  g = textured_gltf({{"uri", "data:image/png;base64," + TestGltf::base64(png)}});
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 2;
  expect_gltf_error(
      g, {"materials[0].pbrMetallicRoughness.baseColorTexture.index is 2, but the file has 1 texture"});
  g = textured_gltf({{"uri", "data:image/png;base64," + TestGltf::base64(png)}});
  g.doc["textures"][0]["source"] = 4;
  expect_gltf_error(g, {"textures[0].source is 4, but the file has 1 image"});
  g = textured_gltf({{"uri", "data:image/png;base64,AAAAAAAA"}});
  expect_gltf_error(g, {"images[0] is not a PNG or JPEG image"});
  g = textured_gltf({{"bufferView", 0}, {"mimeType", "image/png"}});
  expect_gltf_error(g, {"images[0] is not a PNG or JPEG image (mimeType 'image/png', 60 bytes)"});
  g = textured_gltf({{"uri", "tex.png"}});
  expect_gltf_error(g, {"images[0]: cannot read the file 'tex.png' (the glTF was read from memory"},
                    ErrorCode::io);
}

TEST_CASE("gltf errors: invalid JSON, a data: buffer shorter than byteLength") {
  expect_error(
      parse_gltf(bytes_of("{\"asset\": {\"version\": \"2.0\"},\n  \"meshes\": [,]}"), false, "bad.gltf"),
      ErrorCode::parse, {"bad.gltf:2:14: invalid JSON"});
  expect_error(parse_gltf(bytes_of("[1]"), false, "bad.gltf"), ErrorCode::parse,
               {"bad.gltf: the glTF JSON must be an object"});
  expect_error(parse_gltf(bytes_of(std::string(100, '[')), false, "bad.gltf"), ErrorCode::parse,
               {"bad.gltf:1:65: invalid JSON", "nested more than 64 levels"});
  TestGltf g = ref_gltf();
  g.doc["buffers"][0]["byteLength"] = 240;
  expect_error(parse_text(g), ErrorCode::parse,
               {"bad.gltf: buffers[0]: its data: URI holds 120 bytes, but byteLength is 240"});
  expect_error(parse_binary(g), ErrorCode::parse,
               {"bad.glb: buffers[0] has byteLength 240, but the GLB's BIN chunk holds 120 bytes"});
  g = ref_gltf();
  g.doc["buffers"][0]["byteLength"] = "many";
  expect_error(parse_text(g), ErrorCode::parse, {"bad.gltf: invalid glTF (tinygltf: ", "byteLength"});
}

TEST_CASE("gltf errors: truncated and malformed GLB containers") {
  const std::vector<std::uint8_t> glb = ref_gltf().glb();
  const auto parse = [](std::vector<std::uint8_t> b) { return parse_gltf(b, true, "flag.glb"); };
  expect_error(parse(std::vector<std::uint8_t>(glb.begin(), glb.end() - 10)), ErrorCode::parse,
               {"flag.glb: truncated GLB: the header says", "the file holds"});
  expect_error(parse(std::vector<std::uint8_t>(glb.begin(), glb.begin() + 8)), ErrorCode::parse,
               {"flag.glb: 8 bytes is too short for a GLB"});
  auto b = glb;
  b[0] = 'x';
  expect_error(parse(b), ErrorCode::parse, {"flag.glb: not a GLB file"});
  b = glb;
  b[4] = 1;
  expect_error(parse(b), ErrorCode::parse, {"flag.glb: GLB version 1"});
  b = glb;
  b[12] = 0xff; // JSON chunk length
  b[13] = 0xff;
  expect_error(parse(b), ErrorCode::parse, {"flag.glb: truncated GLB: the JSON chunk ends at byte"});
  b = glb;
  b[16] = 'X';
  expect_error(parse(b), ErrorCode::parse, {"flag.glb: the first GLB chunk has type"});
  // The BIN chunk's length reaching 8 bytes past the file: tinygltf's own check misses the header.
  b = glb;
  const std::size_t bin_at = 20 + (std::size_t(b[12]) | std::size_t(b[13]) << 8);
  b[bin_at] = static_cast<std::uint8_t>(b[bin_at] + 8);
  expect_error(parse(b), ErrorCode::parse, {"flag.glb: truncated GLB: the BIN chunk ends at byte"});
  b = glb;
  b[20] = '#';
  expect_error(parse(b), ErrorCode::parse, {"flag.glb (JSON chunk):1:1: invalid JSON"});
}
