# SPDX-License-Identifier: MIT
# Shared fixtures of the Python tests (run by CTest as python:pytest, PYTHONPATH at the build tree's
# package): the CLI to compare with, the sample scenes, and a validated Vulkan world where there is
# a device (on CI, CI=true, a missing device fails instead of skipping).
import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest

import vkcloth

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "samples" / "scenes"


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("VKCLOTH_CLI")
    if not path:
        pytest.fail("VKCLOTH_CLI is not set: run these tests through ctest (python:pytest)")
    return path


def read_positions_csv(path):
    """The rows of vkcloth run --positions as float32: its 9 significant digits give back each
    float exactly."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in rows], dtype=np.float64).astype(np.float32)


@pytest.fixture
def cli_positions(cli, tmp_path):
    """vkcloth run SCENE --positions ... with `sets` overrides: the final positions as float32."""
    def run(scene, sets=(), backend="cpu"):
        out = tmp_path / "positions.csv"
        args = [cli, "run", str(scene), "--positions", str(out), "--backend", backend]
        for s in sets:
            args += ["--set", s]
        done = subprocess.run(args, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return read_positions_csv(out)
    return run


@pytest.fixture(scope="session")
def vulkan_available():
    """Whether a Vulkan device exists (lavapipe counts); CI=true without one fails."""
    try:
        vkcloth.World("vulkan")
        return True
    except vkcloth.NoDeviceError as e:
        if os.environ.get("CI") == "true":
            pytest.fail(f"CI=true but no Vulkan device: {e}")
        return False


@pytest.fixture
def vulkan(vulkan_available):
    if not vulkan_available:
        pytest.skip("no Vulkan device")
