// SPDX-License-Identifier: MIT
#include "render_internal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "internal/barriers.hpp"
#include "collider_shapes.hpp"
#include "internal/pipelines.hpp"
#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/gpu/world.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/shaders/render/cloth_frag_spv.hpp"
#include "vkcloth/shaders/render/cloth_vert_spv.hpp"
#include "vkcloth/shaders/render/line_frag_spv.hpp"
#include "vkcloth/shaders/render/line_vert_spv.hpp"
#include "vkcloth/shaders/render/mesh_frag_spv.hpp"
#include "vkcloth/shaders/render/mesh_vert_spv.hpp"

namespace vkcloth::render {

using detail::ColliderDraw;
using detail::MeshRange;
using detail::MeshVertex;
using detail::Pose;
using gpu::Buffer;
using gpu::MemoryUse;

namespace {

/// The shaders' push constants (shaders/render/render_common.glsl).
struct DrawConstants {
  glm::mat4 view_proj; // the draw's frame -> clip (a collider's: times its rigid pose)
  glm::vec4 eye;       // xyz in the draw's frame, w checker cell
  glm::vec4 light;     // xyz towards the light (draw's frame), w ambient
  glm::vec4 color;     // mesh colour or the cloth's back tint, w mode
  glm::vec4 shape;     // mesh.vert: xyz vertex scale, w capsule half length
};
static_assert(sizeof(DrawConstants) == 128, "push constants must fit the guaranteed 128 bytes");

} // namespace

struct ClothRenderer::Impl {
  std::shared_ptr<gpu::Context::Impl> ctx; // first: outlives the objects below
  Palette palette;
  bool surface = false; // ClothTopology::has_surface(): triangles; else masses and spring lines
  std::uint32_t particle_count = 0;
  float mass_radius = 0.02f;

  Buffer cloth_index; // the topology's triangles (grid or mesh), or chain springs as a line list
  std::uint32_t cloth_index_count = 0;
  Buffer mesh_vertices, mesh_index, zero_instance;
  std::vector<ColliderDraw> draws; // one per create()-time collider
  std::vector<Collider> colliders; // their poses now (create(), set_colliders())
  MeshRange unit_sphere;           // chain masses (instanced at the solver's positions)

  gpu::ImageResource texture;
  gpu::Sampler sampler;
  gpu::DescriptorSetLayout set_layout;
  gpu::DescriptorPool pool;
  VkDescriptorSet set = VK_NULL_HANDLE; // freed with pool
  gpu::PipelineLayout layout;
  gpu::Pipeline cloth_pipeline, mesh_pipeline, line_pipeline;

  Result<Buffer> host_buffer(const void* data, VkDeviceSize bytes, VkBufferUsageFlags usage,
                             const char* what) {
    auto b = gpu::create_buffer(*ctx, std::max<VkDeviceSize>(bytes, 16), usage, MemoryUse::host_upload, true,
                                what);
    if (!b)
      return b.error();
    std::memset(b->mapped, 0, b->size);
    if (bytes)
      std::memcpy(b->mapped, data, bytes); // host-coherent; visible to the device at submission
    return b;
  }

  Result<void> build_geometry(const ClothTopology& topology, const SimParams& params,
                              const RendererOptions& o);
  Result<void> upload_texture(const Image& img);
  Result<void> create_texture_set();
  Result<void> build_pipelines(const RendererOptions& o);
  /// The colliders' draws, each at its pose in `now` (same index; one whose type or mesh is not
  /// the create()-time one there, or missing, is not drawn).
  void record_colliders(VkCommandBuffer cmd, const Camera& camera, float aspect,
                        std::span<const Collider> now) const;
  /// record_draw: the colliders at `now`, then the cloth or chain from `buffers`.
  void record(VkCommandBuffer cmd, const gpu::InstanceBuffers& buffers, std::span<const Collider> now,
              const Camera& camera, VkExtent2D extent) const;
};

Result<void> ClothRenderer::Impl::build_geometry(const ClothTopology& topology, const SimParams& params,
                                                 const RendererOptions& o) {
  // The cloth: the topology's triangles; or a chain's springs as lines.
  const ParticleSystem& system = topology.system();
  std::vector<std::uint32_t> idx;
  if (surface) {
    idx.assign(topology.triangles().begin(), topology.triangles().end());
  } else {
    for (const Spring& s : system.springs)
      idx.insert(idx.end(), {s.a, s.b});
  }
  cloth_index_count = static_cast<std::uint32_t>(idx.size());
  auto ci = host_buffer(idx.data(), idx.size() * sizeof(std::uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                        "cloth indices");
  if (!ci)
    return ci.error();
  cloth_index = std::move(*ci);

  // Colliders: each shape once in its own frame (record_draw poses it); the floor is a square
  // in the world around the scene's centre.
  const Bounds b = scene_bounds(system, params);
  const float half = o.floor_half_size > 0.0f ? o.floor_half_size : std::max(1.0f, 1.6f * b.radius());
  detail::ShapeBuffer shapes;
  for (const Collider& k : params.colliders) {
    auto d = shapes.add(k, colliders.size(), palette, b.center(), half);
    if (!d)
      return d.error();
    draws.push_back(*d);
    colliders.push_back(k);
  }
  unit_sphere = shapes.add_mass_sphere(palette.chain);
  if (o.mass_radius > 0.0f) {
    mass_radius = o.mass_radius;
  } else if (!surface) {
    double shortest = INFINITY;
    for (const Spring& s : system.springs)
      shortest = std::min(shortest, s.rest_length);
    mass_radius = std::isfinite(shortest) && shortest > 0 ? float(shortest) * 0.12f : 0.03f;
  }
  auto mv = host_buffer(shapes.vertices.data(), shapes.vertices.size() * sizeof(MeshVertex),
                        VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "mesh vertices");
  if (!mv)
    return mv.error();
  mesh_vertices = std::move(*mv);
  auto mi = host_buffer(shapes.indices.data(), shapes.indices.size() * sizeof(std::uint32_t),
                        VK_BUFFER_USAGE_INDEX_BUFFER_BIT, "mesh indices");
  if (!mi)
    return mi.error();
  mesh_index = std::move(*mi);
  const glm::vec4 zero(0.0f);
  auto zi = host_buffer(&zero, sizeof(zero), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "zero instance offset");
  if (!zi)
    return zi.error();
  zero_instance = std::move(*zi);
  return {};
}

Result<void> ClothRenderer::Impl::upload_texture(const Image& img) {
  const auto& v = ctx->vk;
  const VkDevice d = ctx->device;
  auto t = gpu::create_image(*ctx, VK_FORMAT_R8G8B8A8_UNORM,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                             VK_IMAGE_ASPECT_COLOR_BIT, img.width, img.height, "texture");
  if (!t)
    return t.error();
  texture = std::move(*t);
  auto staging =
      host_buffer(img.rgba.data(), img.rgba.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "texture staging");
  if (!staging)
    return staging.error();
  auto commands = gpu::CommandContext::create(*ctx, "texture upload");
  if (!commands)
    return commands.error();
  VKCLOTH_TRY(commands->submit_and_wait([&](VkCommandBuffer cmd) {
    gpu::barriers::texture_before_upload(v, cmd, texture.image);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {img.width, img.height, 1};
    v.vkCmdCopyBufferToImage(cmd, staging->buffer, texture.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                             &region);
    gpu::barriers::texture_after_upload(v, cmd, texture.image);
  }));

  VkSamplerCreateInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  si.magFilter = si.minFilter = VK_FILTER_LINEAR;
  si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  si.maxLod = 0.0f;
  VKCLOTH_VK_TRY(v.vkCreateSampler(d, &si, v.allocator, sampler.init(*ctx)), "vkCreateSampler");
  return {};
}

namespace {

struct Shaders {
  std::span<const std::uint32_t> vs, fs;
  const char* name;
};

/// One graphics pipeline of the renderer: `sh` with the given vertex input and topology; no
/// culling (both sides are drawn), depth test and write, dynamic viewport and scissor.
Result<gpu::Pipeline> create_graphics_pipeline(gpu::Context::Impl& ctx, VkPipelineLayout layout,
                                               const RendererOptions& o, const Shaders& sh,
                                               std::span<const VkVertexInputBindingDescription> bindings,
                                               std::span<const VkVertexInputAttributeDescription> attrs,
                                               VkPrimitiveTopology topology) {
  auto vm = gpu::create_shader_module(ctx, sh.vs, sh.name);
  if (!vm)
    return vm.error();
  auto fm = gpu::create_shader_module(ctx, sh.fs, sh.name);
  if (!fm)
    return fm.error();
  VkPipelineShaderStageCreateInfo stages[2]{};
  for (int k = 0; k < 2; ++k) {
    stages[k].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[k].stage = k == 0 ? VK_SHADER_STAGE_VERTEX_BIT : VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[k].module = k == 0 ? vm->get() : fm->get();
    stages[k].pName = "main";
  }
  VkPipelineVertexInputStateCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  vi.vertexBindingDescriptionCount = static_cast<std::uint32_t>(bindings.size());
  vi.pVertexBindingDescriptions = bindings.data();
  vi.vertexAttributeDescriptionCount = static_cast<std::uint32_t>(attrs.size());
  vi.pVertexAttributeDescriptions = attrs.data();
  VkPipelineInputAssemblyStateCreateInfo ia{};
  ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  ia.topology = topology;
  VkPipelineViewportStateCreateInfo vp{};
  vp.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  vp.viewportCount = 1;
  vp.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{};
  rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE; // the cloth is seen from both sides; the shaders pick the side
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{};
  ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  ms.rasterizationSamples = o.samples;
  VkPipelineDepthStencilStateCreateInfo ds{};
  ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;
  VkPipelineColorBlendAttachmentState att{};
  att.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                       VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo cb{};
  cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  cb.attachmentCount = 1;
  cb.pAttachments = &att;
  const VkDynamicState dyn[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{};
  dy.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
  dy.dynamicStateCount = 2;
  dy.pDynamicStates = dyn;
  VkGraphicsPipelineCreateInfo gi{};
  gi.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  gi.stageCount = 2;
  gi.pStages = stages;
  gi.pVertexInputState = &vi;
  gi.pInputAssemblyState = &ia;
  gi.pViewportState = &vp;
  gi.pRasterizationState = &rs;
  gi.pMultisampleState = &ms;
  gi.pDepthStencilState = &ds;
  gi.pColorBlendState = &cb;
  gi.pDynamicState = &dy;
  gi.layout = layout;
  gi.renderPass = o.render_pass;
  gi.subpass = o.subpass;
  gpu::Pipeline out;
  VKCLOTH_VK_TRY(ctx.vk.vkCreateGraphicsPipelines(ctx.device, ctx.pipelines->cache(), 1, &gi,
                                                  ctx.vk.allocator, out.init(ctx)),
                 fmt::format("vkCreateGraphicsPipelines ({})", sh.name));
  return out;
}

} // namespace

// The fabric texture's combined image sampler (set 0 of cloth.frag).
Result<void> ClothRenderer::Impl::create_texture_set() {
  const auto& v = ctx->vk;
  const VkDevice d = ctx->device;
  const VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                             VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo li{};
  li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  li.bindingCount = 1;
  li.pBindings = &binding;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorSetLayout(d, &li, v.allocator, set_layout.init(*ctx)),
                 "vkCreateDescriptorSetLayout (renderer)");
  const VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 1;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &ps;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorPool(d, &dp, v.allocator, pool.init(*ctx)),
                 "vkCreateDescriptorPool (renderer)");
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = set_layout.ptr();
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(d, &ai, &set), "vkAllocateDescriptorSets (renderer)");
  const VkDescriptorImageInfo ii{sampler, texture.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  VkWriteDescriptorSet w{};
  w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  w.dstSet = set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  w.pImageInfo = &ii;
  v.vkUpdateDescriptorSets(d, 1, &w, 0, nullptr);
  return {};
}

// The pipeline layout (texture set, push constants) and the cloth, mesh and line pipelines.
Result<void> ClothRenderer::Impl::build_pipelines(const RendererOptions& o) {
  const auto& v = ctx->vk;
  const VkDevice d = ctx->device;
  VKCLOTH_TRY(create_texture_set());
  const VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                  sizeof(DrawConstants)};
  VkPipelineLayoutCreateInfo pl{};
  pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pl.setLayoutCount = 1;
  pl.pSetLayouts = set_layout.ptr();
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  VKCLOTH_VK_TRY(v.vkCreatePipelineLayout(d, &pl, v.allocator, layout.init(*ctx)),
                 "vkCreatePipelineLayout (renderer)");
  auto make = [&](const Shaders& sh, const std::vector<VkVertexInputBindingDescription>& bindings,
                  const std::vector<VkVertexInputAttributeDescription>& attrs, VkPrimitiveTopology topology,
                  gpu::Pipeline* out) -> Result<void> {
    auto p = create_graphics_pipeline(*ctx, layout, o, sh, bindings, attrs, topology);
    if (!p)
      return p.error();
    *out = std::move(*p);
    return {};
  };
  namespace sp = gpu::spirv;
  constexpr std::uint32_t vec4 = 16;
  VKCLOTH_TRY(make({sp::cloth_vert_spv, sp::cloth_frag_spv, "cloth"},
                   {{0, vec4, VK_VERTEX_INPUT_RATE_VERTEX},
                    {1, vec4, VK_VERTEX_INPUT_RATE_VERTEX},
                    {2, vec4, VK_VERTEX_INPUT_RATE_VERTEX}},
                   {{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0},
                    {1, 1, VK_FORMAT_R32G32B32A32_SFLOAT, 0},
                    {2, 2, VK_FORMAT_R32G32B32A32_SFLOAT, 0}},
                   VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, &cloth_pipeline));
  VKCLOTH_TRY(
      make({sp::mesh_vert_spv, sp::mesh_frag_spv, "mesh"},
           {{0, sizeof(MeshVertex), VK_VERTEX_INPUT_RATE_VERTEX}, {1, vec4, VK_VERTEX_INPUT_RATE_INSTANCE}},
           {{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0},
            {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 16},
            {2, 1, VK_FORMAT_R32G32B32A32_SFLOAT, 0}},
           VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, &mesh_pipeline));
  VKCLOTH_TRY(make({sp::line_vert_spv, sp::line_frag_spv, "line"}, {{0, vec4, VK_VERTEX_INPUT_RATE_VERTEX}},
                   {{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0}}, VK_PRIMITIVE_TOPOLOGY_LINE_LIST,
                   &line_pipeline));
  return {};
}

Result<ClothRenderer> ClothRenderer::create(gpu::Context& context, const gpu::GpuSolver& solver,
                                            const ClothTopology& topology, RendererOptions options) {
  if (topology.size() != solver.particle_count())
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("the topology has {} particles but the solver {}: pass the topology the "
                                  "solver was created from (GpuSolver::topology())",
                                  topology.size(), solver.particle_count()));
  return create(context, solver.params(), topology, std::move(options));
}

Result<ClothRenderer> ClothRenderer::create(gpu::Context& context, const SimParams& params,
                                            const ClothTopology& topology, RendererOptions options) {
  if (!options.render_pass)
    return make_error(ErrorCode::invalid_argument, "RendererOptions::render_pass is required");
  auto impl = std::make_unique<Impl>();
  impl->ctx = gpu::context_impl(context);
  if (!detail::queue_has_graphics(*impl->ctx))
    return make_error(
        ErrorCode::unsupported,
        fmt::format("the Context's queue family {} on '{}' has no graphics support (create the Context with "
                    "ContextOptions::require_graphics)",
                    impl->ctx->queue_family, impl->ctx->name));
  impl->surface = topology.has_surface();
  impl->particle_count = static_cast<std::uint32_t>(topology.size());
  if (options.texture.width && options.encoded_texture)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("RendererOptions sets both a texture ({} x {}) and an encoded texture ('{}'); "
                    "set one",
                    options.texture.width, options.texture.height, options.encoded_texture->source));
  Image texture;
  if (options.texture.width) {
    texture = std::move(options.texture);
  } else if (options.encoded_texture) {
    auto decoded = decode_image(options.encoded_texture->encoded, options.encoded_texture->source);
    if (!decoded)
      return decoded.error();
    texture = std::move(*decoded);
  } else {
    texture = default_fabric_texture();
  }
  const std::uint32_t max_side = impl->ctx->properties.limits.maxImageDimension2D;
  if (texture.width > max_side || texture.height > max_side)
    return make_error(ErrorCode::unsupported,
                      fmt::format("the texture is {} x {} but the device allows at most {} a side",
                                  texture.width, texture.height, max_side));
  VKCLOTH_TRY(impl->build_geometry(topology, params, options));
  VKCLOTH_TRY(impl->upload_texture(texture));
  VKCLOTH_TRY(impl->build_pipelines(options));
  return ClothRenderer(std::move(impl));
}

ClothRenderer::ClothRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ClothRenderer::ClothRenderer(ClothRenderer&&) noexcept = default;
ClothRenderer& ClothRenderer::operator=(ClothRenderer&&) noexcept = default;
ClothRenderer::~ClothRenderer() = default;
const Palette& ClothRenderer::palette() const {
  return impl_->palette;
}
bool ClothRenderer::draws_cloth() const {
  return impl_->surface;
}

Result<void> ClothRenderer::set_colliders(std::span<const Collider> colliders) {
  Impl& s = *impl_;
  if (colliders.size() != s.draws.size())
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("set_colliders: {} colliders, but the renderer was created with {} (create a "
                    "renderer for a different collider list)",
                    colliders.size(), s.draws.size()));
  for (std::size_t i = 0; i < colliders.size(); ++i) {
    const ColliderDraw& d = s.draws[i];
    if (colliders[i].type != d.type)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("set_colliders: collider {} is of type {}, but was {} at create()", i,
                                    std::uint32_t(colliders[i].type), std::uint32_t(d.type)));
    if (d.type == Collider::Type::mesh && colliders[i].mesh.get() != d.mesh)
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("set_colliders: collider {} is a different mesh ('{}') from the one at "
                                    "create(): a renderer draws the meshes it was created with",
                                    i, colliders[i].mesh ? colliders[i].mesh->name() : std::string("none")));
  }
  s.colliders.assign(colliders.begin(), colliders.end());
  return {};
}

void ClothRenderer::Impl::record_colliders(VkCommandBuffer cmd, const Camera& camera, float aspect,
                                           std::span<const Collider> now) const {
  const auto& v = ctx->vk;
  constexpr VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  // One mesh buffer for every shape, one zero instance offset.
  v.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mesh_pipeline);
  v.vkCmdBindIndexBuffer(cmd, mesh_index.buffer, 0, VK_INDEX_TYPE_UINT32);
  const VkBuffer bufs[2] = {mesh_vertices.buffer, zero_instance.buffer};
  const VkDeviceSize offs[2] = {0, 0};
  v.vkCmdBindVertexBuffers(cmd, 0, 2, bufs, offs);
  const glm::mat4 view_proj = camera.view_projection(aspect);
  const glm::dvec3 light(glm::normalize(palette.light_dir)); // as the world-frame draws have it
  DrawConstants pc{};
  for (std::size_t i = 0; i < draws.size() && i < now.size(); ++i) {
    const ColliderDraw& d = draws[i];
    if (now[i].type != d.type || (d.type == Collider::Type::mesh && now[i].mesh.get() != d.mesh))
      continue; // not the collider this draw was built for
    const Pose p = detail::pose_of(d, now[i]);
    // The draw's frame is the collider's: clip from it, the eye and the light in it (the inverse
    // of a rigid pose: R^T (x - t)).
    const glm::dmat3 r(p.model);
    const glm::dvec3 t(p.model[3]);
    pc.view_proj = view_proj * glm::mat4(p.model);
    pc.eye = glm::vec4(glm::transpose(r) * (glm::dvec3(camera.eye) - t), d.range.cell);
    pc.light = glm::vec4(glm::transpose(r) * light, palette.ambient);
    pc.color = glm::vec4(d.range.color, d.range.mode);
    pc.shape = p.shape;
    v.vkCmdPushConstants(cmd, layout, stages, 0, sizeof(pc), &pc);
    v.vkCmdDrawIndexed(cmd, d.range.count, 1, d.range.first, 0, 0);
  }
}

void ClothRenderer::record_draw(VkCommandBuffer cmd, const gpu::GpuSolver& solver, const Camera& camera,
                                VkExtent2D extent) const {
  impl_->record(cmd, solver.buffers(), solver.params().colliders, camera, extent);
}

void ClothRenderer::record_draw(VkCommandBuffer cmd, const gpu::InstanceBuffers& buffers,
                                const Camera& camera, VkExtent2D extent) const {
  impl_->record(cmd, buffers, impl_->colliders, camera, extent);
}

void ClothRenderer::Impl::record(VkCommandBuffer cmd, const gpu::InstanceBuffers& buffers,
                                 std::span<const Collider> now, const Camera& camera,
                                 VkExtent2D extent) const {
  const Impl& s = *this;
  const auto& v = s.ctx->vk;
  const VkViewport viewport{0.0f, 0.0f, float(extent.width), float(extent.height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, extent};
  v.vkCmdSetViewport(cmd, 0, 1, &viewport);
  v.vkCmdSetScissor(cmd, 0, 1, &scissor);
  const float aspect = float(extent.width) / float(std::max(extent.height, 1u));
  DrawConstants pc{};
  pc.view_proj = camera.view_projection(aspect);
  pc.eye = glm::vec4(camera.eye, 1.0f);
  pc.light = glm::vec4(glm::normalize(s.palette.light_dir), s.palette.ambient);
  pc.shape = glm::vec4(1.0f, 1.0f, 1.0f, 0.0f);
  constexpr VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  const VkDeviceSize at = buffers.offset; // this instance's first particle (ClothWorld batches)
  const VkBuffer positions = buffers.positions;

  record_colliders(cmd, camera, aspect, now);

  if (s.surface) {
    // The cloth: the solver's current positions, normals and uvs as vertex buffers.
    v.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.cloth_pipeline);
    v.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.layout, 0, 1, &s.set, 0, nullptr);
    const VkBuffer bufs[3] = {positions, buffers.normals, buffers.uvs};
    const VkDeviceSize offs[3] = {at, at, at};
    v.vkCmdBindVertexBuffers(cmd, 0, 3, bufs, offs);
    // The solver's own copy of the same triangle list when it has one (it does; hosts that fill
    // InstanceBuffers themselves may leave it out).
    const bool solver_indices = buffers.indices && buffers.index_count == s.cloth_index_count;
    v.vkCmdBindIndexBuffer(cmd, solver_indices ? buffers.indices : s.cloth_index.buffer, 0,
                           VK_INDEX_TYPE_UINT32);
    pc.color = glm::vec4(s.palette.back_tint, 0.0f);
    v.vkCmdPushConstants(cmd, s.layout, stages, 0, sizeof(pc), &pc);
    v.vkCmdDrawIndexed(cmd, s.cloth_index_count, 1, 0, 0, 0);
    return;
  }
  // A chain: springs as lines, masses as small spheres instanced at the current positions.
  pc.color = glm::vec4(s.palette.chain, 0.0f);
  pc.shape = glm::vec4(glm::vec3(s.mass_radius), 0.0f);
  if (s.cloth_index_count) {
    v.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.line_pipeline);
    v.vkCmdBindVertexBuffers(cmd, 0, 1, &positions, &at);
    v.vkCmdBindIndexBuffer(cmd, s.cloth_index.buffer, 0, VK_INDEX_TYPE_UINT32);
    v.vkCmdPushConstants(cmd, s.layout, stages, 0, sizeof(pc), &pc);
    v.vkCmdDrawIndexed(cmd, s.cloth_index_count, 1, 0, 0, 0);
  }
  v.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.mesh_pipeline);
  const VkBuffer bufs[2] = {s.mesh_vertices.buffer, positions};
  const VkDeviceSize offs[2] = {0, at};
  v.vkCmdBindVertexBuffers(cmd, 0, 2, bufs, offs);
  v.vkCmdBindIndexBuffer(cmd, s.mesh_index.buffer, 0, VK_INDEX_TYPE_UINT32);
  v.vkCmdPushConstants(cmd, s.layout, stages, 0, sizeof(pc), &pc);
  v.vkCmdDrawIndexed(cmd, s.unit_sphere.count, s.particle_count, s.unit_sphere.first, 0, 0);
}

} // namespace vkcloth::render
