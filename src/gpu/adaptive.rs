//! View-adaptive tessellation of one Bézier patch: how many segments each edge and the interior
//! get for a screen-space error, and the crack-free layout of vertices and triangles that those
//! counts give. This is the f64/integer reference of `shaders/adaptive.wgsl`; both compute the
//! same counts from the same control points and the same triangles from the same counts.
//!
//! # Layout
//! A patch with edge counts `edges = [e0, e1, e2, e3]` (edge 0: t = 0, along s; edge 1: s = 1,
//! along t; edge 2: t = 1, along s; edge 3: s = 0, along t) and interior counts `inner = [nu, nv]`
//! (each at least 2) has
//! - the interior grid vertices (i, j), 1 ≤ i ≤ nu − 1, 1 ≤ j ≤ nv − 1, at (i / nu, j / nv), first,
//!   row by row (`(i − 1)(nv − 1) + j − 1`);
//! - then edge k's e_k + 1 vertices, in increasing parameter m / e_k (the corners appear on both
//!   edges that meet there, at the same point).
//!
//! Two patches sharing an edge give it the same count (it is computed from the edge's control
//! points alone, in the canonical direction) and so the same vertices: no cracks and no
//! T-junctions, whatever counts their interiors have.
//!
//! Triangles: the interior grid's quads, two triangles each; then between each edge and the
//! nearest interior row or column a strip, triangulated by merging the two polylines in order of
//! their segments' midpoints (a zipper; ties put the edge's segment first). A strip between an
//! edge of e segments and an inner polyline of m segments has e + m triangles.

use glam::{DVec2, DVec3, DVec4};

/// Segment counts of one patch: the four edges and the interior (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PatchLevels {
    pub edges: [u32; 4],
    pub inner: [u32; 2],
}

/// How an edge runs in the patch's (s, t): start, direction.
const EDGE_FRAME: [([f64; 2], [f64; 2]); 4] = [
    ([0.0, 0.0], [1.0, 0.0]),
    ([1.0, 0.0], [0.0, 1.0]),
    ([0.0, 1.0], [1.0, 0.0]),
    ([0.0, 0.0], [0.0, 1.0]),
];

impl PatchLevels {
    /// Interior counts below 2 are raised to 2 and edge counts below 1 to 1.
    pub fn new(edges: [u32; 4], inner: [u32; 2]) -> Self {
        Self {
            edges: edges.map(|e| e.max(1)),
            inner: inner.map(|n| n.max(2)),
        }
    }

    fn interior_vertices(&self) -> u32 {
        (self.inner[0] - 1) * (self.inner[1] - 1)
    }

    /// Segments of the inner polyline facing edge k: nu − 2 for edges 0 and 2, nv − 2 for 1, 3.
    fn inner_segments(&self, edge: usize) -> u32 {
        self.inner[edge % 2] - 2
    }

    /// Vertices of the layout.
    pub fn vertex_count(&self) -> u32 {
        self.interior_vertices() + self.edges.iter().map(|e| e + 1).sum::<u32>()
    }

    /// Triangles of the layout.
    pub fn triangle_count(&self) -> u32 {
        let [nu, nv] = self.inner;
        2 * (nu - 2) * (nv - 2)
            + (0..4)
                .map(|k| self.edges[k] + self.inner_segments(k))
                .sum::<u32>()
    }

    /// The first vertex of edge k.
    fn edge_base(&self, edge: usize) -> u32 {
        self.interior_vertices() + self.edges[..edge].iter().map(|e| e + 1).sum::<u32>()
    }

    /// Local index of interior grid vertex (i, j), 1 ≤ i ≤ nu − 1, 1 ≤ j ≤ nv − 1.
    fn interior(&self, i: u32, j: u32) -> u32 {
        (i - 1) * (self.inner[1] - 1) + (j - 1)
    }

    /// Local index of vertex l (0 ≤ l ≤ m) of the inner polyline facing edge k.
    fn inner_vertex(&self, edge: usize, l: u32) -> u32 {
        let [nu, nv] = self.inner;
        match edge {
            0 => self.interior(l + 1, 1),
            1 => self.interior(nu - 1, l + 1),
            2 => self.interior(l + 1, nv - 1),
            _ => self.interior(1, l + 1),
        }
    }

    /// (s, t) of local vertex `k`, and for an edge vertex the edge, its index m and count e
    /// (the shader evaluates those on the boundary curve, from the canonical end).
    pub fn vertex(&self, k: u32) -> (DVec2, Option<(usize, u32, u32)>) {
        let interior = self.interior_vertices();
        if k < interior {
            let (i, j) = (k / (self.inner[1] - 1) + 1, k % (self.inner[1] - 1) + 1);
            return (
                DVec2::new(
                    f64::from(i) / f64::from(self.inner[0]),
                    f64::from(j) / f64::from(self.inner[1]),
                ),
                None,
            );
        }
        let mut rest = k - interior;
        for (edge, (&e, &(start, direction))) in self.edges.iter().zip(&EDGE_FRAME).enumerate() {
            if rest <= e {
                let a = f64::from(rest) / f64::from(e);
                let st = DVec2::from(start) + DVec2::from(direction) * a;
                return (st, Some((edge, rest, e)));
            }
            rest -= e + 1;
        }
        (DVec2::ZERO, None)
    }

    /// Local vertex indices of triangle `k`, counter-clockwise in (s, t) (so facing Su × Sv),
    /// or `None` past [`Self::triangle_count`].
    pub fn triangle(&self, k: u32) -> Option<[u32; 3]> {
        let [nu, nv] = self.inner;
        let quads = (nu - 2) * (nv - 2);
        if k < 2 * quads {
            // The interior grid's quads, as the fixed tessellation splits them.
            let quad = k / 2;
            let (i, j) = (quad / (nv - 2) + 1, quad % (nv - 2) + 1);
            let a = self.interior(i, j);
            let c = self.interior(i + 1, j + 1);
            return Some(if k.is_multiple_of(2) {
                [a, self.interior(i + 1, j), c]
            } else {
                [a, c, self.interior(i, j + 1)]
            });
        }
        let mut rest = k - 2 * quads;
        for edge in 0..4 {
            let count = self.edges[edge] + self.inner_segments(edge);
            if rest < count {
                return Some(self.counter_clockwise(self.strip_triangle(edge, rest)));
            }
            rest -= count;
        }
        None
    }

    /// Triangle `k` of edge `edge`'s strip: its boundary segments' triangles first, then its
    /// inner segments' (see the module doc for the merge).
    fn strip_triangle(&self, edge: usize, k: u32) -> [u32; 3] {
        let e = self.edges[edge];
        let m = self.inner_segments(edge);
        let n = self.inner[edge % 2];
        let base = self.edge_base(edge);
        if k < e {
            // Boundary segment k: the inner vertex after the inner segments whose midpoint
            // (l + 1.5) / n lies strictly before this one's, (k + 0.5) / e.
            let apex = inner_before(k, e, n).min(m);
            [base + k, base + k + 1, self.inner_vertex(edge, apex)]
        } else {
            let l = k - e;
            // Inner segment l: the boundary vertex after the boundary segments whose midpoint
            // lies at or before this one's.
            let apex = boundary_until(l, e, n).min(e);
            [
                self.inner_vertex(edge, l),
                self.inner_vertex(edge, l + 1),
                base + apex,
            ]
        }
    }

    /// The same triangle, turned counter-clockwise in (s, t) if it is not.
    fn counter_clockwise(&self, [a, b, c]: [u32; 3]) -> [u32; 3] {
        let (pa, pb, pc) = (self.vertex(a).0, self.vertex(b).0, self.vertex(c).0);
        if (pb - pa).perp_dot(pc - pa) < 0.0 {
            [a, c, b]
        } else {
            [a, b, c]
        }
    }
}

/// Inner segments l ≥ 0 of a strip whose midpoint (l + 1.5) / n is strictly before boundary
/// segment k's midpoint (k + 0.5) / e: #{l : (2l + 3) e < (2k + 1) n}, not clamped.
pub fn inner_before(k: u32, e: u32, n: u32) -> u32 {
    let x = u64::from(2 * k + 1) * u64::from(n);
    let three_e = 3 * u64::from(e);
    if x <= three_e {
        return 0;
    }
    ((x - 1 - three_e) / (2 * u64::from(e)) + 1) as u32
}

/// Boundary segments k ≥ 0 whose midpoint is at or before inner segment l's:
/// #{k : (2k + 1) n ≤ (2l + 3) e}, not clamped.
pub fn boundary_until(l: u32, e: u32, n: u32) -> u32 {
    let y = u64::from(2 * l + 3) * u64::from(e);
    let n = u64::from(n);
    if y < n {
        return 0;
    }
    ((y - n) / (2 * n) + 1) as u32
}

/// What the tessellation levels are measured against: the camera and the tolerated error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenError {
    /// The eye and the unit view direction (perspective), in world space.
    pub eye: DVec3,
    pub forward: DVec3,
    /// World units per pixel at unit depth (perspective: 2 tan(fov_y / 2) / height in pixels)
    /// or, for an orthographic view, per pixel anywhere.
    pub pixel_scale: f64,
    pub orthographic: bool,
    /// Depths nearer than this count as this (the near plane).
    pub near: f64,
    /// The tolerated distance between the surface and its triangles, in pixels (0.5 default).
    pub tolerance_px: f64,
    /// The longest edge a triangle may have, in pixels, so that shading stays smooth on flat
    /// but large patches.
    pub max_edge_px: f64,
    /// The most segments per edge (the patch's vertex capacity).
    pub max_segments: u32,
}

impl ScreenError {
    /// Size of one pixel (world units) at the nearest of `points`.
    fn pixel_size(&self, points: &[DVec3]) -> f64 {
        if self.orthographic {
            return self.pixel_scale;
        }
        let depth = points
            .iter()
            .map(|p| (*p - self.eye).dot(self.forward))
            .fold(f64::INFINITY, f64::min)
            .max(self.near);
        depth * self.pixel_scale
    }

    /// Segments for a Bézier curve with homogeneous control points `points` so that the
    /// polyline through its samples stays within the tolerance on screen. The chord error of a
    /// polynomial curve sampled at n even steps is at most max |C''| / (8 n²), and
    /// max |C''| ≤ d (d − 1) max |Δ²P| (the second hodograph's control points bound it); for
    /// a rational curve the Euclidean points' second differences are scaled by
    /// (max w / min w)², a bound that is loose but safe for the weights editors use. A second
    /// count keeps every segment under `max_edge_px`. At least 1, at most `max_segments`.
    pub fn curve_segments(&self, points: &[DVec4]) -> u32 {
        let d = points.len().saturating_sub(1);
        if d == 0 {
            return 1;
        }
        let euclidean: Vec<DVec3> = points.iter().map(|p| p.truncate() / p.w).collect();
        let pixel = self.pixel_size(&euclidean);
        let (w_min, w_max) = points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
            (lo.min(p.w), hi.max(p.w))
        });
        let ratio = (w_max / w_min).powi(2);
        let second = euclidean
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).length())
            .fold(0.0, f64::max);
        let bound = (d * d.saturating_sub(1)) as f64 * second * ratio;
        let tolerance = self.tolerance_px * pixel;
        let sag = (bound / (8.0 * tolerance)).sqrt().ceil();
        let chord: f64 = euclidean.windows(2).map(|w| (w[1] - w[0]).length()).sum();
        let length = (chord / (self.max_edge_px * pixel)).ceil();
        let n = sag.max(length).max(1.0);
        if n.is_finite() {
            (n as u32).min(self.max_segments.max(1))
        } else {
            self.max_segments.max(1)
        }
    }

    /// The levels of a (p, q) patch with homogeneous control points `points` (row-major, i
    /// along u: point (i, j) at i (q + 1) + j): each edge from its own curve, each interior
    /// direction the most any row of the net along it needs.
    pub fn patch_levels(&self, degree: [usize; 2], points: &[DVec4]) -> PatchLevels {
        let [p, q] = degree;
        let at = |i: usize, j: usize| points[i * (q + 1) + j];
        let along_u = |j: usize| (0..=p).map(|i| at(i, j)).collect::<Vec<_>>();
        let along_v = |i: usize| (0..=q).map(|j| at(i, j)).collect::<Vec<_>>();
        let edges = [
            self.curve_segments(&along_u(0)),
            self.curve_segments(&along_v(p)),
            self.curve_segments(&along_u(q)),
            self.curve_segments(&along_v(0)),
        ];
        let nu = (0..=q)
            .map(|j| self.curve_segments(&along_u(j)))
            .max()
            .unwrap_or(1);
        let nv = (0..=p)
            .map(|i| self.curve_segments(&along_v(i)))
            .max()
            .unwrap_or(1);
        PatchLevels::new(edges, [nu, nv])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Every triangle counter-clockwise and non-degenerate, the areas summing to the unit
    /// square, every edge between two triangles used once each way and every edge on the
    /// square's boundary once: a tiling of [0, 1]² without holes, overlaps or T-junctions.
    fn assert_tiles_the_square(levels: PatchLevels) {
        let mut area = 0.0;
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        let count = levels.triangle_count();
        for k in 0..count {
            let tri = levels
                .triangle(k)
                .unwrap_or_else(|| panic!("{levels:?}: triangle {k}"));
            let [a, b, c] = tri.map(|v| levels.vertex(v).0);
            let twice = (b - a).perp_dot(c - a);
            assert!(
                twice > 1e-12,
                "{levels:?}: triangle {k} {tri:?} has area {twice}"
            );
            area += 0.5 * twice;
            for (x, y) in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                *directed.entry((x, y)).or_default() += 1;
            }
        }
        assert!(levels.triangle(count).is_none());
        assert!((area - 1.0).abs() < 1e-9, "{levels:?}: area {area}");
        // Vertices by position: the corners appear twice in the layout.
        let key = |v: u32| {
            let p = levels.vertex(v).0;
            ((p.x * 1e9).round() as i64, (p.y * 1e9).round() as i64)
        };
        type Point = (i64, i64);
        let mut by_position: HashMap<(Point, Point), i32> = HashMap::new();
        for (&(x, y), &n) in &directed {
            assert_eq!(n, 1, "{levels:?}: edge {x}-{y} used {n} times one way");
            *by_position.entry((key(x), key(y))).or_default() += 1;
        }
        for &(a, b) in by_position.keys() {
            if by_position.contains_key(&(b, a)) {
                continue;
            }
            // An unpaired edge lies on the square's boundary.
            let on_boundary =
                |(x, y): (i64, i64)| x == 0 || y == 0 || x == 1_000_000_000 || y == 1_000_000_000;
            let same_side = (a.0 == b.0 && (a.0 == 0 || a.0 == 1_000_000_000))
                || (a.1 == b.1 && (a.1 == 0 || a.1 == 1_000_000_000));
            assert!(
                on_boundary(a) && on_boundary(b) && same_side,
                "{levels:?}: open edge {a:?}-{b:?} inside the square"
            );
        }
        // Each boundary edge vertex is used: the boundary is split exactly at m / e.
        for edge in 0..4 {
            let e = levels.edges[edge];
            let boundary_edges = by_position
                .keys()
                .filter(|&&(a, b)| !by_position.contains_key(&(b, a)))
                .filter(|&&(a, b)| {
                    let (pa, pb) = (a, b);
                    match edge {
                        0 => pa.1 == 0 && pb.1 == 0,
                        1 => pa.0 == 1_000_000_000 && pb.0 == 1_000_000_000,
                        2 => pa.1 == 1_000_000_000 && pb.1 == 1_000_000_000,
                        _ => pa.0 == 0 && pb.0 == 0,
                    }
                })
                .count();
            assert_eq!(boundary_edges as u32, e, "{levels:?}: edge {edge}");
        }
    }

    #[test]
    fn every_combination_of_counts_tiles_the_square_without_t_junctions() {
        for nu in 2..=7 {
            for nv in 2..=6 {
                for e in [
                    [1, 1, 1, 1],
                    [1, 2, 3, 4],
                    [7, 1, 5, 2],
                    [9, 9, 1, 13],
                    [2, 2, 2, 2],
                ] {
                    let levels = PatchLevels::new(e, [nu, nv]);
                    assert_tiles_the_square(levels);
                    assert_eq!(
                        levels.vertex_count(),
                        (nu - 1) * (nv - 1) + e.iter().map(|x| x + 1).sum::<u32>()
                    );
                }
            }
        }
        assert_tiles_the_square(PatchLevels::new([64, 3, 1, 40], [33, 17]));
    }

    #[test]
    fn the_merge_counts_agree_with_counting_midpoints() {
        for e in 1..12u32 {
            for n in 2..12u32 {
                let m = n - 2;
                for k in 0..e {
                    let mid = (f64::from(k) + 0.5) / f64::from(e);
                    let expected = (0..m)
                        .filter(|&l| (f64::from(l) + 1.5) / f64::from(n) < mid - 1e-12)
                        .count() as u32;
                    assert_eq!(inner_before(k, e, n).min(m), expected, "k {k} e {e} n {n}");
                }
                for l in 0..m {
                    let mid = (f64::from(l) + 1.5) / f64::from(n);
                    let expected = (0..e)
                        .filter(|&k| (f64::from(k) + 0.5) / f64::from(e) <= mid + 1e-12)
                        .count() as u32;
                    assert_eq!(
                        boundary_until(l, e, n).min(e),
                        expected,
                        "l {l} e {e} n {n}"
                    );
                }
            }
        }
    }

    fn camera(distance: f64) -> ScreenError {
        ScreenError {
            eye: DVec3::new(0.0, 0.0, distance),
            forward: DVec3::NEG_Z,
            // 35° over 800 pixels.
            pixel_scale: 2.0 * (35f64.to_radians() / 2.0).tan() / 800.0,
            orthographic: false,
            near: 0.01,
            tolerance_px: 0.5,
            max_edge_px: 1e9,
            max_segments: 1024,
        }
    }

    /// A quarter circle of radius r as a rational quadratic (The NURBS Book, eq. 7.2 and
    /// Table 7.1: weights 1, √2/2, 1).
    fn quarter_circle(r: f64) -> Vec<DVec4> {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        vec![
            DVec4::new(r, 0.0, 0.0, 1.0),
            DVec4::new(r * w, r * w, 0.0, w),
            DVec4::new(0.0, r, 0.0, 1.0),
        ]
    }

    #[test]
    fn a_circle_gets_the_segments_its_sagitta_needs_on_screen() {
        // The chord of an arc of angle a on a circle of radius r deviates r (1 − cos(a / 2)).
        for distance in [5.0, 20.0, 80.0] {
            let error = camera(distance);
            let n = error.curve_segments(&quarter_circle(1.0));
            let pixel = (distance - 1.0) * error.pixel_scale;
            let sagitta = |n: u32| 1.0 - (std::f64::consts::FRAC_PI_4 / f64::from(n)).cos();
            assert!(
                sagitta(n) <= 0.5 * pixel,
                "{n} segments at distance {distance}: {} px",
                sagitta(n) / pixel
            );
            // Not wastefully many: the bound is within a factor of about 2 of what is needed.
            let needed = (1..).find(|&k| sagitta(k) <= 0.5 * pixel).unwrap_or(1);
            assert!(n <= 3 * needed + 1, "{n} against {needed} needed");
        }
        // Farther away, fewer segments; a straight line needs one.
        let near = camera(5.0).curve_segments(&quarter_circle(1.0));
        let far = camera(80.0).curve_segments(&quarter_circle(1.0));
        assert!(far < near, "{far} vs {near}");
        let line = [
            DVec4::new(0.0, 0.0, 0.0, 1.0),
            DVec4::new(1.0, 0.0, 0.0, 1.0),
        ];
        assert_eq!(camera(5.0).curve_segments(&line), 1);
    }

    #[test]
    fn long_flat_edges_are_split_to_the_longest_edge_allowed() {
        let mut error = camera(10.0);
        error.max_edge_px = 16.0;
        let line = [
            DVec4::new(-1.0, 0.0, 0.0, 1.0),
            DVec4::new(1.0, 0.0, 0.0, 1.0),
        ];
        let pixel = 10.0 * error.pixel_scale;
        let expected = (2.0 / (16.0 * pixel)).ceil() as u32;
        assert_eq!(error.curve_segments(&line), expected);
        error.max_segments = 3;
        assert_eq!(error.curve_segments(&line), 3);
    }

    #[test]
    fn a_shared_edge_gets_one_count_from_both_patches() {
        let error = camera(6.0);
        // Two bicubic patches of z = x² y meeting along x = 1, each net read in its own order.
        let f = |x: f64, y: f64| DVec4::new(x, y, x * x * y, 1.0);
        let left: Vec<DVec4> = (0..4)
            .flat_map(|i| (0..4).map(move |j| f(i as f64 / 3.0, j as f64 / 3.0)))
            .collect();
        let right: Vec<DVec4> = (0..4)
            .flat_map(|i| (0..4).map(move |j| f(1.0 + i as f64 / 3.0, j as f64 / 3.0)))
            .collect();
        let a = error.patch_levels([3, 3], &left);
        let b = error.patch_levels([3, 3], &right);
        // Edge 1 of the left patch (s = 1) is edge 3 of the right one (s = 0).
        assert_eq!(a.edges[1], b.edges[3]);
    }
}
