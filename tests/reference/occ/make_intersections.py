#!/usr/bin/env python3
"""Random surface pairs intersected by OpenCASCADE (GeomAPI_IntSS), for knotwork's
differential intersection test (tests/it/intersect.rs).

Run with the Python bindings of OpenCASCADE (`pip install cadquery-ocp`):

    python3 tests/reference/occ/make_intersections.py FIRST COUNT > OUT.jsonl

Each line is one seed: two surfaces in general position (a rational or polynomial bicubic
sheet with random knots and wavy heights, and either a tilted plane through it or another
such sheet crossing it; both rotated, moved and scaled by 1e-2 to 1e4 together), and
OpenCASCADE's intersection as points sampled along each of its lines. A seed whose
intersection OpenCASCADE cannot compute is skipped. The test suite reads the committed file
(tests/reference/occ/intersections.jsonl: seeds 0 to 11, then the seeds of a long run that
failed once and were fixed, kept as regressions: 1009, 1041, 1078, 1119, 1150, 1992, 4206);
a longer run sets KNOTWORK_RANDOM_INTERSECT to a file this script wrote.
"""

import json
import math
import random
import sys

from OCP.GeomAPI import GeomAPI_IntSS

from make_surface_ops import bspline_surface

SAMPLES = 400


def rotation(rng):
    """A random rotation matrix (a normalised random quaternion)."""
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(c * c for c in q))
    w, x, y, z = (c / n for c in q)
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]


def knots(rng, degree, count):
    """A clamped knot vector on [0, 1] with random interior knots (none closer than 0.05)."""
    inner = count - degree - 1
    while True:
        ks = sorted(rng.uniform(0.08, 0.92) for _ in range(inner))
        if all(b - a > 0.05 for a, b in zip([0.0] + ks, ks + [1.0])):
            break
    return [0.0] * (degree + 1) + ks + [1.0] * (degree + 1)


def sheet(rng, rational, lift):
    """A wavy bicubic sheet over [0, 1]² (heights up to 0.25, plus `lift`(x, y))."""
    degree = [3, 3]
    count = [rng.randint(4, 7), rng.randint(4, 7)]
    phase = [rng.uniform(0, 6.3) for _ in range(3)]
    poles, weights = [], []
    for i in range(count[0]):
        for j in range(count[1]):
            x, y = i / (count[0] - 1), j / (count[1] - 1)
            x += rng.uniform(-0.03, 0.03) if 0 < i < count[0] - 1 else 0.0
            y += rng.uniform(-0.03, 0.03) if 0 < j < count[1] - 1 else 0.0
            z = 0.12 * math.sin(5 * x + phase[0]) * math.cos(4 * y + phase[1])
            z += 0.08 * math.sin(7 * (x + y) + phase[2]) + lift(x, y)
            poles.append([x, y, z])
            weights.append(rng.uniform(0.6, 1.8) if rational else 1.0)
    return degree, [knots(rng, 3, count[0]), knots(rng, 3, count[1])], count, poles, weights


def plane(rng):
    """A tilted plane through the middle of the unit sheet, a bilinear patch past its edges."""
    a, b = rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3)
    poles = []
    for x in (-0.2, 1.2):
        for y in (-0.2, 1.2):
            poles.append([x, y, a * (x - 0.5) + b * (y - 0.5)])
    return [1, 1], [[0, 0, 1, 1], [0, 0, 1, 1]], [2, 2], poles, [1.0] * 4


def crossing_sheet(rng, rational):
    """A sheet standing across the unit sheet: its (x, y, z) turned to (x, z + 0.5, y - 0.5)."""
    degree, ks, count, poles, weights = sheet(rng, rational, lambda x, y: 0.0)
    turned = [[1.3 * p[0] - 0.15, p[2] + 0.5 + 0.2 * (p[0] - 0.5), 1.2 * p[1] - 0.6] for p in poles]
    return degree, ks, count, turned, weights


def placed(record, matrix, scale, move):
    degree, ks, count, poles, weights = record
    out = []
    for p in poles:
        q = [sum(matrix[r][c] * p[c] for c in range(3)) for r in range(3)]
        out.append([scale * q[r] + move[r] for r in range(3)])
    return degree, ks, count, out, weights


def case(seed):
    rng = random.Random(seed)
    rational = rng.random() < 0.5
    a = sheet(rng, rational, lambda x, y: 0.0)
    b = plane(rng) if rng.random() < 0.5 else crossing_sheet(rng, rng.random() < 0.5)
    matrix = rotation(rng)
    scale = 10 ** rng.uniform(-2, 4)
    move = [scale * rng.uniform(-3, 3) for _ in range(3)]
    a, b = placed(a, matrix, scale, move), placed(b, matrix, scale, move)
    sa, ra = bspline_surface(*a)
    sb, rb = bspline_surface(*b)
    tolerance = 1e-7 * scale
    intersection = GeomAPI_IntSS(sa, sb, tolerance)
    if not intersection.IsDone():
        return None
    curves = []
    for k in range(1, intersection.NbLines() + 1):
        line = intersection.Line(k)
        t0, t1 = line.FirstParameter(), line.LastParameter()
        points = []
        for i in range(SAMPLES + 1):
            p = line.Value(t0 + (t1 - t0) * i / SAMPLES)
            # Ten significant digits: far below the tolerances compared.
            points.append([float("%.10g" % c) for c in (p.X(), p.Y(), p.Z())])
        curves.append(points)
    if not curves:
        return None
    return {
        "seed": seed,
        "kind": "plane" if b[2] == [2, 2] else "sheet",
        "rational": rational,
        "scale": scale,
        "a": ra,
        "b": rb,
        "curves": curves,
    }


def main():
    first, count = int(sys.argv[1]), int(sys.argv[2])
    for seed in range(first, first + count):
        record = case(seed)
        if record is not None:
            print(json.dumps(record))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
