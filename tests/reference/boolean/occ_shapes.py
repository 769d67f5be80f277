"""OpenCASCADE helpers (cadquery-ocp) shared by the fixture scripts in this directory."""
from OCP.BRep import BRep_Builder
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_RetDone
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.TopoDS import TopoDS_Compound


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
