"""OpenCASCADE's fillet and chamfer of every sharp edge (C0 between two faces) of a real part, the
references of tests/it/features.rs's real-part check:

    /tmp/ocpenv/bin/python tests/reference/features/occ_real_part.py \
        tests/reference/step-public/cax-if__s1_pe_214__foot_back_prt.stp 0.2

prints BRepFilletAPI_MakeFillet 4 2357.2641141337044 and BRepFilletAPI_MakeChamfer 4
2355.9012748780187 (4 edges: each of the two circles in halves)."""
import sys
from OCP.STEPControl import STEPControl_Reader
from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet, BRepFilletAPI_MakeChamfer
from OCP.TopExp import TopExp_Explorer, TopExp
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_SOLID
from OCP.TopoDS import TopoDS
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve
from OCP.GeomAbs import GeomAbs_C0
path, r = sys.argv[1], float(sys.argv[2])
rd = STEPControl_Reader(); rd.ReadFile(path); rd.TransferRoots(); shape = rd.OneShape()
def shapes(s, kind):
    out = []; ex = TopExp_Explorer(s, kind)
    while ex.More():
        out.append(ex.Current()); ex.Next()
    return out
pairs = []
for f in shapes(shape, TopAbs_FACE):
    for e in shapes(f, TopAbs_EDGE):
        for p in pairs:
            if p[0].IsSame(e):
                p[1].append(f); break
        else:
            pairs.append((e, [f]))
for make in (BRepFilletAPI_MakeFillet, BRepFilletAPI_MakeChamfer):
    mk = make(shape); n = 0
    for e0, fs in pairs:
        e = TopoDS.Edge(e0)
        uniq = []
        for f in fs:
            if not any(f.IsSame(g) for g in uniq): uniq.append(f)
        if len(uniq) != 2: continue
        f1, f2 = [TopoDS.Face(f) for f in uniq]
        if BRep_Tool.Continuity_s(e, f1, f2) != GeomAbs_C0: continue
        mk.Add(r, e); n += 1
    res = mk.Shape(); p = GProp_GProps(); BRepGProp.VolumeProperties_s(res, p)
    print(make.__name__, n, p.Mass())
