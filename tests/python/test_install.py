# SPDX-License-Identifier: MIT
# cmake --install puts the package where this interpreter looks for packages.
import os
import pathlib
import subprocess
import sys

import pytest


def test_the_install_is_importable(tmp_path):
    build, install_dir = os.environ.get("VKCLOTH_BUILD_DIR"), os.environ.get("VKCLOTH_PYTHON_INSTALL_DIR")
    if not build or not install_dir:
        pytest.skip("the build has no install rules (VKCLOTH_INSTALL=OFF)")
    # The default prefix's folder is on the interpreter's path (Debian: /usr/local/lib/python3.X/dist-packages).
    default = pathlib.Path(os.environ["VKCLOTH_INSTALL_PREFIX"]) / install_dir
    assert str(default) in sys.path or pathlib.Path(install_dir).is_absolute() and install_dir in sys.path
    # Installed under another prefix, the package there imports and runs, away from the build tree.
    prefix = tmp_path / "prefix"
    done = subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    site = prefix / install_dir
    code = ("import vkcloth; print(vkcloth.__file__); "
            "print(vkcloth.run(vkcloth.single_spring(steps=10), backend='cpu')[1][2])")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    where, z = done.stdout.split()
    assert pathlib.Path(where).is_relative_to(site) and -1.0 < float(z) < -0.4
