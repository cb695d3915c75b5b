#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The report's single spring (K = 20 N/m, m = 1 kg, mu = 0.5 1/s, started at rest length) against
its closed form, the damped oscillator about the equilibrium m g / K lower: the largest error over
5 s for each time step, on a log-log plot. Euler's two forms are first order (the error halves
with dt); RK4 is fourth order until float32's rounding floor."""
import math

from example_support import arguments, import_vkcloth, save  # first: it finds an interpreter with numpy

import numpy as np

vkcloth = import_vkcloth()
K, M, MU, G, L0, T = 20.0, 1.0, 0.5, 9.81, 0.4, 5.0
DTS = [0.02, 0.01, 0.005, 0.0025, 0.00125]
INTEGRATORS = ["explicit_euler", "semi_implicit_euler", "rk4"]


def exact_z(t):
    """The mass's height: x'' + mu x' + (K/m) x = 0 about the equilibrium, x(0) = m g / K, x'(0) = 0."""
    wd = math.sqrt(K / M - MU * MU / 4)
    x0 = M * G / K
    return -(L0 + x0) + x0 * math.exp(-MU * t / 2) * (math.cos(wd * t) + MU / (2 * wd) * math.sin(wd * t))


def largest_error(integrator, dt):
    scene = vkcloth.single_spring(stiffness=K, mass=M, damping=MU, dt=dt, integrator=integrator)
    world = vkcloth.World("cpu")
    spring = world.add(scene.cloth, scene.params)
    x = world.positions(spring)  # a view: it shows each step
    worst = 0.0
    for k in range(1, round(T / dt) + 1):
        world.simulate(1)
        worst = max(worst, abs(float(x[1, 2]) - exact_z(k * dt)))
    return worst


def main():
    args = arguments(__doc__.splitlines()[0])
    errors = {name: [largest_error(name, dt) for dt in DTS] for name in INTEGRATORS}
    # The order from the three finest steps (the coarse end is not yet asymptotic); RK4 sits at
    # float32's rounding floor (~1e-6 m) from the first one, so its slope says nothing.
    slopes = {name: float(np.polyfit(np.log(DTS[-3:]), np.log(errors[name][-3:]), 1)[0]) for name in INTEGRATORS}
    print("dt (s)    " + "  ".join(f"{n:>20}" for n in INTEGRATORS))
    for k, dt in enumerate(DTS):
        print(f"{dt:<9g} " + "  ".join(f"{errors[n][k]:>18.3e} m" for n in INTEGRATORS))
    print("order    " + "  ".join(f"{slopes[n]:>20.2f}" for n in INTEGRATORS[:2])
          + "   (log-log slope, dt 0.005-0.00125; rk4 is at float32's rounding floor)")

    def draw(plt):
        for name in INTEGRATORS:
            note = "float32's floor" if name == "rk4" else f"slope {slopes[name]:.2f}"
            plt.loglog(DTS, errors[name], "o-", label=f"{name} ({note})")
        plt.loglog(DTS, [errors["semi_implicit_euler"][0] * dt / DTS[0] for dt in DTS], "k:", label="first order")
        plt.xlabel("time step dt (s)")
        plt.ylabel("largest |z - z_exact| over 5 s (m)")
        plt.title("Single spring against its closed form")
        plt.legend()
        plt.grid(True, which="both", alpha=0.3)

    save(args.out, "spring_convergence", {"dt": DTS, "error_m": errors, "order": slopes}, draw)


if __name__ == "__main__":
    main()
