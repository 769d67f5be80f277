#!/usr/bin/env python3
"""Reference points for knotwork's modelling constructions, computed by OpenCASCADE.

Run with the Python bindings of OpenCASCADE (`pip install cadquery-ocp`):

    python3 tests/reference/occ/make_fixtures.py > tests/reference/occ/modelling.json

The test suite (tests/it/occ_reference.rs) reads the JSON this prints; it does not need
OpenCASCADE. Each case gives the inputs (curves as degree, knots, poles and weights, the same
curve knotwork builds) and what OpenCASCADE made of them: points on its surface or curve, or a
measure (an area).
"""

import json
import math

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepGProp import BRepGProp
from OCP.GC import GC_MakeArcOfCircle
from OCP.Geom import Geom_BSplineCurve, Geom_Ellipse, Geom_OffsetCurve, Geom_SurfaceOfRevolution
from OCP.GProp import GProp_GProps
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Elips, gp_Pnt, gp_Vec
from OCP.OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int


def bspline(degree, knots, poles, weights=None):
    """An OpenCASCADE B-spline from a full (clamped) knot vector, and the same as JSON."""
    distinct = []
    for k in knots:
        if distinct and abs(distinct[-1][0] - k) < 1e-15:
            distinct[-1][1] += 1
        else:
            distinct.append([k, 1])
    ks = Array1_double(1, len(distinct))
    ms = Array1_int(1, len(distinct))
    for i, (k, m) in enumerate(distinct):
        ks.SetValue(i + 1, k)
        ms.SetValue(i + 1, m)
    ps = Array1_gp_Pnt(1, len(poles))
    for i, p in enumerate(poles):
        ps.SetValue(i + 1, gp_Pnt(*p))
    if weights is None:
        curve = Geom_BSplineCurve(ps, ks, ms, degree)
    else:
        ws = Array1_double(1, len(weights))
        for i, w in enumerate(weights):
            ws.SetValue(i + 1, w)
        curve = Geom_BSplineCurve(ps, ws, ks, ms, degree)
    record = {"degree": degree, "knots": knots, "points": poles}
    if weights is not None:
        record["weights"] = weights
    return curve, record


def xyz(p):
    return [p.X(), p.Y(), p.Z()]


def curve_points(curve, count):
    a, b = curve.FirstParameter(), curve.LastParameter()
    return [xyz(curve.Value(a + (b - a) * i / count)) for i in range(count + 1)]


def revolve_case():
    profile, record = bspline(
        3,
        [0, 0, 0, 0, 0.4, 1, 1, 1, 1],
        [[1, 0, 0], [1.6, 0.2, 0.5], [0.8, -0.3, 1.2], [1.4, 0.1, 1.8], [1.0, 0.0, 2.5]],
        [1.0, 0.7, 1.4, 0.9, 1.0],
    )
    origin, direction, angle = [0.5, -0.5, 0.0], [0.2, 0.1, 1.0], 270.0
    surface = Geom_SurfaceOfRevolution(profile, gp_Ax1(gp_Pnt(*origin), gp_Dir(*direction)))
    points = []
    for i in range(9):
        u = math.radians(angle) * i / 8
        for j in range(9):
            points.append(xyz(surface.Value(u, j / 8)))
    return {
        "profile": record,
        "origin": origin,
        "direction": direction,
        "angle": angle,
        "points": points,
    }


def arc_case():
    a, b, c = [2, 0, 1], [0, 1, 1.5], [-1, -1, 0]
    arc = GC_MakeArcOfCircle(gp_Pnt(*a), gp_Pnt(*b), gp_Pnt(*c)).Value()
    return {"through": [a, b, c], "points": curve_points(arc, 40)}


def ellipse_case():
    center, normal, x_axis, radii = [1, 2, -1], [0, 0, 1], [1, 1, 0], [3.0, 1.25]
    frame = gp_Ax2(gp_Pnt(*center), gp_Dir(*normal), gp_Dir(*x_axis))
    ellipse = Geom_Ellipse(gp_Elips(frame, radii[0], radii[1]))
    return {
        "center": center,
        "normal": normal,
        "x_axis": x_axis,
        "radii": radii,
        "points": curve_points(ellipse, 60),
    }


def offset_case():
    curve, record = bspline(
        3,
        [0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1],
        [[0, 0, 0], [1, 1.5, 0], [2.5, 1.2, 0], [3.5, -0.5, 0], [5, 0.2, 0], [6, 1, 0]],
    )
    distance, normal = 0.4, [0, 0, 1]
    # Geom_OffsetCurve moves along T ^ V: to the right of the direction of travel seen from V.
    offset = Geom_OffsetCurve(curve, distance, gp_Dir(*normal))
    return {
        "curve": record,
        "distance": distance,
        "normal": normal,
        "points": curve_points(offset, 80),
    }


def planar_case():
    # A stadium in the plane z = x / 2: two lines and two half circles.
    tilt = lambda p: [p[0], p[1], p[0] / 2]
    lines = [([0, 0, 0], [2, 0, 0]), ([2, 2, 0], [0, 2, 0])]
    wire = BRepBuilderAPI_MakeWire()
    edges = []
    for k, (a, b) in enumerate(lines):
        a, b = tilt(a), tilt(b)
        wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(*a), gp_Pnt(*b)).Edge())
        edges.append({"line": [a, b]})
        centre = [2, 1, 0] if k == 0 else [0, 1, 0]
        through = [3, 1, 0] if k == 0 else [-1, 1, 0]
        end = [2, 2, 0] if k == 0 else [0, 0, 0]
        arc = GC_MakeArcOfCircle(gp_Pnt(*b), gp_Pnt(*tilt(through)), gp_Pnt(*tilt(end))).Value()
        wire.Add(BRepBuilderAPI_MakeEdge(arc).Edge())
        edges.append({"arc": [b, tilt(through), tilt(end)]})
        del centre
    face = BRepBuilderAPI_MakeFace(wire.Wire(), True).Face()
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return {"edges": edges, "area": props.Mass()}


def main():
    fixtures = {
        "generator": "OpenCASCADE (cadquery-ocp) via tests/reference/occ/make_fixtures.py",
        "revolve": revolve_case(),
        "arc": arc_case(),
        "ellipse": ellipse_case(),
        "offset": offset_case(),
        "planar": planar_case(),
    }
    print(json.dumps(fixtures, indent=1))


if __name__ == "__main__":
    main()
