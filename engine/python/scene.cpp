// SPDX-License-Identifier: MIT
// Scene files from Python: load_scene (a path or a dict in the scene format) and run, which steps a
// scene as `vkcloth run` does (the same solver on the same backend: the same bits) and returns the
// final positions in the order of `vkcloth run --positions`.
#include "bindings.hpp"

#include <optional>

#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/export.hpp"
#include "vkcloth/gpu/backend_choice.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::python {

BackendPick pick_backend(const std::string& name) {
  if (name != "auto" && name != "cpu" && name != "vulkan")
    throw py::value_error("backend: unknown value \"" + name + "\" (known: auto, cpu, vulkan)");
  BackendPick pick;
  if (name == "cpu") {
    pick.reason = "backend=\"cpu\"";
    return pick;
  }
  auto context = gpu::Context::create();
  if (!context && name == "auto") {
    pick.reason = "no usable Vulkan device (" + context.error().message + "): the CPU solver";
    return pick;
  }
  pick.context = std::make_unique<gpu::Context>(unwrap(std::move(context)));
  if (name == "auto") {
    gpu::BackendChoice choice = gpu::choose_backend(*pick.context);
    pick.reason = choice.reason;
    if (choice.backend == gpu::Backend::cpu)
      pick.context.reset();
  } else {
    pick.reason = "backend=\"vulkan\": " + pick.context->device_name();
  }
  return pick;
}

namespace {

/// A loaded scene and its cloth for a World (built once from the scene's system).
struct PyScene {
  Scene scene;
  Cloth cloth;
};

PyScene wrap(Scene scene) {
  PyScene s{std::move(scene), {}};
  s.cloth.system = std::make_shared<const ParticleSystem>(s.scene.system);
  s.cloth.warnings = s.scene.warnings;
  return s;
}

PyScene load(const py::object& source, const std::vector<std::string>& overrides) {
  if (py::isinstance<py::dict>(source)) {
    const auto text = py::module_::import("json").attr("dumps")(source).cast<std::string>();
    return wrap(unwrap(parse_scene(text, "<dict>", overrides)));
  }
  const py::object os_path = py::module_::import("os").attr("fspath");
  if (!py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
    throw py::type_error("load_scene: a path (str or os.PathLike) or a dict in the scene format");
  return wrap(unwrap(load_scene_file(os_path(source).cast<std::string>(), overrides)));
}

/// The final positions, in the file's vertex order (vkcloth run --positions), as float32.
py::array_t<float> in_file_order(const ParticleSystem& system, std::span<const glm::vec3> positions) {
  std::vector<glm::vec3> ordered;
  ordered.reserve(positions.size());
  for (const std::uint32_t k : file_order(system))
    ordered.push_back(positions[k]);
  return points_array(ordered);
}

py::array_t<float> run(const PyScene& s, std::optional<std::uint64_t> steps, const std::string& backend) {
  const std::uint64_t n = steps.value_or(s.scene.steps);
  BackendPick pick = pick_backend(backend);
  std::optional<Error> error;
  std::vector<glm::vec3> positions;
  {
    py::gil_scoped_release unlocked;
    const auto fail = [&](const Error& e) { error = e; };
    if (!pick.context) {
      auto solver = CpuSolver<float>::create(s.scene.system, s.scene.params);
      if (!solver)
        fail(solver.error());
      else if (auto r = solver->run(n); !r)
        fail(r.error());
      else
        positions.assign(solver->positions().begin(), solver->positions().end());
    } else {
      auto solver = gpu::GpuSolver::create(*pick.context, s.scene.system, s.scene.params);
      if (!solver)
        fail(solver.error());
      else if (auto r = solver->simulate(n); !r)
        fail(r.error());
      else if (auto p = solver->positions(); !p)
        fail(p.error());
      else
        positions = std::move(*p);
    }
  }
  if (error)
    raise(*error);
  return in_file_order(s.scene.system, positions);
}

} // namespace

void bind_scene(py::module_& m) {
  py::class_<PyScene>(m, "Scene", "A loaded, validated scene (docs/scene-format.md)")
      .def_property_readonly("name", [](const PyScene& s) { return s.scene.name; })
      .def_property(
          "steps", [](const PyScene& s) { return s.scene.steps; },
          [](PyScene& s, std::uint64_t steps) { s.scene.steps = steps; }, "integrator.steps: what run() runs")
      .def_property(
          "params", [](const PyScene& s) { return s.scene.params; },
          [](PyScene& s, const SimParams& p) { s.scene.params = p; },
          "A copy of the scene's SimParams (assign a changed one back to run with it)")
      .def_property_readonly(
          "cloth", [](const PyScene& s) { return s.cloth; }, "The scene's system, for World.add")
      .def_property_readonly("up", [](const PyScene& s) { return std::string(to_string(s.scene.up)); })
      .def_property_readonly("warnings", [](const PyScene& s) { return s.scene.warnings; })
      .def_property_readonly(
          "cloths",
          [](const PyScene& s) {
            std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
            for (std::size_t k = 0; k + 1 < s.scene.cloths.size(); ++k)
              ranges.emplace_back(s.scene.cloths[k], s.scene.cloths[k + 1]);
            return ranges;
          },
          "A \"cloths\" scene's cloths as (first, end) particle ranges of Scene.cloth; [] for one cloth")
      .def("__repr__", [](const PyScene& s) {
        return "<vkcloth.Scene '" + s.scene.name + "': " + std::to_string(s.scene.system.size()) +
               " particles, " + std::to_string(s.scene.steps) + " steps>";
      });
  m.def("load_scene", &load, py::arg("source"), py::arg("overrides") = std::vector<std::string>{},
        "A scene from a file path or a dict in the scene format; overrides are \"key.path=value\" strings "
        "as vkcloth run --set takes. A bad key or value is a ValueError naming it");
  m.def("run", &run, py::arg("scene"), py::arg("steps") = py::none(), py::arg("backend") = "auto",
        "Runs `scene` (its integrator.steps unless `steps` is given) as vkcloth run does and returns the "
        "final positions, (n, 3) float32, in the order of vkcloth run --positions");
}

} // namespace vkcloth::python
