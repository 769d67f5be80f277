#!/usr/bin/env python3
"""Reference points for knotwork's surface operations, computed by OpenCASCADE.

Run with the Python bindings of OpenCASCADE (`pip install cadquery-ocp`):

    python3 tests/reference/occ/make_surface_ops.py > tests/reference/occ/surface_ops.json

The test suite (tests/it/surface_ops.rs) reads the JSON this prints; it does not need
OpenCASCADE. Each offset case gives a rational B-spline surface (degrees, full knot vectors,
poles row-major with i along u, weights), a signed distance, and the points of OpenCASCADE's
Geom_OffsetSurface (S + d N, N = Su x Sv / |Su x Sv|) at a grid of parameters.
"""

import json

from OCP.Geom import Geom_BSplineSurface, Geom_OffsetSurface
from OCP.gp import gp_Pnt
from OCP.OCP.collections import Array1_double, Array1_int, Array2_double, Array2_gp_Pnt


def distinct(knots):
    out = []
    for k in knots:
        if out and abs(out[-1][0] - k) < 1e-15:
            out[-1][1] += 1
        else:
            out.append([k, 1])
    ks = Array1_double(1, len(out))
    ms = Array1_int(1, len(out))
    for i, (k, m) in enumerate(out):
        ks.SetValue(i + 1, k)
        ms.SetValue(i + 1, m)
    return ks, ms


def bspline_surface(degrees, knots, count, poles, weights):
    ps = Array2_gp_Pnt(1, count[0], 1, count[1])
    ws = Array2_double(1, count[0], 1, count[1])
    for i in range(count[0]):
        for j in range(count[1]):
            ps.SetValue(i + 1, j + 1, gp_Pnt(*poles[i * count[1] + j]))
            ws.SetValue(i + 1, j + 1, weights[i * count[1] + j])
    uk, um = distinct(knots[0])
    vk, vm = distinct(knots[1])
    surface = Geom_BSplineSurface(ps, ws, uk, vk, um, vm, degrees[0], degrees[1])
    record = {
        "degree": degrees,
        "knots": knots,
        "count": count,
        "points": poles,
        "weights": weights,
    }
    return surface, record


def offset_case(distance):
    count = [5, 6]
    poles = []
    weights = []
    for i in range(count[0]):
        for j in range(count[1]):
            x, y = 1.1 * i, 0.9 * j
            z = 0.5 * ((i * 7 + j * 3) % 5) / 4 - 0.3 * (i == 2 and j == 3)
            poles.append([x, y + 0.15 * i * i / 4, z])
            weights.append(1.0 + 0.3 * ((i + 2 * j) % 3) / 2)
    knots = [
        [0, 0, 0, 0, 0.35, 1, 1, 1, 1],
        [0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1],
    ]
    surface, record = bspline_surface([3, 3], knots, count, poles, weights)
    offset = Geom_OffsetSurface(surface, distance)
    params = []
    points = []
    for a in range(11):
        for b in range(11):
            u, v = a / 10, b / 10
            p = offset.Value(u, v)
            params.append([u, v])
            points.append([p.X(), p.Y(), p.Z()])
    return {"surface": record, "distance": distance, "params": params, "points": points}


def main():
    fixtures = {
        "generator": "OpenCASCADE (cadquery-ocp) via tests/reference/occ/make_surface_ops.py",
        "offsets": [offset_case(0.35), offset_case(-0.2)],
    }
    print(json.dumps(fixtures, indent=1))


if __name__ == "__main__":
    main()
