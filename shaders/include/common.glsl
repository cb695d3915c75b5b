// Helpers shared by force.comp and integrate.comp. Every float expression is written in the
// order engine/src/core/cpu_solver.cpp uses, and `precise` keeps the compiler from fusing or
// reassociating it (no FMA contraction), so lavapipe reproduces the CPU bit for bit.
#ifndef VKCLOTH_COMMON_GLSL
#define VKCLOTH_COMMON_GLSL

layout(local_size_x = VKCLOTH_WORKGROUP_SIZE) in;

#ifdef VKCLOTH_PC_COPY
// The shader copies the push constants into `pc` before any branch (main: pc = pc_block): llvmpipe
// (Mesa 22.x) loads a push constant once and broadcasts it only outside control flow; inside a
// branch (everything after `if (p >= pc.count) return;`) it gathers it lane by lane.
layout(push_constant) uniform PushBlock { PushConstants pc_block; };
PushConstants pc;
#else
layout(push_constant) uniform PushBlock { PushConstants pc; };
#endif

// False: no instance of the batch has colliders (every ip.collider_count == 0), the contact loops
// compiled out. llvmpipe runs a loop body once even when no invocation enters it, per-lane collider
// loads included (GpuSolver creates fused.comp with and without; the other shaders keep the default).
layout(constant_id = 41) const bool SC_COLLIDERS = true;

layout(std430, set = 0, binding = VKCLOTH_BINDING_PARTICLE) readonly buffer ParticleBuf { ParticleInfo particle[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_COLLIDERS) readonly buffer ColliderBuf { Collider colliders[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_FLAGS) buffer FlagBuf { Flags flags[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_INSTANCES) readonly buffer InstanceBuf { InstanceParams instances[]; };

// This invocation's instance of the batch, the index of its particle 0 in the state buffers and
// its parameters; set by begin_instance(), the first call of every main().
uint inst;
uint base;
InstanceParams ip;

#ifdef VKCLOTH_PC_COPY
// The same shaders (force.comp, fused.comp, integrate.comp) read the instance parameters through
// an RGBA32UI texel view (set 1): on llvmpipe an SSBO load is a per-lane loop even at an index
// that is the same for the whole workgroup; a texel fetch is one vectorised call.
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_INSTANCES) uniform usamplerBuffer instances_texel;
#endif

void begin_instance() {
  inst = gl_WorkGroupID.z;
#ifdef VKCLOTH_PC_COPY
  pc = pc_block; // before any branch (see above)
  base = inst * pc.count;
  const int t = int(inst) * 5; // sizeof(InstanceParams) / 16
  const uvec4 a = texelFetch(instances_texel, t), g = texelFetch(instances_texel, t + 1),
              w = texelFetch(instances_texel, t + 2), d = texelFetch(instances_texel, t + 3),
              e = texelFetch(instances_texel, t + 4);
  ip.flags = a.x;
  ip.integrator = a.y;
  ip.collider_first = a.z;
  ip.collider_count = a.w;
  ip.gravity_damping = uintBitsToFloat(g);
  ip.wind = uintBitsToFloat(w);
  ip.dt = uintBitsToFloat(d.x);
  ip.w6 = uintBitsToFloat(d.y);
  ip.band = uintBitsToFloat(d.z);
  ip.eps = uintBitsToFloat(d.w);
  ip.limit = uintBitsToFloat(e.x);
#else
  base = inst * pc.count;
  ip = instances[inst];
#endif
}

// Particle index within the instance: 1-D, with a second grid dimension when one row of workgroups is not enough.
uint particle_index() {
  return gl_WorkGroupID.y * gl_NumWorkGroups.x * uint(VKCLOTH_WORKGROUP_SIZE) + gl_GlobalInvocationID.x;
}

// A step after the first diverged one leaves the state as it was after the bad step (like the
// CPU, which stops there). Stable within a dispatch: first_bad_step only takes this step's value.
bool frozen() { return flags[inst].first_bad_step < pc.step; }

// dot3(a, b) = a.x*b.x + a.y*b.y + a.z*b.z, left to right (CPU dot3).
precise float dot3(vec3 a, vec3 b) {
  precise float r = a.x * b.x + a.y * b.y;
  r = r + a.z * b.z;
  return r;
}

// glm::cross order.
precise vec3 cross3(vec3 x, vec3 y) {
  precise float cx = x.y * y.z - y.y * x.z;
  precise float cy = x.z * y.x - y.z * x.x;
  precise float cz = x.x * y.y - y.x * x.y;
  return vec3(cx, cy, cz);
}

// Signed distance to the instance's collider c and its outward unit normal (CPU collider_contact).
void collider_contact(uint c, vec3 p, out float distance, out vec3 normal) {
  const vec4 shape = colliders[ip.collider_first + c].shape;
  if (colliders[ip.collider_first + c].type == VKCLOTH_COLLIDER_PLANE) {
    normal = shape.xyz;
    precise float d = dot3(shape.xyz, p) - shape.w;
    distance = d;
    return;
  }
  precise vec3 r = p - shape.xyz;
  precise float len = sqrt(dot3(r, r));
  precise vec3 n = len > 0.0 ? r / len : vec3(0.0, 0.0, 1.0); // at the exact centre, push up
  precise float d = len - shape.w;
  normal = n;
  distance = d;
}

#endif
