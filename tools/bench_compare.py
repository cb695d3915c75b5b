#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Compares two vkcloth builds with `vkcloth bench`, alternated in one session (A, B, A, B, ...),
so that a noisy machine slows both alike. Prints, per configuration (backend, variant, size,
instances), each build's median particle-steps/s over the rounds and the ratio B / A, and
writes them as JSON.

Usage: tools/bench_compare.py BEFORE_BIN AFTER_BIN [--rounds N] [--json OUT] -- [bench args...]
e.g.   tools/bench_compare.py /tmp/vkcloth_before build/release/tools/vkcloth/vkcloth --rounds 3 \
           --json out/compare.json -- --backend all --sizes 64,256,512
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def run_bench(binary, bench_args):
    with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as tmp:
        path = tmp.name
    try:
        proc = subprocess.run([binary, "bench", *bench_args, "--json", path], stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True)
        if proc.returncode != 0:
            sys.exit(f"bench_compare: {binary} bench exited {proc.returncode}: {proc.stderr.strip()}")
        with open(path) as f:
            return json.load(f)
    finally:
        os.unlink(path)


def key(row):
    return (row["backend"], row["variant"], row["size"], row.get("instances", 1))


def main():
    argv = sys.argv[1:]
    bench_args = []
    if "--" in argv:
        cut = argv.index("--")
        argv, bench_args = argv[:cut], argv[cut + 1:]
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        sys.exit("bench_compare: --rounds must be at least 1")
    for b in (args.before, args.after):
        if not os.access(b, os.X_OK):
            sys.exit(f"bench_compare: {b} is not an executable")

    samples = {"before": {}, "after": {}}
    device = None
    for r in range(args.rounds):
        for label, binary in (("before", args.before), ("after", args.after)):
            result = run_bench(binary, bench_args)
            device = device or result.get("vulkan_device")
            for row in result["results"]:
                samples[label].setdefault(key(row), []).append(row["particle_steps_per_s"])
            print(f"round {r + 1}/{args.rounds}: {label} done", file=sys.stderr)

    rows = []
    for k in sorted(samples["before"].keys() & samples["after"].keys(), key=str):
        a = statistics.median(samples["before"][k])
        b = statistics.median(samples["after"][k])
        rows.append({"backend": k[0], "variant": k[1], "size": k[2], "instances": k[3],
                     "before_particle_steps_per_s": a, "after_particle_steps_per_s": b,
                     "ratio_after_over_before": b / a if a > 0 else None,
                     "before_samples": samples["before"][k], "after_samples": samples["after"][k]})
    print(f"CPU: {cpu_name()}; Vulkan device: {device}; {args.rounds} alternated rounds, medians")
    print(f"{'backend':8} {'variant':9} {'n':>5} {'inst':>4} {'before M/s':>11} {'after M/s':>10} {'after/before':>12}")
    for row in rows:
        print(f"{row['backend']:8} {row['variant']:9} {row['size']:5d} {row['instances']:4d} "
              f"{row['before_particle_steps_per_s'] / 1e6:11.1f} {row['after_particle_steps_per_s'] / 1e6:10.1f} "
              f"{row['ratio_after_over_before']:12.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"schema": "vkcloth-bench-compare/1", "cpu": cpu_name(), "vulkan_device": device,
                       "rounds": args.rounds, "bench_args": bench_args, "before": args.before,
                       "after": args.after, "rows": rows}, f, indent=2)


if __name__ == "__main__":
    main()
