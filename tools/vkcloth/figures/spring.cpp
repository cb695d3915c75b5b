// SPDX-License-Identifier: MIT
// The single and coupled springs of the report (§2.2-2.3): plots of z(t), energy and error.
#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "figures.hpp"
#include "vkcloth_plot/svg_plot.hpp"

namespace vkcloth::figures {
using plot::palette;
using plot::Plot;
using plot::Series;
using plot::to_svg;

namespace {

constexpr double g = 9.81, L0 = 0.4;

Scene chain_scene(ChainDesc desc, SimParams params, std::string name) {
  Scene s;
  s.name = std::move(name);
  s.system = *make_chain(desc); // the descriptions below are valid by construction
  (void)params.validate();
  s.params = params;
  return s;
}

Scene spring(double K, double mu, double dt, Integrator integ = Integrator::semi_implicit_euler,
             double below = L0) {
  ChainDesc d;
  d.stiffness = {K};
  d.positions = {{0.0, 0.0, -below}};
  SimParams p;
  p.integrator = integ;
  p.dt = dt;
  p.damping = mu;
  return chain_scene(d, p, "spring");
}

/// z(t) of the spring's mass, with the blow-up (if any) marked.
Series z_series(const Trace& tr, std::string label, std::size_t color) {
  Series s{std::move(label), palette(color), {}, {}, false, {}};
  s.x = tr.t;
  for (const auto& p : tr.positions)
    s.y.push_back(p[1].z);
  if (!tr.diverged.empty())
    s.note = fmt::format("diverged at t = {:.2f} s", tr.diverged_at);
  return s;
}

double closed_form_z(double t, double K, double mu, double below) {
  const double w0 = std::sqrt(K), gam = mu / 2.0, wd = std::sqrt(w0 * w0 - gam * gam);
  const double z_eq = -(L0 + g / K), x0 = -below - z_eq;
  return z_eq + std::exp(-gam * t) * (x0 * std::cos(wd * t) + gam * x0 / wd * std::sin(wd * t));
}

/// Largest |z - z_eq| over the trace's last `window` seconds.
double late_amplitude(const Trace& tr, double z_eq, double window) {
  double a = 0.0;
  for (std::size_t i = 0; i < tr.t.size(); ++i)
    if (tr.t[i] >= tr.t.back() - window)
      a = std::max(a, std::abs(tr.positions[i][1].z - z_eq));
  return a;
}

const char* const sec_spring = "Single spring (report §2.2): K, mu and dt";

/// A plot of z(t) of the spring's mass titled `title`; y in [lo, hi] (lo >= hi: the data's range).
Plot z_plot(std::string title, double lo = 0, double hi = 0) {
  return Plot{std::move(title), "t (s)", "z of the mass (m)", {}, lo, hi, 640, 400};
}

/// Draws z(t) of the spring for each value v of one parameter (`run(v)`), M[key][v] = metrics(trace, v).
Result<void> sweep_figure(Gallery& G, nlohmann::json& M, Plot plot, const char* key,
                          std::initializer_list<double> values, fmt::format_string<double> label,
                          const std::function<Result<Trace>(double)>& run,
                          const std::function<nlohmann::json(const Trace&, double)>& metrics, Figure figure) {
  std::size_t c = 0;
  for (double v : values) {
    auto tr = run(v);
    if (!tr)
      return tr.error();
    plot.series.push_back(z_series(*tr, fmt::vformat(label, fmt::make_format_args(v)), c++));
    M[key][fmt::format("{:g}", v)] = metrics(*tr, v);
  }
  VKCLOTH_TRY(G.write_text(figure.file, to_svg(plot)));
  G.figures.push_back(std::move(figure));
  return {};
}

/// Draws z(t) for K = 5 / 20 / 1000.
Result<void> stiffness_figure(Gallery& G, nlohmann::json& M) {
  return sweep_figure(
      G, M, z_plot("Stiffness K (mu = 0.5, dt = 0.02, m = 1)"), "stiffness", {5.0, 20.0, 1000.0}, "K = {:g}",
      [&](double K) { return simulate(spring(K, 0.5, 0.02), G.backend, 1000, 1); },
      [](const Trace& tr, double K) -> nlohmann::json {
        return {{"final_z", tr.positions.back()[1].z},
                {"rest_z", -(L0 + g / K)},
                {"late_amplitude", late_amplitude(tr, -(L0 + g / K), 2.0)}};
      },
      {"spring_stiffness.svg", sec_spring, "Stiffness: K = 5 / 20 / 1000",
       "Semi-implicit Euler, mu = 0.5, dt = 0.02 s, m = 1, L0 = 0.4, started at rest length. "
       "K = 5 hangs far down (sag mg/K = 1.96 m); K = 1000 oscillates for a long time."});
}

/// Draws z(t) for mu = 0 / 0.5 / 100.
Result<void> damping_figure(Gallery& G, nlohmann::json& M) {
  const double z_eq = -(L0 + g / 20.0);
  return sweep_figure(
      G, M, z_plot("Damping mu (K = 20, dt = 0.02)"), "damping", {0.0, 0.5, 100.0}, "mu = {:g}",
      [&](double mu) { return simulate(spring(20.0, mu, 0.02), G.backend, 1000, 1); },
      [&](const Trace& tr, double) -> nlohmann::json {
        int flips = 0;
        for (std::size_t i = tr.velocities.size() - 20; i < tr.velocities.size(); ++i)
          flips += tr.velocities[i][1].z * tr.velocities[i - 1][1].z < 0;
        return {{"late_amplitude", late_amplitude(tr, z_eq, 2.0)},
                {"velocity_sign_flips_last_20_steps", flips}};
      },
      {"spring_damping.svg", sec_spring, "Damping: mu = 0 / 0.5 / 100",
       "K = 20, dt = 0.02 s. mu = 0 never settles; mu = 100 is physically overdamped, but "
       "(1 - dt mu) = -1 makes the velocity flip sign every step: the oscillation is the "
       "integrator's."});
}

/// Draws z(t) for dt = 0.02 / 0.2 / 0.45 over the same 20 s.
Result<void> timestep_figure(Gallery& G, nlohmann::json& M) {
  return sweep_figure(
      G, M, z_plot("Time step dt (K = 20, mu = 0.5)", -3.0, 1.0), "timestep", {0.02, 0.2, 0.45}, "dt = {:g}",
      [&](double dt) {
        return simulate(spring(20.0, 0.5, dt), G.backend, std::uint64_t(std::llround(20.0 / dt)), 1);
      },
      [](const Trace& tr, double) -> nlohmann::json {
        return {{"diverged", !tr.diverged.empty()},
                {"diverged_at", tr.diverged_at},
                {"final_z", tr.positions.back()[1].z}};
      },
      {"spring_timestep.svg", sec_spring, "Time step: dt = 0.02 / 0.2 / 0.45",
       "Semi-implicit Euler, K = 20, mu = 0.5. dt = 0.2 settles without the intermediate "
       "states; dt = 0.45 exceeds the stability limit (K/m) dt^2 + 2 mu dt < 4 (dt < 0.423) "
       "and diverges (marked)."});
}

/// Draws z(t) for K = 1000 started at rest length vs 1.0 below the anchor.
Result<void> stiff_start_figure(Gallery& G, nlohmann::json& M) {
  return sweep_figure(
      G, M, z_plot("K = 1000 started near rest (0.4) and stretched (1.0)"), "stiff_start", {0.4, 1.0},
      "start {:g} below",
      [&](double below) {
        return simulate(spring(1000.0, 0.5, 0.02, Integrator::semi_implicit_euler, below), G.backend, 500, 1);
      },
      [](const Trace& tr, double) -> nlohmann::json {
        return {{"late_amplitude", late_amplitude(tr, -(L0 + g / 1000.0), 2.0)}};
      },
      {"spring_stiff_start.svg", sec_spring, "K = 1000 from (0, 0, 0.4) and (0, 0, 1.0)",
       "The report's start positions, read as distances below the anchor. Stretched by 0.6 m, "
       "the stiff spring swings up through its anchor, folds over and never settles: the motion "
       "stays large, as the report saw."});
}

/// Draws the integrators against the closed form: trajectories, error, energy without damping.
Result<void> integrator_figures(Gallery& G, nlohmann::json& M) {
  const std::string isec = "Integrators against the closed form";
  Plot traj{"Explicit vs semi-implicit Euler vs RK4 (K = 20, mu = 0.5, dt = 0.02)",
            "t (s)",
            "z (m)",
            {},
            0,
            0,
            640,
            400};
  Plot err{"Error against the closed-form damped oscillator (dt = 0.02)",
           "t (s)",
           "|z - z_exact| (m)",
           {},
           0,
           0,
           640,
           400};
  // Zoomed on the start value: explicit Euler leaves through the top within seconds.
  Plot energy{"Total energy without damping (K = 20, mu = 0, dt = 0.02)",
              "t (s)",
              "E (J)",
              {},
              -3.96,
              -3.88,
              640,
              400};
  Series exact{"closed form", "#000000", {}, {}, true, {}};
  std::size_t c = 0;
  for (Integrator integ : {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::rk4}) {
    auto tr = simulate(spring(20.0, 0.5, 0.02, integ), G.backend, 250, 1);
    if (!tr)
      return tr.error();
    traj.series.push_back(z_series(*tr, to_string(integ), c));
    Series e{to_string(integ), palette(c), tr->t, {}, false, {}};
    double worst = 0.0;
    for (std::size_t i = 0; i < tr->t.size(); ++i) {
      e.y.push_back(std::abs(tr->positions[i][1].z - closed_form_z(tr->t[i], 20.0, 0.5, L0)));
      worst = std::max(worst, e.y.back());
    }
    err.series.push_back(e);
    const Scene undamped = spring(20.0, 0.0, 0.02, integ);
    auto te = simulate(undamped, G.backend, 1000, 1);
    if (!te)
      return te.error();
    Series en{to_string(integ), palette(c), te->t, {}, false, {}};
    for (std::size_t i = 0; i < te->t.size(); ++i)
      en.y.push_back(total_energy(undamped, te->positions[i], te->velocities[i]));
    energy.series.push_back(en);
    M["integrators"][to_string(integ)] = {
        {"max_error", worst}, {"energy_start", en.y.front()}, {"energy_end", en.y.back()}};
    ++c;
  }
  for (int i = 0; i <= 250; ++i) {
    exact.x.push_back(0.02 * i);
    exact.y.push_back(closed_form_z(0.02 * i, 20.0, 0.5, L0));
  }
  traj.series.push_back(exact);
  VKCLOTH_TRY(G.write_text("spring_integrators.svg", to_svg(traj)));
  VKCLOTH_TRY(G.write_text("spring_error.svg", to_svg(err)));
  VKCLOTH_TRY(G.write_text("spring_energy.svg", to_svg(energy)));
  G.figures.push_back({"spring_integrators.svg", isec, "Trajectories and the closed form",
                       "K = 20, mu = 0.5, m = 1, dt = 0.02 s; dashed: the exact damped oscillator."});
  G.figures.push_back(
      {"spring_error.svg", isec, "Error against the closed form",
       "The Euler schemes are first order in dt, RK4 fourth order: its error is invisible here."});
  G.figures.push_back({"spring_energy.svg", isec, "Energy without damping",
                       "mu = 0: explicit Euler gains energy (unstable for any dt without damping), "
                       "semi-implicit Euler keeps it bounded, RK4 loses a little."});
  return {};
}

/// Draws the coupled springs from the side (x-z) at eight instants, like the report's image sequence.
std::string side_views(const Trace& tr) {
  std::string svg =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"960\" height=\"300\" font-family=\"sans-serif\" "
      "font-size=\"12\"><rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  double reach = 0.1; // farthest a mass gets from the anchor: sets the drawing scale
  for (const auto& q : tr.positions)
    reach = std::max({reach, -q[1].z, -q[2].z, std::abs(q[1].x), std::abs(q[2].x)});
  for (int k = 0; k < 8; ++k) {
    const std::size_t i = std::min<std::size_t>(tr.positions.size() - 1, std::size_t(k) * 25);
    const auto& q = tr.positions[i];
    const double ox = 60 + 120.0 * k, oy = 30, s = 220.0 / reach; // pixels per metre
    auto X = [&](double x) { return ox + x * s; };
    auto Z = [&](double z) { return oy - z * s; };
    svg += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#888\" "
                       "stroke-width=\"3\"/>",
                       ox - 30, oy, ox + 30, oy);
    svg += fmt::format(
        "<polyline fill=\"none\" stroke=\"#555\" stroke-width=\"1.5\" points=\"{:.1f},{:.1f} {:.1f},{:.1f} "
        "{:.1f},{:.1f}\"/>",
        X(q[0].x), Z(q[0].z), X(q[1].x), Z(q[1].z), X(q[2].x), Z(q[2].z));
    for (int m = 1; m <= 2; ++m)
      svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"7\" fill=\"{}\"/>", X(q[m].x), Z(q[m].z),
                         palette(m - 1));
    svg +=
        fmt::format("<text x=\"{:.1f}\" y=\"290\" text-anchor=\"middle\">t = {:.1f} s</text>\n", ox, tr.t[i]);
  }
  svg += "</svg>\n";
  return svg;
}

/// Draws the coupled springs (report §2.3): x of both masses, and side views over time.
Result<void> double_spring_figures(Gallery& G, nlohmann::json& M) {
  const std::string dsec = "Coupled springs (report §2.3, Figure 3)";
  ChainDesc d;
  d.masses = {1.0, 1.0};
  d.stiffness = {60.0, 60.0};
  d.rest_lengths = {0.4, 0.4};
  d.positions = {{0.3, 0.0, -0.25}, {0.65, 0.0, -0.45}};
  SimParams p;
  p.damping = 0.1;
  const Scene scene = chain_scene(d, p, "double_spring");
  auto tr = simulate(scene, G.backend, 300, 1);
  if (!tr)
    return tr.error();
  Plot xs{"Coupled springs: horizontal position of each mass", "t (s)", "x (m)", {}, 0, 0, 640, 400};
  for (std::size_t m = 1; m <= 2; ++m) {
    Series s{fmt::format("mass {}", m), palette(m - 1), tr->t, {}, false, {}};
    for (const auto& q : tr->positions)
      s.y.push_back(q[m].x);
    xs.series.push_back(s);
  }
  VKCLOTH_TRY(G.write_text("double_spring_x.svg", to_svg(xs)));
  VKCLOTH_TRY(G.write_text("double_spring_sequence.svg", side_views(*tr)));
  G.figures.push_back({"double_spring_sequence.svg", dsec, "Image sequence (side view, x-z)",
                       "Two masses of 1 kg, K = 60, L0 = 0.4, mu = 0.1, dt = 0.02 s, started off-axis; one "
                       "frame every 0.5 s."});
  G.figures.push_back({"double_spring_x.svg", dsec, "Horizontal positions",
                       "The lower mass kicks the middle one: not the single sine of a simple pendulum."});
  M["double_spring"] = {{"energy_start", total_energy(scene, tr->positions.front(), tr->velocities.front())},
                        {"energy_end", total_energy(scene, tr->positions.back(), tr->velocities.back())}};
  return {};
}

} // namespace

Result<void> spring_figures(Gallery& G) {
  auto& M = G.metrics["spring"];
  VKCLOTH_TRY(stiffness_figure(G, M));
  VKCLOTH_TRY(damping_figure(G, M));
  VKCLOTH_TRY(timestep_figure(G, M));
  VKCLOTH_TRY(stiff_start_figure(G, M));
  VKCLOTH_TRY(integrator_figures(G, M));
  VKCLOTH_TRY(double_spring_figures(G, M));
  return {};
}

} // namespace vkcloth::figures
