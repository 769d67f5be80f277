"""Random tools on Blender's Suzanne, with Blender's results: cases beside the committed ones.

    python random_monkey.py DIR COUNT SEED     (KIND=loopcut etc. for one tool only)
    KNOTWORK_CAGE_CASES=DIR cargo test --test it -- every_tool_matches_blender

Needs `bpy` (Python 3.11), as blender_cage.py. Each case is a random region extruded or inset
(as one or each on its own), a loop cut through a random quad edge, a bevel of one edge or of
two edges at a point, a dissolve of an edge, a delete of a region, or a merge of an edge's ends.
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_cage as bc  # noqa: E402


def monkey():
    return bc.cage("monkey")

def main(directory, count, seed):
    rnd = random.Random(seed)
    v, f = monkey()
    bm0 = bc.build(v, f)
    bm0.edges.ensure_lookup_table(); bm0.verts.index_update(); bm0.faces.index_update()
    edges = [(e.verts[0].index, e.verts[1].index) for e in bm0.edges]
    quad_edges = [(e.verts[0].index, e.verts[1].index) for e in bm0.edges
                  if len(e.link_faces) == 2 and all(len(x.verts) == 4 for x in e.link_faces)]
    manifold_edges = [(e.verts[0].index, e.verts[1].index) for e in bm0.edges if len(e.link_faces) == 2]
    def region(n):
        start = rnd.randrange(len(f))
        got = {start}
        for _ in range(100):
            if len(got) >= n: break
            face = bm0.faces[rnd.choice(sorted(got))]
            nb = [l.face.index for e in face.edges for l in e.link_loops]
            got.add(rnd.choice(nb))
        return ",".join(map(str, sorted(got)))
    ops = []
    for k in range(count):
        kind = os.environ.get("KIND") or rnd.choice(["extrude", "inset", "insetI", "loopcut", "bevel", "bevel2", "dissolve", "delete", "merge", "mergef"])
        if kind == "extrude":
            args = "extrude --faces %s --offset %.6g" % (region(rnd.randint(1, 6)), rnd.uniform(-0.2, 0.3))
        elif kind == "inset":
            args = "inset --faces %s --thickness %.6g" % (region(rnd.randint(1, 6)), rnd.uniform(0.005, 0.03))
        elif kind == "insetI":
            args = "inset --faces %s --thickness %.6g --individual" % (region(rnd.randint(1, 4)), rnd.uniform(0.005, 0.02))
        elif kind == "loopcut":
            a, b = rnd.choice(quad_edges)
            args = "loopcut --edge %d,%d --cuts %d" % (a, b, rnd.randint(1, 3))
        elif kind == "bevel":
            a, b = rnd.choice(manifold_edges)
            args = "bevel --edges %d-%d --width %.6g --segments %d" % (a, b, rnd.uniform(0.005, 0.02), rnd.randint(1, 3))
        elif kind == "bevel2":
            # two adjacent edges sharing a vertex
            from collections import defaultdict
            at = defaultdict(list)
            for e in manifold_edges:
                at[e[0]].append(e); at[e[1]].append(e)
            vs = [x for x in at if len(at[x]) >= 2]
            x = rnd.choice(vs)
            (a, b), (c, d) = rnd.sample(at[x], 2)
            args = "bevel --edges %d-%d,%d-%d --width %.6g --segments %d" % (a, b, c, d, rnd.uniform(0.005, 0.015), rnd.randint(1, 2))
        elif kind == "dissolve":
            a, b = rnd.choice(manifold_edges)
            args = "dissolve --edges %d-%d" % (a, b)
        elif kind == "delete":
            args = "delete --faces %s" % region(rnd.randint(1, 5))
        else:
            a, b = rnd.choice(edges)
            args = "merge --vertices %d,%d --at %s" % (a, b, "centre" if kind == "merge" else "first")
        ops.append(args)
    os.makedirs(directory, exist_ok=True)
    lines = []
    for k, args in enumerate(ops):
        stem = "m%03d-monkey-%s" % (k, args.split()[0])
        bm = bc.build(v, f)
        bc.write_obj(os.path.join(directory, stem + ".in.obj"), bm)
        try:
            bc.apply(bm, args.split()[0], args.split()[1:])
        except BaseException as e:
            print("blender refused", stem, args, e)
            continue
        bc.write_obj(os.path.join(directory, stem + ".blender.obj"), bm)
        lines.append(stem + "\t" + args + "\n")
    open(os.path.join(directory, "cases.tsv"), "w").write("".join(lines))

if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]))
