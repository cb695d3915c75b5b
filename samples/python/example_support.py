# SPDX-License-Identifier: MIT
"""What the Python examples share: finding the vkcloth package, their --out folder, and saving
their numbers (JSON) and their picture (PNG, when matplotlib is installed)."""
import argparse
import json
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _run_where_numpy_is():
    """apt's numpy serves Debian's /usr/bin/python3; a pyenv or venv python3 earlier on PATH has
    none, so the example runs again there."""
    try:
        import numpy  # noqa: F401
    except ImportError:
        debian = "/usr/bin/python3"
        if os.access(debian, os.X_OK) and os.path.realpath(sys.executable) != os.path.realpath(debian):
            os.execv(debian, [debian] + sys.argv)
        sys.exit("numpy is not installed (Debian: apt install python3-numpy, or run tools/setup.sh)")


_run_where_numpy_is()


def import_vkcloth():
    """vkcloth as installed, else the one tools/test.sh built (build/release/python)."""
    try:
        import vkcloth
    except ImportError:
        sys.path.insert(0, str(ROOT / "build" / "release" / "python"))
        try:
            import vkcloth
        except ImportError as e:
            sys.exit(f"cannot import vkcloth ({e}): build it with tools/test.sh, or set "
                     "PYTHONPATH=build/release/python")
    return vkcloth


def arguments(description):
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", default="out/python", help="folder for the PNG and the JSON (default out/python)")
    args = parser.parse_args()
    args.out = pathlib.Path(args.out)
    args.out.mkdir(parents=True, exist_ok=True)
    return args


def save(out, name, numbers, draw):
    """Writes NAME.json with `numbers`, and NAME.png with draw(pyplot) when matplotlib is there."""
    (out / f"{name}.json").write_text(json.dumps(numbers, indent=2) + "\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"matplotlib is not installed: the numbers are in {out / (name + '.json')}")
        return
    figure = plt.figure(figsize=(6.4, 4.4), dpi=100)
    draw(plt)
    figure.tight_layout()
    figure.savefig(out / f"{name}.png")
    plt.close(figure)
    print(f"wrote {out / (name + '.png')}")
