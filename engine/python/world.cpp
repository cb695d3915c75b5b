// SPDX-License-Identifier: MIT
// vkcloth.World: many cloths on one backend, CpuWorld or gpu::ClothWorld behind one class.
// positions(id) and velocities(id) are zero-copy, read-only views on the CPU world: the solver keeps
// its positions at one address (CpuSolver::positions), so a view shows every later step; each view
// holds the World (it stays alive while a view does) and a per-instance token, whose count tells
// remove() whether a view of the instance is still alive. On the GPU they are one read-back each.
#include "bindings.hpp"

#include <map>
#include <mutex>
#include <optional>
#include <variant>

#include "vkcloth/cpu_world.hpp"
#include "vkcloth/gpu/world.hpp"

namespace vkcloth::python {
namespace {

struct GpuWorld {
  std::unique_ptr<gpu::Context> context; // declared first: destroyed after the world
  std::optional<gpu::ClothWorld> world;
};

class World {
  /// One call at a time: a second thread's call while simulate() runs is a RuntimeError, never a race.
  struct Busy {
    explicit Busy(World& w) : lock(w.mutex_, std::try_to_lock) {
      if (!lock.owns_lock())
        throw std::runtime_error(
            "vkcloth.World is busy in a call from another thread (one thread drives a World)");
    }
    std::unique_lock<std::mutex> lock;
  };

  bool cpu() const { return std::holds_alternative<CpuWorld>(impl_); }
  template <typename F> auto visit(F&& f) {
    if (auto* cpu = std::get_if<CpuWorld>(&impl_))
      return f(*cpu);
    return f(*std::get<GpuWorld>(impl_).world);
  }

public:
  World(const std::string& backend, unsigned threads) {
    BackendPick pick = pick_backend(backend);
    reason_ = pick.reason;
    if (!pick.context) {
      CpuWorldOptions options;
      options.solver.threads = threads;
      impl_.emplace<CpuWorld>(unwrap(CpuWorld::create(options)));
      return;
    }
    GpuWorld& gpu = impl_.emplace<GpuWorld>();
    gpu.context = std::move(pick.context);
    gpu.world.emplace(unwrap(gpu::ClothWorld::create(*gpu.context)));
  }

  std::string backend() const { return cpu() ? "cpu" : "vulkan"; }
  const std::string& reason() const { return reason_; }
  std::string device() const {
    return cpu() ? std::string("cpu") : std::get<GpuWorld>(impl_).context->device_name();
  }
  std::uint64_t validation_messages() const {
    return cpu() ? 0 : std::get<GpuWorld>(impl_).context->validation_message_count();
  }

  InstanceId add(const Cloth& cloth, const std::optional<SimParams>& params,
                 const std::optional<std::vector<glm::dvec3>>& positions,
                 const std::optional<std::vector<glm::dvec3>>& velocities) {
    const Busy busy(*this);
    InitialState initial;
    if (positions)
      initial.positions = *positions;
    if (velocities)
      initial.velocities = *velocities;
    const auto topology = cloth.topology();
    const SimParams p = params.value_or(SimParams{});
    const InstanceId id = unwrap(visit([&](auto& w) { return w.add(topology, p, initial); }));
    tokens_[id] = py::module_::import("builtins").attr("object")();
    return id;
  }

  void remove(InstanceId id) {
    const Busy busy(*this);
    if (auto t = tokens_.find(id); t != tokens_.end() && t->second.ref_count() > 1)
      throw py::value_error("remove(" + std::to_string(id) +
                            "): " + std::to_string(t->second.ref_count() - 1) +
                            " positions / velocities view(s) of this instance are still alive; delete them "
                            "(or keep copies: numpy.array(view)) first");
    unwrap(visit([&](auto& w) { return w.remove(id); }));
    tokens_.erase(id);
  }

  void simulate(std::uint64_t steps) {
    Result<void> r;
    {
      py::gil_scoped_release unlocked; // other Python threads run meanwhile; Busy keeps them off this World
      const Busy busy(*this);
      r = visit([&](auto& w) { return w.simulate(steps); });
    }
    unwrap(std::move(r));
  }

  /// A view (CPU) or a copy (GPU) of one instance's positions, velocities or normals.
  enum class State { positions, velocities, normals };
  static py::array_t<float> state(const py::object& self, InstanceId id, State which) {
    World& w = self.cast<World&>();
    const Busy busy(w);
    if (auto* cpu = std::get_if<CpuWorld>(&w.impl_)) {
      const CpuSolver<float>* solver = cpu->solver(id);
      if (!solver)
        throw py::value_error("unknown instance id " + std::to_string(id));
      const std::span<const glm::vec3> s = which == State::positions    ? solver->positions()
                                           : which == State::velocities ? solver->velocities()
                                                                        : solver->normals();
      py::array_t<float> view(
          {static_cast<py::ssize_t>(s.size()), py::ssize_t{3}},
          {static_cast<py::ssize_t>(sizeof(glm::vec3)), static_cast<py::ssize_t>(sizeof(float))},
          &s.data()->x, py::make_tuple(self, w.tokens_.at(id)));
      view.attr("setflags")(py::arg("write") = false); // the solver owns them: change them with set_particle
      return view;
    }
    gpu::ClothWorld& gpu = *std::get<GpuWorld>(w.impl_).world;
    auto copy = which == State::positions    ? gpu.positions(id)
                : which == State::velocities ? gpu.velocities(id)
                                             : gpu.normals(id);
    return points_array(std::span<const glm::vec3>(unwrap(std::move(copy))));
  }

  void set_params(InstanceId id, const SimParams& params) {
    const Busy busy(*this);
    unwrap(visit([&](auto& w) { return w.set_params(id, params); }));
  }
  SimParams params(InstanceId id) {
    const Busy busy(*this);
    return unwrap(visit([&](auto& w) { return w.params(id); }));
  }

  void set_pin_targets(InstanceId id, const std::vector<std::uint32_t>& particles,
                       const std::vector<glm::dvec3>& positions, double max_distance) {
    if (particles.size() != positions.size())
      throw py::value_error("set_pin_targets: " + std::to_string(particles.size()) + " particles but " +
                            std::to_string(positions.size()) + " positions (one each)");
    std::vector<PinTarget> targets(particles.size());
    for (std::size_t k = 0; k < targets.size(); ++k)
      targets[k] = PinTarget{particles[k], positions[k], max_distance};
    const Busy busy(*this);
    unwrap(visit([&](auto& w) { return w.set_pin_targets(id, targets); }));
  }

  void set_collider_pose(InstanceId id, std::size_t collider, glm::dvec3 position,
                         std::optional<glm::dvec3> rotate_deg, glm::dvec3 linear_velocity,
                         glm::dvec3 angular_velocity) {
    ColliderPose pose;
    pose.position = position;
    if (rotate_deg)
      pose.rotation = Collider::rotation_from_degrees(*rotate_deg);
    pose.linear_velocity = linear_velocity;
    pose.angular_velocity = angular_velocity;
    const Busy busy(*this);
    unwrap(visit([&](auto& w) { return w.set_collider_pose(id, collider, pose); }));
  }

  void set_particle(InstanceId id, std::uint32_t particle, glm::vec3 position, glm::vec3 velocity) {
    const Busy busy(*this);
    auto* cpu = std::get_if<CpuWorld>(&impl_);
    if (!cpu)
      throw py::value_error("set_particle is a CPU world's (World(backend=\"cpu\"))");
    unwrap(cpu->set_particle(id, particle, position, velocity));
  }

  std::uint64_t step_index(InstanceId id) {
    const Busy busy(*this);
    return visit([&](auto& w) { return w.step_index(id); });
  }
  std::vector<InstanceId> instances() {
    const Busy busy(*this);
    return visit([&](auto& w) { return w.instances(); });
  }

private:
  std::variant<std::monostate, CpuWorld, GpuWorld> impl_;
  std::string reason_;
  std::map<InstanceId, py::object> tokens_;
  std::mutex mutex_;
};

} // namespace

void bind_world(py::module_& m) {
  py::class_<World>(
      m, "World",
      "Many cloths stepped together: World(backend=\"auto\" | \"cpu\" | \"vulkan\"). auto takes "
      "the Vulkan solver on a GPU and the CPU solver on lavapipe or without a device")
      .def(py::init<const std::string&, unsigned>(), py::arg("backend") = "auto", py::arg("threads") = 0,
           "threads: the CPU solver's threads per cloth (0: the cores this process may use)")
      .def_property_readonly("backend", &World::backend, "\"cpu\" or \"vulkan\": where the steps run")
      .def_property_readonly("backend_reason", &World::reason, "Why that backend (for backend=\"auto\")")
      .def_property_readonly("device", &World::device, "The Vulkan device's name, or \"cpu\"")
      .def_property_readonly("validation_messages", &World::validation_messages,
                             "Khronos validation messages so far (VKCLOTH_VALIDATION=1; 0 on the CPU)")
      .def("add", &World::add, py::arg("cloth"), py::arg("params") = py::none(), py::kw_only(),
           py::arg("positions") = py::none(), py::arg("velocities") = py::none(),
           "Adds an instance of `cloth` (make_cloth, make_chain, load_mesh_cloth, Scene.cloth) with `params` "
           "(default SimParams()), optionally from other start positions / velocities; returns its id")
      .def("remove", &World::remove, py::arg("id"))
      .def("simulate", &World::simulate, py::arg("steps"),
           "Runs `steps` steps of every instance (DivergedError names the instance, step and time)")
      .def(
          "positions",
          [](const py::object& self, InstanceId id) {
            return World::state(self, id, World::State::positions);
          },
          py::arg("id"),
          "(n, 3) float32 positions in particle order: on the CPU a read-only view that shows each later "
          "step (copy it to keep one); on the GPU a new array")
      .def(
          "velocities",
          [](const py::object& self, InstanceId id) {
            return World::state(self, id, World::State::velocities);
          },
          py::arg("id"), "(n, 3) float32 velocities, as positions()")
      .def(
          "normals",
          [](const py::object& self, InstanceId id) { return World::state(self, id, World::State::normals); },
          py::arg("id"), "(n, 3) float32 unit normals of the last step, as positions()")
      .def("set_params", &World::set_params, py::arg("id"), py::arg("params"))
      .def("params", &World::params, py::arg("id"))
      .def("set_pin_targets", &World::set_pin_targets, py::arg("id"), py::arg("particles"),
           py::arg("positions"), py::arg("max_distance") = 0.0,
           "The host's targets of `particles` for the next step (pinned ones sit on them, free ones stay "
           "within max_distance)")
      .def("set_collider_pose", &World::set_collider_pose, py::arg("id"), py::arg("collider"),
           py::arg("position"), py::kw_only(), py::arg("rotate_deg") = py::none(),
           py::arg("linear_velocity") = glm::dvec3(0.0), py::arg("angular_velocity") = glm::dvec3(0.0),
           "Moves params(id).colliders[collider] from the next step, keeping its shape and friction")
      .def("set_particle", &World::set_particle, py::arg("id"), py::arg("particle"), py::arg("position"),
           py::arg("velocity") = glm::vec3(0.0f), "Moves one particle (a hand; CPU world)")
      .def("step_index", &World::step_index, py::arg("id"))
      .def_property_readonly("instances", &World::instances)
      .def("__len__", [](World& w) { return w.instances().size(); });
}

} // namespace vkcloth::python
