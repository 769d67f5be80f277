#!/usr/bin/env python3
# Reads a 3MF file with lib3mf (the 3MF Consortium's reference library; `pip install lib3mf`)
# in strict mode and prints its unit, each mesh object with its counts and whether lib3mf finds
# it manifold and oriented, and the base materials. A manual check of `knotwork export -o
# OUT.3mf`; the test suite does not depend on it.
import sys, lib3mf
from lib3mf import get_wrapper
w = get_wrapper()
m = w.CreateModel()
r = m.QueryReader("3mf")
r.SetStrictModeActive(True)
r.ReadFromFile(sys.argv[1])
for i in range(r.GetWarningCount()):
    print("warning", r.GetWarning(i))
print("unit", m.GetUnit())
it = m.GetMeshObjects()
while it.MoveNext():
    o = it.GetCurrentMeshObject()
    print(o.GetName(), o.GetVertexCount(), o.GetTriangleCount(), "manifold+oriented:", o.IsManifoldAndOriented())
mats = m.GetBaseMaterialGroups()
while mats.MoveNext():
    g = mats.GetCurrentBaseMaterialGroup()
    for pid in g.GetAllPropertyIDs():
        c = g.GetDisplayColor(pid)
        print("material", g.GetName(pid), c.Red, c.Green, c.Blue, c.Alpha)
