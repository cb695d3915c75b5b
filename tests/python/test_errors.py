# SPDX-License-Identifier: MIT
# Errors as exceptions carrying vkcloth's messages; none of them may crash the interpreter.
import os
import subprocess
import sys

import pytest

import vkcloth
from conftest import SCENES


def test_a_bad_scene_value_names_the_key():
    with pytest.raises(ValueError, match=r"cloth\.resolution"):
        vkcloth.load_scene({"system": "cloth", "cloth": {"resolution": [0, 3]}})
    with pytest.raises(ValueError, match="bogus"):
        vkcloth.load_scene({"system": "cloth", "bogus": 1})
    with pytest.raises(ValueError, match=r"integrator\.dt"):
        vkcloth.load_scene(SCENES / "cloth_hanging.json", ["integrator.dt=-1"])
    with pytest.raises(OSError, match="no_such_scene"):
        vkcloth.load_scene("no_such_scene.json")
    with pytest.raises(TypeError):
        vkcloth.load_scene(42)


def test_bad_parameters_name_the_field():
    with pytest.raises(TypeError, match="no field 'dtt'"):
        vkcloth.SimParams(dtt=0.01)
    with pytest.raises(ValueError, match="integrator"):
        vkcloth.SimParams(integrator="leapfrog")
    with pytest.raises(ValueError, match="dt"):
        vkcloth.World("cpu").add(vkcloth.make_cloth(), vkcloth.SimParams(dt=-0.01))
    with pytest.raises(ValueError, match="dt"):
        vkcloth.SimParams(dt=float("nan")).validate()
    with pytest.raises(ValueError, match="nx|side|resolution|1\\.\\.8192"):
        vkcloth.make_cloth(nx=0)
    with pytest.raises(ValueError, match="cotton"):
        vkcloth.make_cloth(material="velvet")  # the message lists the presets
    with pytest.raises(ValueError, match="backend"):
        vkcloth.World("metal")
    with pytest.raises(ValueError, match="unknown instance"):
        vkcloth.World("cpu").positions(7)
    world = vkcloth.World("cpu")
    cloth_id = world.add(vkcloth.make_cloth(nx=4, ny=4))
    with pytest.raises(ValueError, match="particle"):
        world.set_pin_targets(cloth_id, [1000], [(0, 0, 0)])
    with pytest.raises(ValueError, match="one each"):
        world.set_pin_targets(cloth_id, [0, 1], [(0, 0, 0)])
    with pytest.raises(ValueError, match="collider"):
        world.set_collider_pose(cloth_id, 3, (0, 0, 0))


def test_a_blow_up_is_a_diverged_error_naming_the_step():
    world = vkcloth.World("cpu")
    stiff = vkcloth.make_cloth(nx=10, ny=10, stiffness={"structural": 5000.0, "shear": 0.0, "bend": 0.0})
    world.add(stiff, vkcloth.SimParams(integrator="explicit_euler", dt=0.02))
    with pytest.raises(vkcloth.DivergedError, match="step") as caught:
        world.simulate(2000)
    assert isinstance(caught.value, RuntimeError)


def test_no_vulkan_device_is_a_runtime_error():
    # A device filter that matches nothing stands for a machine without a device.
    code = ("import vkcloth\n"
            "try:\n    vkcloth.World('vulkan')\nexcept RuntimeError as e:\n"
            "    print(type(e).__name__, e)\n    raise SystemExit(0)\nraise SystemExit(1)\n")
    env = dict(os.environ, VKCLOTH_DEVICE="no-such-device-anywhere", VKCLOTH_VALIDATION="0")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.startswith("NoDeviceError")
    # auto falls back to the CPU solver and says why
    code = "import vkcloth; w = vkcloth.World('auto'); print(w.backend, '|', w.backend_reason)"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.startswith("cpu |"), done.stdout + done.stderr
