"""Random STEP files written by OpenCASCADE (the cadquery-ocp bindings) for the differential
test in tests/it/step_files.rs: each seed draws a shape (primitives, cuts, commons, fuses,
fillets, chamfers, lofts, revolved and extruded splines), puts it in general position (a
random rotation about a random axis, a translation, a scale from 1e-2 to 1e4) and sometimes
converts every surface to a rational B-spline of raised degree (BRepBuilderAPI_NurbsConvert
and GeomConvert), then records what OpenCASCADE measures of the file it wrote: faces, area,
volume (BRepGProp, adaptive to 1e-9, of the file's shape converted to B-splines) and whether
every shell is closed.

Not run by the tests: run it by hand and commit what it writes for the seeds CI keeps
(python3 -m venv v && v/bin/pip install cadquery-ocp-novtk && v/bin/python random_step.py ...).

    random_step.py OUT_DIR FIRST COUNT    seeds FIRST .. FIRST + COUNT - 1: OUT_DIR/seed-N.step
                                          and one line per seed in OUT_DIR/cases.jsonl

A long run: write a few thousand seeds to a scratch folder, then
KNOTWORK_RANDOM_STEP=that-folder cargo test --release --test step_files random -- --nocapture
"""

import json
import math
import os
import random
import sys
import traceback

import make_step

from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeWire,
    BRepBuilderAPI_NurbsConvert,
    BRepBuilderAPI_Transform,
)
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepFilletAPI import BRepFilletAPI_MakeChamfer, BRepFilletAPI_MakeFillet
from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections
from OCP.BRepPrimAPI import (
    BRepPrimAPI_MakeBox,
    BRepPrimAPI_MakeCone,
    BRepPrimAPI_MakeCylinder,
    BRepPrimAPI_MakePrism,
    BRepPrimAPI_MakeRevol,
    BRepPrimAPI_MakeSphere,
    BRepPrimAPI_MakeTorus,
)
from OCP.GC import GC_MakeCircle, GC_MakeEllipse
from OCP.Geom import Geom_BSplineCurve
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Reader, STEPControl_Writer
from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.BRep import BRep_Tool
from OCP.gp import gp_Ax1, gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pnt, gp_Trsf, gp_Vec


def count(shape, kind):
    n = 0
    ex = TopExp_Explorer(shape, kind)
    while ex.More():
        n += 1
        ex.Next()
    return n


def measure(shape):
    """make_step.py's faces, area and volume (adaptive integration to 1e-9) of the shape with
    every surface converted to a B-spline (exactly: BRepBuilderAPI_NurbsConvert), the volume's
    magnitude, whether every shell is closed, and whether BRepCheck finds the shape valid.

    Not of the shape as read: BRepGProp's adaptive integration over a
    Geom_SurfaceOfLinearExtrusion face is wrong by up to a few per cent (seed 11's extrusion of
    a cubic measures 8.6980 where the integral of |C'(u) x d| over its rectangle, its B-spline
    and OpenCASCADE's own mesh all give 8.4702)."""
    m = make_step.measure(BRepBuilderAPI_NurbsConvert(shape, True).Shape())
    shells = count(shape, TopAbs_SHELL)
    closed = 0
    ex = TopExp_Explorer(shape, TopAbs_SHELL)
    while ex.More():
        closed += BRep_Tool.IsClosed_s(ex.Current())
        ex.Next()
    return {
        **m,
        "volume": abs(m["volume"]),
        "closed": shells > 0 and shells == closed,
        "valid": BRepCheck_Analyzer(shape).IsValid(),
    }


def fillet_some(rng, shape, radius, chamfer=False):
    mk = BRepFilletAPI_MakeChamfer(shape) if chamfer else BRepFilletAPI_MakeFillet(shape)
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    added = 0
    while ex.More():
        if rng.random() < 0.5:
            mk.Add(radius, TopoDS.Edge(ex.Current()))
            added += 1
        ex.Next()
    if added == 0:
        return shape
    mk.Build()
    return mk.Shape() if mk.IsDone() else shape


def spline_profile(rng, closed_base=False):
    """A non-rational cubic B-spline in the xz half-plane x > 0 (for revolving or extruding)."""
    n = rng.randint(4, 7)
    pts = Array1_gp_Pnt(1, n)
    for i in range(n):
        pts.SetValue(i + 1, gp_Pnt(rng.uniform(2.0, 6.0), 0.0, 10.0 * i / (n - 1)))
    degree = 3
    inner = n - degree - 1
    knots = Array1_double(1, inner + 2)
    mults = Array1_int(1, inner + 2)
    for k in range(inner + 2):
        knots.SetValue(k + 1, float(k))
        mults.SetValue(k + 1, degree + 1 if k in (0, inner + 1) else 1)
    return Geom_BSplineCurve(pts, knots, mults, degree)


def make_shape(rng):
    kind = rng.choice(
        [
            "box", "cylinder", "sphere", "torus", "cone", "box-fillets", "box-chamfers",
            "box-hole", "torus-cut", "sphere-common", "cylinder-sphere", "fuse", "loft",
            "revolve", "extrude", "partial-revolve",
        ]
    )
    u = rng.uniform
    if kind == "box":
        return kind, BRepPrimAPI_MakeBox(u(1, 5), u(1, 5), u(1, 5)).Shape()
    if kind == "cylinder":
        return kind, BRepPrimAPI_MakeCylinder(u(0.5, 3), u(1, 6)).Shape()
    if kind == "sphere":
        return kind, BRepPrimAPI_MakeSphere(u(0.5, 5)).Shape()
    if kind == "torus":
        major = u(2, 5)
        return kind, BRepPrimAPI_MakeTorus(major, u(0.2, 0.9) * major).Shape()
    if kind == "cone":
        return kind, BRepPrimAPI_MakeCone(u(1, 3), u(0, 0.8), u(1, 5)).Shape()
    if kind in ("box-fillets", "box-chamfers"):
        a, b, c = u(2, 6), u(2, 6), u(2, 6)
        box = BRepPrimAPI_MakeBox(a, b, c).Shape()
        return kind, fillet_some(rng, box, u(0.1, 0.4) * min(a, b, c), kind == "box-chamfers")
    if kind == "box-hole":
        a, b, c = u(3, 6), u(3, 6), u(1, 4)
        box = BRepPrimAPI_MakeBox(a, b, c).Shape()
        r = u(0.2, 0.4) * min(a, b)
        hole = BRepPrimAPI_MakeCylinder(
            gp_Ax2(gp_Pnt(a / 2 + u(-0.1, 0.1), b / 2 + u(-0.1, 0.1), -1), gp_Dir(0, 0, 1)), r, c + 2
        ).Shape()
        return kind, BRepAlgoAPI_Cut(box, hole).Shape()
    if kind == "torus-cut":
        major = u(3, 5)
        minor = u(0.5, 1.5)
        torus = BRepPrimAPI_MakeTorus(major, minor).Shape()
        cyl = BRepPrimAPI_MakeCylinder(
            gp_Ax2(gp_Pnt(0, -10, u(-0.3, 0.3)), gp_Dir(0, 1, 0)), u(0.3, 0.9) * minor, 20
        ).Shape()
        return kind, BRepAlgoAPI_Cut(torus, cyl).Shape()
    if kind == "sphere-common":
        r = u(2, 5)
        sphere = BRepPrimAPI_MakeSphere(r).Shape()
        h = u(0.3, 0.9) * r
        slab = BRepPrimAPI_MakeBox(gp_Pnt(-2 * r, -2 * r, -h), 4 * r, 4 * r, h + u(0.2, 0.9) * r).Shape()
        return kind, BRepAlgoAPI_Common(sphere, slab).Shape()
    if kind == "cylinder-sphere":
        r = u(1, 3)
        cyl = BRepPrimAPI_MakeCylinder(r, 6 * r).Shape()
        ball = BRepPrimAPI_MakeSphere(gp_Pnt(u(-0.5, 0.5) * r, u(-0.5, 0.5) * r, 6 * r), u(1.5, 2.5) * r).Shape()
        return kind, BRepAlgoAPI_Cut(cyl, ball).Shape()
    if kind == "fuse":
        box = BRepPrimAPI_MakeBox(u(2, 5), u(2, 5), u(1, 3)).Shape()
        cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 1, -0.5), gp_Dir(0, 0, 1)), u(0.3, 0.9), u(3, 6)).Shape()
        return kind, BRepAlgoAPI_Fuse(box, cyl).Shape()
    if kind == "loft":
        loft = BRepOffsetAPI_ThruSections(True, False, 1e-6)
        for k in range(rng.randint(2, 4)):
            z = 3.0 * k
            a = u(1.5, 3)
            b = u(0.5, 1) * a
            curve = GC_MakeEllipse(gp_Elips(gp_Ax2(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)), a, b)).Value()
            edge = BRepBuilderAPI_MakeEdge(curve).Edge()
            loft.AddWire(BRepBuilderAPI_MakeWire(edge).Wire())
        loft.Build()
        return kind, loft.Shape()
    if kind in ("revolve", "partial-revolve"):
        profile = spline_profile(rng)
        top = profile.Value(profile.LastParameter())
        bottom = profile.Value(profile.FirstParameter())
        e1 = BRepBuilderAPI_MakeEdge(profile).Edge()
        e2 = BRepBuilderAPI_MakeEdge(top, gp_Pnt(0, 0, top.Z())).Edge()
        e3 = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, top.Z()), gp_Pnt(0, 0, bottom.Z())).Edge()
        e4 = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, bottom.Z()), bottom).Edge()
        wire = BRepBuilderAPI_MakeWire(e1, e2, e3, e4).Wire()
        face = BRepBuilderAPI_MakeFace(wire, True).Face()
        angle = 2 * math.pi if kind == "revolve" else u(0.5, 1.8) * math.pi
        return kind, BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), angle).Shape()
    # extrude: a closed planar profile of a B-spline and the chord between its ends, swept
    # along y. A spline that crosses its chord makes a face whose loop crosses itself, which
    # BRepCheck does not flag: such a seed is skipped.
    profile = spline_profile(rng)
    first = profile.Value(profile.FirstParameter())
    last = profile.Value(profile.LastParameter())
    a, b = profile.FirstParameter(), profile.LastParameter()
    sides = set()
    for k in range(1, 400):
        p = profile.Value(a + (b - a) * k / 400)
        cross = (last.X() - first.X()) * (p.Z() - first.Z()) - (last.Z() - first.Z()) * (p.X() - first.X())
        sides.add(cross > 0)
    if len(sides) > 1:
        raise ValueError("the profile crosses its chord")
    e1 = BRepBuilderAPI_MakeEdge(profile).Edge()
    e2 = BRepBuilderAPI_MakeEdge(last, first).Edge()
    wire = BRepBuilderAPI_MakeWire(e1, e2).Wire()
    face = BRepBuilderAPI_MakeFace(wire, True).Face()
    return kind, BRepPrimAPI_MakePrism(face, gp_Vec(0, u(2, 5), 0)).Shape()


def general_position(rng, shape):
    axis = gp_Dir(rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, 1) + 1e-9)
    rotate = gp_Trsf()
    rotate.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), axis), rng.uniform(0, 2 * math.pi))
    scale = gp_Trsf()
    scale.SetScale(gp_Pnt(0, 0, 0), 10 ** rng.uniform(-2, 4) / 5.0)
    s = scale.ScaleFactor() * 5.0
    move = gp_Trsf()
    move.SetTranslation(gp_Vec(rng.uniform(-s, s), rng.uniform(-s, s), rng.uniform(-s, s)))
    t = move.Multiplied(scale.Multiplied(rotate))
    return BRepBuilderAPI_Transform(shape, t, True).Shape(), s


def case(seed):
    rng = random.Random(seed)
    kind, shape = make_shape(rng)
    shape, size = general_position(rng, shape)
    nurbs = rng.random() < 0.35
    if nurbs:
        shape = BRepBuilderAPI_NurbsConvert(shape, True).Shape()
    return kind, shape, size, nurbs


def write(shape, path):
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    assert w.Write(path) == IFSelect_RetDone


def read(path):
    r = STEPControl_Reader()
    assert r.ReadFile(path) == IFSelect_RetDone
    r.TransferRoots()
    return r.OneShape()


def main():
    out_dir, first, n = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "cases.jsonl"), "a") as cases:
        for seed in range(first, first + n):
            try:
                kind, shape, size, nurbs = case(seed)
                name = f"seed-{seed}.step"
                path = os.path.join(out_dir, name)
                write(shape, path)
                m = measure(read(path))
            except ValueError as e:
                print(f"seed {seed} skipped: {e}", file=sys.stderr)
                continue
            except Exception:
                traceback.print_exc()
                continue
            if not m["valid"] or m["faces"] == 0:
                os.remove(path)
                continue
            line = {"file": name, "seed": seed, "kind": kind, "nurbs": nurbs, "size": size, **m}
            cases.write(json.dumps(line) + "\n")
            cases.flush()
            print(json.dumps(line))


if __name__ == "__main__":
    main()
