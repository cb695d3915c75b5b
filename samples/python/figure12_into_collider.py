#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The report's Figure 12: the into-collider test. A flat cloth starts inside a large sphere
(r = 3 m, centre z = 3.4 m); the first projection puts it on the sphere's bottom cap, where gravity
points out of the sphere. Removing only the inward part of v and F (contact_inward_only, the
default) lets it fall; removing the whole normal part cancels gravity too and glues it there."""
from example_support import arguments, import_vkcloth, save  # first: it finds an interpreter with numpy

import numpy as np

vkcloth = import_vkcloth()
CENTRE, RADIUS, STEPS = np.array([0.0, 0.0, 3.4]), 3.0, 20  # 0.4 s


def run(inward_only):
    cloth = vkcloth.make_cloth(nx=10, ny=10, orientation="horizontal", origin=(-0.5, -0.5, 0.5),
                               pin_default_corners=False)
    params = vkcloth.SimParams(dt=0.02, damping=0.5, contact_inward_only=inward_only,
                               colliders=[vkcloth.Collider.sphere(tuple(CENTRE), RADIUS)])
    world = vkcloth.World("cpu")
    cloth_id = world.add(cloth, params)
    world.simulate(STEPS)
    x = world.positions(cloth_id).astype(np.float64)
    gap = np.linalg.norm(x - CENTRE, axis=1) - RADIUS
    return x, float(np.mean(np.abs(gap) <= 2 * params.contact_epsilon)), float(x[:, 2].mean())


def main():
    args = arguments(__doc__.splitlines()[0])
    results = {name: run(flag) for name, flag in (("inward_only", True), ("cancel_all", False))}
    for name, (_, on_surface, mean_z) in results.items():
        print(f"{name:12} points on the sphere after 0.4 s: {100 * on_surface:5.1f} %, mean z {mean_z:+.3f} m")

    def draw(plt):
        angle = np.linspace(-0.35, 0.35, 100) - np.pi / 2
        plt.plot(CENTRE[0] + RADIUS * np.cos(angle), CENTRE[2] + RADIUS * np.sin(angle), "k-", label="sphere (r = 3 m)")
        for name, (x, on_surface, _) in results.items():
            plt.plot(x[:, 0], x[:, 2], "o", ms=3, label=f"{name}: {100 * on_surface:.0f} % on the sphere")
        plt.xlabel("x (m)")
        plt.ylabel("z (m)")
        plt.title("Figure 12: the into-collider test, 0.4 s")
        plt.axis("equal")
        plt.legend()

    save(args.out, "figure12_into_collider",
         {name: {"on_sphere_fraction": on, "mean_z_m": z} for name, (_, on, z) in results.items()}, draw)


if __name__ == "__main__":
    main()
