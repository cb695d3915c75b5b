#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The report's Figure 7: the cloth with structural springs alone, hanging from its two top
corners, for K_struct = 5 ... 50 N/m (10 x 10 points, 0.05 kg each, dt = 0.02 s, mu = 0.5, 10 s).
The softer it is, the lower its lowest point: at K_struct = 5 it stretches to several metres."""
from example_support import arguments, import_vkcloth, save  # first: it finds an interpreter with numpy

import numpy as np

vkcloth = import_vkcloth()
STIFFNESSES = [5, 10, 20, 30, 40, 50]
STEPS = 500


def lowest_point(k_struct):
    cloth = vkcloth.make_cloth(nx=10, ny=10, stiffness={"structural": k_struct, "shear": 0.0, "bend": 0.0})
    world = vkcloth.World("cpu")
    cloth_id = world.add(cloth, vkcloth.SimParams(dt=0.02, damping=0.5))
    x = world.positions(cloth_id)
    lowest = float(x[:, 2].min())
    for _ in range(STEPS // 10):
        world.simulate(10)
        lowest = min(lowest, float(x[:, 2].min()))
    return lowest, float(x[:, 2].min())


def main():
    args = arguments(__doc__.splitlines()[0])
    over_run, at_end = zip(*(lowest_point(k) for k in STIFFNESSES))
    print("K_struct (N/m)   lowest point over the run (m)   at 10 s (m)")
    for k, low, end in zip(STIFFNESSES, over_run, at_end):
        print(f"{k:>14}   {low:>29.3f}   {end:>11.3f}")

    def draw(plt):
        plt.plot(STIFFNESSES, over_run, "o-", label="lowest over the run")
        plt.plot(STIFFNESSES, at_end, "s--", label="at 10 s")
        plt.xlabel("K_struct (N/m)")
        plt.ylabel("lowest point z (m; the pins are at z = 1)")
        plt.title("Figure 7: structural springs alone")
        plt.legend()
        plt.grid(True, alpha=0.3)

    save(args.out, "figure7_stiffness_sweep",
         {"k_struct": STIFFNESSES, "lowest_over_run_m": list(over_run), "lowest_at_end_m": list(at_end)}, draw)


if __name__ == "__main__":
    main()
