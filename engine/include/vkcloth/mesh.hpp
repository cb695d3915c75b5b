// SPDX-License-Identifier: MIT
// Meshes: the readers of a polygon mesh (vkcloth/polygon_mesh.hpp) from a file (OBJ or glTF 2.0,
// with tinyobjloader and tinygltf), the cloth built from it (springs matching the report's grid,
// docs/model.md "Mesh springs"), and the animated cloth written back out (glTF 2.0, OBJ).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "vkcloth/builders.hpp"
#include "vkcloth/polygon_mesh.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// Largest mesh file the readers accept (checked before reading).
inline constexpr std::size_t max_mesh_bytes = std::size_t{256} << 20;

/// Reads an OBJ file (v, vt, f; o/g/s/usemtl/mtllib are ignored). Errors (ErrorCode::io for a
/// missing or unreadable file, ErrorCode::parse otherwise) name the file and the line.
/// Faces keep their vertex count (quads and n-gons are not triangulated). uvs: each vertex takes the
/// vt of the first face corner that references it (a seam's other uvs are dropped), (0, 0) when no
/// face does; none when the faces have no vt. Positions are as the file holds them; uvs are
/// flipped to glTF's convention (v = 1 - vt's v, see Mesh::uvs).
Result<Mesh> read_obj(const std::filesystem::path& path);
/// The same from memory; `source_name` names it in messages.
Result<Mesh> parse_obj(std::string_view text, std::string_view source_name);

/// Reads a glTF 2.0 file, .gltf (JSON, buffers beside it or as data: URIs) or .glb: every
/// triangle primitive of the first mesh, with its POSITION, TEXCOORD_0 and indices, and its
/// material's base-colour texture. Errors name the file and the accessor, buffer view or buffer.
/// Nothing else is applied: no node transform, skin or morph target (the mesh is in its own space).
/// The texture is the first triangle primitive's that has one. A URI is a file name relative to the
/// .gltf's directory (never expanded); `parse_gltf` without `base_dir` refuses external files.
Result<Mesh> read_gltf(const std::filesystem::path& path);
/// The same from memory (`binary`: .glb); external buffers are looked up in `base_dir`.
Result<Mesh> parse_gltf(std::span<const std::uint8_t> bytes, bool binary, std::string_view source_name,
                        const std::filesystem::path& base_dir = {});

/// read_obj or read_gltf by the extension (.obj, .gltf, .glb; any case); other extensions are
/// ErrorCode::invalid_argument.
Result<Mesh> read_mesh(const std::filesystem::path& path);

/// Placement of a file's mesh in the world: p' = translate + R (scale p), R = Rz Ry Rx (degrees).
struct MeshTransform {
  glm::dvec3 translate{0.0};
  glm::dvec3 rotate_deg{0.0};
  double scale = 1.0;
};

/// An axis-aligned box; every vertex inside it (bounds included) is pinned.
struct PinRegion {
  glm::dvec3 min{0.0};
  glm::dvec3 max{0.0};
};

/// How a mesh becomes a cloth (docs/model.md "Mesh springs").
struct MeshClothDesc {
  MeshTransform transform;
  /// kg/m^2: each vertex gets density * (its share of the area of its faces); else every vertex
  /// has `particle_mass`.
  std::optional<double> density;
  double particle_mass = 0.05;
  ClothStiffness stiffness; ///< a kind with zero stiffness is left out, as on the grid
  /// A physical material (docs/model.md "Materials"): when set it replaces `density`,
  /// `particle_mass` and `stiffness`: masses lumped with its density, each spring's stiffness from
  /// spring_stiffness() with the spring's own spacing on a square lattice (structural: its rest
  /// length; shear: rest / sqrt 2; bend: rest / 2), so a quad mesh of a square grid gets the grid's
  /// springs. (Its damping is a SimParams value: the caller sets it.)
  std::optional<Material> material;
  std::vector<std::uint32_t> pin_vertices; ///< vertex indices of the file
  std::optional<PinRegion> pin_region;
  /// Renumber particles for memory locality (meshoptimizer's spatial order, each run of 64
  /// particles then grouped by valence so that SIMD lanes walk lists of one length); every output
  /// keeps the file's order through Surface::source_vertex. Off: particle p is file vertex p
  /// (isolated vertices aside).
  bool reorder = true;
};

/// A cloth made from a mesh, and what was dropped or ignored while making it.
struct MeshCloth {
  ParticleSystem system; ///< finalized, with `surface` set
  std::vector<std::string> warnings;
};

/// Builds the cloth: structural springs on the edges, shear and bend springs on quads as on the
/// report's grid, bend springs across edge-adjacent triangles; masses, pins, the surface
/// (triangles, uvs: the file's or a planar projection). Degenerate faces (zero area, a zero-length
/// edge) and the vertices left isolated are dropped with a warning that counts them; an edge shared
/// by more than two faces, a pin outside the mesh, non-finite or out-of-range (|x| > 1e30)
/// coordinates and more than max_particles vertices are errors naming the element.
Result<MeshCloth> make_mesh_cloth(const Mesh& mesh, const MeshClothDesc& desc);

/// Writes a mesh as OBJ text: positions with round-trip precision, uvs when present, faces
/// 1-based. Used to hand a grid to the mesh path (tests) and by the sample generator.
std::string format_obj(const Mesh& mesh);

/// The surface of a cloth as a Mesh in the FILE's vertex order (Surface::source_vertex undone;
/// a grid gives its quads), positions from `positions` (solver order, one per particle).
Mesh surface_mesh(const ParticleSystem& system, std::span<const glm::dvec3> positions);

} // namespace vkcloth
