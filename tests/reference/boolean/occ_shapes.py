"""OpenCASCADE helpers (cadquery-ocp) shared by the fixture scripts in this directory."""
import math

from OCP.BRep import BRep_Builder
from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon,
                                BRepBuilderAPI_Transform)
from OCP.BRepGProp import BRepGProp
from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.TopoDS import TopoDS_Compound
from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec


def volume(shape):
    """The shape's volume (BRepGProp)."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return props.Mass()


def compound(shapes):
    """The shapes as one compound."""
    c = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(c)
    for s in shapes:
        b.Add(c, s)
    return c


def write_step(shape, path):
    """The shape written as a STEP file at `path`."""
    w = STEPControl_Writer()
    w.Transfer(shape, STEPControl_AsIs)
    assert w.Write(path) == IFSelect_RetDone


def write_cases(case, rng, cases, step_path, jsonl_path):
    """Draws `cases` cases from `case(rng)` (a (shape, row) pair, or None where it is not
    kept; an exception where OpenCASCADE could not build it, printed with SHOW set) and
    writes their shapes to `step_path` as one compound and their rows, numbered, to
    `jsonl_path`."""
    import json
    import os
    import sys
    inputs, rows = [], []
    while len(rows) < cases:
        try:
            made = case(rng)
        except Exception as e:  # OpenCASCADE could not build it
            if os.environ.get("SHOW"):
                print("refused:", e, file=sys.stderr)
            made = None
        if made is None:
            continue
        shape, row = made
        inputs.append(shape)
        rows.append({"case": len(rows), **row})
    write_step(compound(inputs), step_path)
    with open(jsonl_path, "w") as out:
        for row in rows:
            out.write(json.dumps(row) + "\n")


def prism(points, h):
    """The prism over the polygon `points` (xy, counter-clockwise) of height h."""
    poly = BRepBuilderAPI_MakePolygon()
    for x, y in points:
        poly.Add(gp_Pnt(x, y, 0))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire()).Face()
    return BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, h)).Shape()


def placed(shape, rng):
    """The shape turned about a random axis and moved at random, and the motion."""
    axis = [rng.gauss(0, 1) for _ in range(3)]
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(*axis)), rng.uniform(0, 2 * math.pi))
    s = gp_Trsf()
    s.SetTranslation(gp_Vec(*[rng.uniform(-50, 50) for _ in range(3)]))
    motion = s.Multiplied(t)
    return BRepBuilderAPI_Transform(shape, motion, True).Shape(), motion
