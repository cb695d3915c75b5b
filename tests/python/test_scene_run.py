# SPDX-License-Identifier: MIT
# vkcloth.run and World against the CLI: the same scene on the same backend gives the same bits.
import numpy as np
import pytest

import vkcloth
from conftest import SCENES

# A grid, the report's two chains, a mesh cloth (its outputs in the file's vertex order), a
# collider scene, vbd, several cloths (cloths) and keyframed attachments; 60 steps each keeps the
# run short.
CPU_SCENES = ["cloth_hanging.json", "spring.json", "double_spring.json", "flag_with_hole.json",
              "cloth_on_sphere.json", "cotton_drop_self_collision.json", "layered_drop.json", "twist.json"]
STEPS = 60


@pytest.mark.parametrize("name", CPU_SCENES)
def test_run_matches_cli_bit_for_bit(name, cli_positions):
    scene = vkcloth.load_scene(SCENES / name)
    got = vkcloth.run(scene, steps=STEPS, backend="cpu")
    want = cli_positions(SCENES / name, [f"integrator.steps={STEPS}"])
    assert got.dtype == np.float32 and got.shape == want.shape
    assert np.array_equal(got, want)
    assert not np.array_equal(got, scene.cloth.positions[scene.cloth.file_order].astype(np.float32))  # it moved


def test_world_matches_cli_bit_for_bit(cli_positions):
    # Load, step 200 steps in a World, compare with vkcloth run --positions.
    scene = vkcloth.load_scene(SCENES / "cloth_on_sphere.json")
    world = vkcloth.World("cpu")
    cloth_id = world.add(scene.cloth, scene.params)
    world.simulate(150)
    world.simulate(50)  # in two calls: the steps do not depend on how they are split
    assert world.step_index(cloth_id) == 200
    got = world.positions(cloth_id)[scene.cloth.file_order]
    assert np.array_equal(got, cli_positions(SCENES / "cloth_on_sphere.json", ["integrator.steps=200"]))


def test_overrides_and_dicts_are_the_scene_files(cli_positions):
    scene = vkcloth.load_scene(SCENES / "cloth_hanging.json", ["cloth.stiffness.bend=15"])
    assert scene.params.dt == 0.02
    got = vkcloth.run(scene, steps=40, backend="cpu")
    want = cli_positions(SCENES / "cloth_hanging.json", ["integrator.steps=40", "cloth.stiffness.bend=15"])
    assert np.array_equal(got, want)
    same = vkcloth.load_scene({"system": "chain", "integrator": {"steps": 40}})
    assert vkcloth.run(same).shape == (2, 3)  # the anchor and the mass


def test_vulkan_run_matches_cli_bit_for_bit(vulkan, cli_positions):
    scene = vkcloth.load_scene(SCENES / "cloth_wind.json")
    got = vkcloth.run(scene, steps=STEPS, backend="vulkan")
    assert np.array_equal(got, cli_positions(SCENES / "cloth_wind.json", [f"integrator.steps={STEPS}"], "vulkan"))
    # and the explicit integrators are bit for bit with the CPU on lavapipe
    assert np.array_equal(got, vkcloth.run(scene, steps=STEPS, backend="cpu"))


def test_vulkan_world_reads_back_under_validation(vulkan):
    world = vkcloth.World("vulkan")
    cpu = vkcloth.World("cpu")
    cloth = vkcloth.make_cloth(nx=12, ny=9)
    params = vkcloth.SimParams(dt=0.01, colliders=[vkcloth.Collider.sphere((0.5, 0.3, -0.6), 0.3)])
    ids = [w.add(cloth, params) for w in (world, cpu)]
    for w in (world, cpu):
        w.simulate(80)
    a = world.positions(ids[0])
    b = cpu.positions(ids[1])
    assert a.flags.writeable and not np.shares_memory(a, world.positions(ids[0]))  # a read-back copy each time
    assert np.array_equal(a, b)
    assert np.array_equal(world.velocities(ids[0]), cpu.velocities(ids[1]))
    assert world.backend == "vulkan" and world.validation_messages == 0


def test_auto_backend_says_why():
    world = vkcloth.World("auto")
    assert world.backend in ("cpu", "vulkan") and world.backend_reason


def test_a_scene_of_several_cloths_says_where_each_is():
    scene = vkcloth.load_scene(SCENES / "layered_drop.json")
    ranges = scene.cloths
    assert len(ranges) == 5 and ranges[0][0] == 0 and ranges[-1][1] == scene.cloth.particle_count
    assert all(a[1] == b[0] for a, b in zip(ranges, ranges[1:]))
    assert vkcloth.load_scene(SCENES / "cloth_hanging.json").cloths == []
