// The peers of `cargo bench --bench kernel_eval`: openNURBS (rhino3dm, WebAssembly) and
// verb-nurbs (JavaScript) evaluating the same bicubic rational 8 x 8 surface in node, one thread.
//
//   npm install --prefix benches/peers        (rhino3dm and verb-nurbs at the versions pinned)
//   node benches/peers/kernel_peers.mjs [grid]
//
// Prints one line per figure, `name M/s`, which kernel_eval reads and divides into its own.
import { createRequire } from "node:module";
const require = createRequire(import.meta.url);
const rhino3dm = require("rhino3dm");
// verb-nurbs 3.0.3 reads a browser global `window` when it loads.
globalThis.window ??= globalThis;
const verb = require("verb-nurbs");

const grid = Number(process.argv[2] ?? 400);
const n = 3 + 5; // 8 x 8 control points, degree 3

// The benchmark surface of benches/kernel_eval.rs.
const points = [];
const weights = [];
for (let i = 0; i < n; i++) {
  const rowP = [];
  const rowW = [];
  for (let j = 0; j < n; j++) {
    rowP.push([i, j, Math.sin(0.7 * i) + Math.cos(0.5 * j)]);
    rowW.push(0.5 + ((i * 7 + j * 3) % 5) * 0.4);
  }
  points.push(rowP);
  weights.push(rowW);
}
// Uniform clamped knots on [0, 1]: degree + 1 zeros, interior steps, degree + 1 ones.
const knots = [];
const spans = n - 3;
for (let k = 0; k < n + 4; k++) knots.push(Math.min(Math.max(k - 3, 0), spans) / spans);

const ts = Array.from({ length: grid }, (_, k) => k / (grid - 1));

function rate(count, f) {
  f(); // warm up
  const times = [];
  for (let r = 0; r < 3; r++) {
    const t0 = process.hrtime.bigint();
    f();
    times.push(Number(process.hrtime.bigint() - t0) / 1e9);
  }
  times.sort((a, b) => a - b);
  return count / times[1] / 1e6;
}

// verb-nurbs takes Euclidean points and weights.
const vs = verb.geom.NurbsSurface.byKnotsControlPointsWeights(3, 3, knots, knots, points, weights);
const probe = vs.point(0.3, 0.7);

// openNURBS: its knot vector leaves out the two superfluous end knots.
const rhino = await rhino3dm();
const rs = rhino.NurbsSurface.create(3, true, 4, 4, n, n);
for (let k = 0; k < n + 2; k++) {
  rs.knotsU().set(k, knots[k + 1]);
  rs.knotsV().set(k, knots[k + 1]);
}
for (let i = 0; i < n; i++)
  for (let j = 0; j < n; j++) {
    const [x, y, z] = points[i][j];
    const w = weights[i][j];
    rs.points().set(i, j, [x * w, y * w, z * w, w]);
  }
const check = rs.pointAt(0.3, 0.7);
const off = Math.hypot(check[0] - probe[0], check[1] - probe[1], check[2] - probe[2]);
console.log(`probe ${probe[0]} ${probe[1]} ${probe[2]}`);
console.log(`agree ${off}`);

const cells = grid * grid;
let sink = 0;
console.log(
  `opennurbs_points ${rate(cells, () => {
    for (const u of ts) for (const v of ts) sink += rs.pointAt(u, v)[2];
  })}`,
);
console.log(
  `opennurbs_normals ${rate(cells, () => {
    // normalAt alone (openNURBS finds the point on the way): the peer's best case.
    for (const u of ts) for (const v of ts) sink += rs.normalAt(u, v)[2];
  })}`,
);
const small = ts.filter((_, k) => k % 2 === 0);
console.log(
  `verb_second_derivatives ${rate(small.length * small.length, () => {
    for (const u of small) for (const v of small) sink += vs.derivatives(u, v, 2)[2][0][2];
  })}`,
);
if (!Number.isFinite(sink)) console.log("sink", sink);
