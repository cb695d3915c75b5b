// SPDX-License-Identifier: MIT
// A minimal "host engine" that embeds vkcloth (docs/embedding.md): it creates ITS OWN Vulkan
// instance and device (its own volk, not vkcloth::gpu::Context::create), owns its render pass,
// images, command buffer and queue submission, and adds cloths through the public API only:
// a ClothWorld on the adopted device (two topologies; the hanging one twice, so those two share
// one batch and one dispatch per step), stepped by record_steps() inside the host's command
// buffer, then drawn by one render::ClothRenderer per cloth in the host's render pass. Offscreen: writes
// a PNG (runs on lavapipe without a display). Exit 0 on success, 1 on failure (or a validation
// message with --validate), 4 without a Vulkan device.
//
//   embedding_host [--out embedding.png] [--frames 40] [--validate]
#include <volk.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "vkcloth/vkcloth.hpp"
#include "vkcloth/render/cloth_renderer.hpp"

namespace {

constexpr std::uint32_t width = 640, height = 480;
std::uint32_t g_messages = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* d, void*) {
  ++g_messages;
  std::fprintf(stderr, "validation: %s\n", d->pMessage);
  return VK_FALSE;
}

#define CHECK_VK(call)                                                                                       \
  do {                                                                                                       \
    if (VkResult r_ = (call); r_ != VK_SUCCESS) {                                                            \
      std::fprintf(stderr, "%s failed: %d (line %d)\n", #call, int(r_), __LINE__);                           \
      return 1;                                                                                              \
    }                                                                                                        \
  } while (0)

std::uint32_t memory_type(VkPhysicalDevice pd, std::uint32_t bits, VkMemoryPropertyFlags want) {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(pd, &mp);
  for (std::uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want)
      return i;
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  std::string out = "embedding.png";
  int frames = 40;
  bool validate = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc)
      out = argv[++i];
    else if (a == "--frames" && i + 1 < argc)
      frames = std::stoi(argv[++i]);
    else if (a == "--validate")
      validate = true;
    else {
      std::fprintf(stderr, "usage: embedding_host [--out FILE.png] [--frames N] [--validate]\n");
      return 2;
    }
  }

  // ---- The host's own Vulkan: instance, device, queue (nothing of vkcloth yet). ----
  if (volkInitialize() != VK_SUCCESS)
    return std::fprintf(stderr, "no Vulkan loader\n"), 4;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "embedding_host";
  app.apiVersion = VK_API_VERSION_1_2;
  const char* layers[] = {"VK_LAYER_KHRONOS_validation"};
  const char* exts[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  const VkValidationFeatureEnableEXT sync[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mi.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType =
      VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  mi.pfnUserCallback = on_message;
  VkValidationFeaturesEXT vf{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT, &mi, 1, sync, 0, nullptr};
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  if (validate) {
    ici.pNext = &vf;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = layers;
    ici.enabledExtensionCount = 2;
    ici.ppEnabledExtensionNames = exts;
  }
  VkInstance instance = VK_NULL_HANDLE;
  if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS)
    return std::fprintf(stderr, "vkCreateInstance failed\n"), 4;
  volkLoadInstanceOnly(instance);
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  if (validate)
    CHECK_VK(vkCreateDebugUtilsMessengerEXT(instance, &mi, nullptr, &messenger));
  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(instance, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  vkEnumeratePhysicalDevices(instance, &n, pds.data());
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  for (VkPhysicalDevice p : pds) {
    std::uint32_t nf = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(p, &nf, nullptr);
    std::vector<VkQueueFamilyProperties> fams(nf);
    vkGetPhysicalDeviceQueueFamilyProperties(p, &nf, fams.data());
    for (std::uint32_t f = 0; f < nf && !pd; ++f)
      if ((fams[f].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
          (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
        pd = p, family = f;
  }
  if (!pd)
    return std::fprintf(stderr, "no device with a graphics + compute queue\n"), 4;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, nullptr, 0, family, 1, &priority};
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qi;
  VkDevice device = VK_NULL_HANDLE;
  CHECK_VK(vkCreateDevice(pd, &dci, nullptr, &device));
  volkLoadDevice(device);
  VkQueue queue = VK_NULL_HANDLE;
  vkGetDeviceQueue(device, family, 0, &queue);

  // ---- The host's render target: colour + depth images, render pass, framebuffer, readback. ----
  auto make_image = [&](VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect, VkImage& img,
                        VkDeviceMemory& mem, VkImageView& view) {
    VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ii.imageType = VK_IMAGE_TYPE_2D;
    ii.format = format;
    ii.extent = {width, height, 1};
    ii.mipLevels = ii.arrayLayers = 1;
    ii.samples = VK_SAMPLE_COUNT_1_BIT;
    ii.usage = usage;
    vkCreateImage(device, &ii, nullptr, &img);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, img, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, req.size,
                            memory_type(pd, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)};
    vkAllocateMemory(device, &ai, nullptr, &mem);
    vkBindImageMemory(device, img, mem, 0);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = img;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCreateImageView(device, &vi, nullptr, &view);
  };
  VkImage color = VK_NULL_HANDLE, depth = VK_NULL_HANDLE;
  VkDeviceMemory color_mem = VK_NULL_HANDLE, depth_mem = VK_NULL_HANDLE;
  VkImageView color_view = VK_NULL_HANDLE, depth_view = VK_NULL_HANDLE;
  make_image(VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
             VK_IMAGE_ASPECT_COLOR_BIT, color, color_mem, color_view);
  make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT,
             depth, depth_mem, depth_view);
  VkAttachmentDescription att[2] = {};
  att[0] = {0,
            VK_FORMAT_R8G8B8A8_UNORM,
            VK_SAMPLE_COUNT_1_BIT,
            VK_ATTACHMENT_LOAD_OP_CLEAR,
            VK_ATTACHMENT_STORE_OP_STORE,
            VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            VK_ATTACHMENT_STORE_OP_DONT_CARE,
            VK_IMAGE_LAYOUT_UNDEFINED,
            VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  att[1] = {0,
            VK_FORMAT_D32_SFLOAT,
            VK_SAMPLE_COUNT_1_BIT,
            VK_ATTACHMENT_LOAD_OP_CLEAR,
            VK_ATTACHMENT_STORE_OP_DONT_CARE,
            VK_ATTACHMENT_LOAD_OP_DONT_CARE,
            VK_ATTACHMENT_STORE_OP_DONT_CARE,
            VK_IMAGE_LAYOUT_UNDEFINED,
            VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkAttachmentReference cref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
      dref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &cref;
  sub.pDepthStencilAttachment = &dref;
  VkSubpassDependency deps[2] = {};
  // Attachments: earlier uses (previous frame) before this frame's writes.
  deps[0] = {VK_SUBPASS_EXTERNAL,
             0,
             VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                 VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
             VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                 VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
             VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                 VK_ACCESS_TRANSFER_READ_BIT,
             VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                 VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
             0};
  // The colour writes before the readback copy.
  deps[1] = {0,
             VK_SUBPASS_EXTERNAL,
             VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
             VK_PIPELINE_STAGE_TRANSFER_BIT,
             VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
             VK_ACCESS_TRANSFER_READ_BIT,
             0};
  VkRenderPassCreateInfo rpi{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, nullptr, 0, 2, att, 1, &sub, 2, deps};
  VkRenderPass render_pass = VK_NULL_HANDLE;
  CHECK_VK(vkCreateRenderPass(device, &rpi, nullptr, &render_pass));
  const VkImageView views[2] = {color_view, depth_view};
  VkFramebufferCreateInfo fbi{
      VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO, nullptr, 0, render_pass, 2, views, width, height, 1};
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  CHECK_VK(vkCreateFramebuffer(device, &fbi, nullptr, &framebuffer));
  VkBufferCreateInfo rbi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  rbi.size = VkDeviceSize(width) * height * 4;
  rbi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer readback = VK_NULL_HANDLE;
  CHECK_VK(vkCreateBuffer(device, &rbi, nullptr, &readback));
  VkMemoryRequirements rreq;
  vkGetBufferMemoryRequirements(device, readback, &rreq);
  VkMemoryAllocateInfo rai{
      VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, rreq.size,
      memory_type(pd, rreq.memoryTypeBits,
                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)};
  VkDeviceMemory readback_mem = VK_NULL_HANDLE;
  CHECK_VK(vkAllocateMemory(device, &rai, nullptr, &readback_mem));
  CHECK_VK(vkBindBufferMemory(device, readback, readback_mem, 0));
  VkCommandPoolCreateInfo cpi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO, nullptr,
                              VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, family};
  VkCommandPool pool = VK_NULL_HANDLE;
  CHECK_VK(vkCreateCommandPool(device, &cpi, nullptr, &pool));
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, pool,
                                  VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1};
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  CHECK_VK(vkAllocateCommandBuffers(device, &cai, &cmd));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  CHECK_VK(vkCreateFence(device, &fci, nullptr, &fence));

  int status = 0;
  {
    // ---- vkcloth: adopt the host's device; a world with three cloths; one renderer per cloth. ----
    using namespace vkcloth;
    gpu::HostHandles h;
    h.instance = instance;
    h.physical_device = pd;
    h.device = device;
    h.queue_family = family;
    h.queue = queue;
    h.get_instance_proc_addr = vkGetInstanceProcAddr;
    auto context = gpu::Context::adopt(h);
    if (!context)
      return std::fprintf(stderr, "%s\n", context.error().message.c_str()), 1;
    auto world = gpu::ClothWorld::create(*context);
    if (!world)
      return std::fprintf(stderr, "%s\n", world.error().message.c_str()), 1;

    ClothDesc falling;
    falling.nx = falling.ny = 24;
    falling.orientation = ClothOrientation::horizontal;
    falling.origin = {-0.9, -0.45, 0.45};
    falling.size = {0.9, 0.9};
    falling.pin_default_corners = false;
    ClothDesc hanging;
    hanging.nx = 18;
    hanging.ny = 14;
    hanging.origin = {0.25, 0.2, 0.4};
    hanging.size = {0.7, 0.55};
    hanging.stiffness.structural =
        300.0; // the default 40 N/m would stretch 252 particles of 0.05 kg into a rope
    hanging.stiffness.shear = 30.0;
    hanging.stiffness.bend = 30.0;
    auto falling_sys = make_cloth(falling);
    auto hanging_sys = make_cloth(hanging);
    if (!falling_sys || !hanging_sys)
      return std::fprintf(stderr, "make_cloth failed\n"), 1;
    // Each topology is prepared once; every instance of it shares it (and one batch).
    auto falling_prep = ClothTopology::create(*falling_sys);
    auto hanging_prep = ClothTopology::create(*hanging_sys);
    if (!falling_prep || !hanging_prep)
      return std::fprintf(stderr, "ClothTopology::create failed\n"), 1;
    const std::shared_ptr<const ClothTopology> falling_topo = *falling_prep, hanging_topo = *hanging_prep;
    SimParams on_sphere;
    on_sphere.dt = 0.01;
    on_sphere.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({-0.45, 0.0, 0.18}, 0.18)};
    SimParams windy;
    windy.dt = 0.01;
    windy.substeps = 4; // the stiffer springs need dt / 4 (instances of one batch share the substep count)
    windy.wind.strength = 0.04;
    windy.wind.direction = {0.0, 1.0, 0.2};
    auto a = world->add(falling_topo, on_sphere);
    auto b = world->add(hanging_topo, windy);
    // A second cloth of the same topology, behind the first, with its own start and wind.
    gpu::InitialState behind;
    for (const Particle& q : hanging_topo->system().particles)
      behind.positions.push_back(q.position + glm::dvec3(-0.15, 0.55, 0.2));
    SimParams gusty = windy;
    gusty.wind.strength = 0.12;
    auto c = world->add(hanging_topo, gusty, behind);
    if (!a || !b || !c)
      return std::fprintf(stderr, "ClothWorld::add failed\n"), 1;

    render::RendererOptions ro;
    ro.render_pass = render_pass;
    ro.floor_half_size = 1.2f;
    auto ra = render::ClothRenderer::create(*context, on_sphere, *falling_topo, ro);
    ro.floor_half_size = 0.0f;
    auto rb = render::ClothRenderer::create(*context, windy, *hanging_topo, ro);
    auto rc = render::ClothRenderer::create(*context, gusty, *hanging_topo, ro);
    if (!ra || !rb || !rc)
      return std::fprintf(stderr, "ClothRenderer::create: %s\n",
                          (!ra   ? ra
                           : !rb ? rb
                                 : rc)
                              .error()
                              .message.c_str()),
             1;
    render::Camera camera;
    camera.eye = {0.4f, -2.6f, 1.5f};
    camera.target = {0.0f, 0.1f, 0.25f};

    // ---- The host's frame loop: steps + barrier + its own render pass, one submission. ----
    for (int frame = 0; frame < frames; ++frame) {
      CHECK_VK(vkResetCommandBuffer(cmd, 0));
      VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
      CHECK_VK(vkBeginCommandBuffer(cmd, &bi));
      // The host's per-frame input: a gusting wind on the third cloth. StepParams travel in this
      // command buffer, so this is safe with frames in flight too (docs/embedding.md section 4).
      Wind gust = gusty.wind;
      gust.strength = 0.12 * (1.0 + 0.5 * std::sin(0.3 * frame));
      if (auto r = world->set_step_params(*c, {.wind = gust}); !r)
        return std::fprintf(stderr, "%s\n", r.error().message.c_str()), 1;
      world->record_steps(cmd, 2); // compute: both cloths, 2 steps
      world->record_barrier_to(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
      const VkClearValue clears[2] = {{{{0.62f, 0.72f, 0.84f, 1.0f}}}, {{{1.0f, 0}}}};
      VkRenderPassBeginInfo rb_info{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO,
                                    nullptr,
                                    render_pass,
                                    framebuffer,
                                    {{0, 0}, {width, height}},
                                    2,
                                    clears};
      vkCmdBeginRenderPass(cmd, &rb_info, VK_SUBPASS_CONTENTS_INLINE);
      // Each instance's buffers (and offset in them): the current positions alternate every step.
      ra->record_draw(cmd, *world->buffers(*a), camera, {width, height});
      rb->record_draw(cmd, *world->buffers(*b), camera, {width, height});
      rc->record_draw(cmd, *world->buffers(*c), camera, {width, height}); // same buffers as b, another offset
      vkCmdEndRenderPass(cmd);
      if (frame + 1 == frames) {
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {width, height, 1};
        vkCmdCopyImageToBuffer(cmd, color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &region);
        VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER, nullptr, VK_ACCESS_TRANSFER_WRITE_BIT,
                             VK_ACCESS_HOST_READ_BIT};
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0,
                             nullptr, 0, nullptr);
      }
      CHECK_VK(vkEndCommandBuffer(cmd));
      VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      si.commandBufferCount = 1;
      si.pCommandBuffers = &cmd;
      CHECK_VK(vkQueueSubmit(queue, 1, &si, fence));
      CHECK_VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
      CHECK_VK(vkResetFences(device, 1, &fence));
    }
    if (auto r = world->check_divergence(); !r) {
      std::fprintf(stderr, "%s\n", r.error().message.c_str());
      status = 1;
    }
    // CPU-side use of the results: the lowest particle of each cloth.
    for (auto id : world->instances()) {
      auto p = world->positions(id);
      if (!p)
        return std::fprintf(stderr, "%s\n", p.error().message.c_str()), 1;
      float lowest = 1e9f;
      for (const auto& q : *p)
        lowest = std::min(lowest, q.z);
      std::printf("cloth %llu: %zu particles, lowest z = %.4f after %d steps\n",
                  static_cast<unsigned long long>(id), p->size(), double(lowest), 2 * frames);
    }
    render::Image img;
    img.width = width;
    img.height = height;
    img.rgba.resize(std::size_t(width) * height * 4);
    void* mapped = nullptr;
    CHECK_VK(vkMapMemory(device, readback_mem, 0, VK_WHOLE_SIZE, 0, &mapped));
    std::memcpy(img.rgba.data(), mapped, img.rgba.size());
    vkUnmapMemory(device, readback_mem);
    if (auto w = render::write_png(out, img); !w) {
      std::fprintf(stderr, "%s\n", w.error().message.c_str());
      status = 1;
    } else {
      std::printf("wrote %s\n", out.c_str());
    }
  } // vkcloth objects gone: the host's device is untouched

  vkDeviceWaitIdle(device);
  vkDestroyFence(device, fence, nullptr);
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyBuffer(device, readback, nullptr);
  vkFreeMemory(device, readback_mem, nullptr);
  vkDestroyFramebuffer(device, framebuffer, nullptr);
  vkDestroyRenderPass(device, render_pass, nullptr);
  vkDestroyImageView(device, color_view, nullptr);
  vkDestroyImageView(device, depth_view, nullptr);
  vkDestroyImage(device, color, nullptr);
  vkDestroyImage(device, depth, nullptr);
  vkFreeMemory(device, color_mem, nullptr);
  vkFreeMemory(device, depth_mem, nullptr);
  vkDestroyDevice(device, nullptr);
  if (messenger)
    vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
  vkDestroyInstance(instance, nullptr);
  if (validate && g_messages) {
    std::fprintf(stderr, "%u validation messages\n", g_messages);
    return 1;
  }
  return status;
}
