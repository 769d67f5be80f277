//! Random Catmull-Clark sheets whose limit is known in closed form: a grid of quads with sharp
//! corners, optionally creased (infinitely sharp) along one row of edges, and the bicubic
//! B-spline that each side of the crease is. Shared by the kernel's tests and the app's
//! (which include this file by path).

use glam::DVec3;
use knotwork_kernel::subdiv::{Boundary, Crease, Options, SubdivisionSurface};
use knotwork_kernel::{NurbsSurface, PolygonMesh};

/// A small xorshift generator: uniform numbers in [0, 1).
pub struct Draw(pub u64);

impl Draw {
    pub fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A rotation about a random axis, a scale and a translation, all drawn.
pub fn random_motion(draw: &mut Draw) -> glam::DAffine3 {
    let axis = DVec3::new(draw.unit() - 0.5, draw.unit() - 0.5, draw.unit() - 0.5)
        .try_normalize()
        .unwrap_or(DVec3::Z);
    let rotation = glam::DQuat::from_axis_angle(axis, 6.0 * draw.unit());
    let scale = 10f64.powf(4.0 * draw.unit() - 2.0);
    let shift = DVec3::new(draw.unit(), draw.unit(), draw.unit()) * 200.0 - 100.0;
    glam::DAffine3::from_scale_rotation_translation(DVec3::splat(scale), rotation, shift)
}

/// The uniform bicubic B-spline over `rows` (a grid of points, `rows[i][j]`) with one row and
/// one column extrapolated linearly on every side (P₋₁ = 2 P₀ − P₁, the corners from the
/// extrapolated rows), over [0, rows − 1] × [0, columns − 1]: the closed form of a sheet's
/// Catmull-Clark limit with sharp corners (boundary rule "edge and corner").
fn extended_bspline(rows: &[Vec<DVec3>]) -> NurbsSurface {
    let extend = |line: &[DVec3]| -> Vec<DVec3> {
        let n = line.len();
        let mut out = vec![2.0 * line[0] - line[1]];
        out.extend_from_slice(line);
        out.push(2.0 * line[n - 1] - line[n - 2]);
        out
    };
    let wide: Vec<Vec<DVec3>> = rows.iter().map(|r| extend(r)).collect();
    let columns = wide[0].len();
    let mut net: Vec<Vec<DVec3>> = vec![Vec::new(); wide.len() + 2];
    for j in 0..columns {
        let column: Vec<DVec3> = wide.iter().map(|r| r[j]).collect();
        for (i, p) in extend(&column).into_iter().enumerate() {
            net[i].push(p);
        }
    }
    let knots = |count: usize| (0..count + 4).map(|k| k as f64 - 3.0).collect::<Vec<f64>>();
    let count = [net.len(), columns];
    NurbsSurface::new(
        [3, 3],
        [knots(count[0]), knots(count[1])],
        count,
        net.concat(),
        None,
    )
    .unwrap()
}

/// A sheet of m × n quads, uneven, in general position, with sharp corners (boundary rule
/// "edge and corner"), creased along row `crease_row` of its points when there is one, and
/// its closed form: per side of the crease, the first row of cage faces it holds and its
/// [`extended_bspline`].
pub struct Sheet {
    pub mesh: PolygonMesh,
    pub creases: Vec<Crease>,
    pub options: Options,
    /// Quads per row of faces (the cage face f lies in row f / n).
    pub n: usize,
    pub halves: Vec<(usize, NurbsSurface)>,
    /// The cage's bounding-box diagonal.
    pub size: f64,
}

impl Sheet {
    pub fn random(draw: &mut Draw, m: usize, n: usize, crease_row: Option<usize>) -> Self {
        let motion = random_motion(draw);
        let mut rows: Vec<Vec<DVec3>> = Vec::new();
        for i in 0..=m {
            let row = (0..=n)
                .map(|j| {
                    let (x, y) = (i as f64 + 0.3 * draw.unit(), j as f64 + 0.3 * draw.unit());
                    motion.transform_point3(DVec3::new(x, y, 1.2 * draw.unit() - 0.6))
                })
                .collect();
            rows.push(row);
        }
        let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
        let faces: Vec<Vec<u32>> = (0..m)
            .flat_map(|i| {
                (0..n).map(move |j| vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
            })
            .collect();
        let creases: Vec<Crease> = crease_row
            .map(|r| {
                (0..n)
                    .map(|j| Crease {
                        a: at(r, j),
                        b: at(r, j + 1),
                        sharpness: 10.0,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let halves = match crease_row {
            Some(r) => vec![
                (0, extended_bspline(&rows[..=r])),
                (r, extended_bspline(&rows[r..])),
            ],
            None => vec![(0, extended_bspline(&rows))],
        };
        let mesh = PolygonMesh::new(rows.concat(), &faces).unwrap();
        let (lo, hi) = mesh.bounds().unwrap();
        Self {
            mesh,
            creases,
            options: Options {
                boundary: Boundary::EdgeAndCorner,
                ..Options::default()
            },
            n,
            halves,
            size: (hi - lo).length(),
        }
    }

    /// The sheet as a subdivision surface shown at `level`.
    pub fn surface(&self, level: u32) -> SubdivisionSurface {
        SubdivisionSurface::new(
            self.mesh.clone(),
            self.creases.clone(),
            Vec::new(),
            self.options,
            level,
        )
        .unwrap()
    }

    /// The same sheet under Loop, each quad split along one diagonal, its creases and boundary
    /// rule kept: six triangles at every inner point, three at every boundary point but the
    /// corners and on each side of the crease.
    pub fn loop_surface(&self, level: u32) -> SubdivisionSurface {
        let faces: Vec<Vec<u32>> = self
            .mesh
            .faces()
            .flat_map(|f| [vec![f[0], f[1], f[2]], vec![f[0], f[2], f[3]]])
            .collect();
        SubdivisionSurface::new(
            PolygonMesh::new(self.mesh.points().to_vec(), &faces).unwrap(),
            self.creases.clone(),
            Vec::new(),
            Options {
                scheme: knotwork_kernel::subdiv::Scheme::Loop,
                ..self.options
            },
            level,
        )
        .unwrap()
    }

    /// Every side's closed-form geometry at the parameters of the points of level `level`
    /// (the cage's points at the integers, `2^level` steps between).
    pub fn references(&self, level: u32) -> Vec<knotwork_kernel::surface::LocalGeometry> {
        let steps = 1usize << level;
        self.halves
            .iter()
            .flat_map(|(_, closed)| {
                let [(_, u_end), (_, v_end)] = closed.domain();
                (0..=u_end as usize * steps).flat_map(move |a| {
                    (0..=v_end as usize * steps).map(move |b| {
                        closed
                            .local_geometry(a as f64 / steps as f64, b as f64 / steps as f64)
                            .unwrap()
                    })
                })
            })
            .collect()
    }

    /// The closed form of the side that holds cage face `face`.
    pub fn half_of_face(&self, face: usize) -> &NurbsSurface {
        let row = face / self.n;
        let (_, closed) = self
            .halves
            .iter()
            .rev()
            .find(|(start, _)| row >= *start)
            .unwrap();
        closed
    }
}

/// A triangle lattice (six triangles at every inner point) over an affine image of the
/// integer lattice, its points sampling a quadratic height z = q(x, y), then moved: Loop's
/// limit away from the boundary is that quadric moved up by a constant (the box spline
/// reproduces quadratics up to a constant; linear data exactly, so the limit point's x and y
/// are the lattice's).
pub struct QuadricLattice {
    pub mesh: PolygonMesh,
    lattice: glam::DMat2,
    /// q = c₀x² + c₁xy + c₂y² + c₃x + c₄y.
    c: [f64; 5],
    motion: glam::DAffine3,
    rows: usize,
    columns: usize,
}

impl QuadricLattice {
    pub fn random(draw: &mut Draw, rows: usize, columns: usize) -> Self {
        use glam::{DMat2, DVec2};
        let lattice = DMat2::from_cols(
            DVec2::new(1.0 + 0.4 * draw.unit(), 0.3 * draw.unit() - 0.15),
            DVec2::new(0.5 * draw.unit() - 0.25, 1.0 + 0.4 * draw.unit()),
        );
        let c: [f64; 5] = std::array::from_fn(|_| 0.6 * draw.unit() - 0.3);
        let motion = random_motion(draw);
        let q = |p: DVec2| {
            c[0] * p.x * p.x + c[1] * p.x * p.y + c[2] * p.y * p.y + c[3] * p.x + c[4] * p.y
        };
        let mut points = Vec::new();
        for a in 0..=rows {
            for b in 0..=columns {
                let p = lattice * DVec2::new(a as f64, b as f64);
                points.push(motion.transform_point3(p.extend(q(p))));
            }
        }
        let at = |a: usize, b: usize| (a * (columns + 1) + b) as u32;
        let mut faces = Vec::new();
        for a in 0..rows {
            for b in 0..columns {
                faces.push(vec![at(a, b), at(a + 1, b), at(a, b + 1)]);
                faces.push(vec![at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)]);
            }
        }
        Self {
            mesh: PolygonMesh::new(points, &faces).unwrap(),
            lattice,
            c,
            motion,
            rows,
            columns,
        }
    }

    /// The size the tolerances are relative to: the lattice's longer side, moved.
    pub fn size(&self) -> f64 {
        self.motion.matrix3.x_axis.length() * self.rows.max(self.columns) as f64
    }

    /// The quadric's (K, H) at the limit point `point`, positive toward the normal of the
    /// counter-clockwise faces; `None` within three lattice steps of the boundary, whose
    /// rules change the limit up to two rings in (the box spline's support).
    pub fn curvature_at(&self, point: DVec3) -> Option<(f64, f64)> {
        let xy = self.motion.inverse().transform_point3(point).truncate();
        let ab = self.lattice.inverse() * xy;
        let margin = 3.0 - 1e-9;
        if ab.min_element() < margin
            || ab.x > self.rows as f64 - margin
            || ab.y > self.columns as f64 - margin
        {
            return None;
        }
        let c = &self.c;
        let (qx, qy) = (
            2.0 * c[0] * xy.x + c[1] * xy.y + c[3],
            c[1] * xy.x + 2.0 * c[2] * xy.y + c[4],
        );
        let (qxx, qxy, qyy) = (2.0 * c[0], c[1], 2.0 * c[2]);
        let w = 1.0 + qx * qx + qy * qy;
        let scale = self.motion.matrix3.x_axis.length();
        let gaussian = (qxx * qyy - qxy * qxy) / (w * w) / (scale * scale);
        let mean = ((1.0 + qy * qy) * qxx - 2.0 * qx * qy * qxy + (1.0 + qx * qx) * qyy)
            / (2.0 * w.powf(1.5))
            / scale;
        Some((gaussian, mean))
    }
}
