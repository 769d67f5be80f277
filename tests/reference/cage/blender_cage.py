"""Blender's bmesh as the reference for `knotwork cage`.

    python blender_cage.py IN.obj OUT.obj OP [args]     (the CLI's arguments)
    python blender_cage.py --fixtures DIR [SEED]        (the committed fixtures: SEED 1000)

Needs the `bpy` package from PyPI (Python 3.11). Each operation is the bmesh operator with the
defaults of Blender's own edit-mode tool (even offset for inset, the boundary kept, dissolve
taking the vertices left with two edges), so the figures are what a Blender user gets.
"""
import math
import os
import random
import sys

import bpy  # noqa: F401  (bmesh is importable only after bpy)
import bmesh
from mathutils import Matrix, Quaternion, Vector


def read_obj(path):
    """Points, faces and OpenSubdiv's crease tags (`t crease 2/1/0 A B S`, 0-based)."""
    verts, faces, creases = [], [], []
    for line in open(path):
        f = line.split("#")[0].split()
        if not f:
            continue
        if f[0] == "v":
            verts.append(tuple(float(x) for x in f[1:4]))
        elif f[0] == "f":
            faces.append([int(c.split("/")[0]) - 1 for c in f[1:]])
        elif f[:2] == ["t", "crease"]:
            creases.append((int(f[3]), int(f[4]), float(f[5])))
    return verts, faces, creases


def crease_layer(bm):
    return bm.edges.layers.float.get("crease_edge") or bm.edges.layers.float.new("crease_edge")


def write_obj(path, bm):
    """The points and faces, and each creased edge as a crease tag: Blender's crease (0-1)
    is a tenth of the sharpness (0-10), as its Subdivision modifier hands it to OpenSubdiv."""
    bm.verts.index_update()
    layer = bm.edges.layers.float.get("crease_edge")
    with open(path, "w") as out:
        for v in bm.verts:
            out.write("v %.17g %.17g %.17g\n" % tuple(v.co))
        for f in bm.faces:
            out.write("f " + " ".join(str(v.index + 1) for v in f.verts) + "\n")
        if layer is not None:
            for e in bm.edges:
                if e[layer] > 0:
                    a, b = (v.index for v in e.verts)
                    out.write("t crease 2/1/0 %d %d %.9g\n" % (a, b, 10 * e[layer]))


def build(verts, faces, creases=()):
    bm = bmesh.new()
    for p in verts:
        bm.verts.new(p)
    bm.verts.ensure_lookup_table()
    for face in faces:
        bm.faces.new([bm.verts[i] for i in face])
    bm.verts.ensure_lookup_table()
    bm.faces.ensure_lookup_table()
    bm.edges.ensure_lookup_table()
    if creases:
        layer = crease_layer(bm)
        for a, b, sharpness in creases:
            edge(bm, a, b)[layer] = min(sharpness / 10, 1.0)
    bm.normal_update()
    return bm


def ints(text):
    return [int(x) for x in text.split(",") if x != ""]


def floats(text):
    return [float(x) for x in text.split(",")]


def pairs(text):
    return [tuple(int(x) for x in p.split("-")) for p in text.split(",")]


def edge(bm, a, b):
    e = bm.edges.get((bm.verts[a], bm.verts[b]))
    if e is None:
        raise SystemExit(f"no edge {a}-{b}")
    return e


def ring(bm, start):
    """The edge ring through `start`: across quads to the opposite edge, both ways."""
    found = [start]
    seen = {start}
    for loop in list(start.link_loops)[:2]:
        e, l = start, loop
        while True:
            f = l.face
            if len(f.verts) != 4:
                break
            opp = l.link_loop_next.link_loop_next
            e = opp.edge
            if e in seen:
                break
            seen.add(e)
            found.append(e)
            nxt = [x for x in e.link_loops if x.face is not f]
            if not nxt:
                break
            l = nxt[0]
    return found


def region_of(bm, faces):
    """The named faces with their edges and vertices, as a set."""
    faces = [bm.faces[i] for i in ints(faces)]
    geom = set(faces)
    for f in faces:
        geom.update(f.edges)
        geom.update(f.verts)
    return geom


def apply(bm, op, args):
    opt = {}
    k = 0
    while k < len(args):
        if args[k].startswith("--"):
            key = args[k][2:]
            if k + 1 < len(args) and not args[k + 1].startswith("--"):
                opt[key] = args[k + 1]
                k += 2
            else:
                opt[key] = True
                k += 1
        else:
            k += 1
    if op == "extrude" and opt.get("individual"):
        # Extrude Individual Faces: each face moved along its own normal.
        faces = [bm.faces[i] for i in ints(opt["faces"])]
        new = bmesh.ops.extrude_discrete_faces(bm, faces=faces)["faces"]
        for f in new:
            f.normal_update()
            step = f.normal * float(opt["offset"])
            for v in f.verts:
                v.co += step
    elif op == "extrude" and "faces" in opt:
        faces = [bm.faces[i] for i in ints(opt["faces"])]
        normal = Vector()
        for f in faces:
            normal += f.normal
        normal.normalize()
        region = set(faces)
        for f in faces:
            region.update(f.edges)
            region.update(f.verts)
        geom = bmesh.ops.extrude_face_region(bm, geom=list(region))["geom"]
        moved = [g for g in geom if isinstance(g, bmesh.types.BMVert)]
        bmesh.ops.translate(bm, vec=normal * float(opt["offset"]), verts=moved)
    elif op == "inset":
        faces = [bm.faces[i] for i in ints(opt["faces"])]
        t, d = float(opt["thickness"]), float(opt.get("depth", 0.0))
        if opt.get("individual"):
            bmesh.ops.inset_individual(bm, faces=faces, thickness=t, depth=d,
                                       use_even_offset=True)
        else:
            bmesh.ops.inset_region(bm, faces=faces, thickness=t, depth=d, use_even_offset=True,
                                   use_boundary=True)
    elif op == "loopcut":
        a, b = ints(opt["edge"])
        edges = ring(bm, edge(bm, a, b))
        bmesh.ops.subdivide_edgering(bm, edges=edges, cuts=int(opt["cuts"]),
                                     interp_mode="LINEAR", profile_shape="LINEAR")
    elif op == "bevel" and "vertices" in opt:
        verts = [bm.verts[i] for i in ints(opt["vertices"])]
        bmesh.ops.bevel(bm, geom=verts, offset=float(opt["width"]), offset_type="OFFSET",
                        segments=int(opt.get("segments", 1)), profile=0.5, affect="VERTICES")
    elif op == "bevel":
        edges = [edge(bm, a, b) for a, b in pairs(opt["edges"])]
        bmesh.ops.bevel(bm, geom=edges, offset=float(opt["width"]), offset_type="OFFSET",
                        segments=int(opt["segments"]), profile=0.5, affect="EDGES")
    elif op == "bridge":
        edges = []
        for key in ("loop1", "loop2"):
            loop = ints(opt[key])
            edges += [edge(bm, loop[i], loop[(i + 1) % len(loop)]) for i in range(len(loop))]
        bmesh.ops.bridge_loops(bm, edges=edges)
    elif op == "extrude" and "edges" in opt:
        edges = [edge(bm, a, b) for a, b in pairs(opt["edges"])]
        geom = bmesh.ops.extrude_edge_only(bm, edges=edges)["geom"]
        moved = [g for g in geom if isinstance(g, bmesh.types.BMVert)]
        bmesh.ops.translate(bm, vec=Vector(floats(opt["by"])), verts=moved)
    elif op == "spin":
        if "faces" in opt:
            geom = region_of(bm, opt["faces"])
        else:
            geom = set()
            for a, b in pairs(opt["edges"]):
                e = edge(bm, a, b)
                geom.update([e, e.verts[0], e.verts[1]])
        axis = Vector(floats(opt["axis"])).normalized()
        steps = int(opt.get("steps", 12))
        advance = float(opt.get("advance", 0))
        bmesh.ops.spin(bm, geom=list(geom), cent=Vector(floats(opt["centre"])), axis=axis,
                       dvec=axis * (advance / steps), angle=math.radians(float(opt["angle"])),
                       steps=steps, use_merge=False, use_normal_flip=False,
                       use_duplicate=False)
    elif op == "tris-to-quads":
        bmesh.ops.join_triangles(
            bm, faces=[bm.faces[i] for i in ints(opt["faces"])],
            angle_face_threshold=math.radians(float(opt.get("face-angle", 40))),
            angle_shape_threshold=math.radians(float(opt.get("shape-angle", 40))),
            topology_influence=0.0)
    elif op == "fill":
        loop = ints(opt["loop"])
        edges = [edge(bm, loop[i], loop[(i + 1) % len(loop)]) for i in range(len(loop))]
        bmesh.ops.contextual_create(bm, geom=edges)
    elif op == "grid-fill" and "loop1" in opt:
        edges = [edge(bm, c[i], c[i + 1]) for c in (ints(opt["loop1"]), ints(opt["loop2"]))
                 for i in range(len(c) - 1)]
        bmesh.ops.grid_fill(bm, edges=edges, use_interp_simple=False)
    elif op == "grid-fill":
        rim = ints(opt["loop"])
        n = len(rim)
        edges = [edge(bm, rim[i], rim[(i + 1) % n]) for i in range(n)]
        if "span" not in opt and "offset" not in opt:
            # Blender's own Grid Fill on the selected rim: corner and span its choice.
            run_operator(bm, edges, lambda: bpy.ops.mesh.fill_grid())
        else:
            # The rim cut as the operator cuts it, from the vertex at --offset: the first
            # --span edges and as many from the middle on are the rails, the rest the chains.
            k, span = int(opt["offset"]), min(int(opt["span"]), n // 2 - 1)
            rim = rim[k:] + rim[:k] + [rim[k]]
            chains = (rim[span:n // 2 + 1], rim[n // 2 + span:])
            edges = [edge(bm, c[i], c[i + 1]) for c in chains for i in range(len(c) - 1)]
            bmesh.ops.grid_fill(bm, edges=edges, use_interp_simple=False)
    elif op == "connect":
        bmesh.ops.connect_verts(bm, verts=[bm.verts[i] for i in ints(opt["vertices"])])
    elif op == "merge" and "distance" in opt:
        # Blender's edit mode hands the selected points over in index order.
        verts = [bm.verts[i] for i in sorted(set(ints(opt["vertices"])))] if "vertices" in opt else list(bm.verts)
        bmesh.ops.remove_doubles(bm, verts=verts, dist=float(opt["distance"]))
    elif op == "merge":
        verts = [bm.verts[i] for i in ints(opt["vertices"])]
        if opt.get("at", "centre") == "first":
            co = verts[0].co.copy()
        elif opt.get("at") == "last":
            co = verts[-1].co.copy()
        else:
            co = sum((v.co for v in verts), Vector()) / len(verts)
        bmesh.ops.pointmerge(bm, verts=verts, merge_co=co)
    elif op == "dissolve" and "vertices" in opt:
        verts = [bm.verts[i] for i in ints(opt["vertices"])]
        bmesh.ops.dissolve_verts(bm, verts=verts, use_face_split=False, use_boundary_tear=False)
        drop_loose(bm)
    elif op == "dissolve" and "faces" in opt:
        faces = [bm.faces[i] for i in ints(opt["faces"])]
        bmesh.ops.dissolve_faces(bm, faces=faces, use_verts=True)
    elif op == "dissolve":
        edges = [edge(bm, a, b) for a, b in pairs(opt["edges"])]
        bmesh.ops.dissolve_edges(bm, edges=edges, use_verts=True)
    elif op == "delete" and "vertices" in opt:
        bmesh.ops.delete(bm, geom=[bm.verts[i] for i in ints(opt["vertices"])], context="VERTS")
        drop_loose(bm)
    elif op == "delete" and "edges" in opt:
        edges = [edge(bm, a, b) for a, b in pairs(opt["edges"])]
        bmesh.ops.delete(bm, geom=edges, context="EDGES")
        drop_loose(bm)
    elif op == "delete":
        faces = [bm.faces[i] for i in ints(opt["faces"])]
        bmesh.ops.delete(bm, geom=faces, context="FACES")
    elif op == "triangulate":
        faces = [bm.faces[i] for i in ints(opt["faces"])]
        bmesh.ops.triangulate(bm, faces=faces, quad_method="BEAUTY", ngon_method="BEAUTY")
    elif op == "subdivide":
        # Blender's Subdivide: the faces' edges cut, every quad and triangle they close filled
        # with a grid (no single-edge or corner patterns: other faces take the points).
        edges = {e for i in ints(opt["faces"]) for e in bm.faces[i].edges}
        bmesh.ops.subdivide_edges(bm, edges=list(edges), cuts=int(opt.get("cuts", 1)),
                                  use_grid_fill=True, use_single_edge=False,
                                  quad_corner_type="STRAIGHT_CUT")
    elif op == "poke":
        bmesh.ops.poke(bm, faces=[bm.faces[i] for i in ints(opt["faces"])])
    elif op == "knife":
        # Bisect: the plane cuts the faces' edges and splits the faces; points within the
        # threshold (by default 1e-6 of the cage's bounding diagonal) lie on the plane.
        if "faces" in opt:
            geom = list(region_of(bm, opt["faces"]))
        else:
            geom = list(bm.verts) + list(bm.edges) + list(bm.faces)
        lo = Vector([min(v.co[k] for v in bm.verts) for k in range(3)])
        hi = Vector([max(v.co[k] for v in bm.verts) for k in range(3)])
        dist = float(opt["threshold"]) if "threshold" in opt else 1e-6 * (hi - lo).length
        bmesh.ops.bisect_plane(bm, geom=geom, dist=dist, plane_co=Vector(floats(opt["point"])),
                               plane_no=Vector(floats(opt["normal"])).normalized(),
                               use_snap_center=False, clear_outer=False, clear_inner=False)
    elif op == "mirror":
        # The Mirror modifier applied: bmesh's mirror welds the points within the distance
        # of the plane; the copies' faces are turned to agree with the originals.
        before = set(bm.faces)
        bmesh.ops.mirror(bm, geom=list(bm.verts) + list(bm.edges) + list(bm.faces),
                         matrix=Matrix(), merge_dist=float(opt.get("merge-distance", 0.001)),
                         axis=opt["axis"].upper())
        bmesh.ops.reverse_faces(bm, faces=[f for f in bm.faces if f not in before])
    else:
        raise SystemExit(f"unknown operation {op}")


def run_operator(bm, edges, call):
    """Runs edit-mode operator `call` on `bm` with `edges` selected (no active element);
    `bm` takes the result."""
    for seq in (bm.verts, bm.edges, bm.faces):
        for e in seq:
            e.select = False
    for e in edges:
        e.select = True
        for v in e.verts:
            v.select = True
    bm.select_history.clear()
    mesh = bpy.data.meshes.new("cage")
    bm.to_mesh(mesh)
    obj = bpy.data.objects.new("cage", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.context.tool_settings.mesh_select_mode = (False, True, False)
    call()
    bpy.ops.object.mode_set(mode="OBJECT")
    bm.clear()
    bm.from_mesh(mesh)
    bpy.data.objects.remove(obj)


def drop_loose(bm):
    """Removes the edges and vertices no face uses: a cage is its faces."""
    bmesh.ops.delete(bm, geom=[e for e in bm.edges if not e.link_faces], context="EDGES")
    bmesh.ops.delete(bm, geom=[v for v in bm.verts if not v.link_faces], context="VERTS")


def cage(name):
    """The test cages, as (points, faces)."""
    if name == "box":
        v = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
        f = [[0, 1, 3, 2], [2, 3, 7, 6], [6, 7, 5, 4], [4, 5, 1, 0], [2, 6, 4, 0], [7, 3, 1, 5]]
        return v, f
    if name == "prism":
        v = [(0, 0, 0), (2, 0, 0), (0.7, 1.6, 0), (0, 0, 1.5), (2, 0, 1.5), (0.7, 1.6, 1.5)]
        return v, [[0, 2, 1], [3, 4, 5], [0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]]
    if name == "frustum":
        # A box narrowing and leaning as it rises: flat faces, no two corners alike.
        v = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0),
             (-0.4, -0.7, 1.3), (0.5, -0.7, 1.3), (0.5, 0.2, 1.3), (-0.4, 0.2, 1.3)]
        f = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
        return v, f
    if name == "grid":
        n, m = 4, 3
        v = [(i * 0.9, j * 1.1, 0.1 * ((i * j) % 3)) for j in range(m + 1) for i in range(n + 1)]
        f = [[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i] for j in range(m) for i in range(n)]
        return v, f
    if name == "torus":
        n, m, big, small = 8, 6, 2.0, 0.7
        v = []
        for i in range(n):
            for j in range(m):
                a, b = 2 * math.pi * i / n, 2 * math.pi * j / m
                r = big + small * math.cos(b)
                v.append((r * math.cos(a), r * math.sin(a), small * math.sin(b)))
        f = [[i * m + j, ((i + 1) % n) * m + j, ((i + 1) % n) * m + (j + 1) % m,
              i * m + (j + 1) % m] for i in range(n) for j in range(m)]
        return v, f
    if name == "tube":
        n, h = 8, 3
        v = [(math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0.7 * k)
             for k in range(h + 1) for i in range(n)]
        f = [[k * n + i, k * n + (i + 1) % n, (k + 1) * n + (i + 1) % n, (k + 1) * n + i]
             for k in range(h) for i in range(n)]
        return v, f
    if name in ("cap5", "cap6"):
        # An n-sided prism, its ends fans of triangles round a centre: vertices of n edges
        # (the centres) and of four (the rims), slightly uneven.
        n = int(name[3:])
        rnd = random.Random(5)
        v = []
        for z, rx, ry in ((0.0, 1.3, 1.0), (1.0, 1.2, 1.1)):
            for k in range(n):
                a = 2 * math.pi * k / n + rnd.uniform(-0.2, 0.2)
                v.append((rx * math.cos(a), ry * math.sin(a), z + rnd.uniform(-0.1, 0.1)))
        v += [(0.05, 0.02, -0.3), (-0.03, 0.04, 1.4)]
        f = [[k, (k + 1) % n, n + (k + 1) % n, n + k] for k in range(n)]
        f += [[(k + 1) % n, k, 2 * n] for k in range(n)]
        f += [[n + k, n + (k + 1) % n, 2 * n + 1] for k in range(n)]
        return v, f
    if name == "ngons":
        # A prism on an uneven heptagon (one corner pushed in: not convex), its ends 7-gons.
        radii = (1.2, 0.9, 1.1, 0.5, 1.0, 1.3, 0.8)
        v = []
        for z in (0.0, 1.1):
            for k, r in enumerate(radii):
                a = 2 * math.pi * k / 7 + 0.1 * math.sin(3 * k)
                v.append((r * math.cos(a), 0.8 * r * math.sin(a), z + 0.05 * math.cos(5 * k)))
        f = [list(range(6, -1, -1)), list(range(7, 14))]
        f += [[k, (k + 1) % 7, 7 + (k + 1) % 7, 7 + k] for k in range(7)]
        return v, f
    if name == "uprism":
        # A U-shaped prism: its ends concave octagons that a plane across the U's arms
        # crosses four times.
        u = [(0, 0), (3, 0), (3, 2), (2, 2), (2, 0.8), (1, 0.8), (1, 2), (0, 2)]
        v = [(x, y, z) for z in (0.0, 0.9) for x, y in u]
        f = [list(range(7, -1, -1)), list(range(8, 16))]
        f += [[k, (k + 1) % 8, 8 + (k + 1) % 8, 8 + k] for k in range(8)]
        return v, f
    if name == "trigrid":
        # The grid's quads split into triangles, the diagonals alternating as a checkerboard.
        v, quads = cage("grid")
        f = []
        for k, (a, b, c, d) in enumerate(quads):
            f += [[a, b, c], [a, c, d]] if k % 2 == 0 else [[a, b, d], [b, c, d]]
        return v, f
    if name == "openbox":
        # The box without its first face: an open rim of four edges.
        v, f = cage("box")
        return v, f[1:]
    if name == "seam":
        # Two 3 × 2 grids side by side, the points of the seam doubled, each copy moved by up
        # to 1e-7 (float noise, as from a mirror: merged by distance at 1e-5).
        rnd = random.Random(7)
        v, f = [], []
        for side in (0, 1):
            base = len(v)
            for j in range(3):
                for i in range(4):
                    x = 3 * side + i
                    jitter = [rnd.uniform(-1e-7, 1e-7) for _ in range(3)] if i in (0, 3) else [0] * 3
                    v.append((x + jitter[0], j * 1.2 + jitter[1], 0.2 * ((x + j) % 2) + jitter[2]))
            f += [[base + j * 4 + i, base + j * 4 + i + 1, base + (j + 1) * 4 + i + 1,
                   base + (j + 1) * 4 + i] for j in range(2) for i in range(3)]
        return v, f
    if name == "split5":
        # cap5 with each bottom triangle's centre its own point, the five within 3.5e-4 of
        # each other: a cluster of five for merge by distance.
        v, f = cage("cap5")
        rnd = random.Random(9)
        n = 5
        centre = v[2 * n]
        for k in range(1, n):
            face = f[n + k]
            v.append(tuple(c + rnd.uniform(-1e-4, 1e-4) for c in centre))
            f[n + k] = [face[0], face[1], len(v) - 1]
        return v, f
    if name == "holed":
        # A 6 × 5 grid of uneven height without its inner 3 × 2 quads: a rim of 10 edges.
        n, m = 6, 5
        v = [(i * 0.8 + 0.05 * j, j * 1.0, 0.3 * math.sin(1.3 * i) * math.cos(0.9 * j))
             for j in range(m + 1) for i in range(n + 1)]
        f = [[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i] for j in range(m) for i in range(n)
             if not (1 <= i <= 3 and 1 <= j <= 2)]
        return v, f
    if name == "tube12":
        # An open tube of 12 sides, uneven: rims of 12 edges to fill across.
        n, h = 12, 2
        v = [((1 + 0.15 * math.cos(3 * i)) * math.cos(2 * math.pi * i / n),
              (0.8 + 0.1 * math.sin(2 * i)) * math.sin(2 * math.pi * i / n),
              0.9 * k + 0.1 * math.sin(i)) for k in range(h + 1) for i in range(n)]
        f = [[k * n + i, k * n + (i + 1) % n, (k + 1) * n + (i + 1) % n, (k + 1) * n + i]
             for k in range(h) for i in range(n)]
        return v, f
    if name in ("disc6", "cone3", "cone6", "grid3"):
        # Blender's own primitives: a disc of six triangles round a centre, cones of three
        # and six sides (a closed tetrahedron; a hexagon base), a flat 2 × 2 grid.
        bm = bmesh.new()
        if name == "disc6":
            bmesh.ops.create_circle(bm, cap_ends=True, cap_tris=True, segments=6, radius=1.0)
        elif name == "grid3":
            bmesh.ops.create_grid(bm, x_segments=2, y_segments=2, size=1.0)
        else:
            bmesh.ops.create_cone(bm, cap_ends=True, cap_tris=False, segments=int(name[4:]),
                                  radius1=1.0, radius2=0.0, depth=1.5)
        bm.verts.index_update()
        return [tuple(v.co) for v in bm.verts], [[v.index for v in f.verts] for f in bm.faces]
    if name in ("fan3", "fan4", "fan5"):
        # Quads round a point on the border: n of them over an angle (108°, 180°, 270°), of
        # uneven heights, so that the point has n faces and n + 1 edges, two on the border.
        n = int(name[3:])
        span = {3: 0.6, 4: 1.0, 5: 1.5}[n] * math.pi
        v = [(0.0, 0.0, 0.1)]
        for k in range(n + 1):
            a = span * k / n
            v.append((math.cos(a), math.sin(a), 0.6 * math.sin(2.1 * k + 0.4)))
        for k in range(n):
            a = span * (k + 0.5) / n
            v.append((1.4 * math.cos(a), 1.4 * math.sin(a), 0.3 * math.cos(1.7 * k)))
        return v, [[0, 1 + k, n + 2 + k, 2 + k] for k in range(n)]
    if name in ("splitbox", "bentbox"):
        # The box with a point 8 on its edge 0-1, held by both faces there (a point of two
        # edges): in line with the edge, or moved out of it (the two faces bent there).
        v, f = cage("box")
        bend = 0.2 if name == "bentbox" else 0.0
        mid = [(v[0][k] + v[1][k]) / 2 for k in range(3)]
        v = v + [(mid[0] - bend, mid[1], mid[2] - bend)]
        split = []
        for face in f:
            g = []
            for k, x in enumerate(face):
                g.append(x)
                if {x, face[(k + 1) % len(face)]} == {0, 1}:
                    g.append(8)
            split.append(g)
        return v, split
    if name == "tee":
        # A pentagon with a straight corner at point 1 (points 0, 1, 2 in line) over two
        # triangles: point 1 has three edges, two of them in line in the pentagon.
        v = [(0, 0, 0), (1, 0, 0), (2, 0, 0), (2, 1, 0.3), (0, 1, -0.2), (1, -1, 0.25)]
        return v, [[0, 1, 2, 3, 4], [2, 1, 5], [1, 0, 5]]
    if name == "monkey":
        # Blender's Suzanne (bmesh.ops.create_monkey): a modelled cage nobody here made, with
        # triangles, poles of three to eight edges, open eyes and a mouth.
        bm = bmesh.new()
        bmesh.ops.create_monkey(bm)
        bm.verts.index_update()
        return [tuple(v.co) for v in bm.verts], [[v.index for v in f.verts] for f in bm.faces]
    raise SystemExit(f"no cage {name}")


def motion(seed):
    """A random rotation, scale (0.3 to 4) and translation (±50)."""
    rnd = random.Random(seed)
    q = [rnd.gauss(0, 1) for _ in range(4)]
    rot = Quaternion([c / math.sqrt(sum(x * x for x in q)) for c in q]).to_matrix()
    scale = rnd.uniform(0.3, 4.0)
    shift = Vector([rnd.uniform(-50, 50) for _ in range(3)])
    return rot, scale, shift


def placed(points, seed):
    """The points under the random motion of `seed`, and its scale."""
    rot, scale, shift = motion(seed)
    return [tuple(rot @ (Vector(p) * scale) + shift) for p in points], scale


def moved_argument(arg, seed, scale):
    """An argument under the case's motion: a length "xU" scaled, a point "x,y,zP" moved, a
    vector "x,y,zV" turned and scaled."""
    if arg.endswith("U"):
        return "%.17g" % (float(arg[:-1]) * scale)
    if arg[-1:] in ("P", "V") and arg.count(",") == 2:
        rot, _, shift = motion(seed)
        v = rot @ (Vector([float(c) for c in arg[:-1].split(",")]) * scale)
        if arg.endswith("P"):
            v += shift
        return ",".join("%.17g" % c for c in v)
    return arg


# (cage, tool, arguments with the length unit U scaled by the placement)
CASES = [
    ("box", "extrude --faces 0 --offset 0.5U"),
    ("box", "extrude --faces 0,1 --offset 0.4U"),
    ("grid", "extrude --faces 5,6,9,10 --offset 0.4U"),
    ("torus", "extrude --faces 0,1,2,6,7,8 --offset -0.2U"),
    ("box", "inset --faces 0 --thickness 0.3U"),
    ("box", "inset --faces 0,1 --thickness 0.25U"),
    ("grid", "inset --faces 5,6,9,10 --thickness 0.2U"),
    ("grid", "inset --faces 0,1,2 --thickness 0.1U"),
    ("torus", "inset --faces 0,1,2 --thickness 0.1U"),
    ("torus", "inset --faces 5,6,9,10 --thickness 0.1U"),
    ("prism", "inset --faces 0 --thickness 0.1U"),
    ("prism", "inset --faces 2,3 --thickness 0.1U"),
    ("box", "inset --faces 0,1,4 --thickness 0.2U --individual"),
    ("torus", "inset --faces 0,1,2,5 --thickness 0.1U --individual"),
    ("box", "loopcut --edge 0,1 --cuts 3"),
    ("grid", "loopcut --edge 0,5 --cuts 2"),
    ("grid", "loopcut --edge 1,2 --cuts 1"),
    ("torus", "loopcut --edge 0,6 --cuts 2"),
    ("torus", "loopcut --edge 1,2 --cuts 4"),
    ("tube", "loopcut --edge 0,8 --cuts 2"),
    ("prism", "loopcut --edge 0,1 --cuts 2"),
    ("box", "bevel --edges 0-1 --width 0.3U --segments 1"),
    ("box", "bevel --edges 0-1 --width 0.3U --segments 3"),
    ("box", "bevel --edges 0-1,6-7 --width 0.2U --segments 2"),
    ("prism", "bevel --edges 0-3 --width 0.2U --segments 3"),
    ("prism", "bevel --edges 1-4 --width 0.1U --segments 4"),
    ("prism", "bevel --edges 3-4,4-5,5-3 --width 0.15U --segments 2"),
    # (Not prism 0-1,1-4: its corner point falls exactly on an edge, where Blender's f32
    # rounding picks the face it is dropped onto.)
    ("frustum", "bevel --edges 1-2,2-6 --width 0.1U --segments 3"),
    ("box", "bevel --edges 0-1,1-3,3-2,2-0 --width 0.2U --segments 3"),
    ("box", "bevel --edges 0-1,0-2,0-4 --width 0.2U --segments 1"),
    ("box", "bevel --edges 0-1,1-3,3-2,2-0,4-5,5-7,7-6,6-4,0-4,1-5,2-6,3-7 --width 0.2U --segments 1"),
    ("frustum", "bevel --edges 0-1 --width 0.2U --segments 3"),
    ("frustum", "bevel --edges 1-5 --width 0.2U --segments 3"),
    ("frustum", "bevel --edges 0-1,1-2 --width 0.1U --segments 4"),
    ("frustum", "bevel --edges 4-5,5-6,5-1 --width 0.1U --segments 1"),
    ("torus", "bevel --edges 0-6,6-12,12-18,18-24,24-30,30-36,36-42,42-0 --width 0.1U --segments 2"),
    ("frustum", "bevel --edges 4-5,5-6,6-7,7-4 --width 0.15U --segments 3"),
    ("frustum", "bevel --edges 0-1,1-5 --width 0.15U --segments 2"),
    ("torus", "bevel --edges 0-1,1-2,2-3,3-4,4-5,5-0 --width 0.1U --segments 3"),
    ("frustum", "extrude --faces 1,3 --offset 0.3U"),
    ("frustum", "inset --faces 1,2 --thickness 0.1U"),
    ("frustum", "inset --faces 1,2,3 --thickness 0.1U --individual"),
    ("frustum", "loopcut --edge 0,1 --cuts 3"),
    ("tube", "bridge --loop1 0,1,2,3,4,5,6,7 --loop2 24,25,26,27,28,29,30,31"),
    ("tube", "bridge --loop1 0,1,2,3,4,5,6,7 --loop2 27,26,25,24,31,30,29,28"),
    ("tube", "bridge --loop1 0,1,2,3,4,5,6,7 --loop2 26,27,28,29,30,31,24,25"),
    ("box", "merge --vertices 3,1"),
    ("box", "merge --vertices 0,3"),
    ("box", "merge --vertices 3,1,7 --at first"),
    ("grid", "merge --vertices 6,7,12"),
    ("torus", "merge --vertices 6,7 --at first"),
    ("box", "dissolve --edges 2-3"),
    ("grid", "dissolve --edges 6-7,7-12"),
    ("grid", "dissolve --edges 6-7,7-8"),
    ("torus", "dissolve --edges 0-1,1-2,2-3"),
    ("box", "delete --faces 0,2"),
    ("grid", "delete --faces 5,6"),
    ("torus", "delete --faces 5,6,7"),
    # Bevel ends of one beveled edge at vertices of four to six edges, and on the border.
    ("grid", "bevel --edges 6-7 --width 0.2U --segments 3"),
    ("torus", "bevel --edges 0-1 --width 0.15U --segments 2"),
    ("cap5", "bevel --edges 10-0 --width 0.2U --segments 3"),
    ("cap6", "bevel --edges 12-3 --width 0.1U --segments 2"),
    ("cap6", "bevel --edges 13-8 --width 0.15U --segments 1"),
    ("grid", "bevel --edges 1-6 --width 0.2U --segments 2"),
    # Two beveled edges with two or more unbeveled ones between them, at vertices of four
    # to six edges (the torus's top: an edge between lying flat with its faces).
    ("grid", "bevel --edges 1-6,6-7 --width 0.2U --segments 2"),
    ("torus", "bevel --edges 0-1,1-7 --width 0.15U --segments 1"),
    ("tube", "bevel --edges 9-10,9-17,4-12 --width 0.1U --segments 3"),
    ("cap5", "bevel --edges 10-0,10-2 --width 0.1U --segments 3"),
    ("cap6", "bevel --edges 12-0,12-3 --width 0.1U --segments 2"),
    # Three and four beveled edges at vertices of four to six edges, one segment.
    ("torus", "bevel --edges 0-1,0-6,0-5 --width 0.1U --segments 1"),
    ("cap6", "bevel --edges 12-0,12-1,12-3,12-4 --width 0.1U --segments 1"),
    # Mirror: a cage name ending in "!" is not moved, so that points lie on the plane and weld.
    ("grid!", "mirror --axis x"),
    ("grid!", "mirror --axis y --merge-distance 0.01"),
    ("tube!", "mirror --axis z --merge-distance 0.01"),
    ("box", "mirror --axis z"),
    ("frustum", "poke --faces 0,2"),
    ("cap6", "poke --faces 0,6,12"),
    ("torus", "poke --faces 3,4,10"),
    # Corners of three or more beveled edges with several segments: Blender's corner mesh
    # (a sphere octant where three faces meet nearly square, the general mesh refined by
    # Catmull-Clark steps, the pipe where two beveled edges run on in line).
    ("box", "bevel --edges 0-1,1-3,3-2,2-0,4-5,5-7,7-6,6-4,0-4,1-5,2-6,3-7 --width 0.2U --segments 2"),
    ("box", "bevel --edges 0-1,1-3,3-2,2-0,4-5,5-7,7-6,6-4,0-4,1-5,2-6,3-7 --width 0.15U --segments 3"),
    ("box", "bevel --edges 0-1,1-3,3-2,2-0,4-5,5-7,7-6,6-4,0-4,1-5,2-6,3-7 --width 0.25U --segments 5"),
    ("box", "bevel --edges 0-1,0-2,0-4 --width 0.3U --segments 4"),
    ("prism", "bevel --edges 0-1,1-2,2-0,3-4,4-5,5-3,0-3,1-4,2-5 --width 0.1U --segments 3"),
    ("frustum", "bevel --edges 4-5,5-6,5-1 --width 0.1U --segments 5"),
    ("torus", "bevel --edges 0-1,0-6,0-5 --width 0.1U --segments 3"),
    ("torus", "bevel --edges 0-1,0-6,0-5,0-42 --width 0.1U --segments 2"),
    ("cap5", "bevel --edges 4-9,0-4,3-4 --width 0.05U --segments 4"),
    ("cap5", "bevel --edges 0-1,0-10,0-5 --width 0.05U --segments 3"),
    ("cap6", "bevel --edges 12-0,12-1,12-3,12-4 --width 0.1U --segments 3"),
    ("cap6", "bevel --edges 12-0,12-1,12-2,12-3,12-4,12-5 --width 0.1U --segments 4"),
    ("cap6", "bevel --edges 2-3,1-2,8-9,2-12,9-13,3-9,2-8 --width 0.15U --segments 3"),
    ("grid", "bevel --edges 1-6,6-7,5-6,6-11 --width 0.05U --segments 5"),
    # Subdivide: grids in the faces whose edges are all cut, straight cuts across faces with
    # two cut edges, Blender's pattern in quads with three.
    ("box", "subdivide --faces 0 --cuts 1"),
    ("box", "subdivide --faces 0,1 --cuts 2"),
    ("prism", "subdivide --faces 0,1 --cuts 3"),
    ("frustum", "subdivide --faces 0,1,2,3 --cuts 2"),
    ("torus", "subdivide --faces 0,6 --cuts 2"),
    ("cap6", "subdivide --faces 6,7 --cuts 2"),
    ("grid", "subdivide --faces 5,6,9 --cuts 2"),
    ("cap5", "subdivide --faces 2,11,0 --cuts 2"),
    # Dissolve faces: each joined region one face.
    ("box", "dissolve --faces 0,1"),
    ("grid", "dissolve --faces 5,6,9,10"),
    ("torus", "dissolve --faces 0,1,20,21"),
    ("cap6", "dissolve --faces 6,7,8"),
    # Delete vertices and edges (their faces go; the loose edges Blender keeps are dropped).
    ("grid", "delete --vertices 6,0"),
    ("torus", "delete --vertices 3,10,30"),
    ("box", "delete --edges 0-1"),
    ("cap5", "delete --edges 0-1,1-10"),
    # Dissolve vertices: the faces round each joined, the vertex gone.
    ("grid", "dissolve --vertices 6,0,1"),
    ("grid", "dissolve --vertices 6,7"),
    ("box", "dissolve --vertices 0"),
    ("torus", "dissolve --vertices 0,14"),
    ("cap6", "dissolve --vertices 12"),
    ("ngons", "dissolve --vertices 3,10"),
    # Merge by distance: float noise on a seam, a cluster of five.
    ("seam", "merge --distance 1e-5U"),
    ("seam", "merge --distance 1e-5U --vertices 3,7,11,12,16"),
    ("split5", "merge --distance 1e-3U"),
    ("split5", "merge --distance 1e-4U"),
    # Triangulate (Beauty): quads by the better diagonal, polygons by ears and flips. (Not the
    # grid's face 5: a symmetric saddle whose diagonals tie exactly, where Blender's float
    # rounding picks one.)
    ("grid", "triangulate --faces 0,1,2,3,4,6,7,8,9,10,11"),
    ("cap6", "triangulate --faces 0,1,2"),
    ("ngons", "triangulate --faces 0,1,2,5"),
    # Extrude edges: open edges pulled out into quads (points and vectors under the motion).
    ("grid", "extrude --edges 0-1,1-2,2-3 --by 0,0.3,0.5V"),
    ("tube", "extrude --edges 0-1,1-2,2-3,3-4,4-5,5-6,6-7,7-0 --by 0,0,-0.8V"),
    # Spin and screw of faces and of open edges.
    ("grid", "spin --faces 0,1 --angle 90 --steps 3 --centre 0,-1,0P --axis 1,0,0V"),
    ("grid", "spin --faces 5 --angle -120 --steps 4 --centre 0,0,-2P --axis 0.2,1,0V --advance 1.5U"),
    ("grid", "spin --edges 0-1,1-2 --angle 300 --steps 5 --centre 0,-1,0P --axis 1,0,0.1V --advance 0.7U"),
    ("tube", "spin --edges 0-1,1-2,2-3 --angle 75 --steps 3 --centre 3,0,0P --axis 0,0,1V"),
    # Fill a loop of open edges (named either way round), and connect vertices across faces.
    ("openbox", "fill --loop 0,2,3,1"),
    ("tube", "fill --loop 0,1,2,3,4,5,6,7"),
    ("grid", "fill --loop 0,1,2,3,4,9,14,19,18,17,16,15,10,5"),
    ("ngons", "connect --vertices 0,2,4"),
    ("ngons", "connect --vertices 0,1,3"),
    ("grid", "connect --vertices 0,6,12,18"),
    ("torus", "connect --vertices 0,7,14"),
    # Tris to quads: the squarest pairs first, within the angle limits.
    ("trigrid", "tris-to-quads --faces " + ",".join(str(k) for k in range(24))),
    ("trigrid", "tris-to-quads --faces 0,1,2,3,4,5,6,7,8,9,10,11,12,13 --face-angle 12"),
    ("trigrid", "tris-to-quads --faces " + ",".join(str(k) for k in range(24)) + " --shape-angle 15"),
    # Knife (Bisect): planes across every face or some, concave faces crossed four times,
    # and a plane through four corners of the box.
    ("box", "knife --point 0.1,0.2,-0.1P --normal 0.3,1,0.2V"),
    ("torus", "knife --point 0.3,0,0.1P --normal 0.2,0.1,1V"),
    ("torus", "knife --point 0.5,0.5,0P --normal 1,0.3,0.05V"),
    ("grid", "knife --faces 5,6,9,10,11 --point 1.6,1.5,0P --normal 1,0.4,0.1V"),
    ("ngons", "knife --point 0,0,0.5P --normal 0.1,0.05,1V"),
    ("ngons", "knife --point -0.1,0.1,0P --normal 1,0.2,0.3V"),
    ("uprism", "knife --point 0,1.5,0.4P --normal 0.05,1,0.1V"),
    ("uprism", "knife --faces 0,2,3 --point 0,1.2,0P --normal 0.1,1,-0.2V"),
    ("box", "knife --point 0,0,0P --normal 1,-1,0V --threshold 1e-5U"),
    # The corner at vertex 4 cut off through two named faces: the third face at the corner
    # takes the two new points and stays whole.
    ("frustum", "knife --faces 1,5 --point -0.25,-0.55,1.15P --normal -1,-1,1V"),
    # Vertex bevel: corners of three edges, a torus's points of four, a heptagon prism's,
    # the grid's border points of three and two edges (the corner only cut), neighbours.
    ("box", "bevel --vertices 7 --width 0.3U"),
    ("box", "bevel --vertices 0,3,5,6 --width 0.4U"),
    ("box", "bevel --vertices 0,1 --width 0.3U"),
    ("torus", "bevel --vertices 0,7,20 --width 0.2U"),
    ("ngons", "bevel --vertices 3,10 --width 0.15U"),
    ("grid", "bevel --vertices 1,0,6,19 --width 0.2U"),
    ("cap5", "bevel --vertices 10,11,0 --width 0.2U"),
    # Grid fill: between two chains (named either way, the long or the short sides), over a
    # whole rim as Blender's operator cuts it (its corner and span) or at a given offset and
    # span (the rim named the way Blender walks it: the span runs along it), and a single quad.
    ("holed", "grid-fill --loop1 8,9,10,11 --loop2 22,23,24,25"),
    ("holed", "grid-fill --loop1 25,24,23,22 --loop2 8,9,10,11"),
    ("holed", "grid-fill --loop1 8,15,22 --loop2 11,18,25"),
    ("holed", "grid-fill --loop 8,15,22,23,24,25,18,11,10,9"),
    ("tube12", "grid-fill --loop 0,1,2,3,4,5,6,7,8,9,10,11"),
    ("tube12", "grid-fill --loop 24,25,26,27,28,29,30,31,32,33,34,35 --span 2 --offset 1"),
    ("tube12", "grid-fill --loop 0,1,2,3,4,5,6,7,8,9,10,11 --span 3 --offset 5"),
    ("tube12", "grid-fill --loop1 0,1,2,3 --loop2 9,8,7,6"),
    ("tube", "grid-fill --loop 0,1,2,3,4,5,6,7 --span 1 --offset 2"),
    ("openbox", "grid-fill --loop1 0,2 --loop2 1,3"),
    # Inset with depth: a flat face, two faces round an edge, curved regions with inner
    # points (a torus's, a fan's centre), a region on the border, and faces each on its own.
    ("box", "inset --faces 0 --thickness 0.3U --depth 0.2U"),
    ("box", "inset --faces 0,1 --thickness 0.25U --depth -0.15U"),
    ("torus", "inset --faces 0,1,2,6,7,8 --thickness 0.1U --depth 0.1U"),
    ("grid", "inset --faces 5,6,9,10 --thickness 0.2U --depth 0.3U"),
    ("cap5", "inset --faces 5,6,7,8,9 --thickness 0.15U --depth 0.2U"),
    ("grid", "inset --faces 0,1,4,5 --thickness 0.1U --depth -0.2U"),
    ("torus", "inset --faces 0,7,14 --thickness 0.1U --depth 0.15U --individual"),
    ("ngons", "inset --faces 0,3 --thickness 0.1U --depth 0.2U --individual"),
    # Extrude individual faces: neighbours (each its own sides where they met), a torus's
    # faces, a fan's triangles, heptagons, and inward.
    ("box", "extrude --faces 0,1 --offset 0.4U --individual"),
    ("torus", "extrude --faces 0,1,2,7 --offset 0.3U --individual"),
    ("cap5", "extrude --faces 5,6,7 --offset 0.2U --individual"),
    ("ngons", "extrude --faces 0,1 --offset -0.3U --individual"),
    ("grid", "extrude --faces 0,5,6 --offset 0.25U --individual"),
    # Merge at last: the last named point stays where it is.
    ("torus", "merge --vertices 0,1,7 --at last"),
    ("grid", "merge --vertices 6,7,12 --at last"),
    # Vertex bevel of several segments: Blender's corner mesh over arcs in the faces.
    ("box", "bevel --vertices 7 --width 0.3U --segments 2"),
    ("box", "bevel --vertices 0,5 --width 0.4U --segments 3"),
    ("torus", "bevel --vertices 0,20 --width 0.2U --segments 4"),
    ("ngons", "bevel --vertices 10 --width 0.15U --segments 3"),
    ("cap5", "bevel --vertices 10 --width 0.2U --segments 5"),
    ("grid", "bevel --vertices 6,12 --width 0.2U --segments 2"),
    # On the border: a point of three edges (the corner mesh's third side across the open
    # side, straight on the grid, an arc on the tube's round rim) and a corner of two.
    ("grid", "bevel --vertices 2,0 --width 0.2U --segments 3"),
    ("tube12", "bevel --vertices 0,14 --width 0.15U --segments 2"),
    # Creases through a bevel (the third item: edges and sharpness): a beveled edge's on its
    # band's two outer rails, an unbeveled edge's on what is left of it, an arc in a face
    # with no beveled edge at the end taking that of the face's edge leaving the end.
    ("box", "bevel --edges 0-1 --width 0.3U --segments 2", [(0, 1, 3), (0, 2, 1.5), (1, 5, 2.5)]),
    ("box", "bevel --edges 0-1 --width 0.2U --segments 1", [(0, 1, 4), (0, 4, 2), (1, 3, 6)]),
    ("box", "bevel --edges 0-1,0-2,0-4 --width 0.2U --segments 1", [(0, 1, 2), (0, 2, 4), (1, 3, 1)]),
    ("box", "bevel --edges 0-1,1-3,3-2,2-0 --width 0.2U --segments 3", [(0, 1, 2), (3, 2, 5), (2, 6, 3)]),
    ("frustum", "bevel --edges 0-1,1-2 --width 0.1U --segments 3", [(0, 1, 5), (1, 5, 2), (2, 6, 3)]),
    ("torus", "bevel --edges 0-1 --width 0.15U --segments 2", [(0, 1, 2), (0, 6, 1), (1, 7, 3), (0, 5, 2)]),
    ("grid", "bevel --edges 6-7 --width 0.2U --segments 3", [(6, 7, 2), (1, 6, 1.5), (7, 12, 2.5), (6, 5, 1)]),
    ("box", "bevel --vertices 7 --width 0.3U --segments 2", [(7, 3, 2), (7, 6, 4), (1, 5, 1)]),
    ("torus", "bevel --vertices 0 --width 0.2U", [(0, 1, 2), (0, 6, 3)]),
    ("monkey", "extrude --faces 20,22,24,26,28,36 --offset 0.0105U"),
    ("monkey", "inset --faces 294,295,296,298,306,307 --thickness 0.0077U"),
    ("monkey", "inset --faces 260,304,342,354 --thickness 0.0158U --individual"),
    ("monkey", "bevel --edges 147-145,117-147 --width 0.008U --segments 2"),
    ("monkey", "loopcut --edge 183,232 --cuts 1"),
    ("monkey", "dissolve --edges 337-331"),
    ("monkey", "delete --faces 269,271,279,281"),
    ("monkey", "merge --vertices 77,350 --at centre"),
    # A ring that comes back across a quad it crossed: Blender leaves it uncut.
    ("monkey", "loopcut --edge 412,418 --cuts 1"),
    # Widths beyond the edge the new point slides along: Blender stops it at the far end.
    ("monkey", "bevel --edges 64-62 --width 0.0197507U --segments 2"),
    ("monkey", "bevel --edges 221-219 --width 0.0183615U --segments 3"),
    # Blender's primitives. A whole piece extruded keeps its faces, turned over: an open disc
    # becomes a closed slab, a closed tetrahedron two of them.
    ("disc6", "extrude --faces 0,1,2,3,4,5 --offset 0.4U"),
    ("cone3", "extrude --faces 0,1,2,3 --offset -0.5U"),
    # A cone's base edge dissolved: the side triangle beside it folds into an edge.
    ("cone6", "dissolve --edges 4-3"),
    # Two beveled edges running on in one line through a point of four edges.
    ("grid3", "bevel --edges 4-7,1-4 --width 0.19U --segments 1"),
    # A tetrahedron's edge dissolved: the two triangles left over the same corners are one.
    ("cone3", "dissolve --edges 2-1"),
]

# Cases of random_blender.py (batch seed, case number, the batch's KIND and SHAPE) that
# showed a difference once.
RANDOM_CASES = [
    (4, 69, None, None),  # offset lines Blender's intersection calls coplanar (within 1e-6)
    (5, 30, "loopcut", None),  # a loop cut's sides joined by edges beside the ring, cut too
    (5, 95, "loopcut", None),
    (5, 59, "loopcut", None),  # a ring touching itself at a point: Blender leaves it uncut
    (5, 100, "loopcut", None),
    # Faces turning back on themselves at a beveled point (reflex corners on Suzanne): the
    # offsets go to the faces' inner sides.
    (6, 11, "bevel", "monkey"),
    (7, 35, "bevel2", "monkey"),
    (7, 16, "bevel2", "monkey"),
    (6, 41, "bevel", "monkey"),  # a slide past a short edge's end stops 5e-5 short of it
    (8, 64, None, None),  # an open tube's rims bridged through it
    # Loops of different lengths bridged: two tubes' facing rims, and two holes in a grid.
    (12, 0, "bridge", "tubes"),
    (12, 4, "bridge", "tubes"),
    (12, 8, "bridge", "tubes"),
    (12, 13, "bridge", "tubes"),
    (12, 23, "bridge", "tubes"),
    (12, 1, "bridge", "holes2"),
    (12, 10, "bridge", "holes2"),
    (12, 12, "bridge", "holes2"),
    (12, 15, "bridge", "holes2"),
    # Bevels ending on the border at points of three or more faces: one beveled edge (the
    # point opens into a polygon closed by the border), two (the border edges share one
    # point between them).
    (40, 14, "bevel", "holes"),
    (40, 20, "bevel", "holes"),
    (41, 6, "bevel2", "holes"),
    (41, 10, "bevel2", "holes"),
    (41, 11, "bevel2", "holes2"),
    # A beveled edge and the edge beside it within 2° of one direction: the point lies on
    # the beveled edge.
    (40, 2, "bevel", "monkey"),
    # Every edge between two beveled ones flat with its faces: their offset lines meet as
    # if there were none.
    (41, 17, "bevel2", "disc"),
]

# Cases added after the random ones: bevels at a point on the border with more beveled edges
# (on fans of quads round it), by a straight corner of a face, and at points of two edges;
# border edges named to a bevel or a dissolve; insets of regions with no border and loop
# cuts of edges with no quad; merges of points that share a face; dissolves of faces;
# subdivisions of polygons.
LATER_CASES = [
    ("fan4", "bevel --edges 0-2,0-3,0-4 --width 0.15U --segments 1"),
    ("fan4", "bevel --edges 0-2,0-4 --width 0.15U --segments 2"),
    ("fan4", "bevel --edges 0-3 --width 0.2U --segments 3"),
    ("fan4", "bevel --edges 0-2,0-3 --width 0.1U --segments 2"),
    ("fan4", "bevel --edges 0-2,0-3,0-4 --width 0.1U --segments 2"),
    ("fan4", "bevel --edges 0-2,0-3,0-4 --width 0.08U --segments 5"),
    ("fan5", "bevel --edges 0-2,0-3,0-4,0-5 --width 0.1U --segments 1"),
    ("fan5", "bevel --edges 0-2,0-3,0-4,0-5 --width 0.1U --segments 4"),
    ("fan5", "bevel --edges 0-2,0-4,0-5 --width 0.1U --segments 3"),
    ("fan5", "bevel --edges 0-3,0-5 --width 0.1U --segments 3"),
    ("fan3", "bevel --edges 0-2,0-3 --width 0.1U --segments 3"),
    ("fan3", "bevel --edges 0-3 --width 0.1U --segments 1"),
    # A beveled edge running on in line with the unbeveled edge beside it (a straight corner
    # of a face): the new point lies square to both, in the face.
    ("tee", "bevel --edges 1-2 --width 0.2U --segments 2"),
    ("tee", "bevel --edges 1-0 --width 0.15U --segments 1"),
    # Bevels ending at a point of two edges: each face takes a point square to the beveled
    # edge and a made-up point on the other edge closes a fan; both edges beveled.
    ("splitbox", "bevel --edges 8-1 --width 0.3U --segments 1"),
    ("splitbox", "bevel --edges 8-1 --width 0.3U --segments 3"),
    ("bentbox", "bevel --edges 8-1 --width 0.3U --segments 2"),
    ("bentbox", "bevel --edges 8-0 --width 0.25U --segments 1"),
    ("splitbox", "bevel --edges 8-1,8-0 --width 0.3U --segments 2"),
    ("bentbox", "bevel --edges 8-1,8-0 --width 0.2U --segments 1"),
    ("bentbox", "bevel --edges 8-1,8-0 --width 0.2U --segments 3"),
    # Border edges (one face) named to a bevel or a dissolve: passed over beside inner edges,
    # and the cage left as it is where every named edge is on the border.
    ("grid", "bevel --edges 0-1,1-6 --width 0.2U --segments 2"),
    ("fan4", "bevel --edges 0-1,0-3 --width 0.15U --segments 3"),
    ("fan5", "bevel --edges 0-6,0-2,0-4 --width 0.1U --segments 2"),
    ("grid", "bevel --edges 0-1,1-2 --width 0.2U --segments 1"),
    ("grid", "dissolve --edges 0-1,1-6"),
    ("fan4", "dissolve --edges 0-1,0-2,0-3"),
    ("disc6", "dissolve --edges 1-2,0-2"),
    ("disc6", "dissolve --edges 0-1,3-4"),
    ("grid", "dissolve --edges 5-10"),
    # A region inset whose faces enclose the whole cage: no border, left as it is.
    ("box", "inset --faces 0,1,2,3,4,5 --thickness 0.2U"),
    ("prism", "inset --faces 0,1,2,3,4 --thickness 0.1U"),
    # Loop cuts through an edge with no quad on either side (a disc's spoke, a cone's base
    # edge between a triangle and the base): no ring, left as it is.
    ("disc6", "loopcut --edge 0,1 --cuts 2"),
    ("cone6", "loopcut --edge 1,2 --cuts 1"),
    # Merges where a face holds a merged point and the point it merges into, not side by
    # side (Blender's weld splits the face between them), or two merged points without
    # that point (the face goes).
    ("ngons", "merge --vertices 9,12 --at centre"),
    ("ngons", "merge --vertices 0,9,12 --at first"),
    ("ngons", "merge --vertices 2,5,9 --at centre"),
    # A merge by distance with no two points that near: left as it is.
    ("grid", "merge --distance 0.05U"),
    # Faces dissolved: every end of a dissolved edge left between two edges goes, beside a
    # face that keeps both its edges there too (Blender's dissolve of edges keeps that one).
    ("grid", "dissolve --faces 2,6,7"),
    ("box", "dissolve --faces 0,1"),
    # A polygon of seven sides subdivided: with three or more cut edges it only takes the
    # points into them (Blender splits a polygon of five or more sides only across two).
    ("ngons", "subdivide --faces 0 --cuts 2"),
    ("ngons", "subdivide --faces 2,3 --cuts 1"),
    # Edges dissolved round a point until its faces are one: the edge left between two of
    # them goes too (Blender's join takes every edge between the faces it joins), and the
    # point with it.
    ("cone6", "dissolve --edges 1-0,5-0"),
    ("box", "dissolve --edges 3-7,6-7"),
]


def fixture(directory, k, name, args, creased=(), seed=1000):
    """Writes fixed case k (a cage by name, placed by a seeded random motion unless the name
    ends in "!") and Blender's result; its line of `cases.tsv`."""
    points, faces = cage(name.rstrip("!"))
    if name.endswith("!"):
        name, scale = name[:-1], 1.0
        args = " ".join(moved_argument(a, None, 1.0) if a.endswith("U") else a
                        for a in args.split())
    else:
        points, scale = placed(points, seed + k)
        args = " ".join(moved_argument(a, seed + k, scale) for a in args.split())
    stem = "%02d-%s-%s" % (k, name, args.split()[0])
    bm = build(points, faces, creased)
    write_obj(os.path.join(directory, stem + ".in.obj"), bm)
    apply(bm, args.split()[0], args.split()[1:])
    write_obj(os.path.join(directory, stem + ".blender.obj"), bm)
    return stem + "\t" + args + "\n"


def fixtures(directory, seed=1000):
    """Writes each case's input (placed by a seeded random motion), Blender's result, and
    `cases.tsv`: name, tool and arguments. The random cases follow the fixed ones and the
    later cases follow them, so that earlier cases keep their numbers."""
    os.makedirs(directory, exist_ok=True)
    lines = [fixture(directory, k, name, args, *creased, seed=seed)
             for k, (name, args, *creased) in enumerate(CASES)]
    import random_blender  # it imports this module
    for k, (batch, number, kind, shape) in enumerate(RANDOM_CASES, start=len(CASES)):
        made = random_blender.case(batch, number, kind, shape)
        if made is None:
            raise SystemExit(f"random case {batch}/{number} has no tool")
        stem, points, faces, args = made
        stem = "%02d-%s" % (k, stem)
        if not random_blender.write_case(directory, stem, points, faces, args):
            raise SystemExit(f"Blender refused random case {batch}/{number}")
        lines.append(stem + "\t" + args + "\n")
    first = len(CASES) + len(RANDOM_CASES)
    lines += [fixture(directory, k, name, args, seed=seed)
              for k, (name, args) in enumerate(LATER_CASES, start=first)]
    with open(os.path.join(directory, "cases.tsv"), "w") as out:
        out.write("".join(lines))


def main():
    if sys.argv[1] == "--fixtures":
        return fixtures(sys.argv[2], *[int(a) for a in sys.argv[3:4]])
    src, dst, op = sys.argv[1:4]
    verts, faces, creases = read_obj(src)
    bm = build(verts, faces, creases)
    apply(bm, op, sys.argv[4:])
    write_obj(dst, bm)


if __name__ == "__main__":
    main()
