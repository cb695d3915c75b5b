// SPDX-License-Identifier: MIT
// Square grids of triangles for the mesh-collider tests: a flat sheet, a bumpy height field, a
// skinned mesh's rest pose.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <doctest/doctest.h>
#include <glm/vec3.hpp>

#include "vkcloth/collider_mesh.hpp"

namespace vkcloth::test {

/// n x n quads over [-size/2, size/2]^2, each split in two triangles counter-clockwise seen from +z,
/// at height z = height(x, y): (n + 1)^2 vertices, 2 n^2 triangles.
struct GridMesh {
  std::vector<glm::dvec3> positions;
  std::vector<std::uint32_t> triangles;
};
template <typename Height> GridMesh grid_mesh(int n, double size, Height height) {
  GridMesh g;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = size * (double(i) / n - 0.5), y = size * (double(j) / n - 0.5);
      g.positions.push_back({x, y, height(x, y)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = std::uint32_t(j * (n + 1) + i), b = a + 1, c = a + std::uint32_t(n + 1), d = c + 1;
      g.triangles.insert(g.triangles.end(), {a, b, d, a, d, c});
    }
  return g;
}

/// grid_mesh as a mesh collider's mesh.
template <typename Height>
std::shared_ptr<const ColliderMesh> grid_collider(int n, double size, Height height, std::string name) {
  const GridMesh g = grid_mesh(n, size, height);
  auto m = ColliderMesh::create(g.positions, g.triangles, std::move(name));
  REQUIRE(m.ok());
  return *m;
}

} // namespace vkcloth::test
