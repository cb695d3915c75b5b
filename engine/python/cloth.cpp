// SPDX-License-Identifier: MIT
// Cloths for a World: the report's grid (make_cloth), a chain of springs (make_chain) and a cloth
// from a mesh file (load_mesh_cloth), each with its rest state as numpy arrays.
#include "bindings.hpp"

#include <array>
#include <optional>

#include "vkcloth/builders.hpp"
#include "vkcloth/export.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth/mesh.hpp"

namespace vkcloth::python {
namespace {

Cloth cloth_of(ParticleSystem system, std::vector<std::string> warnings = {}) {
  Cloth c;
  c.system = std::make_shared<const ParticleSystem>(std::move(system));
  c.warnings = std::move(warnings);
  return c;
}

/// A material given as a preset name or a Material.
std::optional<Material> material_arg(const py::object& material) {
  if (material.is_none())
    return std::nullopt;
  if (py::isinstance<py::str>(material)) {
    const auto name = material.cast<std::string>();
    if (auto preset = material_preset(name))
      return preset;
    throw py::value_error("material: unknown preset \"" + name + "\" (known: " + material_preset_list() +
                          ")");
  }
  return material.cast<Material>();
}

/// Spring stiffnesses given as a ClothStiffness, a dict of its fields or None (the defaults).
ClothStiffness stiffness_arg(const py::object& stiffness) {
  if (stiffness.is_none())
    return {};
  if (py::isinstance<py::dict>(stiffness))
    return py::module_::import("vkcloth._vkcloth").attr("Stiffness")(**stiffness).cast<ClothStiffness>();
  return stiffness.cast<ClothStiffness>();
}

ClothOrientation orientation_arg(const std::string& name) {
  if (name == "vertical")
    return ClothOrientation::vertical;
  if (name == "horizontal")
    return ClothOrientation::horizontal;
  throw py::value_error("orientation: unknown value \"" + name + "\" (known: vertical, horizontal)");
}

UpAxis up_arg(const std::string& name) {
  if (auto up = parse_up_axis(name))
    return *up;
  throw py::value_error("up: unknown value \"" + name + "\" (known: z, y)");
}

Cloth make_grid(std::uint32_t nx, std::uint32_t ny, std::array<double, 2> size, glm::dvec3 origin,
                const std::string& orientation, const std::string& up, double particle_mass,
                const py::object& stiffness, const py::object& material,
                std::optional<std::vector<std::array<std::uint32_t, 2>>> pins, bool pin_default_corners) {
  ClothDesc desc;
  desc.nx = nx;
  desc.ny = ny;
  desc.size = {size[0], size[1]};
  desc.origin = origin;
  desc.orientation = orientation_arg(orientation);
  desc.up = up_arg(up);
  desc.particle_mass = particle_mass;
  desc.stiffness = stiffness_arg(stiffness);
  desc.material = material_arg(material);
  if (pins)
    desc.pins = std::move(*pins);
  desc.pin_default_corners = pin_default_corners;
  unwrap(check_cloth_material(desc.particle_mass, desc.stiffness));
  return cloth_of(unwrap(make_cloth(desc)));
}

Cloth make_spring_chain(std::vector<double> masses, std::vector<double> stiffness,
                        std::vector<double> rest_lengths, std::optional<std::vector<glm::dvec3>> positions,
                        glm::dvec3 anchor, const std::string& up) {
  ChainDesc desc;
  desc.anchor = anchor;
  desc.masses = std::move(masses);
  desc.stiffness = std::move(stiffness);
  desc.rest_lengths = std::move(rest_lengths);
  desc.positions = positions ? std::move(*positions) : std::vector<glm::dvec3>{};
  desc.up = up_arg(up);
  return cloth_of(unwrap(make_chain(desc)));
}

Cloth mesh_cloth(const std::string& path, const py::object& material, double particle_mass,
                 std::optional<double> density, const py::object& stiffness,
                 std::vector<std::uint32_t> pin_vertices, glm::dvec3 translate, glm::dvec3 rotate_deg,
                 double scale, bool reorder) {
  Mesh mesh = unwrap(read_mesh(path));
  MeshClothDesc desc;
  desc.transform = {translate, rotate_deg, scale};
  desc.density = density;
  desc.particle_mass = particle_mass;
  desc.stiffness = stiffness_arg(stiffness);
  desc.material = material_arg(material);
  desc.pin_vertices = std::move(pin_vertices);
  desc.reorder = reorder;
  MeshCloth made = unwrap(make_mesh_cloth(mesh, desc));
  return cloth_of(std::move(made.system), std::move(made.warnings));
}

} // namespace

void bind_cloth(py::module_& m) {
  py::class_<ClothStiffness> stiffness(m, "Stiffness",
                                       "A grid's spring stiffnesses (N/m): structural, shear, bend");
  init_from_keywords<ClothStiffness>(stiffness, "Stiffness");
  stiffness.def_readwrite("structural", &ClothStiffness::structural)
      .def_readwrite("shear", &ClothStiffness::shear)
      .def_readwrite("bend", &ClothStiffness::bend);

  py::class_<Cloth>(m, "Cloth",
                    "A particle-spring system at rest (a grid, a chain or a mesh cloth), ready for "
                    "World.add; its topology is built once and shared by every instance")
      .def_property_readonly("particle_count", [](const Cloth& c) { return c.system->size(); })
      .def_property_readonly("spring_count", [](const Cloth& c) { return c.system->springs.size(); })
      .def_property_readonly(
          "positions",
          [](const Cloth& c) {
            std::vector<glm::dvec3> x;
            for (const Particle& p : c.system->particles)
              x.push_back(p.position);
            return points_array(x);
          },
          "The rest positions, (n, 3) float64, in particle order")
      .def_property_readonly("masses",
                             [](const Cloth& c) {
                               py::array_t<double> out(static_cast<py::ssize_t>(c.system->size()));
                               auto w = out.mutable_unchecked<1>();
                               for (std::size_t p = 0; p < c.system->size(); ++p)
                                 w(static_cast<py::ssize_t>(p)) = c.system->particles[p].mass;
                               return out;
                             })
      .def_property_readonly(
          "pinned",
          [](const Cloth& c) {
            std::vector<std::uint32_t> pinned;
            for (std::size_t p = 0; p < c.system->size(); ++p)
              if (c.system->particles[p].pinned)
                pinned.push_back(static_cast<std::uint32_t>(p));
            return py::array_t<std::uint32_t>(static_cast<py::ssize_t>(pinned.size()), pinned.data());
          },
          "The pinned particles' indices")
      .def_property_readonly(
          "grid",
          [](const Cloth& c) -> py::object {
            if (!c.system->grid)
              return py::none();
            return py::make_tuple(c.system->grid->nx, c.system->grid->ny);
          },
          "(nx, ny) for a grid (particle (i, j) is j * nx + i), else None")
      .def_property_readonly(
          "file_order",
          [](const Cloth& c) {
            const auto order = file_order(*c.system);
            return py::array_t<std::uint32_t>(static_cast<py::ssize_t>(order.size()), order.data());
          },
          "The particles in the mesh file's vertex order (the order of vkcloth run --positions): "
          "positions[file_order] lists them as the file does; the identity for grids and chains")
      .def_readonly("warnings", &Cloth::warnings)
      .def("__repr__", [](const Cloth& c) {
        return "<vkcloth.Cloth " + std::to_string(c.system->size()) + " particles, " +
               std::to_string(c.system->springs.size()) + " springs>";
      });

  m.def("make_cloth", &make_grid, py::kw_only(), py::arg("nx") = 10, py::arg("ny") = 10,
        py::arg("size") = std::array<double, 2>{1.0, 1.0}, py::arg("origin") = glm::dvec3(0.0),
        py::arg("orientation") = "vertical", py::arg("up") = "z", py::arg("particle_mass") = 0.05,
        py::arg("stiffness") = py::none(), py::arg("material") = py::none(), py::arg("pins") = py::none(),
        py::arg("pin_default_corners") = true,
        "The report's cloth: an nx x ny grid over size[0] x size[1] metres, structural / shear / bend "
        "springs, the two top corners pinned unless `pins` ((i, j) cells) says otherwise. `material` (a "
        "preset name or a Material) replaces particle_mass and stiffness; its damping is a SimParams value");
  m.def("make_chain", &make_spring_chain, py::kw_only(), py::arg("masses") = std::vector<double>{1.0},
        py::arg("stiffness") = std::vector<double>{20.0}, py::arg("rest_lengths") = std::vector<double>{0.4},
        py::arg("positions") = py::none(), py::arg("anchor") = glm::dvec3(0.0), py::arg("up") = "z",
        "A pinned anchor and masses joined in a line (the report's single and coupled springs); without "
        "positions the masses hang from the anchor at their rest lengths");
  m.def(
      "structural_strain",
      [](const Cloth& c, const py::array_t<double, py::array::c_style | py::array::forcecast>& positions) {
        if (positions.ndim() != 2 || positions.shape(1) != 3 ||
            static_cast<std::size_t>(positions.shape(0)) != c.system->size())
          throw py::value_error("structural_strain: positions must be (" + std::to_string(c.system->size()) +
                                ", 3), one row per particle");
        const std::span<const glm::dvec3> x(reinterpret_cast<const glm::dvec3*>(positions.data()),
                                            c.system->size());
        return unwrap(structural_strain(*c.system, x)).max;
      },
      py::arg("cloth"), py::arg("positions"),
      "The largest structural strain (|x_b - x_a| - L0) / L0 of `positions` (particle order), 0 without "
      "structural springs");
  m.def("load_mesh_cloth", &mesh_cloth, py::arg("path"), py::kw_only(), py::arg("material") = py::none(),
        py::arg("particle_mass") = 0.05, py::arg("density") = py::none(), py::arg("stiffness") = py::none(),
        py::arg("pin_vertices") = std::vector<std::uint32_t>{}, py::arg("translate") = glm::dvec3(0.0),
        py::arg("rotate_deg") = glm::dvec3(0.0), py::arg("scale") = 1.0, py::arg("reorder") = true,
        "A cloth from an OBJ, glTF or GLB file (docs/model.md \"Mesh springs\"); pin_vertices are the "
        "file's vertex indices");
}

} // namespace vkcloth::python
