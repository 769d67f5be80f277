"""Random tools on Blender's own meshes, in general position, with Blender's results: cases
beside the committed ones.

    python random_blender.py DIR COUNT SEED     (KIND=loopcut etc. for one tool only,
                                                 SHAPE=monkey etc. for one mesh only)
    KNOTWORK_CAGE_CASES=DIR cargo test --test it -- every_tool_matches_blender

Needs `bpy` (Python 3.11), as blender_cage.py. The meshes are made by bmesh's primitive
operators with random sizes: Suzanne, a UV sphere (triangle fans at the poles), an ico sphere
(all triangles), a cylinder (n-gon ends) and a cone (a triangle fan at its tip), a grid, a cube
cut by subdivide_edges, and a circle filled with triangles. Each is put in general position by
a random rotation, scale and shift. Each case is a random region extruded or inset (as one or
each on its own), a loop cut through a random quad edge, a bevel of one edge or of two edges at
a point, a dissolve of an edge, a delete of a region, or a merge of an edge's ends; lengths are
fractions of the mesh's mean edge length.
"""
import math
import os
import random
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_cage as bc  # noqa: E402
import bmesh  # noqa: E402

SHAPES = ["monkey", "uvsphere", "icosphere", "cylinder", "cone", "grid", "cube", "disc",
          "tube", "holes", "holes2", "tubes"]
KINDS = ["extrude", "extrudeI", "inset", "insetI", "insetD", "loopcut", "bevel", "bevel2",
         "dissolve", "delete", "merge", "mergef", "bridge"]
# Batches before seed 8 drew from the first eight meshes and these ten tools, and those before
# seed 12 from the first ten meshes; they keep them, so that a case once found is made again
# the same.
SHAPES_BEFORE_8 = SHAPES[:8]
SHAPES_BEFORE_12 = SHAPES[:10]
KINDS_BEFORE_8 = ["extrude", "inset", "insetI", "loopcut", "bevel", "bevel2", "dissolve",
                  "delete", "merge", "mergef"]


def primitive(shape, rnd):
    """A Blender primitive of random proportions, as (points, faces, description)."""
    bm = bmesh.new()
    if shape == "monkey":
        bmesh.ops.create_monkey(bm)
        what = "monkey"
    elif shape == "uvsphere":
        u, v = rnd.randint(5, 12), rnd.randint(3, 8)
        bmesh.ops.create_uvsphere(bm, u_segments=u, v_segments=v, radius=1.0)
        what = "uvsphere %d×%d" % (u, v)
    elif shape == "icosphere":
        n = rnd.randint(1, 2)
        bmesh.ops.create_icosphere(bm, subdivisions=n, radius=1.0)
        what = "icosphere %d" % n
    elif shape in ("cylinder", "cone"):
        n = rnd.randint(3, 10)
        r2 = rnd.uniform(0.3, 1.5) if shape == "cylinder" else 0.0
        bmesh.ops.create_cone(bm, cap_ends=True, cap_tris=False, segments=n, radius1=1.0,
                              radius2=r2, depth=rnd.uniform(0.5, 3.0))
        if shape == "cylinder" and rnd.random() < 0.5:
            # Rings across the side: one or two horizontal cuts.
            side = [e for e in bm.edges if all(len(f.verts) == 4 for f in e.link_faces)
                    and len(e.link_faces) == 2 and abs(e.verts[0].co.z - e.verts[1].co.z) > 1e-6]
            bmesh.ops.subdivide_edges(bm, edges=side, cuts=rnd.randint(1, 2), use_grid_fill=True)
        what = "%s %d" % (shape, n)
    elif shape == "tube":
        # An open tube: two rims to bridge, cut across once or twice.
        n = rnd.randint(4, 10)
        bmesh.ops.create_cone(bm, cap_ends=False, cap_tris=False, segments=n, radius1=1.0,
                              radius2=rnd.uniform(0.5, 1.5), depth=rnd.uniform(1.0, 3.0))
        side = [e for e in bm.edges if len(e.link_faces) == 2]
        bmesh.ops.subdivide_edges(bm, edges=side, cuts=rnd.randint(1, 2), use_grid_fill=True)
        what = "tube %d" % n
    elif shape == "holes":
        # A grid with two faces two or more apart taken out: two square holes.
        x, y = rnd.randint(6, 9), rnd.randint(3, 5)
        bmesh.ops.create_grid(bm, x_segments=x, y_segments=y, size=1.0)
        bm.faces.ensure_lookup_table()
        row = rnd.randrange(1, y - 1)
        gone = [bm.faces[row * x + 1], bm.faces[row * x + x - 2]]
        bmesh.ops.delete(bm, geom=gone, context="FACES_ONLY")
        for v in bm.verts:
            v.co.z = 0.2 * rnd.uniform(-1, 1)
        what = "holes %d×%d" % (x, y)
    elif shape == "holes2":
        # A grid with holes of different sizes: one face, and a block of 1×2 to 2×3 faces
        # two or more faces away (rims of 4 and of 6 to 10 points, to bridge).
        x, y = rnd.randint(7, 10), rnd.randint(5, 7)
        bmesh.ops.create_grid(bm, x_segments=x, y_segments=y, size=1.0)
        bm.faces.ensure_lookup_table()
        row = rnd.randrange(1, y - 2)
        w, h = rnd.choice([(2, 1), (1, 2), (2, 2), (3, 1), (3, 2)])
        gone = [bm.faces[row * x + 1]]
        gone += [bm.faces[(row + r) * x + x - 1 - w + c] for r in range(h) for c in range(w)]
        bmesh.ops.delete(bm, geom=gone, context="FACES_ONLY")
        for v in bm.verts:
            v.co.z = 0.2 * rnd.uniform(-1, 1)
        what = "holes2 %d×%d, %d×%d" % (x, y, w, h)
    elif shape == "tubes":
        # Two open tubes of different segment counts one above the other, their facing
        # rims (or any two rims) to bridge.
        n1, n2 = rnd.sample(range(4, 13), 2)
        for n, z in ((n1, 0.0), (n2, rnd.uniform(2.5, 4.0))):
            made = bmesh.ops.create_cone(bm, cap_ends=False, cap_tris=False, segments=n,
                                         radius1=rnd.uniform(0.7, 1.3),
                                         radius2=rnd.uniform(0.7, 1.3), depth=1.0)
            turn = rnd.uniform(0, 6.3)
            for v in made["verts"]:
                x, y = v.co.x, v.co.y
                v.co.x = x * math.cos(turn) - y * math.sin(turn)
                v.co.y = x * math.sin(turn) + y * math.cos(turn)
                v.co.z += z
        what = "tubes %d, %d" % (n1, n2)
    elif shape == "grid":
        x, y = rnd.randint(2, 7), rnd.randint(2, 7)
        bmesh.ops.create_grid(bm, x_segments=x, y_segments=y, size=1.0)
        for v in bm.verts:
            v.co.z = 0.2 * rnd.uniform(-1, 1)
        what = "grid %d×%d" % (x, y)
    elif shape == "cube":
        bmesh.ops.create_cube(bm, size=1.0)
        cuts = rnd.randint(1, 2)
        bmesh.ops.subdivide_edges(bm, edges=list(bm.edges), cuts=cuts, use_grid_fill=True)
        what = "cube cut %d" % cuts
    else:
        n = rnd.randint(5, 12)
        bmesh.ops.create_circle(bm, cap_ends=True, cap_tris=True, segments=n, radius=1.0)
        what = "disc %d" % n
    # Uneven: every point moved a little, so no two faces are alike.
    for v in bm.verts:
        v.co.x *= 1.0 + 0.05 * rnd.uniform(-1, 1)
        v.co.y *= 1.0 + 0.05 * rnd.uniform(-1, 1)
        v.co.z += 0.03 * rnd.uniform(-1, 1)
    bm.verts.index_update()
    points = [tuple(v.co) for v in bm.verts]
    faces = [[v.index for v in f.verts] for f in bm.faces]
    return points, faces, what


def open_loops(bm):
    """The closed loops of open edges, each as its vertices in order."""
    bm.edges.index_update()
    bm.verts.index_update()
    left = {e for e in bm.edges if len(e.link_faces) == 1}
    loops = []
    while left:
        e = min(left, key=lambda x: x.index)
        start, at = e.verts[0], e.verts[1]
        chain = [start.index]
        left.discard(e)
        while at is not start:
            chain.append(at.index)
            nxt = [x for x in at.link_edges if x in left]
            if not nxt:
                break
            left.discard(nxt[0])
            at = nxt[0].other_vert(at)
        if at is start:
            loops.append(chain)
    return loops


def random_tool(kind, bm0, rnd, unit, facing=False):
    """The command line of a random tool of `kind` on the bmesh `bm0`, or None."""
    edges = [(e.verts[0].index, e.verts[1].index) for e in bm0.edges]
    quad_edges = [(e.verts[0].index, e.verts[1].index) for e in bm0.edges
                  if len(e.link_faces) == 2 and all(len(x.verts) == 4 for x in e.link_faces)]
    manifold_edges = [(e.verts[0].index, e.verts[1].index) for e in bm0.edges
                      if len(e.link_faces) == 2]

    def region(n):
        got = {rnd.randrange(len(bm0.faces))}
        for _ in range(100):
            if len(got) >= n:
                break
            face = bm0.faces[rnd.choice(sorted(got))]
            got.add(rnd.choice([l.face.index for e in face.edges for l in e.link_loops]))
        return ",".join(map(str, sorted(got)))

    if kind == "extrude":
        offset = rnd.uniform(-0.4, 0.6) * unit
        return "extrude --faces %s --offset %.9g" % (region(rnd.randint(1, 6)), offset)
    if kind == "extrudeI":
        offset = rnd.uniform(-0.4, 0.6) * unit
        return "extrude --faces %s --offset %.9g --individual" % (
            region(rnd.randint(1, 4)), offset)
    if kind == "insetD":
        thickness = rnd.uniform(0.05, 0.2) * unit
        depth = rnd.uniform(-0.3, 0.3) * unit
        return "inset --faces %s --thickness %.9g --depth %.9g%s" % (
            region(rnd.randint(1, 5)), thickness, depth,
            " --individual" if rnd.random() < 0.5 else "")
    if kind == "bridge":
        # Two open loops: the rims of the mesh's holes, or of two faces taken out.
        loops = open_loops(bm0)
        if len(loops) < 2:
            return None
        if facing:
            # The two loops of different lengths that face each other: the nearest centres,
            # a holed grid's rim (the longest of its three loops) left out.
            if len(loops) == 3:
                loops.remove(max(loops, key=len))
            centre = lambda l: sum((bm0.verts[v].co for v in l), bm0.verts[l[0]].co * 0) / len(l)
            first, second = min(((a, b) for a in loops for b in loops if len(a) != len(b)),
                                key=lambda p: (centre(p[0]) - centre(p[1])).length)
            if rnd.random() < 0.5:
                first, second = second, first
        else:
            first, second = rnd.sample(loops, 2)
        return "bridge --loop1 %s --loop2 %s" % (
            ",".join(map(str, first)), ",".join(map(str, second)))
    if kind == "inset":
        thickness = rnd.uniform(0.05, 0.25) * unit
        return "inset --faces %s --thickness %.9g" % (region(rnd.randint(1, 6)), thickness)
    if kind == "insetI":
        thickness = rnd.uniform(0.05, 0.2) * unit
        return "inset --faces %s --thickness %.9g --individual" % (
            region(rnd.randint(1, 4)), thickness)
    if kind == "loopcut":
        if not quad_edges:
            return None
        a, b = rnd.choice(quad_edges)
        return "loopcut --edge %d,%d --cuts %d" % (a, b, rnd.randint(1, 3))
    if kind == "bevel":
        if not manifold_edges:
            return None
        a, b = rnd.choice(manifold_edges)
        return "bevel --edges %d-%d --width %.9g --segments %d" % (
            a, b, rnd.uniform(0.05, 0.2) * unit, rnd.randint(1, 3))
    if kind == "bevel2":
        at = defaultdict(list)
        for e in manifold_edges:
            at[e[0]].append(e)
            at[e[1]].append(e)
        vs = sorted(x for x in at if len(at[x]) >= 2)
        if not vs:
            return None
        (a, b), (c, d) = rnd.sample(at[rnd.choice(vs)], 2)
        return "bevel --edges %d-%d,%d-%d --width %.9g --segments %d" % (
            a, b, c, d, rnd.uniform(0.05, 0.15) * unit, rnd.randint(1, 2))
    if kind == "dissolve":
        if not manifold_edges:
            return None
        a, b = rnd.choice(manifold_edges)
        return "dissolve --edges %d-%d" % (a, b)
    if kind == "delete":
        return "delete --faces %s" % region(rnd.randint(1, 5))
    a, b = rnd.choice(edges)
    return "merge --vertices %d,%d --at %s" % (a, b, "centre" if kind == "merge" else "first")


def case(seed, k, kind=None, shape=None):
    """Case k of batch `seed` (each case draws from its own generator, so one can be made
    again on its own; `kind` and `shape`, or KIND and SHAPE, fix the tool and the mesh as for
    the batch): (stem, points, faces, arguments), or None where the mesh has no edge the
    tool needs."""
    rnd = random.Random(seed * 100003 + k)
    shape = shape or os.environ.get("SHAPE") or rnd.choice(
        SHAPES if seed >= 12 else SHAPES_BEFORE_12 if seed >= 8 else SHAPES_BEFORE_8)
    kind = kind or os.environ.get("KIND") or rnd.choice(
        KINDS if seed >= 8 else KINDS_BEFORE_8)
    points, faces, what = primitive(shape, rnd)
    points, _ = bc.placed(points, seed * 1000 + k)
    bm0 = bc.build(points, faces)
    bm0.verts.index_update()
    bm0.faces.index_update()
    unit = sum(e.calc_length() for e in bm0.edges) / len(bm0.edges)
    args = random_tool(kind, bm0, rnd, unit, facing=shape in ("holes2", "tubes"))
    if args is None:
        return None
    return "r%d-%03d-%s-%s" % (seed, k, shape, args.split()[0]), points, faces, args


def write_case(directory, stem, points, faces, args):
    """Writes the case's input and Blender's result; False where Blender refused."""
    bm = bc.build(points, faces)
    bc.write_obj(os.path.join(directory, stem + ".in.obj"), bm)
    try:
        bc.apply(bm, args.split()[0], args.split()[1:])
    except BaseException as e:  # Blender refused: no case
        print("blender refused", stem, args, e)
        os.remove(os.path.join(directory, stem + ".in.obj"))
        return False
    bc.write_obj(os.path.join(directory, stem + ".blender.obj"), bm)
    return True


def main(directory, count, seed):
    os.makedirs(directory, exist_ok=True)
    lines = []
    for k in range(count):
        made = case(seed, k)
        if made is None:
            continue
        stem, points, faces, args = made
        if write_case(directory, stem, points, faces, args):
            lines.append(stem + "\t" + args + "\n")
            print(stem, args)
    open(os.path.join(directory, "cases.tsv"), "w").write("".join(lines))


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]))
