// SPDX-License-Identifier: MIT
// What the Python module's files share: vkcloth's errors as Python exceptions, GLM vectors as
// tuples, and the cloth a World adds (a ParticleSystem and its topology, built once).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <utility>

#include <glm/vec3.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"

namespace py = pybind11;

// A 3-vector from any sequence of three numbers (tuple, list, numpy array), and back as a tuple.
namespace pybind11::detail {
template <typename T> struct vec3_caster {
  PYBIND11_TYPE_CASTER(T, const_name("tuple[float, float, float]"));
  bool load(handle src, bool) {
    if (!src || !PySequence_Check(src.ptr()) || PyUnicode_Check(src.ptr()) || PyBytes_Check(src.ptr()))
      return false;
    auto seq = reinterpret_borrow<sequence>(src);
    if (seq.size() != 3)
      return false;
    try {
      for (std::size_t k = 0; k < 3; ++k)
        value[static_cast<int>(k)] = static_cast<typename T::value_type>(seq[k].cast<double>());
    } catch (const cast_error&) {
      return false;
    }
    return true;
  }
  static handle cast(const T& v, return_value_policy, handle) {
    return make_tuple(double(v.x), double(v.y), double(v.z)).release();
  }
};
template <> struct type_caster<glm::dvec3> : vec3_caster<glm::dvec3> {};
template <> struct type_caster<glm::vec3> : vec3_caster<glm::vec3> {};
} // namespace pybind11::detail

namespace vkcloth::python {

/// Raises the Python exception for `error` (the module's exception types, module.cpp):
/// invalid_argument and parse -> ValueError, io -> OSError, diverged -> DivergedError,
/// no_device -> NoDeviceError (a RuntimeError), out_of_memory -> MemoryError, others -> RuntimeError.
/// Needs the GIL.
[[noreturn]] void raise(const Error& error);
/// Registers the exception types on the module (module.cpp).
void add_exceptions(py::module_& m);

/// The value of `result`, or its error raised.
template <typename T> T unwrap(Result<T>&& result) {
  if (!result)
    raise(result.error());
  if constexpr (!std::is_void_v<T>)
    return std::move(*result);
}

/// `T(**fields)`: each keyword sets the attribute of that name; an unknown one is a TypeError
/// naming it and the fields there are.
template <typename T, typename Class> void init_from_keywords(Class& cls, const char* name) {
  cls.def(py::init([name](const py::kwargs& fields) {
            auto value = std::make_unique<T>();
            py::object view = py::cast(value.get(), py::return_value_policy::reference);
            for (auto [key, field] : fields) {
              const auto key_name = py::cast<std::string>(key);
              if (key_name.starts_with('_') || !py::hasattr(view, key_name.c_str())) {
                std::string known;
                for (py::handle attr : py::list(py::module_::import("builtins").attr("dir")(view)))
                  if (auto a = py::cast<std::string>(attr);
                      !a.starts_with('_') && !PyCallable_Check(view.attr(a.c_str()).ptr()))
                    known += (known.empty() ? "" : ", ") + a;
                throw py::type_error(std::string(name) + " has no field '" + key_name +
                                     "' (fields: " + known + ")");
              }
              view.attr(key_name.c_str()) = field;
            }
            return value;
          }),
          (std::string(name) + "(**fields): every field at its default unless given").c_str());
}

/// A cloth ready for a World: the system and its topology (ClothTopology::create, once, shared by
/// every instance and every World it is added to).
struct Cloth {
  std::shared_ptr<const ParticleSystem> system;
  std::vector<std::string> warnings; ///< what building it dropped (meshes)
  std::shared_ptr<const ClothTopology> topology() const;

private:
  mutable std::shared_ptr<const ClothTopology> topology_;
};

/// An (n, 3) float32 array holding a copy of `points`.
py::array_t<float> points_array(std::span<const glm::vec3> points);
/// An (n, 3) float64 array holding a copy of `points`.
py::array_t<double> points_array(std::span<const glm::dvec3> points);

/// Where a World or run() steps: `name` "cpu", "vulkan" or "auto" (gpu::choose_backend: the Vulkan
/// solver on a GPU, the CPU solver on lavapipe or when no device is found). `context` is set for
/// Vulkan. An unknown name is a ValueError; "vulkan" without a device is a NoDeviceError.
struct BackendPick {
  std::unique_ptr<gpu::Context> context;
  std::string reason;
};
BackendPick pick_backend(const std::string& name);

// The parts of the module, each in its own file.
void bind_params(py::module_& m); // params.cpp: SimParams and what it holds, materials
void bind_cloth(py::module_& m);  // cloth.cpp: Cloth, make_cloth, make_chain, load_mesh_cloth
void bind_world(py::module_& m);  // world.cpp: World
void bind_scene(py::module_& m);  // scene.cpp: Scene, load_scene, run

} // namespace vkcloth::python
