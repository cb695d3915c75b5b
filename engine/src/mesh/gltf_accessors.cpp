// SPDX-License-Identifier: MIT
// The glTF reader's element access: accessors, buffer views and buffers as tinygltf loaded them,
// each checked (type, component type, sparse, stride, byte range against its view and buffer, with
// saturating arithmetic) before a byte of it is read, then the elements read from the checked
// views: positions and texture coordinates (finite, |x| <= 1e30) and indices (below the
// primitive's vertex count).
#include <algorithm>
#include <cmath>
#include <cstring>

#include "gltf_detail.hpp"

namespace vkcloth::gltf_detail {
namespace {

constexpr double max_abs_coordinate = 1e30;

/// a + b and a * b, saturated at UINT64_MAX: byte ranges from the file, compared with buffer sizes.
std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}
std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) {
  std::uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}

std::string type_name(int type) {
  switch (type) {
  case TINYGLTF_TYPE_SCALAR:
    return "SCALAR";
  case TINYGLTF_TYPE_VEC2:
    return "VEC2";
  case TINYGLTF_TYPE_VEC3:
    return "VEC3";
  case TINYGLTF_TYPE_VEC4:
    return "VEC4";
  case TINYGLTF_TYPE_MAT2:
    return "MAT2";
  case TINYGLTF_TYPE_MAT3:
    return "MAT3";
  case TINYGLTF_TYPE_MAT4:
    return "MAT4";
  }
  return fmt::format("{}", type);
}

std::string component_name(int component_type) {
  switch (component_type) {
  case TINYGLTF_COMPONENT_TYPE_BYTE:
    return "5120 (byte)";
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    return "5121 (unsigned byte)";
  case TINYGLTF_COMPONENT_TYPE_SHORT:
    return "5122 (short)";
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
    return "5123 (unsigned short)";
  case TINYGLTF_COMPONENT_TYPE_INT:
    return "5124 (int)";
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    return "5125 (unsigned int)";
  case TINYGLTF_COMPONENT_TYPE_FLOAT:
    return "5126 (float)";
  }
  return fmt::format("{}", component_type);
}

} // namespace

/// "the file has 1 accessor" / "... 3 accessors"
std::string has_count(std::size_t n, std::string_view singular, std::string_view plural) {
  return fmt::format("the file has {} {}", n, n == 1 ? singular : plural);
}

/// The bytes of bufferViews[index], checked against its buffer.
Result<std::span<const std::uint8_t>> buffer_view_bytes(const tinygltf::Model& model, int index,
                                                        std::string_view referrer, std::string_view source) {
  if (index < 0 || std::size_t(index) >= model.bufferViews.size())
    return gltf_error(source,
                      fmt::format("{} refers to bufferViews[{}], but {}", referrer, index,
                                  has_count(model.bufferViews.size(), "buffer view", "buffer views")));
  const tinygltf::BufferView& view = model.bufferViews[std::size_t(index)];
  if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
    return gltf_error(source, fmt::format("bufferViews[{}] refers to buffers[{}], but {}", index, view.buffer,
                                          has_count(model.buffers.size(), "buffer", "buffers")));
  const auto& data = model.buffers[std::size_t(view.buffer)].data;
  const std::uint64_t end = add_sat(view.byteOffset, view.byteLength);
  if (end > data.size())
    return gltf_error(source,
                      fmt::format("bufferViews[{}] covers bytes {}..{} of buffers[{}], which holds {} bytes",
                                  index, view.byteOffset, end, view.buffer, data.size()));
  return std::span<const std::uint8_t>(data.data() + view.byteOffset, view.byteLength);
}

namespace {

Result<void> check_accessor_kind(const tinygltf::Accessor& a, const AccessorSpec& spec,
                                 const std::string& label, std::string_view source) {
  if (a.sparse.isSparse)
    return gltf_error(source, fmt::format("{} is sparse; sparse accessors are not supported", label));
  if (a.type != spec.type)
    return gltf_error(
        source, fmt::format("{} has type {}, expected {}", label, type_name(a.type), type_name(spec.type)));
  if (std::find(spec.component_types.begin(), spec.component_types.end(), a.componentType) ==
      spec.component_types.end()) {
    std::string expected;
    for (const int c : spec.component_types)
      expected += (expected.empty() ? "" : " or ") + component_name(c);
    return gltf_error(source, fmt::format("{} has componentType {}, expected {}", label,
                                          component_name(a.componentType), expected));
  }
  if (spec.integers_normalized && a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT && !a.normalized)
    return gltf_error(source, fmt::format("{} has componentType {} without \"normalized\": true", label,
                                          component_name(a.componentType)));
  if (a.count > spec.max_count)
    return gltf_error(source, fmt::format("{} has {} elements, more than max_particles ({})", label, a.count,
                                          spec.max_count));
  return {};
}

} // namespace

Result<AccessorView> accessor_view(const tinygltf::Model& model, int index, const AccessorSpec& spec,
                                   std::string_view referrer, std::string_view source) {
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    return gltf_error(source, fmt::format("{} refers to accessors[{}], but {}", referrer, index,
                                          has_count(model.accessors.size(), "accessor", "accessors")));
  const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
  AccessorView view{fmt::format("accessors[{}] ({})", index, spec.role), nullptr, 0, a.count,
                    a.componentType};
  VKCLOTH_TRY(check_accessor_kind(a, spec, view.label, source));
  if (a.bufferView < 0)
    return gltf_error(source, fmt::format("{} has no bufferView", view.label));
  auto bytes = buffer_view_bytes(model, a.bufferView, view.label, source);
  if (!bytes)
    return bytes.error();
  const std::size_t element = std::size_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType))) *
                              std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(a.type)));
  const std::size_t byte_stride = model.bufferViews[std::size_t(a.bufferView)].byteStride;
  if (byte_stride != 0 && byte_stride < element)
    return gltf_error(source,
                      fmt::format("bufferViews[{}] has byteStride {}, less than one element of {} ({} bytes)",
                                  a.bufferView, byte_stride, view.label, element));
  view.stride = byte_stride != 0 ? byte_stride : element;
  const std::uint64_t end = a.count == 0
                                ? a.byteOffset
                                : add_sat(add_sat(a.byteOffset, mul_sat(a.count - 1, view.stride)), element);
  if (end > bytes->size())
    return gltf_error(source, fmt::format("{} reads bytes {}..{} of bufferViews[{}], which holds {} bytes",
                                          view.label, a.byteOffset, end, a.bufferView, bytes->size()));
  view.data = bytes->data() + a.byteOffset;
  return view;
}

namespace {

float read_float(const std::uint8_t* p) {
  float f = 0.0f;
  std::memcpy(&f, p, sizeof f);
  return f;
}

std::uint32_t read_unsigned(const std::uint8_t* p, int component_type) {
  switch (component_type) {
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    return *p;
  case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
    std::uint16_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  default: {
    std::uint32_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  }
}

/// A float component that must be finite and within +-1e30.
Result<double> checked_component(float f, const AccessorView& view, std::size_t element,
                                 std::string_view what, std::string_view source) {
  const double v = f;
  if (!std::isfinite(v))
    return gltf_error(source, fmt::format("{} {} {}: {} is not finite", view.label, what, element, v));
  if (std::abs(v) > max_abs_coordinate)
    return gltf_error(source, fmt::format("{} {} {}: {} is out of range (|coordinate| > 1e30)", view.label,
                                          what, element, v));
  return v;
}

} // namespace

Result<void> append_positions(const AccessorView& view, std::string_view source,
                              std::vector<glm::dvec3>& out) {
  for (std::size_t i = 0; i < view.count; ++i) {
    const std::uint8_t* p = view.data + i * view.stride;
    glm::dvec3 x;
    for (int c = 0; c < 3; ++c) {
      auto v = checked_component(read_float(p + 4 * c), view, i, "vertex", source);
      if (!v)
        return v.error();
      x[c] = *v;
    }
    out.push_back(x);
  }
  return {};
}

Result<void> append_texcoords(const AccessorView& view, std::string_view source,
                              std::vector<glm::dvec2>& out) {
  const int size = tinygltf::GetComponentSizeInBytes(std::uint32_t(view.component_type));
  for (std::size_t i = 0; i < view.count; ++i) {
    const std::uint8_t* p = view.data + i * view.stride;
    glm::dvec2 uv;
    for (int c = 0; c < 2; ++c) {
      if (view.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        auto v = checked_component(read_float(p + 4 * c), view, i, "element", source);
        if (!v)
          return v.error();
        uv[c] = *v;
      } else { // normalized unsigned byte / short
        const double max = view.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ? 255.0 : 65535.0;
        uv[c] = read_unsigned(p + size * c, view.component_type) / max;
      }
    }
    out.push_back(uv);
  }
  return {};
}

Result<void> append_indices(const AccessorView& view, std::size_t vertex_count, std::size_t base,
                            std::string_view source, std::vector<std::uint32_t>& out) {
  for (std::size_t i = 0; i < view.count; ++i) {
    const std::uint32_t index = read_unsigned(view.data + i * view.stride, view.component_type);
    if (index >= vertex_count)
      return gltf_error(source,
                        fmt::format("{} element {} is {}, out of range (the primitive has {} vertices)",
                                    view.label, i, index, vertex_count));
    out.push_back(static_cast<std::uint32_t>(base + index));
  }
  return {};
}

} // namespace vkcloth::gltf_detail
