#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the sample meshes of samples/meshes/ (OBJ, a few kB each), deterministically:

  tablecloth.obj      a round cloth of irregular triangles (jittered rings, zipped together)
  flag_with_hole.obj  a quad flag, 1.2 m x 0.8 m in the x-z plane, with a round hole
  skirt.obj           an open cylinder of quads (a skirt), its top ring at z = 0
  chair.obj           a low-poly chair for a mesh collider: seat, back and four legs, each a closed
                      box (6 boxes, 48 vertices, 72 triangles), standing on z = 0
  torus_knot.obj      a (2, 3) torus knot (a trefoil) for a mesh collider: a closed tube of
                      96 x 10 quads split into 1 920 triangles, about 0.95 m across and 0.44 m
                      thick (z), centred on the origin

Usage: tools/make_meshes.py [OUT_DIR]   (default: samples/meshes next to this script's parent)
       tools/make_meshes.py --tablecloth-rings N FILE.obj   (one tablecloth of 1 + 3 N (N + 1) vertices;
                                                             N = 147 gives the bench's ~65 000)
       tools/make_meshes.py --torus-knot SEGMENTS SIDES FILE.obj
                            (one torus knot as torus_knot.obj, SEGMENTS along the knot and SIDES around
                             the tube: 2 SEGMENTS SIDES triangles, SEGMENTS SIDES vertices;
                             --torus-knot 500 10 gives the bench's 10 000 triangles)
A test (samples:meshes_up_to_date) regenerates them and compares with the committed files.
"""
import math
import os
import sys


def rand01(k):
    """A deterministic hash in [0, 1): the same meshes on every machine and Python version."""
    x = (k * 2654435761 + 12345) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 2246822519) & 0xFFFFFFFF
    x ^= x >> 13
    return x / 2**32


def write_obj(path, comment, positions, uvs, faces):
    """uvs None: faces without texture coordinates (the colliders)."""
    lines = [f"# {comment}", "# written by tools/make_meshes.py"]
    lines += [f"v {x:.4f} {y:.4f} {z:.4f}" for x, y, z in positions]
    if uvs is None:
        lines += ["f " + " ".join(f"{i + 1}" for i in face) for face in faces]
    else:
        lines += [f"vt {u:.4f} {v:.4f}" for u, v in uvs]
        lines += ["f " + " ".join(f"{i + 1}/{i + 1}" for i in face) for face in faces]
    with open(path, "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")


def tablecloth(rings=8, radius=0.5):
    """Ring k (1..rings) holds 6k vertices, each rotated and pushed in or out a little; the rings are
    zipped into triangles by always advancing along the ring whose next vertex comes first in angle."""
    positions, uvs, ring_ids = [(0.0, 0.0, 0.0)], [(0.5, 0.5)], [[0]]
    for k in range(1, rings + 1):
        ids, n = [], 6 * k
        for j in range(n):
            jitter_a = (rand01(1000 * k + j) - 0.5) * 0.45 * (2 * math.pi / n)
            jitter_r = (rand01(7919 * k + j) - 0.5) * 0.35 * (radius / rings) if k < rings else 0.0
            a = 2 * math.pi * j / n + jitter_a + 0.3 * k
            r = radius * k / rings + jitter_r
            ids.append(len(positions))
            positions.append((r * math.cos(a), r * math.sin(a), 0.0))
            uvs.append((0.5 + 0.5 * r * math.cos(a) / radius, 0.5 + 0.5 * r * math.sin(a) / radius))
        ring_ids.append(ids)

    def angle(v):
        x, y, _ = positions[v]
        return math.atan2(y, x) % (2 * math.pi)

    faces = []
    for k in range(1, rings + 1):
        inner, outer = ring_ids[k - 1], ring_ids[k]
        if len(inner) == 1:
            faces += [(inner[0], outer[j], outer[(j + 1) % len(outer)]) for j in range(len(outer))]
            continue
        # Start both rings at their vertex of smallest angle, then merge by angle (counter-clockwise).
        inner = sorted(inner, key=angle)
        outer = sorted(outer, key=angle)
        i = o = 0
        while i < len(inner) or o < len(outer):
            ni = angle(inner[(i + 1) % len(inner)]) + (2 * math.pi if i + 1 >= len(inner) else 0)
            no = angle(outer[(o + 1) % len(outer)]) + (2 * math.pi if o + 1 >= len(outer) else 0)
            if o < len(outer) and (i >= len(inner) or no <= ni):
                faces.append((inner[i % len(inner)], outer[o], outer[(o + 1) % len(outer)]))
                o += 1
            else:
                faces.append((inner[i], outer[o % len(outer)], inner[(i + 1) % len(inner)]))
                i += 1
    return positions, uvs, faces


def flag_with_hole(nx=25, nz=17, width=1.2, height=0.8, hole=(0.75, 0.4, 0.16)):
    """An nx x nz vertex grid of quads in the x-z plane, minus the quads whose centre is in the hole
    (the vertices only those quads used are left out too)."""
    dx, dz = width / (nx - 1), height / (nz - 1)
    cx, cz, r = hole
    quads = []
    for j in range(nz - 1):
        for i in range(nx - 1):
            mx, mz = (i + 0.5) * dx, (j + 0.5) * dz
            if (mx - cx) ** 2 + (mz - cz) ** 2 >= r * r:
                a = j * nx + i
                quads.append((a, a + 1, a + 1 + nx, a + nx))
    used = sorted({v for q in quads for v in q})
    index = {v: k for k, v in enumerate(used)}
    positions = [((v % nx) * dx, 0.0, (v // nx) * dz) for v in used]
    uvs = [((v % nx) / (nx - 1), (v // nx) / (nz - 1)) for v in used]
    return positions, uvs, [tuple(index[v] for v in q) for q in quads]


def skirt(around=32, rows=9, radius=0.25, length=0.4, flare=0.08):
    """An open cylinder (slightly flared towards the hem) of quads; row 0 is the waist at z = 0."""
    positions, uvs, faces = [], [], []
    for j in range(rows):
        r = radius + flare * j / (rows - 1)
        z = -length * j / (rows - 1)
        for i in range(around):
            a = 2 * math.pi * i / around
            positions.append((r * math.cos(a), r * math.sin(a), z))
            uvs.append((i / around, 1.0 - j / (rows - 1)))
    for j in range(rows - 1):
        for i in range(around):
            a, b = j * around + i, j * around + (i + 1) % around
            faces.append((a, a + around, b + around, b))  # counter-clockwise seen from outside
    return positions, uvs, faces

def tidy(p):
    """Rounded to the file's 4 decimals, with no negative zero ("-0.0000" would read as 0 anyway)."""
    return tuple(round(c, 4) + 0.0 for c in p)


def box(lo, hi, base):
    """A closed box [lo, hi]: 8 corners (vertex base + 0..7, bit 0 x, bit 1 y, bit 2 z) and 12
    triangles, counter-clockwise seen from outside."""
    corners = [(hi[0] if k & 1 else lo[0], hi[1] if k & 2 else lo[1], hi[2] if k & 4 else lo[2]) for k in range(8)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(base + a, base + b, base + c), (base + a, base + c, base + d)]
    return corners, tris


def chair(seat=(0.44, 0.42), seat_z=0.45, seat_t=0.04, leg=0.04, back_h=0.45, back_t=0.04):
    """A chair standing on z = 0, its seat centred on the z axis, the back along +y: six closed
    boxes (seat, back, four legs) that meet but do not overlap."""
    sx, sy = seat[0] / 2, seat[1] / 2
    lz = seat_z - seat_t  # the legs end under the seat
    boxes = [((-sx, -sy, lz), (sx, sy, seat_z)),                              # seat
             ((-sx, sy - back_t, seat_z), (sx, sy, seat_z + back_h))]         # back, on the seat's rear edge
    for x0 in (-sx, sx - leg):
        for y0 in (-sy, sy - leg):
            boxes.append(((x0, y0, 0.0), (x0 + leg, y0 + leg, lz)))           # legs, inside the corners
    positions, faces = [], []
    for lo, hi in boxes:
        corners, tris = box(lo, hi, len(positions))
        positions += [tidy(c) for c in corners]
        faces += tris
    return positions, None, faces


def torus_knot(segments=96, sides=10, p=2, q=3, radius=0.3, tube=0.07):
    """A closed tube of radius `tube` around the (p, q) torus knot
    ((2 + cos(q u / p)) cos u, (2 + cos(q u / p)) sin u, sin(q u / p)) radius / 2, u in [0, 2 pi p):
    `segments` rings of `sides` vertices, each ring in the plane across the curve (the frame of
    three.js's TorusKnotGeometry: tangent T, then B = T x (P + P'), N = B x T), quads split in two."""

    def curve(u):
        r = (2 + math.cos(q * u / p)) * radius / 2
        return (r * math.cos(u), r * math.sin(u), math.sin(q * u / p) * radius / 2)

    def norm(v):
        length = math.sqrt(sum(c * c for c in v))
        return tuple(c / length for c in v)

    def cross(a, b):
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    positions, faces = [], []
    for i in range(segments):
        u = 2 * math.pi * p * i / segments
        c0, c1 = curve(u), curve(u + 0.01)
        t = tuple(b - a for a, b in zip(c0, c1))
        b = norm(cross(t, tuple(a + b for a, b in zip(c0, c1))))
        n = norm(cross(b, t))
        for j in range(sides):
            a = 2 * math.pi * j / sides
            ca, sa = tube * math.cos(a), tube * math.sin(a)
            positions.append(tidy(tuple(c0[k] + ca * n[k] + sa * b[k] for k in range(3))))
    for i in range(segments):
        for j in range(sides):
            a, b = i * sides + j, i * sides + (j + 1) % sides
            c, d = ((i + 1) % segments) * sides + (j + 1) % sides, ((i + 1) % segments) * sides + j
            faces += [(a, c, d), (a, b, c)]  # counter-clockwise seen from outside
    return positions, None, faces


def main():
    if len(sys.argv) == 4 and sys.argv[1] == "--tablecloth-rings":
        rings = int(sys.argv[2])
        write_obj(sys.argv[3], f"round tablecloth, {rings} rings, irregular triangles", *tablecloth(rings, 0.5))
        return
    if len(sys.argv) == 5 and sys.argv[1] == "--torus-knot":
        segments, sides = int(sys.argv[2]), int(sys.argv[3])
        if segments < 3 or sides < 3:
            sys.exit("--torus-knot: SEGMENTS and SIDES must be at least 3")
        write_obj(sys.argv[4], f"(2, 3) torus knot, {segments} x {sides}: {2 * segments * sides} triangles",
                  *torus_knot(segments, sides))
        return
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "samples", "meshes")
    os.makedirs(out, exist_ok=True)
    write_obj(os.path.join(out, "tablecloth.obj"), "round tablecloth, radius 0.5 m, irregular triangles",
              *tablecloth())
    write_obj(os.path.join(out, "flag_with_hole.obj"), "flag 1.2 m x 0.8 m (x-z plane) with a round hole, quads",
              *flag_with_hole())
    write_obj(os.path.join(out, "skirt.obj"), "skirt: open cylinder of quads, waist radius 0.25 m at z = 0",
              *skirt())
    write_obj(os.path.join(out, "chair.obj"), "chair: seat, back and four legs, closed boxes, standing on z = 0",
              *chair())
    write_obj(os.path.join(out, "torus_knot.obj"), "(2, 3) torus knot, 96 x 10: 1920 triangles", *torus_knot())


if __name__ == "__main__":
    main()
