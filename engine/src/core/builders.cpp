// SPDX-License-Identifier: MIT
#include "vkcloth/builders.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "internal/argument_checks.hpp"

namespace vkcloth {
using detail::bad_argument;
using detail::finite;
glm::dvec3 polygon_vector_area(std::span<const std::uint32_t> face, std::span<const glm::dvec3> x) {
  glm::dvec3 sum(0.0);
  const glm::dvec3 o = x[face[0]];
  for (std::size_t k = 1; k + 1 < face.size(); ++k)
    sum += glm::cross(x[face[k]] - o, x[face[k + 1]] - o);
  return sum;
}

void lump_masses(std::span<const std::uint32_t> face_offsets, std::span<const std::uint32_t> corners,
                 std::span<const glm::dvec3> x, double density, std::span<Particle> particles) {
  for (Particle& p : particles)
    p.mass = 0.0;
  for (std::size_t f = 0; f + 1 < face_offsets.size(); ++f) {
    const auto face = corners.subspan(face_offsets[f], face_offsets[f + 1] - face_offsets[f]);
    const double area = 0.5 * glm::length(polygon_vector_area(face, x));
    for (std::uint32_t v : face)
      particles[v].mass += density * area / double(face.size());
  }
}

Result<void> check_cloth_material(double particle_mass, const ClothStiffness& stiffness) {
  if (!std::isfinite(particle_mass) || particle_mass <= 0.0)
    return bad_argument(fmt::format("cloth.particle_mass must be finite and > 0, got {}", particle_mass));
  const std::pair<const char*, double> ks[] = {
      {"structural", stiffness.structural}, {"shear", stiffness.shear}, {"bend", stiffness.bend}};
  for (auto [name, k] : ks)
    if (!std::isfinite(k) || k < 0.0)
      return bad_argument(fmt::format("cloth.stiffness.{} must be finite and >= 0, got {}", name, k));
  return {};
}

Result<ParticleSystem> make_chain(const ChainDesc& d) {
  const std::size_t n = d.masses.size();
  if (n == 0)
    return bad_argument("chain.masses must hold at least one mass");
  if (n > max_particles)
    return bad_argument(
        fmt::format("chain.masses holds {} masses, more than the limit {}", n, max_particles));
  auto per_spring = [&](const std::vector<double>& v, const char* key) -> Result<std::vector<double>> {
    if (v.size() == 1)
      return std::vector<double>(n, v[0]); // one value for every spring
    if (v.size() != n)
      return bad_argument(
          fmt::format("chain.{} must hold 1 or {} values (one per mass), got {}", key, n, v.size()));
    return v;
  };
  auto k = per_spring(d.stiffness, "stiffness");
  if (!k)
    return k.error();
  auto l0 = per_spring(d.rest_lengths, "rest_lengths");
  if (!l0)
    return l0.error();
  if (!finite(d.anchor))
    return bad_argument("chain.anchor must be finite");
  VKCLOTH_TRY(check_up_axis(d.up, "chain.up"));
  if (!d.positions.empty() && d.positions.size() != n)
    return bad_argument(
        fmt::format("chain.positions must hold {} positions (one per mass), got {}", n, d.positions.size()));

  ParticleSystem sys;
  sys.particles.push_back(Particle{d.anchor, {}, 1.0, true});
  glm::dvec3 below = d.anchor;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(d.masses[i]) || d.masses[i] <= 0.0)
      return bad_argument(fmt::format("chain.masses[{}] must be finite and > 0, got {}", i, d.masses[i]));
    if (!std::isfinite((*k)[i]) || (*k)[i] < 0.0)
      return bad_argument(fmt::format("chain.stiffness[{}] must be finite and >= 0, got {}", i, (*k)[i]));
    if (!std::isfinite((*l0)[i]) || (*l0)[i] < 0.0)
      return bad_argument(fmt::format("chain.rest_lengths[{}] must be finite and >= 0, got {}", i, (*l0)[i]));
    below -= up_vector(d.up) * (*l0)[i]; // default: hanging straight down, each spring at rest length
    const glm::dvec3 p = d.positions.empty() ? below : d.positions[i];
    if (!finite(p))
      return bad_argument(fmt::format("chain.positions[{}] must be finite", i));
    sys.particles.push_back(Particle{p, {}, d.masses[i], false});
    sys.springs.push_back(Spring{static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1), (*l0)[i],
                                 (*k)[i], SpringKind::plain});
  }
  sys.finalize();
  return sys;
}

const char* to_string(UpAxis up) {
  switch (up) {
  case UpAxis::z:
    return "z";
  case UpAxis::y:
    return "y";
  }
  return "?";
}

std::optional<UpAxis> parse_up_axis(std::string_view name) {
  for (UpAxis up : {UpAxis::z, UpAxis::y})
    if (name == to_string(up))
      return up;
  return std::nullopt;
}

Result<void> check_up_axis(UpAxis up, std::string_view what) {
  if (up != UpAxis::z && up != UpAxis::y)
    return bad_argument(fmt::format("{}: unknown up axis {} (z = 0 or y = 1)", what, std::uint32_t(up)));
  return {};
}

glm::dmat3 z_up_to(UpAxis up) {
  if (up == UpAxis::y) // columns: where x, y, z go
    return glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  return glm::dmat3(1.0);
}

glm::dvec3 up_vector(UpAxis up) {
  return z_up_to(up) * glm::dvec3(0, 0, 1);
}

glm::dvec3 default_gravity(UpAxis up) {
  return up == UpAxis::y ? glm::dvec3(0.0, -9.81, 0.0) : glm::dvec3(0.0, 0.0, -9.81); // SimParams' for z
}

glm::vec2 default_grid_uv(std::uint32_t i, std::uint32_t j, std::uint32_t nx, std::uint32_t ny) {
  return {nx > 1 ? float(i) / float(nx - 1) : 0.0f, ny > 1 ? float(j) / float(ny - 1) : 0.0f};
}

namespace {

/// The description's sizes, extent, origin and material (or per-particle mass and stiffness).
Result<void> check_cloth_desc(const ClothDesc& d) {
  if (d.nx < 1 || d.ny < 1 || d.nx > max_cloth_side || d.ny > max_cloth_side)
    return bad_argument(fmt::format("cloth.resolution [{}, {}] is out of range: each side must be in 1..{}",
                                    d.nx, d.ny, max_cloth_side));
  const std::uint64_t count = std::uint64_t(d.nx) * d.ny;
  if (count > max_particles)
    return bad_argument(fmt::format("cloth.resolution [{}, {}] makes {} particles, more than the limit {}",
                                    d.nx, d.ny, count, max_particles));
  if (!std::isfinite(d.size.x) || !std::isfinite(d.size.y) || d.size.x <= 0.0 || d.size.y <= 0.0)
    return bad_argument(fmt::format("cloth.size must be finite and > 0, got [{}, {}]", d.size.x, d.size.y));
  if (!finite(d.origin))
    return bad_argument("cloth.origin must be finite");
  if (std::uint32_t(d.orientation) > std::uint32_t(ClothOrientation::horizontal))
    return bad_argument(
        fmt::format("cloth.orientation: unknown orientation {}", std::uint32_t(d.orientation)));
  VKCLOTH_TRY(check_up_axis(d.up, "cloth.up"));
  if (!d.material)
    return check_cloth_material(d.particle_mass, d.stiffness);
  VKCLOTH_TRY(check_material(*d.material));
  if (d.nx < 2 || d.ny < 2)
    return bad_argument(
        fmt::format("cloth.material needs a grid of at least 2 x 2 points, got [{}, {}]", d.nx, d.ny));
  return {};
}

/// The springs' stiffness along i (spacing dx) and along j (dy): the description's for both
/// without a material, else the material's at these spacings.
struct GridStiffness {
  ClothStiffness i, j;
};
Result<GridStiffness> grid_stiffness(const ClothDesc& d, double dx, double dy) {
  if (!d.material)
    return GridStiffness{d.stiffness, d.stiffness};
  const Material& m = *d.material;
  auto k = [&](SpringKind kind, double along, double across) {
    return spring_stiffness(m, kind, along, across);
  };
  auto si = k(SpringKind::structural, dx, dy), sj = k(SpringKind::structural, dy, dx);
  auto sh = k(SpringKind::shear, dx, dy);
  auto bi = k(SpringKind::bend, dx, dy), bj = k(SpringKind::bend, dy, dx);
  for (const Result<double>* r : {&si, &sj, &sh, &bi, &bj})
    if (!*r)
      return r->error();
  return GridStiffness{{*si, *sh, *bi}, {*sj, *sh, *bj}};
}

/// The grid's texture coordinates: the description's, or its uv_transform of the default ones;
/// empty for the default ones themselves (default_grid_uv).
Result<std::vector<glm::vec2>> grid_uvs(const ClothDesc& d) {
  const std::uint32_t nx = d.nx, ny = d.ny;
  const std::size_t count = std::size_t(nx) * ny;
  if (!d.uvs.empty()) {
    if (d.uvs.size() != count)
      return bad_argument(fmt::format("cloth uvs: {} texture coordinates for a {} x {} grid of {} particles",
                                      d.uvs.size(), nx, ny, count));
    for (std::size_t k = 0; k < count; ++k)
      if (!std::isfinite(d.uvs[k].x) || !std::isfinite(d.uvs[k].y))
        return bad_argument(fmt::format("cloth uvs: texture coordinate {} is not finite ({}, {})", k,
                                        d.uvs[k].x, d.uvs[k].y));
    return d.uvs;
  }
  if (d.uv_transform == UvTransform{})
    return std::vector<glm::vec2>{};
  const UvTransform& m = d.uv_transform;
  for (const glm::vec2 a : {m.offset, m.u_axis, m.v_axis})
    if (!std::isfinite(a.x) || !std::isfinite(a.y))
      return bad_argument("cloth uv_transform must be finite");
  std::vector<glm::vec2> uvs(count);
  for (std::uint32_t j = 0; j < ny; ++j)
    for (std::uint32_t i = 0; i < nx; ++i) {
      const glm::vec2 st = default_grid_uv(i, j, nx, ny);
      uvs[std::size_t(j) * nx + i] = m.offset + st.x * m.u_axis + st.y * m.v_axis;
    }
  return uvs;
}

/// Pins the description's grid points (by default the two top corners).
Result<void> pin_grid(const ClothDesc& d, ParticleSystem& sys) {
  const std::uint32_t nx = d.nx, ny = d.ny;
  std::vector<std::array<std::uint32_t, 2>> pins = d.pins;
  if (pins.empty() && d.pin_default_corners)
    pins = {{0, ny - 1}, {nx - 1, ny - 1}};
  for (std::size_t k = 0; k < pins.size(); ++k) {
    const auto [i, j] = pins[k];
    if (i >= nx || j >= ny)
      return bad_argument(
          fmt::format("cloth.pins[{}] = [{}, {}] is outside the {} x {} grid", k, i, j, nx, ny));
    sys.particles[j * nx + i].pinned = true;
  }
  return {};
}

/// The report's springs, kind by kind (structural, shear, bend; this order is the gather order).
/// A kind is left out when its stiffness is zero (a material's are all > 0 but structural). A
/// material's springs along the border stand for half a cell (as the border's masses do): half the
/// stiffness, so that the lattice's energy under a uniform strain is the membrane's.
void add_grid_springs(ParticleSystem& sys, std::uint32_t nx, std::uint32_t ny, double dx, double dy,
                      const GridStiffness& k, bool material) {
  auto add = [&](std::uint32_t i0, std::uint32_t j0, std::uint32_t i1, std::uint32_t j1, double rest,
                 double stiffness, SpringKind kind) {
    sys.springs.push_back(Spring{j0 * nx + i0, j1 * nx + i1, rest, stiffness, kind});
  };
  const double half = material ? 0.5 : 1.0;
  auto row_edge = [&](std::uint32_t j) { return j == 0 || j == ny - 1 ? half : 1.0; };
  auto col_edge = [&](std::uint32_t i) { return i == 0 || i == nx - 1 ? half : 1.0; };
  if (k.i.structural > 0.0 || k.j.structural > 0.0) {
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i + 1 < nx; ++i)
        add(i, j, i + 1, j, dx, row_edge(j) * k.i.structural, SpringKind::structural);
    for (std::uint32_t j = 0; j + 1 < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i)
        add(i, j, i, j + 1, dy, col_edge(i) * k.j.structural, SpringKind::structural);
  }
  if (k.i.shear > 0.0) {
    const double diag = std::sqrt(dx * dx + dy * dy);
    for (std::uint32_t j = 0; j + 1 < ny; ++j)
      for (std::uint32_t i = 0; i + 1 < nx; ++i) {
        add(i, j, i + 1, j + 1, diag, k.i.shear, SpringKind::shear);
        add(i + 1, j, i, j + 1, diag, k.i.shear, SpringKind::shear);
      }
  }
  if (k.i.bend > 0.0 || k.j.bend > 0.0) {
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i + 2 < nx; ++i)
        add(i, j, i + 2, j, 2 * dx, row_edge(j) * k.i.bend, SpringKind::bend);
    for (std::uint32_t j = 0; j + 2 < ny; ++j)
      for (std::uint32_t i = 0; i < nx; ++i)
        add(i, j, i, j + 2, 2 * dy, col_edge(i) * k.j.bend, SpringKind::bend);
  }
}

/// A material's masses: lumped over the grid's cells (a, a+1, a+1+nx, a+nx) at `density`.
void lump_grid_masses(ParticleSystem& sys, std::uint32_t nx, std::uint32_t ny, double density) {
  std::vector<glm::dvec3> x(sys.particles.size());
  for (std::size_t p = 0; p < x.size(); ++p)
    x[p] = sys.particles[p].position;
  std::vector<std::uint32_t> offsets{0}, corners;
  for (std::uint32_t j = 0; j + 1 < ny; ++j)
    for (std::uint32_t i = 0; i + 1 < nx; ++i) {
      const std::uint32_t a = j * nx + i;
      corners.insert(corners.end(), {a, a + 1, a + 1 + nx, a + nx});
      offsets.push_back(static_cast<std::uint32_t>(corners.size()));
    }
  lump_masses(offsets, corners, x, density, sys.particles);
}

} // namespace

Result<ParticleSystem> make_cloth(const ClothDesc& d) {
  VKCLOTH_TRY(check_cloth_desc(d));
  const std::uint32_t nx = d.nx, ny = d.ny;
  const double dx = nx > 1 ? d.size.x / (nx - 1) : 0.0;
  const double dy = ny > 1 ? d.size.y / (ny - 1) : 0.0;
  auto stiffness = grid_stiffness(d, dx, dy);
  if (!stiffness)
    return stiffness.error();
  auto uvs = grid_uvs(d);
  if (!uvs)
    return uvs.error();

  ParticleSystem sys;
  sys.grid = Grid{nx, ny, std::move(*uvs)};
  // z up: vertical spans x and z, horizontal x and y. y up: the same sheets turned by z_up_to(up)
  // ((x, y, z) -> (x, z, -y)): vertical spans x and y, horizontal x and -z (normals still up).
  const glm::dvec3 eu{1, 0, 0};
  const glm::dvec3 ev = z_up_to(d.up) * (d.orientation == ClothOrientation::vertical ? glm::dvec3{0, 0, 1}
                                                                                     : glm::dvec3{0, 1, 0});
  sys.particles.resize(std::size_t(nx) * ny);
  for (std::uint32_t j = 0; j < ny; ++j)
    for (std::uint32_t i = 0; i < nx; ++i)
      sys.particles[j * nx + i] =
          Particle{d.origin + (i * dx) * eu + (j * dy) * ev, {}, d.particle_mass, false};
  VKCLOTH_TRY(pin_grid(d, sys));
  add_grid_springs(sys, nx, ny, dx, dy, *stiffness, d.material.has_value());
  if (d.material)
    lump_grid_masses(sys, nx, ny, d.material->density);
  sys.finalize();
  return sys;
}

} // namespace vkcloth
