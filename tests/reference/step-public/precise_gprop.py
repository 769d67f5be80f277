"""OpenCASCADE's area and volume of each public STEP file by adaptive integration to 1e-9
(BRepGProp.SurfaceProperties_s / VolumeProperties_s with an eps), for the exact mass
properties' test in tests/it/step_files.rs. The measures in occt-reference.jsonl came from
BRepGProp's default (fixed-order) integration, which on rational B-spline faces is off by up to
a few 1e-4 (a quarter sphere of radius 60 in cax-if__s1-tu-203__headfront.stp, whose exact area
is 3600 pi).

Not run by the tests: run it by hand and commit what it writes
(python3 -m venv v && v/bin/pip install cadquery-ocp && v/bin/python precise_gprop.py).

    precise_gprop.py            writes occt-precise.jsonl beside this file: one line per file of
                                occt-reference.jsonl, {"file", "area", "volume"} (the volume
                                of the closed shells, its magnitude)
"""

import json
import os
import sys

from OCP.IFSelect import IFSelect_RetDone
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_Reader

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "occ"))
import make_step  # noqa: E402  (its measure: adaptive integration to 1e-9)


def read(path):
    Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    reader = STEPControl_Reader()
    if reader.ReadFile(path) != IFSelect_RetDone:
        raise RuntimeError(f"cannot read {path}")
    reader.TransferRoots()
    return reader.OneShape()


def measure(shape):
    m = make_step.measure(shape)
    return {"area": m["area"], "volume": abs(m["volume"])}


def main():
    out = []
    with open(os.path.join(HERE, "occt-reference.jsonl")) as f:
        for line in f:
            name = json.loads(line)["file"]
            try:
                out.append({"file": name, **measure(read(os.path.join(HERE, name)))})
            except Exception as e:  # a file OpenCASCADE cannot measure is left out
                print(f"{name}: {e}")
    with open(os.path.join(HERE, "occt-precise.jsonl"), "w") as f:
        for row in out:
            f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
