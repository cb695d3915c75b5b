// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage (shaders/CMakeLists.txt)
// Self-collision (CpuSolver::self_collide; docs/model.md "Self-collision"), one pass per stage
// (self_collision_shared.h), after the substep's update and stretch control, on the positions
// being written (POS_OUT). The spatial hash is a counting sort of the particles by
// bucket (of their cell keys): COUNT (integer atomics), prefix sums in two levels (SCAN_BLOCKS,
// SCAN_TOP, then SCAN_ADD makes them absolute), SCATTER (slots in any order), then SORT (each
// bucket's particles in increasing index): integer work only, so the table is the same on every
// run and the same as the CPU's. COLLIDE and APPLY are then cloth_kernel.h self_collide and
// self_apply per particle, each invocation writing only its own particle.
#include "kernel/layout/vkcloth_shared.h"
#include "kernel/layout/self_collision_shared.h"

// cloth_kernel.h self_collide's accessors (defined below, after common.glsl's globals).
#define SELF_DATA_PARAM uint self_data
#define SELF_DATA self_data
void self_range(uint unused, uint b, out uint first, out uint stop);
void self_entry(uint unused, uint i, out uint q, out uint key);
void self_particle(uint unused, uint q, out vec3 x, out float w, out vec3 rest);
vec3 self_velocity(uint unused, uint q);
void self_list_put(uint unused, uint p, uint slot, uint q);
void self_entry_particle(uint unused, uint i, uint q, out vec3 x, out vec3 rest);
uint self_list_get(uint unused, uint p, uint i);
#define VKCLOTH_PUSH_STRUCT SelfPush
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_PARAMS) readonly buffer SelfParamBuf { SelfParams self_params[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_REST) readonly buffer RestBuf { vec4 rest_pos[]; }; // xyz, w: 1/m (0: pinned)
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_COUNTS) buffer CountBuf { uint counts[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_STARTS) buffer StartBuf { uint starts[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_BLOCKS) buffer BlockBuf { uint blocks[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_KEYS) buffer KeyBuf { uint key_of[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_SORTED) buffer SortedBuf { uvec2 sorted[]; }; // particle, key
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_DELTA) buffer DeltaBuf { vec4 delta[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_BUILT) buffer BuiltBuf { vec4 built[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_LISTED) buffer ListedBuf { uint listed[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_LIST) buffer ListBuf { uint list[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_SELF_STALE) buffer StaleBuf { uint stale[]; };
// vbd's scratch that the explicit integrators' RK4 stages use: self-contact's force and stiffness block.
layout(std430, set = 0, binding = VKCLOTH_BINDING_ACC_POS) writeonly buffer ContactF { vec4 contact_f[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_ACC_VEL) writeonly buffer ContactDiag { vec4 contact_diag[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_STAGE_VEL) writeonly buffer ContactOff { vec4 contact_off[]; };
// vbd's positions at the step's start (CONTACT: the friction's slips).
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_IN) readonly buffer StepStart { vec4 step_start[]; };
// CONTACT: self_velocity gives each particle's move since the step's start in place of its velocity.
bool contact_pass = false;

shared uint partial[VKCLOTH_WORKGROUP_SIZE];

// This instance's table: pc.table_size buckets (counts), pc.table_size + 1 starts, and its scan blocks.
uint table_base() { return inst * pc.table_size; }
uint start_base() { return inst * (pc.table_size + 1u); }
uint block_base() { return inst * (pc.table_size / VKCLOTH_SELF_SCAN_BLOCK); }

// Bucket b's first entry in `sorted` (within the instance), once SCAN_ADD has run; starts has
// one more entry per instance than the table has buckets, the particle count.
uint bucket_start(uint b) { return starts[start_base() + b]; }

// What COLLIDE reads (its own particle, then every candidate's entry, particle and bucket range):
// read_pos_out, read_velocity, read_self_rest, read_bucket_start, read_sorted.
#define VKCLOTH_ACCESS_SELF_COLLIDE
#include "buffer_access.glsl"

void self_range(uint unused, uint b, out uint first, out uint stop) {
  first = read_bucket_start(b);
  stop = read_bucket_start(b + 1u);
}
void self_entry(uint unused, uint i, out uint q, out uint key) {
  const uvec2 e = read_sorted(i);
  q = e.x;
  key = e.y;
}
void self_particle(uint unused, uint q, out vec3 x, out float w, out vec3 rest) {
  x = read_pos_out(q);
  const vec4 r = read_self_rest(q);
  w = r.w; // the host's kernel inverse_mass, as the CPU's
  rest = r.xyz;
}
vec3 self_velocity(uint unused, uint q) {
  return contact_pass ? read_pos_out(q) - step_start[base + q].xyz : read_velocity(q);
}

void self_entry_particle(uint unused, uint i, uint q, out vec3 x, out vec3 rest) {
  x = read_pos_out(q);
  rest = read_self_rest(q).xyz;
}
void self_list_put(uint unused, uint p, uint slot, uint q) { list[(base + p) * VKCLOTH_SELF_LIST_CAPACITY + slot] = q; }
uint self_list_get(uint unused, uint p, uint i) { return list[(base + p) * VKCLOTH_SELF_LIST_CAPACITY + i]; }

// Whether this pass builds the hash (and the lists): without a skin before a substep's first
// pass, with one when CHECK found a particle that moved more than half the skin. Uniform per instance.
bool building(SelfParams sp) { return sp.half_skin2 > 0.0 ? stale[2u * inst] != 0u : pc.iteration == 0u; }

// Workgroup exclusive prefix sum of one value per invocation (integers: the same sums in any
// order); the workgroup's total is left in scan_total. Called in uniform control flow.
shared uint scan_total;
uint workgroup_exclusive_scan(uint value) {
  const uint i = gl_LocalInvocationID.x;
  partial[i] = value;
  barrier();
  if (i == 0u) {
    uint run = 0u;
    for (uint k = 0u; k < VKCLOTH_WORKGROUP_SIZE; ++k) {
      const uint c = partial[k];
      partial[k] = run;
      run += c;
    }
    scan_total = run;
  }
  barrier();
  return partial[i];
}

// One pipeline per pass (SC_STAGE; SelfCollisionGpu): COUNT, the scans, SORT and APPLY without
// COLLIDE's walk (docs/performance.md "lavapipe (llvmpipe) notes").
void main() {
  begin_instance();
  const SelfParams sp = self_params[inst];
  if (sp.iterations == 0u || frozen())
    return;
  const uint stage = pass_stage();
  const uint mask = pc.table_size - 1u;
  if (pc.iteration >= sp.iterations) // past this instance's passes (another asks for more)
    return;
  // vbd's sweeps record the lists and CONTACT of the instances that take self-contact as an energy;
  // the passes after the step are the others'.
  const bool energy = sp.stiffness > 0.0 && sp.half_skin2 > 0.0;
  if (energy != (pc.in_sweeps != 0u))
    return;
  const bool lists = sp.half_skin2 > 0.0;
  if ((stage == VKCLOTH_SELF_CHECK || stage == VKCLOTH_SELF_LIST) && !lists)
    return;
  const bool every_pass = stage == VKCLOTH_SELF_CHECK || stage == VKCLOTH_SELF_COLLIDE ||
                          stage == VKCLOTH_SELF_APPLY || stage == VKCLOTH_SELF_CONTACT;
  if (!every_pass && !building(sp)) // the hash and the lists: only when built
    return;
  if (stage == VKCLOTH_SELF_SCAN_BLOCKS) {
    // Workgroup = one block of VKCLOTH_SELF_SCAN_BLOCK buckets; 8 consecutive buckets per invocation.
    const uint block = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    const uint first = block * VKCLOTH_SELF_SCAN_BLOCK + gl_LocalInvocationID.x * VKCLOTH_SELF_SCAN_PER_INVOCATION;
    uint sum = 0u;
    for (uint k = 0u; k < VKCLOTH_SELF_SCAN_PER_INVOCATION; ++k)
      sum += counts[table_base() + first + k];
    uint run = workgroup_exclusive_scan(sum);
    for (uint k = 0u; k < VKCLOTH_SELF_SCAN_PER_INVOCATION; ++k) {
      starts[start_base() + first + k] = run;
      run += counts[table_base() + first + k];
    }
    if (gl_LocalInvocationID.x == 0u)
      blocks[block_base() + block] = scan_total;
    return;
  }
  if (stage == VKCLOTH_SELF_SCAN_TOP) {
    // One workgroup per instance: the block totals, in place, become the blocks' starts.
    const uint nblocks = pc.table_size / VKCLOTH_SELF_SCAN_BLOCK;
    const uint per = (nblocks + VKCLOTH_WORKGROUP_SIZE - 1u) / VKCLOTH_WORKGROUP_SIZE;
    const uint first = gl_LocalInvocationID.x * per;
    const uint stop = min(first + per, nblocks);
    uint sum = 0u;
    for (uint k = first; k < stop; ++k)
      sum += blocks[block_base() + k];
    uint run = workgroup_exclusive_scan(sum);
    for (uint k = first; k < stop; ++k) {
      const uint c = blocks[block_base() + k];
      blocks[block_base() + k] = run;
      run += c;
    }
    return;
  }
  if (stage == VKCLOTH_SELF_SCAN_ADD) {
    const uint b = particle_index(); // the bucket: its block's start added to its own
    if (b < pc.table_size)
      starts[start_base() + b] += blocks[block_base() + b / VKCLOTH_SELF_SCAN_BLOCK];
    else if (b == pc.table_size)
      starts[start_base() + b] = pc.count; // past the last bucket: every particle
    return;
  }
  if (stage == VKCLOTH_SELF_SORT) {
    const uint b = particle_index(); // the bucket
    if (b >= pc.table_size)
      return;
    const uint first = bucket_start(b), stop = bucket_start(b + 1u);
    for (uint i = first + 1u; i < stop; ++i) { // insertion sort by particle: buckets hold a few
      const uvec2 e = sorted[base + i];
      uint j = i;
      while (j > first && sorted[base + j - 1u].x > e.x) {
        sorted[base + j] = sorted[base + j - 1u];
        j -= 1u;
      }
      sorted[base + j] = e;
    }
    return;
  }
  const uint p = particle_index();
  if (p >= pc.count)
    return;
  if ((stage == VKCLOTH_SELF_COLLIDE || stage == VKCLOTH_SELF_CONTACT) && p == 0u)
    stale[2u * inst] = 0u; // the first pass after CHECK and the build, which have read it (barriers since)
  if (stage == VKCLOTH_SELF_COUNT) {
    const uint key = self_key(pos_out[base + p].xyz, sp.inv_cell);
    key_of[base + p] = key;
    atomicAdd(counts[table_base() + self_bucket(key, mask)], 1u);
  } else if (stage == VKCLOTH_SELF_SCATTER) {
    const uint key = key_of[base + p];
    const uint b = self_bucket(key, mask);
    const uint left = atomicAdd(counts[table_base() + b], 0xffffffffu); // minus one
    sorted[base + bucket_start(b) + left - 1u] = uvec2(p, key);
  } else if (stage == VKCLOTH_SELF_CHECK) { // also stale when built for another reach or thickness
    const vec4 b = built[base + p];
    if (self_moved(pos_out[base + p].xyz, b.xyz, sp.half_skin2) || b.w != sp.reach2 ||
        stale[2u * inst + 1u] != floatBitsToUint(sp.thickness))
      atomicOr(stale[2u * inst], 1u);
  } else if (stage == VKCLOTH_SELF_CONTACT) {
    vec3 f = vec3(0.0);
    SpringBlock hc = zero_block();
    contact_pass = true;
    const vec3 x = pos_out[base + p].xyz;
    if (particle[p].pinned == 0u)
      self_energy_listed(0u, p, listed[base + p], key_of[base + p], x, x - step_start[base + p].xyz,
                         rest_pos[p].xyz, sp.thickness, mask, sp.stiffness, sp.friction, ip.dt, f, hc);
    contact_f[base + p] = vec4(f, 0.0);
    contact_diag[base + p] = vec4(hc.diag, 0.0);
    contact_off[base + p] = vec4(hc.off, 0.0);
  } else if (stage == VKCLOTH_SELF_LIST) {
    const vec3 x = pos_out[base + p].xyz;
    listed[base + p] =
        self_gather(0u, p, key_of[base + p], x, rest_pos[p].xyz, sp.thickness, sp.reach2, sp.inv_cell, mask);
    built[base + p] = vec4(x, sp.reach2);
    if (p == 0u)
      stale[2u * inst + 1u] = floatBitsToUint(sp.thickness);
  } else {
    if (particle[p].pinned != 0u)
      return;
    if (stage == VKCLOTH_SELF_COLLIDE) {
      const vec3 x = read_pos_out(p);
      const vec3 v = read_velocity(p);
      const vec4 r = read_self_rest(p);
      vec3 dx;
      vec3 dv;
      if (lists)
        self_collide_listed(0u, p, listed[base + p], key_of[base + p], x, v, r.w, r.xyz, sp.thickness, mask,
                            sp.friction, dx, dv);
      else
        self_collide(0u, p, x, v, r.w, r.xyz, sp.thickness, sp.inv_cell, mask, sp.friction, dx, dv);
      delta[2u * (base + p)] = vec4(dx, 0.0);
      delta[2u * (base + p) + 1u] = vec4(dv, 0.0);
    } else { // VKCLOTH_SELF_APPLY
      vec3 x = pos_out[base + p].xyz;
      vec3 v = vel[base + p].xyz;
      self_apply(x, v, delta[2u * (base + p)].xyz, delta[2u * (base + p) + 1u].xyz);
      pos_out[base + p] = vec4(x, 1.0);
      vel[base + p] = vec4(v, 0.0);
    }
  }
}
