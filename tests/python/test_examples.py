# SPDX-License-Identifier: MIT
# Each example of samples/python runs, writes its picture (matplotlib is installed by tools/setup.sh)
# and its numbers, and the numbers show the physics it is about.
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

EXAMPLES = ROOT / "samples" / "python"


def run_example(name, out):
    done = subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py"), "--out", str(out)],
                          capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"), timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert (out / f"{name}.png").stat().st_size > 10_000
    return json.loads((out / f"{name}.json").read_text())


def test_spring_convergence_is_first_order(tmp_path):
    r = run_example("spring_convergence", tmp_path)
    for euler in ("explicit_euler", "semi_implicit_euler"):
        assert 0.9 < r["order"][euler] < 1.2
    assert max(r["error_m"]["rk4"]) < 1e-5  # fourth order: at float32's floor already


def test_figure7_lowest_point_rises_with_stiffness(tmp_path):
    r = run_example("figure7_stiffness_sweep", tmp_path)
    low = r["lowest_at_end_m"]
    assert all(a < b for a, b in zip(low, low[1:]))
    assert low[0] == pytest.approx(-7.27, abs=0.01) and low[-1] == pytest.approx(-1.04, abs=0.01)  # docs/model.md


def test_figure12_inward_only_lets_the_cloth_fall(tmp_path):
    r = run_example("figure12_into_collider", tmp_path)
    assert r["inward_only"]["on_sphere_fraction"] == 0.0 and r["inward_only"]["mean_z_m"] == pytest.approx(-0.34, abs=0.01)
    assert r["cancel_all"]["on_sphere_fraction"] == 1.0 and r["cancel_all"]["mean_z_m"] == pytest.approx(0.43, abs=0.01)


def test_material_sweep_orders_the_materials(tmp_path):
    r = run_example("material_sweep", tmp_path)
    peak = {name: max(s) for name, s in r["strain"].items()}
    assert peak["leather"] < peak["cotton"] < peak["rubber"] < 0.15 < peak["report"]


def test_without_matplotlib_the_numbers_are_written(tmp_path):
    script = EXAMPLES / "figure12_into_collider.py"
    code = ("import runpy, sys\n"
            "sys.modules['matplotlib'] = None  # import matplotlib now raises ImportError\n"
            f"sys.path.insert(0, {str(EXAMPLES)!r})\n"
            f"sys.argv = [{str(script)!r}, '--out', {str(tmp_path)!r}]\n"
            f"runpy.run_path({str(script)!r}, run_name='__main__')\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "matplotlib is not installed" in done.stdout
    assert not (tmp_path / "figure12_into_collider.png").exists()
    assert json.loads((tmp_path / "figure12_into_collider.json").read_text())["cancel_all"]["on_sphere_fraction"] == 1.0
