// SPDX-License-Identifier: MIT
// SimParams and the records it holds (Wind, StretchLimit, SelfCollision, Collider, Attachment), and
// the materials. Each class takes its fields as keyword arguments; the enumerations are their
// scene-file names ("vbd", "provot", ...). Values are checked where the C++ API checks them
// (World.add, set_params, SimParams.validate), so the errors are the C++ messages.
#include "bindings.hpp"

#include <optional>
#include <string_view>

#include "vkcloth/material.hpp"
#include "vkcloth/params.hpp"

namespace vkcloth::python {
namespace {

/// A read-write attribute holding an enumeration as its name (to_string / parse_*); a name that is
/// none of them is a ValueError listing the known ones.
template <typename Class, typename Owner, typename Enum, typename Parse>
void enum_property(Class& cls, const char* name, Enum Owner::*field, Parse parse, const char* known) {
  cls.def_property(
      name, [field](const Owner& o) { return std::string(to_string(o.*field)); },
      [field, parse, name, known](Owner& o, const std::string& value) {
        const auto parsed = parse(value);
        if (!parsed)
          throw py::value_error(std::string(name) + ": unknown value \"" + value + "\" (known: " + known +
                                ")");
        o.*field = *parsed;
      });
}

const char* type_name(Collider::Type type) {
  switch (type) {
  case Collider::Type::plane:
    return "plane";
  case Collider::Type::sphere:
    return "sphere";
  case Collider::Type::capsule:
    return "capsule";
  case Collider::Type::box:
    return "box";
  case Collider::Type::mesh:
    return "mesh";
  }
  return "unknown";
}

Collider with_friction(Collider c, double friction) {
  c.friction = friction;
  return c;
}

void bind_colliders(py::module_& m) {
  py::class_<Collider> collider(m, "Collider",
                                "A collider (docs/model.md \"Collisions\"): made by Collider.plane, sphere, "
                                "capsule or box; its fields are its pose, friction and motion now");
  collider.def_property_readonly("type", [](const Collider& c) { return std::string(type_name(c.type)); })
      .def_readwrite("normal", &Collider::normal)
      .def_readwrite("offset", &Collider::offset)
      .def_readwrite("center", &Collider::center)
      .def_readwrite("radius", &Collider::radius)
      .def_readwrite("a", &Collider::a)
      .def_readwrite("b", &Collider::b)
      .def_readwrite("half_extents", &Collider::half_extents)
      .def_readwrite("friction", &Collider::friction)
      .def_readwrite("static_friction", &Collider::static_friction)
      .def_readwrite("linear_velocity", &Collider::linear_velocity)
      .def_readwrite("angular_velocity", &Collider::angular_velocity)
      .def_static(
          "plane",
          [](glm::dvec3 normal, double offset, double friction) {
            return with_friction(Collider::plane(normal, offset), friction);
          },
          py::arg("normal") = glm::dvec3(0, 0, 1), py::arg("offset") = 0.0, py::arg("friction") = 0.0,
          "The plane <normal, p> = offset, its outside the side the normal points to")
      .def_static(
          "sphere",
          [](glm::dvec3 center, double radius, double friction) {
            return with_friction(Collider::sphere(center, radius), friction);
          },
          py::arg("center"), py::arg("radius"), py::arg("friction") = 0.0)
      .def_static(
          "capsule",
          [](glm::dvec3 a, glm::dvec3 b, double radius, double friction) {
            return with_friction(Collider::capsule(a, b, radius), friction);
          },
          py::arg("a"), py::arg("b"), py::arg("radius"), py::arg("friction") = 0.0)
      .def_static(
          "box",
          [](glm::dvec3 center, glm::dvec3 half_extents, glm::dvec3 rotate_deg, double friction) {
            return with_friction(
                Collider::box(center, half_extents, Collider::rotation_from_degrees(rotate_deg)), friction);
          },
          py::arg("center"), py::arg("half_extents"), py::arg("rotate_deg") = glm::dvec3(0.0),
          py::arg("friction") = 0.0, "A box turned by rotate_deg (R = Rz Ry Rx, degrees) about its centre")
      .def("__repr__",
           [](const Collider& c) { return std::string("<vkcloth.Collider ") + type_name(c.type) + ">"; });
}

void bind_records(py::module_& m) {
  py::class_<Wind> wind(m, "Wind",
                        "Wind F = Kw <n, u> n on each cloth vertex (strength Kw, unit direction u)");
  init_from_keywords<Wind>(wind, "Wind");
  wind.def_readwrite("strength", &Wind::strength).def_readwrite("direction", &Wind::direction);

  py::class_<StretchLimit> stretch(m, "StretchLimit", "Stretch control (docs/model.md \"Stretch control\")");
  init_from_keywords<StretchLimit>(stretch, "StretchLimit");
  enum_property(stretch, "method", &StretchLimit::method, parse_stretch_method,
                "off, tethers, provot, both, projection");
  enum_property(stretch, "tether_distance", &StretchLimit::tether_distance, parse_tether_distance,
                "euclidean, geodesic");
  enum_property(stretch, "order", &StretchLimit::order, parse_sweep_order, "colours, chains");
  stretch.def_readwrite("max_strain", &StretchLimit::max_strain)
      .def_readwrite("iterations", &StretchLimit::iterations);

  py::class_<SelfCollision> self(m, "SelfCollision", "Self-collision (docs/model.md \"Self-collision\")");
  init_from_keywords<SelfCollision>(self, "SelfCollision");
  self.def_readwrite("enabled", &SelfCollision::enabled)
      .def_readwrite("thickness", &SelfCollision::thickness)
      .def_readwrite("friction", &SelfCollision::friction)
      .def_readwrite("iterations", &SelfCollision::iterations)
      .def_readwrite("skin", &SelfCollision::skin)
      .def_readwrite("stiffness", &SelfCollision::stiffness);

  py::class_<Attachment> attachment(m, "Attachment",
                                    "Particles that follow a collider: particles[i] at offsets[i] of the "
                                    "collider's frame (docs/model.md \"Attachments\")");
  init_from_keywords<Attachment>(attachment, "Attachment");
  attachment.def_readwrite("collider", &Attachment::collider)
      .def_readwrite("particles", &Attachment::particles)
      .def_readwrite("offsets", &Attachment::offsets)
      .def_readwrite("max_distance", &Attachment::max_distance);
}

void bind_sim_params(py::module_& m) {
  py::class_<SimParams> params(m, "SimParams",
                               "A cloth's simulation parameters (C++ vkcloth::SimParams), every field at "
                               "its default unless given: SimParams(integrator=\"vbd\", dt=0.01)");
  init_from_keywords<SimParams>(params, "SimParams");
  enum_property(params, "integrator", &SimParams::integrator, parse_integrator,
                "explicit_euler, semi_implicit_euler, rk4, implicit_euler, vbd");
  params.def_readwrite("dt", &SimParams::dt)
      .def_readwrite("substeps", &SimParams::substeps)
      .def_readwrite("cg_tolerance", &SimParams::cg_tolerance)
      .def_readwrite("cg_max_iterations", &SimParams::cg_max_iterations)
      .def_readwrite("vbd_iterations", &SimParams::vbd_iterations)
      .def_readwrite("gravity", &SimParams::gravity)
      .def_readwrite("damping", &SimParams::damping)
      .def_readwrite("wind", &SimParams::wind)
      .def_readwrite("colliders", &SimParams::colliders,
                     "A list of Collider (assign a new list to change it)")
      .def_readwrite("contact_epsilon", &SimParams::contact_epsilon)
      .def_readwrite("contact_inward_only", &SimParams::contact_inward_only)
      .def_readwrite("divergence_limit", &SimParams::divergence_limit)
      .def_readwrite("stretch_limit", &SimParams::stretch_limit)
      .def_readwrite("self_collision", &SimParams::self_collision)
      .def_readwrite("attachments", &SimParams::attachments,
                     "A list of Attachment (assign a new list to change it)")
      .def(
          "validate",
          [](const SimParams& p) {
            SimParams copy = p;
            unwrap(copy.validate());
            return copy;
          },
          "The parameters checked as a solver checks them (ValueError naming the field), directions "
          "normalised");
}

void bind_materials(py::module_& m) {
  py::class_<Material> material(m, "Material",
                                "A cloth material in SI units (docs/model.md \"Materials\"): density kg/m^2, "
                                "stretch and shear N/m, bend N m, damping 1/s");
  init_from_keywords<Material>(material, "Material");
  material.def_readwrite("density", &Material::density)
      .def_readwrite("stretch", &Material::stretch)
      .def_readwrite("shear", &Material::shear)
      .def_readwrite("bend", &Material::bend)
      .def_readwrite("damping", &Material::damping);
  m.def(
      "material",
      [](const std::string& name) {
        if (auto preset = material_preset(name))
          return *preset;
        throw py::value_error("unknown material \"" + name + "\" (known: " + material_preset_list() + ")");
      },
      py::arg("name"), "The material preset called `name` (cotton, silk, denim, leather, rubber, report)");
  m.def("material_names", [] {
    std::vector<std::string> names;
    for (std::string_view n : material_preset_names())
      names.emplace_back(n);
    return names;
  });
}

} // namespace

void bind_params(py::module_& m) {
  bind_colliders(m);
  bind_records(m);
  bind_sim_params(m);
  bind_materials(m);
}

} // namespace vkcloth::python
