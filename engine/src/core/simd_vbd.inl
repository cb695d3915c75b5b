// SPDX-License-Identifier: MIT
// The CPU's SIMD kernels of vertex block descent (a colour's sweep, the begin and the finish of a
// substep), W particles per vector. Included by row_kernel_simd.inl, inside its anonymous namespace,
// after the lanes' helpers (load3, store3, lane_shape, lane_mesh, ...) it defines; the same rule:
// no formula is written here, every term is the shared kernel's function (engine/kernel/vbd.h).

// ---- Vertex block descent: one colour of a sweep (VbdArgs) ------------------------------------
// CpuSolver::vbd_solve_colour, W particles of the colour per vector: vbd_add_spring over each
// particle's gather list in its order (padded per vector: VbdArgs), vbd_step, each collider's
// vbd_friction, then each collider's project_out from the substep's start. The lists differ in length (a
// grid's border, a mesh): slot s of a lane past its list is a zero-length spring to itself, which
// vbd_add_spring's `len > 0` select leaves out, as the reference's early return does. The particles of a
// colour are scattered (a grid's lie 5 apart along a row): positions come by T::gather3, stores go lane by
// lane.
template <typename T>
std::int64_t simd_vbd_colour(const vkcloth::detail::VbdArgs<typename T::Real>& a, std::int64_t k0,
                             std::int64_t k1) {
  using Real = typename T::Real;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
  using S = typename ShapeOf<T>::type;
  using B = typename BlockOf<T>::type;
  constexpr int W = T::W;
  if (a.shape_count > vkcloth::detail::finish_max_shapes)
    return k0; // the caller steps them all
  S shapes[vkcloth::detail::finish_max_shapes];
  for (std::uint32_t c = 0; c < a.shape_count; ++c)
    shapes[c] = lane_shape<T>(a.shapes[c]);
  const L h(a.h), mu(a.mu), eps(a.eps), band(Real(2) * a.eps);
  // W values into lanes (through memory: element stores into a vector type read as uninitialised).
  auto lanes = [](const Real(&v)[W]) {
    L r;
    __builtin_memcpy(&r.v, v, sizeof r.v);
    return r;
  };
  const std::uint32_t last = a.particles - 1;
  auto gather = [&](const Real* v, const std::uint32_t* index) { // T::gather3 reads past the last
    typename T::V x, y, z;
    bool reads_last = false;
    for (int l = 0; l < W; ++l)
      reads_last = reads_last || index[l] == last;
    if (reads_last)
      T::gather3_last(v, index, x, y, z);
    else
      T::gather3(v, index, x, y, z);
    return L3(L(x), L(y), L(z));
  };
  std::int64_t k = k0;
  for (; k + W <= k1; k += W) {
    const std::uint32_t* idx = a.order + k;
    const L3 x = gather(a.pos, idx), y = gather(a.target, idx), x0 = gather(a.start, idx);
    Real mv[W];
    for (int l = 0; l < W; ++l)
      mv[l] = a.mass[idx[l]];
    const L m = lanes(mv);
    L3 f(L(Real(0)));
    B hessian{L3(L(Real(0))), L3(L(Real(0)))};
    const std::size_t v = a.vector0 + std::size_t(k / W);
    const bool reads_last = a.reads_last[v];
    for (std::uint32_t s = a.spring_begin[v]; s < a.spring_begin[v + 1]; s += W) {
      typename T::V ox, oy, oz;
      if (reads_last)
        T::gather3_last(a.pos, a.other + s, ox, oy, oz);
      else
        T::gather3(a.pos, a.other + s, ox, oy, oz);
      vbd_add_spring(f, hessian, L3(L(ox), L(oy), L(oz)) - x, load<T>(a.rest + s), load<T>(a.stiff + s));
    }
    if (a.contact_f)
      vbd_add_contact(f, hessian, gather(a.contact_f, idx),
                      B{gather(a.contact_diag, idx), gather(a.contact_off, idx)});
    L3 stepped = vbd_step(x, y, x0, f, hessian, m, h, mu);
    const L inertia = vbd_inertia_weight(m, h, mu);
    for (std::uint32_t c = 0; c < a.shape_count; ++c)
      vbd_friction(stepped, lane_mesh<T>(a.shapes[c], 0, idx), shapes[c], x, x0, hessian, inertia, band, h);
    L3 projected = stepped, unused(L(Real(0)));
    for (std::uint32_t c = 0; c < a.shape_count; ++c)
      project_out(lane_mesh<T>(a.shapes[c], 0, idx), shapes[c], eps, x0, projected, unused);
    const L3 push = projected - stepped;
    Real out[6][W];
    const L* parts[6] = {&projected.x, &projected.y, &projected.z, &push.x, &push.y, &push.z};
    for (int c = 0; c < 6; ++c)
      __builtin_memcpy(out[c], &parts[c]->v, sizeof out[c]);
    for (int l = 0; l < W; ++l) {
      if (a.pinned[idx[l]])
        continue;
      for (int d = 0; d < 3; ++d) {
        a.pos[3 * std::size_t(idx[l]) + d] = out[d][l];
        a.push[3 * std::size_t(idx[l]) + d] = out[3 + d][l];
      }
    }
  }
  return k;
}

// CpuSolver::vbd_begin on W consecutive particles per vector (VbdBeginArgs).
template <typename T>
std::int64_t simd_vbd_begin(const vkcloth::detail::VbdBeginArgs<typename T::Real>& a, std::int64_t q0,
                            std::int64_t q1) {
  using Real = typename T::Real;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
  using S = typename ShapeOf<T>::type;
  constexpr int W = T::W;
  if (a.shape_count > vkcloth::detail::finish_max_shapes)
    return q0; // the caller begins them all
  S shapes[vkcloth::detail::finish_max_shapes];
  for (std::uint32_t c = 0; c < a.shape_count; ++c)
    shapes[c] = lane_shape<T>(a.shapes[c]);
  const L h(a.h), eps(a.eps), kw(a.kw), zero(Real(0));
  const L3 g(L(a.gravity[0]), L(a.gravity[1]), L(a.gravity[2]));
  const L3 wind_dir(L(a.wind_dir[0]), L(a.wind_dir[1]), L(a.wind_dir[2]));
  const bool wind = a.kw != Real(0);
  std::int64_t q = q0;
  for (; q + W <= q1; q += W) {
    const std::size_t v = std::size_t(q / W);
    const L3 x0 = load3<T>(a.start + 3 * q), v0 = load3<T>(a.vel + 3 * q);
    const L m = load<T>(a.mass + q);
    L3 fan(zero);
    const bool reads_last = a.fan_reads_last[v];
    for (std::uint32_t s = a.fan_begin[v]; s < a.fan_begin[v + 1]; s += W) { // normal_at
      typename T::V ax, ay, az, bx, by, bz;
      if (reads_last) {
        T::gather3_last(a.start, a.fan_a + s, ax, ay, az);
        T::gather3_last(a.start, a.fan_b + s, bx, by, bz);
      } else {
        T::gather3(a.start, a.fan_a + s, ax, ay, az);
        T::gather3(a.start, a.fan_b + s, bx, by, bz);
      }
      L3 sum = fan;
      add_fan_triangle(sum, L3(L(ax), L(ay), L(az)) - x0, L3(L(bx), L(by), L(bz)) - x0);
      fan = select(load<T>(a.fan_on + s) != zero, sum, fan); // padding adds nothing, not even +0
    }
    const L3 n = unit_or_zero(fan);
    store3<T>(a.normal + 3 * q, n);
    const L3 f_ext = add_body_forces(L3(zero), m, L3(zero), g, zero, wind, n, wind_dir, kw);
    const L3 y = vbd_inertia_target(x0, v0, f_ext, m, h);
    L3 x = vbd_first_guess(x0, v0, h), unused(zero);
    for (std::uint32_t c = 0; c < a.shape_count; ++c) // project_at
      project_out(lane_mesh<T>(a.shapes[c], std::uint32_t(q)), shapes[c], eps, x0, x, unused);
    const Mask<T> pin(T::pinmask(a.pinned + q));
    store3<T>(a.target + 3 * q, select(pin, x0, y));
    store3<T>(a.pos + 3 * q, select(pin, x0, x));
  }
  return q;
}

// CpuSolver::vbd_finish on W consecutive particles per vector (VbdFinishArgs).
template <typename T>
std::int64_t simd_vbd_finish(const vkcloth::detail::VbdFinishArgs<typename T::Real>& a, std::int64_t q0,
                             std::int64_t q1) {
  using Real = typename T::Real;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
  using S = typename ShapeOf<T>::type;
  constexpr int W = T::W;
  if (a.shape_count > vkcloth::detail::finish_max_shapes)
    return q0; // the caller finishes them all
  S shapes[vkcloth::detail::finish_max_shapes];
  for (std::uint32_t c = 0; c < a.shape_count; ++c)
    shapes[c] = lane_shape<T>(a.shapes[c]);
  const L h(a.h), band(a.band), eps(a.eps);
  std::int64_t q = q0;
  for (; q + W <= q1; q += W) {
    const L3 x0 = load3<T>(a.start + 3 * q), v0 = load3<T>(a.vel + 3 * q), x_in = load3<T>(a.pos + 3 * q);
    const L m = load<T>(a.mass + q);
    const L h_over_m = h / m;
    L3 x = x_in;
    L3 v = vbd_velocity(x, load3<T>(a.push + 3 * q), x0, h);
    L3 no_force(L(Real(0)));
    for (std::uint32_t c = 0; c < a.shape_count; ++c) { // contact_at without friction
      const S s = without_friction(shapes[c]);
      L distance;
      L3 n, deform;
      collider_contact(lane_mesh<T>(a.shapes[c], std::uint32_t(q)), s, x, x, band, distance, n, deform);
      contact_response(v, no_force, s, x, n, distance, band, a.both, h_over_m, deform);
    }
    for (std::uint32_t c = 0; c < a.shape_count; ++c) // project_at
      project_out(lane_mesh<T>(a.shapes[c], std::uint32_t(q)), shapes[c], eps, x0, x, v);
    const L3 f = vbd_net_force(v, v0, m, h);
    const Mask<T> pin(T::pinmask(a.pinned + q));
    store3<T>(a.force + 3 * q, select(pin, L3(L(Real(0))), f));
    store3<T>(a.pos + 3 * q, select(pin, x_in, x));
    store3<T>(a.vel + 3 * q, select(pin, v0, v));
  }
  return q;
}
