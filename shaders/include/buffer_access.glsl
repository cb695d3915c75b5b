// SPDX-License-Identifier: MIT
// How the shaders read their buffers: the ONE place that tests VKCLOTH_TEXEL_VIEWS. force,
// integrate, fused, strain_links, strain_finish and self_collision .comp have two builds
// (shaders/CMakeLists.txt): <name>_texel (-DVKCLOTH_TEXEL_VIEWS) reads the buffers below through
// set 1's uniform texel buffer views, <name>_storage from set 0's storage buffers; DeviceLayout
// picks one per device (docs/architecture.md "Per-device layout"; why the views:
// docs/performance.md "lavapipe (llvmpipe) notes"). Every read_* returns the same bits from
// either: a 32-bit texel is a copy of the buffer's word, and uintBitsToFloat gives a float back
// unchanged. The other shaders (one build) read the storage buffers.
//
// Included several times: each inclusion emits the sections its includer asked for, by defining
// VKCLOTH_ACCESS_<SECTION> just before (the section undefines it), so that every build declares
// the bindings it reads and no others. A section's storage reads may use buffers and functions
// its includer declares (listed with the section). q: a particle of this instance (state buffers:
// base + q); p: a particle of the shared topology.

// INSTANCE (common.glsl, every shader): the instance parameters, the colliders and the mesh
// colliders' nodes and triangles (common.glsl begin_instance, collider_shape, mesh_node,
// mesh_triangle). Through set 1 only in the solver passes' texel builds, the VKCLOTH_PC_COPY
// shaders (force, integrate, fused, strain_*): self_collision.comp's set 1 has none of them.
//   InstanceParams read_instance(uint i)     INSTANCES[i]   view: RGBA32UI, 5 texels each
//   Collider read_collider(uint i)           COLLIDERS[i]   RGBA32UI, VKCLOTH_COLLIDER_TEXELS each
//   MeshNode read_mesh_node(uint i)          MESH_NODES[i]  RGBA32UI, 2 each
//   MeshTriangle read_mesh_triangle(uint i)  MESH_TRIS[i]   RGBA32UI, 3 each
// Storage: common.glsl's instances, colliders, mesh_nodes, mesh_tris.
#ifdef VKCLOTH_ACCESS_INSTANCE
#undef VKCLOTH_ACCESS_INSTANCE
#if defined(VKCLOTH_TEXEL_VIEWS) && defined(VKCLOTH_PC_COPY)
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_INSTANCES) uniform usamplerBuffer instances_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_COLLIDERS) uniform usamplerBuffer colliders_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_MESH_NODES) uniform usamplerBuffer mesh_nodes_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_MESH_TRIS) uniform usamplerBuffer mesh_tris_texel;
InstanceParams read_instance(uint i) {
  const int t = int(i) * 5; // sizeof(InstanceParams) / 16
  const uvec4 a = texelFetch(instances_texel, t), g = texelFetch(instances_texel, t + 1),
              w = texelFetch(instances_texel, t + 2), d = texelFetch(instances_texel, t + 3),
              e = texelFetch(instances_texel, t + 4);
  InstanceParams r;
  r.flags = a.x;
  r.integrator = a.y;
  r.collider_first = a.z;
  r.collider_count = a.w;
  r.gravity_damping = uintBitsToFloat(g);
  r.wind = uintBitsToFloat(w);
  r.dt = uintBitsToFloat(d.x);
  r.w6 = uintBitsToFloat(d.y);
  r.band = uintBitsToFloat(d.z);
  r.eps = uintBitsToFloat(d.w);
  r.limit = uintBitsToFloat(e.x);
  r.max_strain = uintBitsToFloat(e.y);
  r.stretch = e.z;
  r.stretch_sweeps = e.w;
  return r;
}
Collider read_collider(uint i) {
  const int t = int(VKCLOTH_COLLIDER_TEXELS * i); // the Collider's 16-byte rows, in order
  Collider c;
  c.shape = uintBitsToFloat(texelFetch(colliders_texel, t));
  const uvec4 head = texelFetch(colliders_texel, t + 1);
  c.type = head.x;
  c.moving = head.y;
  c.mesh_root = head.z;
  c.mesh_tri0 = head.w;
  c.end_b = uintBitsToFloat(texelFetch(colliders_texel, t + 2));
  c.axis_x = uintBitsToFloat(texelFetch(colliders_texel, t + 3));
  c.axis_y = uintBitsToFloat(texelFetch(colliders_texel, t + 4));
  c.axis_z = uintBitsToFloat(texelFetch(colliders_texel, t + 5));
  c.velocity = uintBitsToFloat(texelFetch(colliders_texel, t + 6));
  c.spin = uintBitsToFloat(texelFetch(colliders_texel, t + 7));
  c.pivot = uintBitsToFloat(texelFetch(colliders_texel, t + 8));
  return c;
}
MeshNode read_mesh_node(uint i) {
  const int t = int(2u * i);
  return MeshNode(uintBitsToFloat(texelFetch(mesh_nodes_texel, t)),
                  uintBitsToFloat(texelFetch(mesh_nodes_texel, t + 1)));
}
MeshTriangle read_mesh_triangle(uint i) {
  const int t = int(3u * i);
  return MeshTriangle(uintBitsToFloat(texelFetch(mesh_tris_texel, t)),
                      uintBitsToFloat(texelFetch(mesh_tris_texel, t + 1)),
                      uintBitsToFloat(texelFetch(mesh_tris_texel, t + 2)));
}
#else
InstanceParams read_instance(uint i) { return instances[i]; }
Collider read_collider(uint i) { return colliders[i]; }
MeshNode read_mesh_node(uint i) { return mesh_nodes[i]; }
MeshTriangle read_mesh_triangle(uint i) { return mesh_tris[i]; }
#endif
#endif

// POS_IN (force_body.glsl): the positions the force pass reads (POS_IN: positions[read] or an RK4
// stage), all particles of the instance.
//   vec3 read_pos_in(uint q)                 POS_IN[base + q].xyz  view: RGBA32F
// Storage: pos_in (force_body.glsl).
#ifdef VKCLOTH_ACCESS_POS_IN
#undef VKCLOTH_ACCESS_POS_IN
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_POS_IN) uniform samplerBuffer pos_in_texel;
vec3 read_pos_in(uint q) { return texelFetch(pos_in_texel, int(base + q)).xyz; }
#else
vec3 read_pos_in(uint q) { return pos_in[base + q].xyz; }
#endif
#endif

// LISTS (force_body.glsl): the topology's gather lists (the mesh path: CSR gather and ring normal).
//   uvec3 read_list_range(uint p)            particle p's entries [x, z) of EDGES, of which [x, y)
//                                            are its fan's (with ring bits)
//   const bool FAN_EXIT                      whether y is only z, so that the fan loop must stop at
//                                            the first entry without ring bits
//   Edge read_edge(uint e)                   EDGES[e]  view: RGBA32UI, one texel per Edge
// The texel builds read all three ends from one RANGES texel (SolverBatch: begin, fan end, end;
// only the views have it); the storage builds take begin and end from OFFSETS, and y = end.
#ifdef VKCLOTH_ACCESS_LISTS
#undef VKCLOTH_ACCESS_LISTS
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_RANGES) uniform usamplerBuffer ranges_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_EDGES) uniform usamplerBuffer edges_texel;
uvec3 read_list_range(uint p) { return texelFetch(ranges_texel, int(p)).xyz; }
const bool FAN_EXIT = false;
Edge read_edge(uint e) {
  const uvec4 t = texelFetch(edges_texel, int(e));
  return Edge(t.x, uintBitsToFloat(t.y), uintBitsToFloat(t.z), t.w);
}
#else
layout(std430, set = 0, binding = VKCLOTH_BINDING_OFFSETS) readonly buffer OffsetBuf { uint offsets[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_EDGES) readonly buffer EdgeBuf { Edge edges[]; };
uvec3 read_list_range(uint p) { return uvec3(offsets[p], offsets[p + 1u], offsets[p + 1u]); }
const bool FAN_EXIT = true;
Edge read_edge(uint e) { return edges[e]; }
#endif
#endif

// POS_OUT (strain_*.comp): the positions and velocities a pass corrects in place, POS_OUT
// (positions[write]) and VEL, which it declares (writeonly in the texel builds: they read them
// through set 1, whose POS_IN view passes/stretch.cpp and finish.cpp point at positions[write]). Within
// one pass no invocation reads what another writes (a colour's links share no particle; tether
// anchors are pinned and never written). With VEL_FLAGS for the velocities.
//   vec3 read_pos_out(uint q)                POS_OUT[base + q].xyz  view: set 1's POS_IN, RGBA32F
#ifdef VKCLOTH_ACCESS_POS_OUT
#undef VKCLOTH_ACCESS_POS_OUT
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_POS_IN) uniform samplerBuffer pos_out_texel;
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) writeonly buffer VelBuf { vec4 vel[]; };
vec3 read_pos_out(uint q) { return texelFetch(pos_out_texel, int(base + q)).xyz; }
#else
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
vec3 read_pos_out(uint q) { return pos_out[base + q].xyz; }
#endif
#endif

// PARTICLE (force_body.glsl, strain_*.comp): the topology's particle constants.
//   ParticleInfo read_particle(uint p)       PARTICLE[p]  view: RG32UI (the mass's bits, pinned)
// Storage: common.glsl's particle.
#ifdef VKCLOTH_ACCESS_PARTICLE
#undef VKCLOTH_ACCESS_PARTICLE
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_PARTICLE) uniform usamplerBuffer particle_texel;
ParticleInfo read_particle(uint p) {
  const uvec4 t = texelFetch(particle_texel, int(p));
  return ParticleInfo(uintBitsToFloat(t.x), t.y);
}
#else
ParticleInfo read_particle(uint p) { return particle[p]; }
#endif
#endif

// VEL_FLAGS (fused.comp, strain_*.comp): the state velocities and the instance's flags word.
//   vec3 read_velocity(uint q)               VEL[base + q].xyz  view: RGBA32F
//   bool read_frozen()                       common.glsl frozen(), from FLAGS[inst].first_bad_step
//                                            (view: R32UI, 4 texels per Flags)
// Each invocation reads only velocities that no other one writes in the pass, and any flags value
// a dispatch can see gives the same answer (older steps' values are visible through the barrier;
// this step's own writes are >= pc.step). Storage: vel (fused.comp, or POS_OUT above).
#ifdef VKCLOTH_ACCESS_VEL_FLAGS
#undef VKCLOTH_ACCESS_VEL_FLAGS
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_VEL) uniform samplerBuffer vel_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_FLAGS) uniform usamplerBuffer flags_texel;
vec3 read_velocity(uint q) { return texelFetch(vel_texel, int(base + q)).xyz; }
bool read_frozen() { return texelFetch(flags_texel, int(inst * 4u + 1u)).x < pc.step; }
#else
vec3 read_velocity(uint q) { return vel[base + q].xyz; }
bool read_frozen() { return frozen(); }
#endif
#endif

// STRAIN_LINKS (strain_links.comp):
//   StrainLink read_strain_link(uint l)      STRAIN_LINKS[l]  view: R32UI, 3 texels each
#ifdef VKCLOTH_ACCESS_STRAIN_LINKS
#undef VKCLOTH_ACCESS_STRAIN_LINKS
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_STRAIN_LINKS) uniform usamplerBuffer links_texel;
StrainLink read_strain_link(uint l) {
  const int t = 3 * int(l);
  return StrainLink(texelFetch(links_texel, t).x, texelFetch(links_texel, t + 1).x,
                    uintBitsToFloat(texelFetch(links_texel, t + 2).x));
}
#else
layout(std430, set = 0, binding = VKCLOTH_BINDING_STRAIN_LINKS) readonly buffer LinkBuf { StrainLink links[]; };
StrainLink read_strain_link(uint l) { return links[l]; }
#endif
#endif

// TETHERS (strain_finish.comp):
//   TetherSlot read_tether(uint s)           TETHERS[s]  view: RG32UI, one texel each
#ifdef VKCLOTH_ACCESS_TETHERS
#undef VKCLOTH_ACCESS_TETHERS
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_TETHERS) uniform usamplerBuffer tethers_texel;
TetherSlot read_tether(uint s) {
  const uvec2 t = texelFetch(tethers_texel, int(s)).xy;
  return TetherSlot(t.x, uintBitsToFloat(t.y));
}
#else
layout(std430, set = 0, binding = VKCLOTH_BINDING_TETHERS) readonly buffer TetherBuf { TetherSlot tethers[]; };
TetherSlot read_tether(uint s) { return tethers[s]; }
#endif
#endif

// SELF_COLLIDE (self_collision.comp): what its COLLIDE pass reads (its own particle, then every
// candidate's entry, particle and bucket range), through set 1 of self-collision's own layout
// (self_collision_shared.h VKCLOTH_SELF_TEXEL_*) in the texel build. Written only by the other
// passes (APPLY, SCAN_*, SCATTER, SORT), with a barrier between each.
//   vec3 read_pos_out(uint q)                POS_OUT[base + q].xyz (the positions being written)
//   vec3 read_velocity(uint q)               VEL[base + q].xyz
//   vec4 read_self_rest(uint p)              SELF_REST[p]: xyz the rest position, w 1/m (0: pinned)
//   uint read_bucket_start(uint b)           SELF_STARTS[start_base() + b]: bucket b's first entry
//   uvec2 read_sorted(uint i)                SELF_SORTED[base + i]: particle, key
// Storage: pos_out, vel, rest_pos, starts, sorted and start_base() (self_collision.comp).
#ifdef VKCLOTH_ACCESS_SELF_COLLIDE
#undef VKCLOTH_ACCESS_SELF_COLLIDE
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_SELF_TEXEL_POS) uniform samplerBuffer pos_texel;
layout(set = 1, binding = VKCLOTH_SELF_TEXEL_VEL) uniform samplerBuffer vel_texel;
layout(set = 1, binding = VKCLOTH_SELF_TEXEL_REST) uniform samplerBuffer rest_texel;
layout(set = 1, binding = VKCLOTH_SELF_TEXEL_STARTS) uniform usamplerBuffer starts_texel;
layout(set = 1, binding = VKCLOTH_SELF_TEXEL_SORTED) uniform usamplerBuffer sorted_texel;
vec3 read_pos_out(uint q) { return texelFetch(pos_texel, int(base + q)).xyz; }
vec3 read_velocity(uint q) { return texelFetch(vel_texel, int(base + q)).xyz; }
vec4 read_self_rest(uint p) { return texelFetch(rest_texel, int(p)); }
uint read_bucket_start(uint b) { return texelFetch(starts_texel, int(start_base() + b)).x; }
uvec2 read_sorted(uint i) { return texelFetch(sorted_texel, int(base + i)).xy; }
#else
vec3 read_pos_out(uint q) { return pos_out[base + q].xyz; }
vec3 read_velocity(uint q) { return vel[base + q].xyz; }
vec4 read_self_rest(uint p) { return rest_pos[p]; }
uint read_bucket_start(uint b) { return starts[start_base() + b]; }
uvec2 read_sorted(uint i) { return sorted[base + i]; }
#endif
#endif
