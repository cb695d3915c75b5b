// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: one (shaders/CMakeLists.txt)
// Stretch control by fast projection (CpuSolver::project_strain; docs/model.md "Stretch
// control"), after the tethers on the positions being written (POS_OUT). ONE workgroup per
// instance runs the whole projection: Newton iterations, each a Jacobi-preconditioned CG over the
// links in the solve, in the phases of strain_projection_shared.h, with workgroup barriers between
// them (every phase reads what other invocations wrote in the last one), and its dot products as
// fixed-shape trees in shared memory, which the CPU sums in the same order (workgroup_sums): the
// same bits on lavapipe. llvmpipe caps an invocation's loop iterations, so one dispatch runs at most
// pc.phase_budget phases and leaves the rest to the next dispatch, its state in ProjState; the host records
// enough indirect dispatches for the worst case, and the last instance to finish sets their group
// count to zero (ProjArgsHead), so that the dispatches left are empty.
#include "kernel/layout/vkcloth_shared.h"
#include "kernel/layout/strain_projection_shared.h"
#define VKCLOTH_PUSH_STRUCT ProjectionPush
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) coherent buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) coherent buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_STRAIN_LINKS) readonly buffer LinkBuf { StrainLink links[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_PROJ_INCIDENCE) readonly buffer IncBuf { uint incidence[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_PROJ_LINKS) coherent buffer LinkState { vec4 link_state[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_PROJ_GATHER) coherent buffer GatherBuf { vec4 gathered[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_PROJ_STATE) buffer StateBuf { ProjState state[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_PROJ_ARGS) buffer ArgBuf {
  ProjArgsHead args;
  uint counted[]; // per instance: 1 once it added itself to args.finished this substep
};

shared vec4 red[VKCLOTH_WORKGROUP_SIZE];

// (sum of x, sum of y, max of z) over the workgroup, to every invocation: a fixed-shape tree.
// Called in uniform control flow.
vec3 workgroup_reduce(vec3 value) {
  const uint l = gl_LocalInvocationID.x;
  red[l] = vec4(value, 0.0);
  barrier();
  for (uint s = VKCLOTH_WORKGROUP_SIZE / 2u; s > 0u; s >>= 1) {
    if (l < s) {
      precise vec4 a = red[l], b = red[l + s];
      precise float x = a.x + b.x;
      precise float y = a.y + b.y;
      red[l] = vec4(x, y, max(a.z, b.z), 0.0);
    }
    barrier();
  }
  const vec3 total = red[0].xyz;
  barrier(); // everyone has read red[0] before the next call writes it
  return total;
}

// Every invocation's writes of this phase visible to the whole workgroup before the next reads them.
void end_phase() {
  memoryBarrierBuffer();
  barrier();
}

float inv_mass_of(uint p) { return inverse_mass(particle[p].mass, particle[p].pinned != 0u); }
uint link_slot(uint i) { return 2u * (inst * pc.links + i); }

// grad C^T s for particle p: s is the link state's component `which` (2: d, 0: lambda).
vec3 gather_at(uint p, uint which) {
  const uint n = pc.count;
  vec3 u = vec3(0.0);
  for (uint k = incidence[p]; k < incidence[p + 1u]; ++k) {
    const uint e = incidence[n + 1u + k];
    const uint i = e >> 1;
    const vec4 b = link_state[link_slot(i) + 1u];
    projection_gather(u, link_state[link_slot(i)].xyz, which == 2u ? b.z : b.x, (e & 1u) != 0u);
  }
  return u;
}

// Once per substep, an instance that is done (or has no projection to run) counts itself; the
// last one empties the substep's remaining dispatches.
void count_finished() {
  if (counted[inst] != 0u)
    return;
  counted[inst] = 1u;
  if (atomicAdd(args.finished, 1u) + 1u == gl_NumWorkGroups.z)
    args.x = 0u;
}

void main() {
  begin_instance();
  if ((ip.stretch & VKCLOTH_STRETCH_PROJECTION) == 0u || frozen()) {
    if (gl_LocalInvocationID.x == 0u)
      count_finished();
    return;
  }
  const uint l = gl_LocalInvocationID.x, W = VKCLOTH_WORKGROUP_SIZE;
  const uint m = pc.links, n = pc.count;
  ProjState st = state[inst];
  if (pc.stage == 0u) { // the substep's first dispatch: a new projection
    st.phase = VKCLOTH_PROJ_LINKS;
    st.newton = 0u;
  }
  const float c_tolerance = projection_c_tolerance(ip.max_strain);
  for (uint budget = pc.phase_budget; budget > 0u && st.phase != VKCLOTH_PROJ_DONE; --budget) {
    if (st.phase == VKCLOTH_PROJ_LINKS) {
      precise vec3 acc = vec3(0.0, 0.0, -1.0); // r.z, r.r, max C
      for (uint i = l; i < m; i += W) {
        const StrainLink link = links[i];
        const float wa = inv_mass_of(link.a), wb = inv_mass_of(link.b);
        vec3 g;
        const float c = projection_constraint(pos_out[base + link.a].xyz, pos_out[base + link.b].xyz,
                                              stretch_bound(link.rest_length, ip.max_strain), g);
        const bool kept = st.newton > 0u && link_state[link_slot(i) + 1u].x > 0.0;
        const float inv = projection_inv_diag(c, kept, g, wa, wb);
        const float r = projection_rhs(c, inv);
        precise float z = r * inv;
        link_state[link_slot(i)] = vec4(g, inv);
        link_state[link_slot(i) + 1u] = vec4(0.0, r, z, 0.0);
        precise float rz = acc.x + r * z;
        precise float rr = acc.y + r * r;
        acc = vec3(rz, rr, max(acc.z, c));
      }
      const vec3 sums = workgroup_reduce(acc);
      if (!(sums.z > c_tolerance)) {
        st.phase = VKCLOTH_PROJ_DONE; // every link within the tolerance
      } else {
        st.rz = sums.x;
        st.rr = sums.y;
        precise float stop = float(VKCLOTH_PROJECTION_CG_TOL2) * sums.y;
        st.stop = stop;
        st.cg = 0u;
        st.phase = pc.cg_cap > 0u && st.rr > st.stop ? VKCLOTH_PROJ_GATHER : VKCLOTH_PROJ_APPLY;
      }
    } else if (st.phase == VKCLOTH_PROJ_GATHER) {
      for (uint p = l; p < n; p += W)
        gathered[base + p] = vec4(gather_at(p, 2u), 0.0);
      st.phase = VKCLOTH_PROJ_MATVEC;
    } else if (st.phase == VKCLOTH_PROJ_MATVEC) {
      precise float dq = 0.0;
      for (uint i = l; i < m; i += W) {
        const StrainLink link = links[i];
        const vec4 a = link_state[link_slot(i)];
        vec4 b = link_state[link_slot(i) + 1u];
        b.w = projection_row(a.xyz, inv_mass_of(link.a), gathered[base + link.a].xyz, inv_mass_of(link.b),
                             gathered[base + link.b].xyz, a.w);
        link_state[link_slot(i) + 1u] = b;
        dq = dq + b.z * b.w;
      }
      const float total = workgroup_reduce(vec3(dq, 0.0, 0.0)).x;
      if (!(total > 0.0)) {
        st.phase = VKCLOTH_PROJ_APPLY; // A is positive definite on the links in the solve: d = 0
      } else {
        st.alpha = st.rz / total;
        st.phase = VKCLOTH_PROJ_UPDATE;
      }
    } else if (st.phase == VKCLOTH_PROJ_UPDATE) {
      precise vec3 acc = vec3(0.0);
      for (uint i = l; i < m; i += W) {
        const float inv = link_state[link_slot(i)].w;
        vec4 b = link_state[link_slot(i) + 1u];
        float lambda = b.x, r = b.y;
        const float z = projection_cg_update(lambda, r, b.z, b.w, st.alpha, inv);
        link_state[link_slot(i) + 1u] = vec4(lambda, r, b.z, b.w);
        precise float rz = acc.x + r * z;
        precise float rr = acc.y + r * r;
        acc = vec3(rz, rr, 0.0);
      }
      const vec3 sums = workgroup_reduce(acc);
      st.beta = sums.x / st.rz;
      st.rz = sums.x;
      st.rr = sums.y;
      st.cg += 1u;
      st.phase = VKCLOTH_PROJ_DIRECTION;
    } else if (st.phase == VKCLOTH_PROJ_DIRECTION) {
      for (uint i = l; i < m; i += W) {
        const float inv = link_state[link_slot(i)].w;
        vec4 b = link_state[link_slot(i) + 1u];
        precise float z = b.y * inv;
        precise float d = z + st.beta * b.z;
        link_state[link_slot(i) + 1u] = vec4(b.x, b.y, d, b.w);
      }
      st.phase = st.cg < pc.cg_cap && st.rr > st.stop ? VKCLOTH_PROJ_GATHER : VKCLOTH_PROJ_APPLY;
    } else { // VKCLOTH_PROJ_APPLY
      for (uint p = l; p < n; p += W) {
        if (particle[p].pinned != 0u)
          continue;
        vec3 x = pos_out[base + p].xyz, v = vel[base + p].xyz;
        apply_correction(x, v, projection_move(gather_at(p, 0u), inv_mass_of(p)), ip.dt);
        pos_out[base + p] = vec4(x, 1.0);
        vel[base + p] = vec4(v, 0.0);
      }
      st.newton += 1u;
      st.phase = st.newton < ip.stretch_sweeps ? VKCLOTH_PROJ_LINKS : VKCLOTH_PROJ_DONE;
    }
    end_phase();
  }
  if (l == 0u) {
    state[inst] = st;
    if (st.phase == VKCLOTH_PROJ_DONE)
      count_finished();
  }
}
