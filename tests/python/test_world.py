# SPDX-License-Identifier: MIT
# World on the CPU: zero-copy views that follow the steps and keep the world alive, hosts' targets
# and colliders, the report's single spring against its closed form.
import gc
import math

import numpy as np
import pytest

import vkcloth


def test_positions_are_a_view_that_follows_the_steps():
    world = vkcloth.World("cpu")
    cloth_id = world.add(vkcloth.make_cloth(nx=16, ny=16), vkcloth.SimParams(dt=0.01))
    x = world.positions(cloth_id)
    v = world.velocities(cloth_id)
    start = x.copy()
    for steps in (1, 2, 7):  # odd and even step counts: the solver keeps its positions in place
        world.simulate(steps)
        fresh = world.positions(cloth_id)
        assert np.shares_memory(x, fresh) and np.array_equal(x, fresh)
    assert not np.array_equal(x, start)
    assert np.abs(v).max() > 0 and np.shares_memory(v, world.velocities(cloth_id))
    with pytest.raises(ValueError):
        x[0, 0] = 1.0  # read-only: the solver owns it


def test_a_view_keeps_the_world_alive():
    world = vkcloth.World("cpu")
    cloth_id = world.add(vkcloth.make_cloth(nx=8, ny=8))
    world.simulate(10)
    x = world.positions(cloth_id)
    copy = x.copy()
    del world
    gc.collect()
    assert np.array_equal(x, copy)  # the memory is still the solver's


def test_remove_refuses_while_a_view_lives():
    world = vkcloth.World("cpu")
    a = world.add(vkcloth.make_cloth(nx=6, ny=6))
    b = world.add(vkcloth.make_cloth(nx=5, ny=5))
    x = world.positions(a)
    with pytest.raises(ValueError, match="view"):
        world.remove(a)
    del x
    world.remove(a)
    assert world.instances == [b] and len(world) == 1
    with pytest.raises(ValueError):
        world.positions(a)


def test_pin_targets_and_collider_poses_move_the_cloth():
    world = vkcloth.World("cpu")
    cloth = vkcloth.make_cloth(nx=10, ny=10)
    params = vkcloth.SimParams(colliders=[vkcloth.Collider.sphere((0.5, 0.2, -0.5), 0.2)])
    cloth_id = world.add(cloth, params)
    pinned = cloth.pinned
    targets = cloth.positions[pinned] + [0.0, 0.0, 0.25]
    world.set_pin_targets(cloth_id, pinned, targets)
    world.set_collider_pose(cloth_id, 0, (0.5, 0.5, -0.7))
    world.simulate(1)
    np.testing.assert_allclose(world.positions(cloth_id)[pinned], targets, atol=1e-6)
    assert world.params(cloth_id).colliders[0].center == pytest.approx((0.5, 0.5, -0.7))


def test_single_spring_follows_its_closed_form():
    # m x'' = -K x - mu m x' about the equilibrium mg/K below rest length (docs/model.md "Single spring").
    dt, steps = 0.001, 3000
    scene = vkcloth.single_spring(dt=dt, steps=steps)
    world = vkcloth.World("cpu")
    spring = world.add(scene.cloth, scene.params)
    x = world.positions(spring)
    K, m, mu, g, L0 = 20.0, 1.0, 0.5, 9.81, 0.4
    wd = math.sqrt(K / m - mu * mu / 4)
    x0 = m * g / K  # starts at rest length: mg/K above the equilibrium
    worst = 0.0
    for k in range(1, steps + 1):
        world.simulate(1)
        t = k * dt
        exact = -(L0 + x0) + x0 * math.exp(-mu * t / 2) * (math.cos(wd * t) + mu / (2 * wd) * math.sin(wd * t))
        worst = max(worst, abs(float(x[1, 2]) - exact))
    assert worst < 5e-3  # first order in dt: 0.0015 m here at dt = 1 ms over 3 s


def test_double_spring_loses_energy():
    scene = vkcloth.double_spring(steps=300)
    world = vkcloth.World("cpu")
    chain = world.add(scene.cloth, scene.params)
    masses = scene.cloth.masses

    def energy():
        x = world.positions(chain).astype(np.float64)
        v = world.velocities(chain).astype(np.float64)
        e = 0.5 * (masses[1:] * (v[1:] ** 2).sum(axis=1)).sum() + 9.81 * (masses[1:] * x[1:, 2]).sum()
        lengths = np.linalg.norm(np.diff(x, axis=0), axis=1)
        return e + 0.5 * (20.0 * (lengths - 0.4) ** 2).sum()

    e0 = energy()
    world.simulate(300)
    assert energy() < e0 - 1.0  # damping mu = 0.5 takes energy out


def test_materials_and_strain():
    assert "cotton" in vkcloth.material_names()
    cotton = vkcloth.material("cotton")
    cloth = vkcloth.make_cloth(nx=12, ny=12, material="cotton", orientation="horizontal")
    heavier = vkcloth.make_cloth(nx=12, ny=12, material=vkcloth.Material(
        density=2 * cotton.density, stretch=cotton.stretch, shear=cotton.shear, bend=cotton.bend,
        damping=cotton.damping))
    assert heavier.masses.sum() == pytest.approx(2 * cloth.masses.sum())
    assert vkcloth.structural_strain(cloth, cloth.positions) == pytest.approx(0.0, abs=1e-12)
    stretched = cloth.positions * [1.1, 1.0, 1.0]
    assert vkcloth.structural_strain(cloth, stretched) == pytest.approx(0.1, rel=1e-9)


def test_a_second_thread_gets_an_error_not_a_race():
    import threading
    import time
    world = vkcloth.World("cpu", threads=1)
    cloth_id = world.add(vkcloth.make_cloth(nx=64, ny=64))
    errors = []
    started = threading.Event()

    def step():
        started.set()
        world.simulate(1500)  # ~0.5 s: long enough to be caught in the act on a loaded machine

    t = threading.Thread(target=step)
    t.start()
    started.wait()
    while t.is_alive():  # while the other thread simulates (it releases the GIL), calls are refused
        try:
            world.step_index(cloth_id)
        except RuntimeError as e:
            errors.append(str(e))
            break
        time.sleep(0.0005)
    t.join()
    assert errors and "busy" in errors[0]
    assert world.step_index(cloth_id) == 1500


def test_hostile_values_raise():
    for bad in (dict(nx=-1), dict(nx=2 ** 40), dict(nx=8193), dict(size=(1.0,)), dict(pins=[(99, 0)])):
        with pytest.raises((TypeError, ValueError)):
            vkcloth.make_cloth(**bad)
    world = vkcloth.World("cpu")
    cloth_id = world.add(vkcloth.make_chain())
    with pytest.raises(TypeError):
        world.simulate(-1)
    with pytest.raises(TypeError):
        vkcloth.SimParams(substeps=2 ** 40)
    with pytest.raises(ValueError):
        world.add(vkcloth.make_chain(), positions=[(0, 0, 0)])  # one position for two particles
    with pytest.raises(ValueError, match="substeps"):
        world.set_params(cloth_id, vkcloth.SimParams(substeps=0))
