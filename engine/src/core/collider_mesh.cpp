// SPDX-License-Identifier: MIT
// ColliderMesh: the triangles of a mesh collider and a bounding-volume hierarchy over them
// (median split along the longest axis of the triangles' centroids, at most leaf_size triangles per
// leaf, children adjacent), walked by cloth_kernel.h mesh_nearest on both backends; deformed() refits it.
#include "vkcloth/collider_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "internal/kernel.hpp"
#include "vkcloth/polygon_mesh.hpp"

namespace vkcloth {
namespace {

struct Builder {
  std::vector<ColliderMesh::Triangle> tris;
  std::vector<std::uint32_t> corners; // per triangle: its vertices
  std::vector<glm::vec3> centroid;
  std::vector<std::uint32_t> order;
  std::vector<ColliderMesh::Node> nodes;
  std::uint32_t depth = 0;

  // Fills node `at` with the triangles order[begin .. end) and, when there are too many for a leaf,
  // appends its two children (adjacent) and fills them.
  void build(std::uint32_t at, std::uint32_t begin, std::uint32_t end, std::uint32_t level) {
    depth = std::max(depth, level);
    glm::vec3 lo(INFINITY), hi(-INFINITY), clo(INFINITY), chi(-INFINITY);
    for (std::uint32_t k = begin; k < end; ++k) {
      const ColliderMesh::Triangle& t = tris[order[k]];
      lo = glm::min(glm::min(lo, t.a), glm::min(t.b, t.c));
      hi = glm::max(glm::max(hi, t.a), glm::max(t.b, t.c));
      clo = glm::min(clo, centroid[order[k]]);
      chi = glm::max(chi, centroid[order[k]]);
    }
    nodes[at].lo = lo;
    nodes[at].hi = hi;
    if (end - begin <= ColliderMesh::leaf_size) {
      nodes[at].first = begin; // triangles are written in `order` afterwards
      nodes[at].count = end - begin;
      return;
    }
    const glm::vec3 extent = chi - clo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const std::uint32_t mid = begin + (end - begin) / 2;
    // Median by centroid, ties by index: the same tree on every machine.
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](std::uint32_t a, std::uint32_t b) {
                       return centroid[a][axis] < centroid[b][axis] ||
                              (centroid[a][axis] == centroid[b][axis] && a < b);
                     });
    const auto left = static_cast<std::uint32_t>(nodes.size());
    nodes.resize(nodes.size() + 2);
    nodes[at].first = left;
    nodes[at].count = 0;
    build(left, begin, mid, level + 1);
    build(left + 1, mid, end, level + 1);
  }
};

/// The first vertex with a coordinate that is not finite, if any.
std::optional<std::size_t> first_non_finite(std::span<const glm::dvec3> positions) {
  for (std::size_t v = 0; v < positions.size(); ++v)
    if (!std::isfinite(positions[v].x) || !std::isfinite(positions[v].y) || !std::isfinite(positions[v].z))
      return v;
  return std::nullopt;
}

/// Each triangle's clearances (ColliderMesh::Triangle) over the hierarchy: from its centroid, the
/// nearest other triangle reaching in front of its plane by more than the smallest contact guard
/// (cloth_kernel.h mesh_guard: 2^-18), less the centroid's distance to the triangle's farthest corner
/// (every point of the triangle is that close to the centroid); rounded down to float.
void compute_clearances(std::span<ColliderMesh::Triangle> tris, std::span<const ColliderMesh::Node> nodes) {
  const kernel::MeshData md{nodes.data(), tris.data()};
  constexpr double tol = 1.0 / 262144.0; // 2^-18
  auto down = [](double x) {
    const float f = float(x);
    return double(f) > x ? std::nextafter(f, 0.0f) : f;
  };
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const glm::dvec3 a(tris[i].a), b(tris[i].b), c(tris[i].c);
    const glm::dvec3 centroid = (a + b + c) / 3.0, n = glm::normalize(glm::cross(b - a, c - a));
    const double corner =
        std::max({glm::length(a - centroid), glm::length(b - centroid), glm::length(c - centroid)});
    float clearance[2];
    for (int side = 0; side < 2; ++side) {
      const glm::dvec3 m = side == 0 ? n : -n;
      std::uint32_t nearest, unused;
      const double best =
          kernel::f64::mesh_nearest(md, 0, 0, centroid, 1e18, std::uint32_t(i), std::uint32_t(i), m,
                                    glm::dot(m, a), m, glm::dot(m, a), tol, 1.0, nearest, unused);
      clearance[side] = nearest == VKCLOTH_MESH_NONE ? 3e38f : down(std::max(0.0, std::sqrt(best) - corner));
    }
    tris[i].clearance_front = clearance[0];
    tris[i].clearance_back = clearance[1];
  }
}

/// Per triangle, the triangle across each edge (ColliderMesh::neighbours): edges keyed by their
/// corners' positions, so that a seam's duplicated vertices still join.
std::vector<std::uint32_t> find_neighbours(std::span<const ColliderMesh::Triangle> tris) {
  using Point = std::tuple<float, float, float>;
  auto point = [](glm::vec3 v) { return Point{v.x, v.y, v.z}; };
  std::map<std::pair<Point, Point>, std::vector<std::uint32_t>> edges; // edge -> 3 t + k
  for (std::size_t t = 0; t < tris.size(); ++t) {
    const glm::vec3 v[3] = {tris[t].a, tris[t].b, tris[t].c};
    for (std::uint32_t k = 0; k < 3; ++k) {
      const Point p = point(v[(k + 1) % 3]), q = point(v[(k + 2) % 3]);
      edges[std::minmax(p, q)].push_back(std::uint32_t(3 * t + k));
    }
  }
  std::vector<std::uint32_t> out(3 * tris.size(), ColliderMesh::no_neighbour);
  for (const auto& [edge, sides] : edges)
    if (sides.size() == 2) {
      out[sides[0]] = sides[1] / 3;
      out[sides[1]] = sides[0] / 3;
    }
  return out;
}

Error bad(const std::string& name, const std::string& what) {
  return Error{ErrorCode::invalid_argument, fmt::format("mesh collider {}: {}", name, what)};
}

} // namespace

Result<std::shared_ptr<const ColliderMesh>> ColliderMesh::create(std::span<const glm::dvec3> positions,
                                                                 std::span<const std::uint32_t> triangles,
                                                                 std::string name) {
  if (triangles.size() % 3 != 0)
    return bad(name, fmt::format("{} triangle indices is not a multiple of 3", triangles.size()));
  if (const auto v = first_non_finite(positions))
    return bad(name, fmt::format("vertex {} is not finite ({}, {}, {})", *v, positions[*v].x, positions[*v].y,
                                 positions[*v].z));
  Builder b;
  std::uint32_t dropped = 0;
  for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
    glm::vec3 corner[3];
    std::uint32_t vertex[3];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = triangles[t + std::size_t(k)];
      if (i >= positions.size())
        return bad(name, fmt::format("triangle {} uses vertex {} but there are {} vertices", t / 3, i,
                                     positions.size()));
      corner[k] = glm::vec3(positions[i]);
      vertex[k] = i;
    }
    if (glm::length(glm::cross(corner[1] - corner[0], corner[2] - corner[0])) == 0.0f) {
      ++dropped; // no normal, no area: nothing to collide with
      continue;
    }
    b.tris.push_back({corner[0], 0.0f, corner[1], 0.0f, corner[2], 0.0f});
    b.corners.insert(b.corners.end(), vertex, vertex + 3);
    b.centroid.push_back((corner[0] + corner[1] + corner[2]) / 3.0f);
  }
  if (b.tris.empty())
    return bad(name, triangles.empty() ? std::string("it has no triangles")
                                       : fmt::format("all of its {} triangles have zero area", dropped));
  if (b.tris.size() > (std::size_t{1} << 28))
    return bad(name, fmt::format("{} triangles are too many (at most 2^28)", b.tris.size()));
  b.order.resize(b.tris.size());
  std::iota(b.order.begin(), b.order.end(), 0u);
  b.nodes.resize(1);
  b.nodes.reserve(2 * b.tris.size() / leaf_size + 2);
  b.build(0, 0, static_cast<std::uint32_t>(b.tris.size()), 1);
  auto mesh = std::make_shared<ColliderMesh>();
  mesh->triangles_.reserve(b.tris.size());
  for (const std::uint32_t i : b.order) {
    mesh->triangles_.push_back(b.tris[i]);
    mesh->corners_.insert(mesh->corners_.end(), b.corners.begin() + 3 * i, b.corners.begin() + 3 * i + 3);
  }
  for (const glm::dvec3& p : positions)
    mesh->positions_.emplace_back(p);
  mesh->nodes_ = std::move(b.nodes);
  compute_clearances(mesh->triangles_, mesh->nodes_);
  mesh->neighbours_ = find_neighbours(mesh->triangles_);
  mesh->name_ = std::move(name);
  mesh->depth_ = b.depth;
  mesh->dropped_ = dropped;
  return std::shared_ptr<const ColliderMesh>(std::move(mesh));
}

Result<std::shared_ptr<const ColliderMesh>> ColliderMesh::deformed(std::span<const glm::dvec3> positions,
                                                                   double dt) const {
  if (positions.size() != positions_.size())
    return bad(name_, fmt::format("the skinned update has {} vertices, but the mesh has {}", positions.size(),
                                  positions_.size()));
  if (!std::isfinite(dt) || dt <= 0.0)
    return bad(name_, fmt::format("the skinned update's dt must be finite and > 0, got {}", dt));
  if (const auto v = first_non_finite(positions))
    return bad(name_, fmt::format("skinned vertex {} is not finite ({}, {}, {})", *v, positions[*v].x,
                                  positions[*v].y, positions[*v].z));
  auto mesh = std::make_shared<ColliderMesh>(*this);
  for (std::size_t v = 0; v < positions.size(); ++v)
    mesh->positions_[v] = glm::vec3(positions[v]);
  const float inv_dt = float(1.0 / dt);
  mesh->velocities_.resize(triangles_.size());
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    glm::vec3 now[3], vel[3];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = corners_[3 * t + std::size_t(k)];
      now[k] = mesh->positions_[v];
      vel[k] = (now[k] - positions_[v]) * inv_dt;
    }
    mesh->triangles_[t] = {now[0], 0.0f, now[1], 0.0f, now[2], 0.0f};
    mesh->velocities_[t] = {vel[0], 0.0f, vel[1], 0.0f, vel[2], 0.0f};
  }
  // Refit: children follow their parent in nodes_, so one backward pass sees every child first.
  for (std::size_t i = mesh->nodes_.size(); i-- > 0;) {
    Node& n = mesh->nodes_[i];
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    if (n.count > 0)
      for (std::uint32_t t = n.first; t < n.first + n.count; ++t) {
        const Triangle& tri = mesh->triangles_[t];
        lo = glm::min(glm::min(lo, tri.a), glm::min(tri.b, tri.c));
        hi = glm::max(glm::max(hi, tri.a), glm::max(tri.b, tri.c));
      }
    else
      for (std::uint32_t c = n.first; c < n.first + 2; ++c) {
        lo = glm::min(lo, mesh->nodes_[c].lo);
        hi = glm::max(hi, mesh->nodes_[c].hi);
      }
    n.lo = lo;
    n.hi = hi;
  }
  return std::shared_ptr<const ColliderMesh>(std::move(mesh));
}

Result<std::shared_ptr<const ColliderMesh>> ColliderMesh::from_mesh(const Mesh& mesh, double scale,
                                                                    std::string name) {
  if (!std::isfinite(scale) || scale <= 0.0)
    return bad(name, fmt::format("scale must be finite and > 0, got {}", scale));
  std::vector<glm::dvec3> positions(mesh.positions.size());
  for (std::size_t v = 0; v < positions.size(); ++v)
    positions[v] = mesh.positions[v] * scale;
  std::vector<std::uint32_t> tris;
  for (std::size_t f = 0; f < mesh.face_count(); ++f) {
    const std::uint32_t first = mesh.face_offsets[f], end = mesh.face_offsets[f + 1];
    for (std::uint32_t k = first + 1; k + 1 < end; ++k) // a fan around the face's first corner
      tris.insert(tris.end(), {mesh.indices[first], mesh.indices[k], mesh.indices[k + 1]});
  }
  return create(positions, tris, std::move(name));
}

} // namespace vkcloth
