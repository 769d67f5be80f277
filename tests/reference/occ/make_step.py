"""STEP fixtures written by OpenCASCADE (the cadquery-ocp bindings), with the areas and volumes
OpenCASCADE computes for them, for tests/it/step_files.rs. Not run by the tests: run it by hand
(python3 -m venv v && v/bin/pip install cadquery-ocp && v/bin/python make_step.py) and commit
the files it writes into tests/reference/occ/step/.

    make_step.py            the test fixtures and step.json
    make_step.py plate N    the bench plate: N x N filleted holes (N = 20: about 1,000 faces),
                            written to step/plate-N.step
    make_step.py blind N    the same with blind holes (N = 20: 1,206 faces), step/blind-N.step
    make_step.py mesh FILE DEFLECTION   reads and meshes FILE with OpenCASCADE, prints seconds
    make_step.py measure FILE           prints OpenCASCADE's faces, area and volume of FILE
    make_step.py roundtrip ORIGINAL WRITTEN   both measured, and their relative differences
"""

import json
import math
import os
import sys
import time

from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Common
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
from OCP.BRepGProp import BRepGProp
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepPrimAPI import (
    BRepPrimAPI_MakeBox,
    BRepPrimAPI_MakeCylinder,
    BRepPrimAPI_MakeSphere,
    BRepPrimAPI_MakeTorus,
)
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Reader, STEPControl_Writer
from OCP.STEPCAFControl import STEPCAFControl_Writer
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.TDocStd import TDocStd_Document
from OCP.TCollection import TCollection_ExtendedString
from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_ColorType
from OCP.Quantity import Quantity_Color, Quantity_TOC_RGB
from OCP.TDataStd import TDataStd_Name
from OCP.TopLoc import TopLoc_Location

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "step")


def measure(shape):
    # Adaptive integration to 1e-9: the default Gauss rule is off by about 1e-3 on rational
    # B-spline faces (OpenCASCADE's own NURBS conversion of sphere-cut measures 1157.48).
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props, 1e-9)
    area = props.Mass()
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-9)
    volume = props.Mass()
    faces = 0
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        faces += 1
        ex.Next()
    return {"faces": faces, "area": area, "volume": volume}


def write(shape, name, unit="MM"):
    Interface_Static.SetCVal_s("write.step.unit", unit)
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    path = os.path.join(HERE, name)
    assert w.Write(path) == IFSelect_RetDone
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    return path


def read(path):
    r = STEPControl_Reader()
    assert r.ReadFile(path) == IFSelect_RetDone
    r.TransferRoots()
    return r.OneShape()


def fillet_edges(shape, radius, keep):
    mk = BRepFilletAPI_MakeFillet(shape)
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge(ex.Current())
        if keep(e):
            mk.Add(radius, e)
        ex.Next()
    return mk.Shape()


def vertical(edge):
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    c = BRepAdaptor_Curve(edge)
    a = c.Value(c.FirstParameter())
    b = c.Value(c.LastParameter())
    return abs(a.X() - b.X()) < 1e-9 and abs(a.Y() - b.Y()) < 1e-9


def box_with_hole():
    box = BRepPrimAPI_MakeBox(40.0, 30.0, 20.0).Shape()
    box = fillet_edges(box, 3.0, vertical)
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(20, 15, -1), gp_Dir(0, 0, 1)), 5.0, 22.0).Shape()
    return BRepAlgoAPI_Cut(box, hole).Shape()


def sphere_cut():
    sphere = BRepPrimAPI_MakeSphere(10.0).Shape()
    slab = BRepPrimAPI_MakeBox(gp_Pnt(-20, -20, -6), 40.0, 40.0, 12.0).Shape()
    return BRepAlgoAPI_Common(sphere, slab).Shape()


def torus_minus_cylinder():
    torus = BRepPrimAPI_MakeTorus(20.0, 5.0).Shape()
    cyl = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, -30, 0), gp_Dir(0, 1, 0)), 3.0, 60.0).Shape()
    return BRepAlgoAPI_Cut(torus, cyl).Shape()


def cylinder_under_sphere():
    """A cylinder (radius 10, z from 0 to 60) with the sphere of radius 25 about (5, 0, 50)
    taken away: the side's edge z(θ) = 50 − √(500 + 100 cos θ) is a curve (not a straight
    line) in the cylinder's (angle, height), and one on the sphere too."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    cyl = BRepPrimAPI_MakeCylinder(10.0, 60.0).Shape()
    ball = BRepPrimAPI_MakeSphere(gp_Pnt(5, 0, 50), 25.0).Shape()
    return BRepAlgoAPI_Cut(cyl, ball).Shape()


def cylinder_under_sphere_analytic():
    import numpy as np
    # The side: ∫ 10 (50 − √(500 + 100 cos θ)) dθ by the trapezoid rule, exact to rounding
    # for a smooth periodic integrand.
    n = 4096
    theta = np.arange(n) * (2 * math.pi / n)
    side = float(np.sum(10 * (50 - np.sqrt(500 + 100 * np.cos(theta)))) * 2 * math.pi / n)
    # The sphere's part over the disc: ∫∫ R / √(R² − (x − 5)² − y²) dA in polar coordinates
    # about the axis (Gauss–Legendre in ρ, the trapezoid rule in φ).
    x, w = np.polynomial.legendre.leggauss(200)
    rho = 5 * (x + 1)
    phi = np.arange(n) * (2 * math.pi / n)
    rr, pp = np.meshgrid(rho, phi)
    integrand = 25 / np.sqrt(625 - (rr * np.cos(pp) - 5) ** 2 - (rr * np.sin(pp)) ** 2) * rr
    cap = float(np.sum(integrand * (5 * w)[None, :]) * 2 * math.pi / n)
    disc = 100 * math.pi
    return {"analytic_area": side + cap + disc, "analytic_side_area": side}


def face_across_seam():
    """One face of a periodic B-spline cylinder (radius 10, height 20) from u = −1 to 1: it
    crosses the surface's seam at u = 0 without going round, and its edges along the circle
    are arcs of a periodic B-spline circle between vertices on either side of that curve's
    seam."""
    from OCP.Geom import Geom_CylindricalSurface, Geom_RectangularTrimmedSurface
    from OCP.GeomConvert import GeomConvert
    from OCP.gp import gp_Ax3
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    cylinder = Geom_CylindricalSurface(gp_Ax3(), 10.0)
    trimmed = Geom_RectangularTrimmedSurface(cylinder, 0.0, 2 * math.pi, 0.0, 20.0)
    surface = GeomConvert.SurfaceToBSplineSurface_s(trimmed)
    if not surface.IsUPeriodic():
        surface.SetUPeriodic()
    return BRepBuilderAPI_MakeFace(surface, -1.0, 1.0, 0.0, 20.0, 1e-7).Face()


def plate(n, blind=False):
    """A 10 mm pitch plate, 5 mm thick, with n x n holes of radius 2.5 whose top rims are
    filleted (radius 0.8); blind ones stop 3 mm down (a floor each: planes, cylinders, tori)."""
    pitch = 10.0
    size = n * pitch
    shape = BRepPrimAPI_MakeBox(size, size, 5.0).Shape()
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound
    builder = BRep_Builder()
    tools = TopoDS_Compound()
    builder.MakeCompound(tools)
    for i in range(n):
        for j in range(n):
            bottom, height = (2.0, 4.0) if blind else (-1.0, 7.0)
            c = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(pitch * (i + 0.5), pitch * (j + 0.5), bottom), gp_Dir(0, 0, 1)), 2.5, height).Shape()
            builder.Add(tools, c)
    shape = BRepAlgoAPI_Cut(shape, tools).Shape()
    # Fillet the holes' top rims.
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_Circle

    def top_rim(e):
        c = BRepAdaptor_Curve(e)
        return c.GetType() == GeomAbs_Circle and abs(c.Value(c.FirstParameter()).Z() - 5.0) < 1e-9

    return fillet_edges(shape, 0.8, top_rim)


def assembly():
    """Two boxes placed by the assembly, named and coloured (the test converts its unit to inches)."""
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    colours = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    part = BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape()
    part_label = shapes.AddShape(part, False)
    TDataStd_Name.Set_s(part_label, TCollection_ExtendedString("brick"))
    colours.SetColor(part_label, Quantity_Color(0.8, 0.2, 0.1, Quantity_TOC_RGB), XCAFDoc_ColorType.XCAFDoc_ColorSurf)
    top = shapes.NewShape()
    TDataStd_Name.Set_s(top, TCollection_ExtendedString("pair"))
    for dx in (0.0, 5.0):
        t = gp_Trsf()
        t.SetTranslation(gp_Vec(dx, 1.0, 0.0))
        shapes.AddComponent(top, part_label, TopLoc_Location(t))
    shapes.UpdateAssemblies()
    Interface_Static.SetCVal_s("write.step.unit", "IN")
    w = STEPCAFControl_Writer()
    w.SetColorMode(True)
    w.SetNameMode(True)
    w.Transfer(doc, STEPControl_AsIs)
    path = os.path.join(HERE, "assembly.step")
    assert w.Write(path) == IFSelect_RetDone
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    return path


def main():
    os.makedirs(HERE, exist_ok=True)
    if len(sys.argv) > 1 and sys.argv[1] in ("plate", "blind"):
        n = int(sys.argv[2])
        blind = sys.argv[1] == "blind"
        s = plate(n, blind)
        path = write(s, f"{'blind' if blind else 'plate'}-{n}.step")
        print(path, measure(read(path)))
        return
    if len(sys.argv) > 1 and sys.argv[1] == "mesh":
        t0 = time.perf_counter()
        s = read(sys.argv[2])
        t1 = time.perf_counter()
        BRepMesh_IncrementalMesh(s, float(sys.argv[3]), False, 0.5, False)
        t2 = time.perf_counter()
        print(json.dumps({"read_s": t1 - t0, "mesh_s": t2 - t1, "total_s": t2 - t0}))
        return
    if len(sys.argv) > 1 and sys.argv[1] == "measure":
        print(json.dumps(measure(read(sys.argv[2]))))
        return
    if len(sys.argv) > 1 and sys.argv[1] == "roundtrip":
        a = measure(read(sys.argv[2]))
        b = measure(read(sys.argv[3]))
        rel = {k: abs(a[k] - b[k]) / abs(a[k]) for k in ("area", "volume")}
        print(json.dumps({"original": a, "written": b, "relative": rel, "same_faces": a["faces"] == b["faces"]}))
        return
    added = {
        "under-sphere": ("cylinder-under-sphere.step", cylinder_under_sphere, cylinder_under_sphere_analytic),
        "across-seam": ("face-across-seam.step", face_across_seam, dict),
    }
    if len(sys.argv) > 1 and sys.argv[1] in added:
        # Adds this one fixture (and its entry in step.json) without remaking the others.
        name, make, analytic = added[sys.argv[1]]
        path = write(make(), name)
        json_path = os.path.join(HERE, "step.json")
        with open(json_path) as f:
            out = json.load(f)
        out[name] = {**measure(read(path)), **analytic()}
        with open(json_path, "w") as f:
            json.dump(out, f, indent=1, sort_keys=True)
        print(json.dumps(out[name], indent=1))
        return
    out = {}
    cases = {
        "box-hole-fillets.step": (box_with_hole(), None),
        "sphere-cut.step": (sphere_cut(), None),
        "torus-minus-cylinder.step": (torus_minus_cylinder(), None),
        "plate-3.step": (plate(3), None),
        "cylinder-under-sphere.step": (cylinder_under_sphere(), None),
        "face-across-seam.step": (face_across_seam(), None),
    }
    for name, (shape, _) in cases.items():
        path = write(shape, name)
        out[name] = measure(read(path))
    path = assembly()
    out["assembly.step"] = measure(read(path))
    # Analytic values.
    r = 10.0
    h = 6.0
    # Sphere between z = -6 and 6: the zone's area 2πr·2h plus two discs of radius 8.
    out["sphere-cut.step"]["analytic_area"] = 2 * math.pi * r * 2 * h + 2 * math.pi * (r * r - h * h)
    out["sphere-cut.step"]["analytic_volume"] = math.pi * (2 * h * r * r - 2 * h ** 3 / 3)
    out["cylinder-under-sphere.step"].update(cylinder_under_sphere_analytic())
    # Two 1 x 2 x 3 mm bricks.
    out["assembly.step"]["analytic_volume_mm3"] = 2 * 6.0
    with open(os.path.join(HERE, "step.json"), "w") as f:
        json.dump(out, f, indent=1, sort_keys=True)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
