# SPDX-License-Identifier: MIT
"""vkcloth: mass-spring cloth on the CPU and on Vulkan compute, from Python.

Build a model, step it, read the state as numpy arrays::

    import vkcloth
    cloth = vkcloth.make_cloth(nx=20, ny=20, material="cotton")
    world = vkcloth.World("cpu")
    cloth_id = world.add(cloth, vkcloth.SimParams(integrator="vbd", dt=1 / 300))
    x = world.positions(cloth_id)     # (n, 3) float32, a view: it follows the steps
    world.simulate(300)
    print(x[:, 2].min())

or run a scene file as ``vkcloth run`` does::

    positions = vkcloth.run(vkcloth.load_scene("samples/scenes/cloth_hanging.json"))

Errors are exceptions carrying vkcloth's message, which names the key or parameter and the value:
ValueError (a bad key or value), OSError (a file), NoDeviceError (no Vulkan device, a
RuntimeError), DivergedError (a blow-up, naming the step; a RuntimeError).
"""

from ._vkcloth import (  # noqa: F401  (the public API)
    Attachment,
    Cloth,
    Collider,
    DivergedError,
    Material,
    NoDeviceError,
    Scene,
    SelfCollision,
    SimParams,
    Stiffness,
    StretchLimit,
    Wind,
    World,
    load_mesh_cloth,
    load_scene,
    make_chain,
    make_cloth,
    material,
    material_names,
    run,
    structural_strain,
)


def single_spring(stiffness=20.0, mass=1.0, rest_length=0.4, damping=0.5, dt=0.02, steps=500,
                  integrator="semi_implicit_euler"):
    """The report's single spring (§2): a mass hanging from a fixed anchor, started at rest length
    0.4 m below it, under gravity and fluid damping, as samples/scenes/spring.json."""
    return load_scene({
        "name": "single_spring",
        "system": "chain",
        "integrator": {"method": integrator, "dt": dt, "steps": steps},
        "physics": {"gravity": [0, 0, -9.81], "damping": damping},
        "chain": {"anchor": [0, 0, 0], "masses": [mass], "stiffness": [stiffness],
                  "rest_lengths": [rest_length], "positions": [[0, 0, -rest_length]]},
    })


def double_spring(stiffness=(20.0, 20.0), masses=(1.0, 1.0), damping=0.5, dt=0.02, steps=1000,
                  integrator="semi_implicit_euler"):
    """The report's two coupled springs (§2.3), started off the vertical as
    samples/scenes/double_spring.json: it swings like a double pendulum."""
    return load_scene({
        "name": "double_spring",
        "system": "chain",
        "integrator": {"method": integrator, "dt": dt, "steps": steps},
        "physics": {"gravity": [0, 0, -9.81], "damping": damping},
        "chain": {"anchor": [0, 0, 0], "masses": list(masses), "stiffness": list(stiffness),
                  "rest_lengths": [0.4, 0.4], "positions": [[0.3, 0, -0.25], [0.65, 0, -0.45]]},
    })
