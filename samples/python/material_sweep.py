#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Every material preset as a 1 m cloth of 11 x 11 points (the report preset's bend springs allow
no finer grid) hanging from its two top corners, with vertex block descent (dt = 1/120 s, 2 s): its largest structural strain over time. Leather
stretches least and rubber most of the physical ones; the report's own cloth (the "report"
preset, its springs' K = 40 N/m) stretches to several times its length."""
from example_support import arguments, import_vkcloth, save  # first: it finds an interpreter with numpy

import numpy as np

vkcloth = import_vkcloth()
DT, STEPS = 1 / 120, 240


def strain_over_time(name):
    material = vkcloth.material(name)
    cloth = vkcloth.make_cloth(nx=11, ny=11, material=name)
    world = vkcloth.World("cpu")
    cloth_id = world.add(cloth, vkcloth.SimParams(integrator="vbd", dt=DT, damping=material.damping))
    x = world.positions(cloth_id)
    strain = []
    for _ in range(STEPS):
        world.simulate(1)
        strain.append(vkcloth.structural_strain(cloth, x))
    return strain


def main():
    args = arguments(__doc__.splitlines()[0])
    curves = {name: strain_over_time(name) for name in vkcloth.material_names()}
    print("material   largest strain over 2 s   at 2 s")
    for name, s in curves.items():
        print(f"{name:10} {100 * max(s):>22.2f} %   {100 * s[-1]:>5.2f} %")

    def draw(plt):
        t = DT * np.arange(1, STEPS + 1)
        for name, s in curves.items():
            plt.plot(t, 100 * np.array(s), label=name)
        plt.xlabel("time (s)")
        plt.ylabel("largest structural strain (%)")
        plt.title("Material presets: a hanging 1 m cloth, vbd")
        plt.yscale("log")
        plt.legend()
        plt.grid(True, which="both", alpha=0.3)

    save(args.out, "material_sweep", {"dt": DT, "strain": curves}, draw)


if __name__ == "__main__":
    main()
