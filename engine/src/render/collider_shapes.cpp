// SPDX-License-Identifier: MIT
#include "collider_shapes.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace vkcloth::render::detail {

namespace {

constexpr float pi = 3.14159265358979f;

/// Unit tangents t, s with (t, s, n) right-handed, as the floor square is laid out.
glm::mat3 plane_frame(glm::vec3 n) {
  const glm::vec3 t =
      glm::normalize(glm::cross(n, std::abs(n.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0)));
  return glm::mat3(t, glm::cross(n, t), n);
}

/// The collider shapes a cloth rests on are drawn slightly inside the true surface. Particles rest
/// at the surface + eps, but the flat cloth triangles between them cut chords through a curved
/// surface (a sag of h^2 / 8r for a spacing h over radius r): a sphere or capsule drawn at full
/// size would poke through a coarse cloth draped on it, so both are drawn 5% thinner. A box's
/// faces are flat (no chords): drawn 1 mm inside, like the floor, so cloth lying on a face never
/// z-fights with it.
constexpr double round_shrink = 0.95;
constexpr double box_inset = 1e-3;

} // namespace

void add_sphere(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, glm::vec3 c, float r,
                std::uint32_t slices, std::uint32_t stacks) {
  const auto base = static_cast<std::uint32_t>(v.size());
  for (std::uint32_t j = 0; j <= stacks; ++j) {
    const float th = pi * float(j) / float(stacks);
    for (std::uint32_t i = 0; i <= slices; ++i) {
      const float ph = 2.0f * pi * float(i) / float(slices);
      const glm::vec3 n(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      v.push_back({glm::vec4(c + r * n, 0.0f), glm::vec4(n, 0.0f)});
    }
  }
  for (std::uint32_t j = 0; j < stacks; ++j)
    for (std::uint32_t i = 0; i < slices; ++i) {
      const std::uint32_t a = base + j * (slices + 1) + i, b = a + slices + 1;
      idx.insert(idx.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
}

void add_unit_capsule(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, std::uint32_t slices,
                      std::uint32_t half_stacks) {
  const auto base = static_cast<std::uint32_t>(v.size());
  const std::uint32_t rings = 2 * (half_stacks + 1); // each half: pole .. equator
  for (std::uint32_t ring = 0; ring < rings; ++ring) {
    const bool upper = ring <= half_stacks;
    const std::uint32_t j = upper ? ring : ring - 1; // the equator (j = half_stacks) twice
    const float th = pi * float(j) / float(2 * half_stacks);
    for (std::uint32_t i = 0; i <= slices; ++i) {
      const float ph = 2.0f * pi * float(i) / float(slices);
      const glm::vec3 n(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      v.push_back({glm::vec4(n, upper ? 1.0f : -1.0f), glm::vec4(n, 0.0f)});
    }
  }
  for (std::uint32_t ring = 0; ring + 1 < rings; ++ring)
    for (std::uint32_t i = 0; i < slices; ++i) {
      const std::uint32_t a = base + ring * (slices + 1) + i, b = a + slices + 1;
      idx.insert(idx.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
}

void add_unit_box(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx) {
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      glm::vec3 n(0.0f), t(0.0f), s(0.0f);
      n[axis] = side;
      t[(axis + 1) % 3] = 1.0f;
      s[(axis + 2) % 3] = 1.0f;
      const auto base = static_cast<std::uint32_t>(v.size());
      for (int q = 0; q < 4; ++q) {
        const float u = (q == 1 || q == 2) ? 1.0f : -1.0f, w = q >= 2 ? 1.0f : -1.0f;
        v.push_back({glm::vec4(n + u * t + w * s, 0.0f), glm::vec4(n, 0.0f)});
      }
      idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
}

void add_collider_mesh(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx,
                       const ColliderMesh& mesh) {
  for (const ColliderMesh::Triangle& t : mesh.triangles()) {
    const glm::vec3 c = glm::cross(t.b - t.a, t.c - t.a);
    const float len = glm::length(c);
    const glm::vec3 n = len > 0.0f ? c / len : glm::vec3(0.0f, 0.0f, 1.0f);
    const auto base = static_cast<std::uint32_t>(v.size());
    for (const glm::vec3& p : {t.a, t.b, t.c})
      v.push_back({glm::vec4(p, 0.0f), glm::vec4(n, 0.0f)});
    idx.insert(idx.end(), {base, base + 1, base + 2});
  }
}

glm::vec3 plane_centre(glm::vec3 n, float offset, glm::vec3 around) {
  return around - (glm::dot(n, around) - offset + 1e-3f) * n;
}

void add_plane(std::vector<MeshVertex>& v, std::vector<std::uint32_t>& idx, glm::vec3 n, glm::vec3 centre,
               float half) {
  const glm::mat3 f = plane_frame(n);
  const auto base = static_cast<std::uint32_t>(v.size());
  for (int q = 0; q < 4; ++q) {
    const float u = (q == 1 || q == 2) ? half : -half, w = q >= 2 ? half : -half;
    v.push_back({glm::vec4(centre + u * f[0] + w * f[1], u + half), glm::vec4(n, w + half)});
  }
  idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

Pose pose_of(const ColliderDraw& d, const Collider& k) {
  Pose p;
  switch (k.type) {
  case Collider::Type::plane: {
    // Built in the world; a plane moved along (or turned from) its create()-time normal is the same
    // square carried onto the new plane: the old centre to the new, the old frame onto the new.
    const glm::vec3 n = glm::normalize(glm::vec3(k.normal));
    const glm::vec3 c = plane_centre(n, float(k.offset), d.around);
    if (n == d.plane_normal && c == d.plane_centre)
      return p; // where it was built: the identity
    const glm::dmat3 turn =
        glm::dmat3(plane_frame(n)) * glm::transpose(glm::dmat3(plane_frame(d.plane_normal)));
    p.model = glm::translate(glm::dmat4(1.0), glm::dvec3(c)) * glm::dmat4(turn) *
              glm::translate(glm::dmat4(1.0), -glm::dvec3(d.plane_centre));
    return p;
  }
  case Collider::Type::sphere:
    p.model = glm::translate(glm::dmat4(1.0), k.center);
    p.shape = glm::vec4(glm::vec3(float(k.radius * round_shrink)), 0.0f);
    return p;
  case Collider::Type::capsule: {
    // The unit capsule lies along z: turn z onto b - a (any turn about the axis will do) and put
    // its middle at (a + b) / 2. a == b: a sphere (half length 0).
    const glm::dvec3 axis = k.b - k.a;
    const double length = glm::length(axis);
    const glm::dvec3 z = length > 0.0 ? axis / length : glm::dvec3(0.0, 0.0, 1.0);
    const glm::dvec3 x =
        glm::normalize(glm::cross(std::abs(z.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0), z));
    p.model = glm::dmat4(glm::dvec4(x, 0.0), glm::dvec4(glm::cross(z, x), 0.0), glm::dvec4(z, 0.0),
                         glm::dvec4((k.a + k.b) * 0.5, 1.0));
    p.shape = glm::vec4(glm::vec3(float(k.radius * round_shrink)), float(0.5 * length));
    return p;
  }
  case Collider::Type::box: {
    const glm::dvec3 h = glm::max(k.half_extents - box_inset, 0.9 * k.half_extents);
    p.model = glm::translate(glm::dmat4(1.0), k.center) * glm::dmat4(k.rotation);
    p.shape = glm::vec4(glm::vec3(h), 0.0f);
    return p;
  }
  case Collider::Type::mesh:
    // Drawn as it is: the cloth rests `thickness` away from its triangles.
    p.model = glm::translate(glm::dmat4(1.0), k.center) * glm::dmat4(k.rotation);
    return p;
  }
  return p;
}

Result<ColliderDraw> ShapeBuffer::add(const Collider& k, std::size_t index, const Palette& palette,
                                      glm::vec3 around, float floor_half) {
  ColliderDraw d;
  d.type = k.type;
  switch (k.type) {
  case Collider::Type::plane:
    d.plane_normal = glm::normalize(glm::vec3(k.normal));
    d.around = around;
    d.plane_centre = plane_centre(d.plane_normal, float(k.offset), d.around);
    d.range = shape([&] { add_plane(vertices, indices, d.plane_normal, d.plane_centre, floor_half); });
    d.range.mode = 1.0f;
    d.range.cell = floor_half / 5.0f;
    d.range.color = palette.floor;
    return d;
  case Collider::Type::sphere:
    if (!sphere_)
      sphere_ = shape([&] { add_sphere(vertices, indices, glm::vec3(0.0f), 1.0f, 48, 24); });
    d.range = *sphere_;
    d.range.color = palette.sphere;
    return d;
  case Collider::Type::capsule:
    if (!capsule_)
      capsule_ = shape([&] { add_unit_capsule(vertices, indices, 48, 12); });
    d.range = *capsule_;
    d.range.color = palette.capsule;
    return d;
  case Collider::Type::box:
    if (!box_)
      box_ = shape([&] { add_unit_box(vertices, indices); });
    d.range = *box_;
    d.range.color = palette.box;
    return d;
  case Collider::Type::mesh: {
    if (!k.mesh)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("collider {} is a mesh without its ColliderMesh", index));
    d.mesh = k.mesh.get();
    auto known =
        std::find_if(meshes_.begin(), meshes_.end(), [&](const auto& m) { return m.first == d.mesh; });
    if (known == meshes_.end())
      known = meshes_.emplace(meshes_.end(), d.mesh,
                              shape([&] { add_collider_mesh(vertices, indices, *k.mesh); }));
    d.range = known->second;
    d.range.color = palette.mesh;
    return d;
  }
  }
  return make_error(ErrorCode::invalid_argument,
                    fmt::format("collider {} has an unknown type ({})", index, std::uint32_t(k.type)));
}

MeshRange ShapeBuffer::add_mass_sphere(glm::vec3 color) {
  MeshRange r = shape([&] { add_sphere(vertices, indices, glm::vec3(0.0f), 1.0f, 16, 8); });
  r.color = color;
  return r;
}

} // namespace vkcloth::render::detail
