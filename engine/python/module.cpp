// SPDX-License-Identifier: MIT
// The Python module vkcloth._vkcloth (imported by the package vkcloth, engine/python/vkcloth):
// vkcloth's C++ API with numpy arrays. Every C++ error becomes a Python exception carrying the C++
// message, which names the key or parameter and the value.
#include "bindings.hpp"

#include <algorithm>
#include <cstring>

namespace vkcloth::python {
namespace {

PyObject* diverged_error = nullptr;
PyObject* no_device_error = nullptr;

} // namespace

void raise(const Error& error) {
  PyObject* type = PyExc_RuntimeError;
  std::string message = error.message;
  switch (error.code) {
  case ErrorCode::invalid_argument:
  case ErrorCode::parse:
    type = PyExc_ValueError;
    break;
  case ErrorCode::io:
    type = PyExc_OSError;
    break;
  case ErrorCode::diverged:
    type = diverged_error;
    break;
  case ErrorCode::no_device:
    type = no_device_error;
    break;
  case ErrorCode::out_of_memory:
    type = PyExc_MemoryError;
    break;
  case ErrorCode::vulkan:
  case ErrorCode::unsupported:
    message = std::string(to_string(error.code)) + ": " + message;
    break;
  }
  PyErr_SetString(type, message.c_str());
  throw py::error_already_set();
}

void add_exceptions(py::module_& m) {
  diverged_error = PyErr_NewExceptionWithDoc(
      "vkcloth.DivergedError",
      "The simulation blew up (NaN, inf or a runaway position); the message names the step and time.",
      PyExc_RuntimeError, nullptr);
  no_device_error = PyErr_NewExceptionWithDoc(
      "vkcloth.NoDeviceError", "No usable Vulkan device (a RuntimeError).", PyExc_RuntimeError, nullptr);
  if (!diverged_error || !no_device_error)
    throw py::error_already_set();
  m.add_object("DivergedError", py::handle(diverged_error));
  m.add_object("NoDeviceError", py::handle(no_device_error));
}

std::shared_ptr<const ClothTopology> Cloth::topology() const {
  if (!topology_)
    topology_ = unwrap(ClothTopology::create(*system));
  return topology_;
}

template <typename T>
static py::array_t<T> copy_points(std::span<const glm::vec<3, T, glm::defaultp>> points) {
  py::array_t<T> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  if (!points.empty())
    std::memcpy(out.mutable_data(), points.data(), points.size() * sizeof(points[0]));
  return out;
}
py::array_t<float> points_array(std::span<const glm::vec3> points) {
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  return copy_points<float>(points);
}
py::array_t<double> points_array(std::span<const glm::dvec3> points) {
  static_assert(sizeof(glm::dvec3) == 3 * sizeof(double));
  return copy_points<double>(points);
}

} // namespace vkcloth::python

PYBIND11_MODULE(_vkcloth, m) {
  using namespace vkcloth::python;
  m.doc() = "vkcloth: mass-spring cloth on the CPU and on Vulkan compute (the C++ API with numpy arrays)";
  add_exceptions(m);
  bind_params(m);
  bind_cloth(m);
  bind_world(m);
  bind_scene(m);
}
