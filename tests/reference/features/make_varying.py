"""Writes fixtures of fillets whose radius varies along their edges: random right prisms over
convex polygons and L outlines, turned and moved at random, each with one to six edges that
share no vertex filleted from one radius at one end to another at the other, as
OpenCASCADE's BRepFilletAPI_MakeFillet makes them. The radius law is linear along the edge:
OpenCASCADE's own two-radius law (SetRadius(R1, R2, ...)) is an S-shaped cubic, so the law is
given as 401 (relative parameter, radius) pairs on the line, which OpenCASCADE interpolates
(its volume then differs from the linear law's by about 1e-8 of the fillet's). Each case is
one solid of varying.step (in order) and one row of occt-varying.jsonl: points halfway along
the edges (near), each end's radius at its vertex (radii: [x, y, z, r]), and the result's
volume and area (BRepGProp). A case is kept only where OpenCASCADE's result is valid
(BRepCheck_Analyzer).

    /tmp/ocpenv/bin/python tests/reference/features/make_varying.py
"""
import math
import os
import random
import sys

from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.OCP.collections import Array1_gp_Pnt2d
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Pnt2d

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "boolean"))
from occ_shapes import placed, prism, volume, write_cases  # noqa: E402

HERE = os.environ.get("OUT", os.path.dirname(os.path.abspath(__file__)))
CASES = int(os.environ.get("CASES", "24"))
SEED = int(os.environ.get("SEED", "5"))


def area(shape):
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    return props.Mass()


def outline(rng):
    """A convex polygon (random angles on an ellipse) or an L, counter-clockwise."""
    if rng.random() < 0.3:
        a, b = rng.uniform(5, 9), rng.uniform(5, 9)
        w = rng.uniform(2, 0.6 * min(a, b))
        return "ell", [(0, 0), (a, 0), (a, w), (w, w), (w, b), (0, b)]
    n = rng.randint(3, 7)
    angles = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
    rx, ry = rng.uniform(3, 6), rng.uniform(3, 6)
    points = [(rx * math.cos(t), ry * math.sin(t)) for t in angles]
    # Sides no shorter than 1.5 and corners no sharper than 35°, so the fillets fit.
    for i in range(n):
        p, q, r = points[i - 1], points[i], points[(i + 1) % n]
        if math.dist(p, q) < 1.5:
            return None
        u, v = (p[0] - q[0], p[1] - q[1]), (r[0] - q[0], r[1] - q[1])
        cos = (u[0] * v[0] + u[1] * v[1]) / (math.hypot(*u) * math.hypot(*v))
        if math.degrees(math.acos(max(-1, min(1, cos)))) < 35:
            return None
    return "prism", points


def xyz(p):
    return [p.X(), p.Y(), p.Z()]


def case(rng):
    made = outline(rng)
    if made is None:
        return None
    kind, points = made
    shape, _ = placed(prism(points, rng.uniform(3, 8)), rng)
    edges = []
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge(ex.Current())
        if not any(e.IsSame(f) for f in edges):
            edges.append(e)
        ex.Next()
    rng.shuffle(edges)
    count = rng.randint(1, 6)
    picked, used = [], []
    for e in edges:
        ends = [xyz(BRep_Tool.Pnt_s(TopExp.FirstVertex_s(e))),
                xyz(BRep_Tool.Pnt_s(TopExp.LastVertex_s(e)))]
        if any(math.dist(p, q) < 1e-6 for p in ends for q in used):
            continue
        picked.append(e)
        used.extend(ends)
        if len(picked) == count:
            break
    maker = BRepFilletAPI_MakeFillet(shape)
    row = {"kind": kind, "near": [], "radii": []}
    for e in picked:
        maker.Add(1.0, e)
        contour = maker.NbContours()
        r0, r1 = rng.uniform(0.1, 0.7), rng.uniform(0.1, 0.7)
        law = Array1_gp_Pnt2d(1, 401)
        for i in range(401):
            x = i / 400
            law.SetValue(i + 1, gp_Pnt2d(x, r0 + (r1 - r0) * x))
        maker.SetRadius(law, contour, 1)
        first = xyz(BRep_Tool.Pnt_s(maker.FirstVertex(contour)))
        last = xyz(BRep_Tool.Pnt_s(maker.LastVertex(contour)))
        c = BRepAdaptor_Curve(e)
        row["near"].append(xyz(c.Value(0.5 * (c.FirstParameter() + c.LastParameter()))))
        row["radii"].extend([first + [r0], last + [r1]])
    maker.Build()
    if not maker.IsDone():
        return None
    result = maker.Shape()
    if not BRepCheck_Analyzer(result).IsValid():
        return None
    row["volume"] = volume(result)
    row["area"] = area(result)
    return shape, row


write_cases(case, random.Random(SEED), CASES, os.path.join(HERE, "varying.step"),
            os.path.join(HERE, "occt-varying.jsonl"))
