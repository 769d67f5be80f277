"""Writes the boolean fixtures: input STEP files made with OpenCASCADE (cadquery-ocp) and
OpenCASCADE's own volumes of their union, difference and intersection (BRepAlgoAPI_Fuse, Cut
and Common; BRepGProp), in occt-booleans.jsonl.

    python3 -m venv /tmp/ocpenv && /tmp/ocpenv/bin/pip install cadquery-ocp
    /tmp/ocpenv/bin/python tests/reference/boolean/make_fixtures.py
"""
import json
import math
import os

from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder, BRepPrimAPI_MakeSphere
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec

from occ_shapes import compound, volume, write_step

HERE = os.path.dirname(os.path.abspath(__file__))


def placed(shape, seed):
    """The shape in general position: a rotation about a skew axis and a shift."""
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0.3 + seed, -0.5, 0.8)), 0.7 + 0.3 * seed)
    s = gp_Trsf()
    s.SetTranslation(gp_Vec(12.5 * seed, -7.25, 3.125))
    t = s.Multiplied(t)
    return BRepBuilderAPI_Transform(shape, t, True).Shape()


def write(shape, name):
    write_step(shape, os.path.join(HERE, name))


def box(x, y, z, dx, dy, dz):
    return BRepPrimAPI_MakeBox(gp_Pnt(x, y, z), dx, dy, dz).Shape()


def cylinder(p, d, r, h):
    return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(*p), gp_Dir(*d)), r, h).Shape()


cases = {
    "hole": (box(0, 0, 0, 20, 15, 10), cylinder((9, 7, -5), (0, 0, 1), 4, 20)),
    "slanted-hole": (box(0, 0, 0, 20, 15, 10), cylinder((6, 7, -5), (0.3, 0.1, 1), 3, 25)),
    "pins": (
        box(0, 0, 0, 40, 40, 5),
        compound([cylinder((8 + 12 * i, 8 + 12 * j, -2), (0, 0.15 * (i - 1), 1), 2, 9)
                  for i in range(3) for j in range(3)]),
    ),
    "blocks": (box(0, 0, 0, 20, 15, 10), box(12, 7, 4, 13, 17, 11)),
    "flush": (box(0, 0, 0, 20, 20, 10), box(5, 5, 5, 10, 20, 5)),
    "ball-block": (box(0, 0, 0, 20, 20, 20), BRepPrimAPI_MakeSphere(gp_Pnt(20, 10, 10), 7).Shape()),
    # Tools wholly inside: the difference is a solid with a void (BREP_WITH_VOIDS).
    "cavity": (box(0, 0, 0, 20, 15, 10), box(5, 4, 3, 6, 5, 4)),
    "bubble": (box(0, 0, 0, 20, 15, 10), BRepPrimAPI_MakeSphere(gp_Pnt(11, 6, 5), 3.5).Shape()),
}

# The benchmark: a 130 x 130 x 10 plate minus 144 pins through it, every third one slanted.
# OpenCASCADE's time to read both files, cut and write the result is recorded beside it.
plate = box(0, 0, 0, 130, 130, 10)
pins = compound([
    cylinder((5 + 10.5 * i, 5 + 10.5 * j, -4), (0.15, 0.1, 1) if (i + j) % 3 == 0 else (0, 0, 1),
             3, 18)
    for i in range(12) for j in range(12)
])
write(plate, "plate-a.step")
write(pins, "plate-b.step")


def plate_with_opencascade():
    from OCP.STEPControl import STEPControl_Reader
    import time
    started = time.perf_counter()
    shapes = []
    for name in ["plate-a.step", "plate-b.step"]:
        reader = STEPControl_Reader()
        reader.ReadFile(os.path.join(HERE, name))
        reader.TransferRoots()
        shapes.append(reader.OneShape())
    cut = BRepAlgoAPI_Cut(shapes[0], shapes[1]).Shape()
    write(cut, "/tmp/plate-occt-cut.step")
    return time.perf_counter() - started, volume(cut)


with open(os.path.join(HERE, "occt-plate.json"), "w") as out:
    seconds, cut_volume = plate_with_opencascade()
    row = {"difference": cut_volume, "occt_read_cut_write_seconds": seconds}
    out.write(json.dumps(row) + "\n")
    print(row)

with open(os.path.join(HERE, "occt-booleans.jsonl"), "w") as out:
    for seed, (name, (a, b)) in enumerate(sorted(cases.items())):
        a, b = placed(a, seed % 3), placed(b, seed % 3)
        write(a, f"{name}-a.step")
        write(b, f"{name}-b.step")
        row = {"case": name, "a": volume(a), "b": volume(b)}
        for op, maker in [("union", BRepAlgoAPI_Fuse), ("difference", BRepAlgoAPI_Cut),
                          ("intersection", BRepAlgoAPI_Common)]:
            result = maker(a, b).Shape()
            row[op] = volume(result)
            # OpenCASCADE's own results for knotwork to read: a solid with a void (its shell
            # an ORIENTED_CLOSED_SHELL in a BREP_WITH_VOIDS), a dent bounded by a meridian.
            if name in ("cavity", "ball-block") and op == "difference":
                write(result, f"{name}-occt-{op}.step")
        out.write(json.dumps(row) + "\n")
        print(row)
