// SPDX-License-Identifier: MIT
// The OBJ reader (vkcloth/mesh.hpp) and the readers' file handling: files read exactly, and every
// malformed input refused with the right ErrorCode and a message naming the file and the line;
// missing files, folders, size limits.
#include "mesh_io_test_util.hpp"

// ---- OBJ -----------------------------------------------------------------------------------------

TEST_CASE("obj: a quad and a triangle with texture coordinates read exactly, quads kept") {
  auto m = parse_obj(ref_obj, "cloth.obj");
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->positions == ref_positions);
  CHECK(m->uvs == ref_uvs);
  CHECK(m->face_offsets == std::vector<std::uint32_t>{0, 4, 7});
  CHECK(m->indices == std::vector<std::uint32_t>{0, 1, 2, 3, 1, 4, 2});
  CHECK(!m->texture);
}

TEST_CASE("obj: read_obj and read_mesh (any case of .obj) read a file") {
  const fs::path path = temp_dir() / "Cloth.OBJ";
  write_file(path, std::string_view(ref_obj));
  auto a = read_obj(path);
  auto b = read_mesh(path);
  REQUIRE_MESSAGE(a.ok(), a.error().message);
  REQUIRE_MESSAGE(b.ok(), b.error().message);
  CHECK(a->positions == ref_positions);
  CHECK(b->indices == a->indices);
}

TEST_CASE("obj: shortest round-trip coordinates read back exactly (correctly rounded)") {
  // tinyobjloader's own number parser is a few ulps off for most of these.
  std::string text;
  std::vector<glm::dvec3> expected;
  const auto shortest = [](double v) {
    char buf[32];
    return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
  };
  for (int i = 1; i <= 60; ++i) {
    const glm::dvec3 p(1.0 / (3.0 * i), -std::sqrt(double(i)) * 1e-7, std::exp(double(i)) * 1e3);
    expected.push_back(p);
    text += "v " + shortest(p.x) + " " + shortest(p.y) + " " + shortest(p.z) + "\n";
  }
  text += "f 1 2 3\n";
  auto m = parse_obj(text, "precise.obj");
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->positions == expected);
}

TEST_CASE("obj: n-gons are kept, and no vt, or vt no face uses, leaves uvs empty") {
  auto m = parse_obj("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nvt 0 0\nf 1 2 3 4 5\n", "ngon.obj");
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->face_offsets == std::vector<std::uint32_t>{0, 5});
  CHECK(m->uvs.empty());
  // A face of 300 vertices: more than tinyobjloader's mesh_t keeps (unsigned char), kept here.
  std::string big;
  for (int i = 0; i < 300; ++i)
    big += "v " + std::to_string(std::cos(i * 0.02)) + " " + std::to_string(std::sin(i * 0.02)) + " 0\n";
  big += "f";
  for (int i = 1; i <= 300; ++i)
    big.append(" ").append(std::to_string(i)); // not " " + ...: GCC 12 warns (-Wrestrict, a false positive)
  auto n = parse_obj(big + "\n", "big.obj");
  REQUIRE_MESSAGE(n.ok(), n.error().message);
  CHECK(n->face_offsets == std::vector<std::uint32_t>{0, 300});
}

TEST_CASE("obj: the first corner that references a vertex gives its uv, and unreferenced vertices get 0") {
  auto m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nvt 0.25 0.5\nvt 1 0\nvt 0 1\nvt 0.75 0.75\n"
                     "f 1/1 2/2 3/3\nf 3/4 2/4 1/4\n",
                     "seam.obj");
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->uvs == std::vector<glm::dvec2>{{0.25, 0.5}, {1, 1}, {0, 0}, {0, 0}}); // v flipped: 1 - vt's v
}

TEST_CASE("obj errors: face indices name the line and the index") {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  expect_obj_error(quad + "f 1 2 40\n",
                   {"bad.obj:5: ", "face index 40 is out of range (the file has 4 vertices)"});
  expect_obj_error(quad + "f -5 -1 -2\n",
                   {"bad.obj:5: ", "face index -5 is out of range (4 vertices precede this line)"});
  expect_obj_error(quad + "f 0 1 2\n", {"bad.obj:5: ", "face index 0 is invalid"});
  expect_obj_error(quad + "\n\nf 1 2\n", {"bad.obj:7: ", "face 1 has 2 vertices; a face needs at least 3"});
  expect_obj_error(quad + "f\n", {"bad.obj:5: ", "face 1 has 0 vertices"});
  expect_obj_error(quad + "f 1/a 2 3\n", {"bad.obj:5: ", "'1/a' is not a vertex reference"});
  expect_obj_error(quad + "f 1/ 2/ 3/\n", {"bad.obj:5: ", "'1/' is not a vertex reference"});
  expect_obj_error(quad + "f 1 2 3 4\nf 1 2 +3\n", {"bad.obj:6: ", "'+3' is not a vertex reference"});
  expect_obj_error(quad + "f 1 2 99999999999\n", {"bad.obj:5: ", "'99999999999' is not a vertex reference"});
  expect_obj_error(quad + std::string("f 1 2 3\0 4\n", 12),
                   {"bad.obj:5: ", "'3\\x00' is not a vertex reference"});
}

TEST_CASE("obj errors: texture coordinates on some corners or faces only, or out of range") {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n";
  expect_obj_error(tri + "f 1/1 2 3\n",
                   {"bad.obj:7: ", "face 1 has texture coordinates on 1 of its 3 corners"});
  expect_obj_error(tri + "f 1/1 2/2 3/3\n# next\nf 1 2 3\n",
                   {"bad.obj:9: ", "face 2 has no texture coordinates, but face 1 (line 7) has"});
  expect_obj_error(tri + "f 1 2 3\nf 1/1 2/2 3/3\n",
                   {"bad.obj:8: ", "face 2 has texture coordinates, but face 1 (line 7) has none"});
  expect_obj_error(tri + "f 1/9 2/2 3/3\n",
                   {"bad.obj:7: ", "texture index 9 is out of range (the file has 3 texture coordinates)"});
  expect_obj_error(
      tri + "f 1/-4 2/2 3/3\n",
      {"bad.obj:7: ", "texture index -4 is out of range (3 texture coordinates precede this line)"});
}

TEST_CASE("obj errors: coordinates that are not numbers, not finite or out of range name line and vertex") {
  const std::string face = "f 1 2 3\n";
  expect_obj_error("v 0 0 0\nv 1 nan 0\nv 0 1 0\n" + face,
                   {"bad.obj:2: ", "vertex 2: y = nan is not finite"});
  expect_obj_error("v 0 0 0\nv 1 0 0\nv -inf 1 0\n" + face,
                   {"bad.obj:3: ", "vertex 3: x = -inf is not finite"});
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 1e39\n" + face,
                   {"bad.obj:3: ", "vertex 3: z = 1e+39 is out of range (|coordinate| > 1e30)"});
  expect_obj_error("v 0 0 1e999\nv 1 0 0\nv 0 1 0\n" + face,
                   {"bad.obj:1: ", "vertex 1: z = '1e999' is out of range"});
  expect_obj_error("v 0 abc 0\nv 1 0 0\nv 0 1 0\n" + face,
                   {"bad.obj:1: ", "vertex 1: 'abc' is not a number"});
  expect_obj_error("v 0 0\nv 1 0 0\nv 0 1 0\n" + face, {"bad.obj:1: ", "vertex 1 has 2 values, expected 3"});
  expect_obj_error("v 0 0 0 1 1\nv 1 0 0\nv 0 1 0\n" + face, {"bad.obj:1: ", "vertex 1 has 5 values"});
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 nan\n" + face,
                   {"bad.obj:4: ", "texture coordinate 1: v = nan is not finite"});
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt\n" + face,
                   {"bad.obj:4: ", "texture coordinate 1 has 0 values"});
  // Tiny values underflow to 0 and are accepted.
  auto m = parse_obj("v 1e-400 0 0\nv 1 0 0\nv 0 1 0\n" + face, "tiny.obj");
  REQUIRE_MESSAGE(m.ok(), m.error().message);
  CHECK(m->positions[0].x == 0.0);
}

TEST_CASE("obj errors: no faces") {
  expect_obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n", {"bad.obj: no faces"});
  expect_obj_error("", {"bad.obj: no faces"});
  expect_obj_error("# only a comment\n\n", {"bad.obj: no faces"});
}

// ---- files ---------------------------------------------------------------------------------------

TEST_CASE("files: missing, a directory, over max_mesh_bytes, an unknown extension") {
  const fs::path dir = temp_dir();
  for (const char* name : {"missing.obj", "missing.gltf", "missing.glb"})
    expect_error(read_mesh(dir / name), ErrorCode::io, {(dir / name).string(), "no such mesh file"});
  fs::create_directories(dir / "folder.obj");
  expect_error(read_obj(dir / "folder.obj"), ErrorCode::io, {"folder.obj: is a directory"});
  expect_error(read_gltf(dir / "folder.obj"), ErrorCode::io, {"folder.obj: is a directory"});

  const fs::path huge = dir / "huge.obj";
  { std::ofstream(huge).put('v'); }
  fs::resize_file(huge, max_mesh_bytes + 1); // sparse: nothing is written, nothing must be read
  expect_error(read_obj(huge), ErrorCode::io,
               {"huge.obj: the file is 268435457 bytes, more than the mesh size limit"});
  fs::remove(huge);

  write_file(dir / "cloth.stl", std::string_view("solid"));
  expect_error(read_mesh(dir / "cloth.stl"), ErrorCode::invalid_argument,
               {"cloth.stl: unknown mesh file extension '.stl' (expected .obj, .gltf or .glb)"});
}

TEST_CASE("limits: text over max_mesh_bytes in memory is refused before parsing") {
  const std::string big(max_mesh_bytes + 1, '\n');
  expect_error(parse_obj(big, "big.obj"), ErrorCode::parse, {"big.obj: the mesh is 268435457 bytes"});
  expect_error(parse_gltf(bytes_of(big), false, "big.gltf"), ErrorCode::parse, {"big.gltf: the mesh is"});
}

TEST_CASE("limits: an OBJ with more than max_particles vertices names the line") {
  std::string text;
  text.reserve((max_particles + 1) * 8);
  for (std::uint64_t i = 0; i <= max_particles; ++i)
    text += "v 0 0 0\n";
  const std::string line = std::to_string(max_particles + 1);
  expect_error(parse_obj(text, "many.obj"), ErrorCode::parse,
               {"many.obj:" + line + ": more than 16777216 vertices (max_particles)"});
}
