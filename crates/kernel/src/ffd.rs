//! Free-form deformation (Sederberg & Parry, "Free-Form Deformation of Solid Geometric Models",
//! SIGGRAPH 1986): a trivariate Bézier lattice maps space onto itself, and every surface inside
//! follows.
//!
//! A point X has local coordinates (s, t, u) = A (X − X₀) in the lattice's box, where X₀ is the
//! box's corner and A the inverse of the matrix whose columns are the box's edges S, T, U. Its
//! image is the trivariate Bézier sum
//! F(X) = Σᵢ Σⱼ Σₖ B_{i,l}(s) B_{j,m}(t) B_{k,n}(u) P_{ijk},
//! which is X itself for the undisturbed lattice P_{ijk} = X₀ + (i/l) S + (j/m) T + (k/n) U
//! (linear precision of the Bernstein basis). Outside the box the polynomial goes on (no seam).
//!
//! A surface S(u, v) is deformed by composition, F ∘ S. Its derivatives follow by the chain rule
//! with the lattice's Jacobian J = ∂F/∂X and Hessian: (F∘S)_u = J S_u, (F∘S)_uv = J S_uv +
//! H[S_u, S_v]; normals map by the cofactor matrix, N' ∝ cof(J) N = det(J) J⁻ᵀ N (which is
//! J S_u × J S_v wherever S_u × S_v ∝ N, and still defined at a pole).
//!
//! Baking: F is a polynomial of total degree D = l + m + n in X, so a polynomial patch of degree
//! (p, q) becomes one of degree (Dp, Dq), and a rational one of weight w a rational one with
//! weight w^D ([`Lattice::compose_patch`], [`Lattice::compose_triangle`]). Where that degree is
//! too high, [`hermite_cells`] refits bicubic cells from the deformed positions and derivatives.

use glam::{DMat3, DVec3, DVec4};

use super::GeometryError;
use super::bernstein::bernstein_all;
use super::diffgeo::SurfaceDerivatives;

/// The highest lattice degree per direction (the GPU reads (l + 1)(m + 1)(n + 1) ≤ 125 points).
pub const MAX_LATTICE_DEGREE: usize = 4;

/// The highest degree per direction a baked patch keeps exactly: the GPU evaluator's limit for
/// tensor-product patches (`gpu::records::GPU_MAX_DEGREE`; a test checks that they agree).
pub const EXACT_MAX_DEGREE: usize = 9;

/// The most bicubic cells per Bézier span and direction a refit makes.
pub const MAX_REFIT_CELLS: usize = 64;

fn lattice_error(message: impl Into<String>) -> GeometryError {
    GeometryError::Construction {
        what: "lattice",
        message: message.into(),
    }
}

/// A trivariate Bézier lattice over a box (a parallelepiped: corner and three edges).
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice {
    /// The box and the degrees (boxed: an object carries its lattice inline).
    frame: Box<Frame>,
    /// P_{ijk} at `(i (m + 1) + j) (n + 1) + k`.
    points: Vec<DVec3>,
}

/// A lattice's box (corner and edges), degrees (l, m, n) and group.
#[derive(Debug, Clone, PartialEq)]
struct Frame {
    origin: DVec3,
    axes: [DVec3; 3],
    degrees: [usize; 3],
    group: u64,
}

/// The lattice's map at one point, in local coordinates: F, its first derivatives
/// (∂F/∂s, ∂F/∂t, ∂F/∂u) and its second ones (`second[a][b]` = ∂²F/∂a∂b).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatticeJet {
    pub value: DVec3,
    pub first: [DVec3; 3],
    pub second: [[DVec3; 3]; 3],
}

/// B_{i,n}(x), B′ and B″ for i = 0..=n (The NURBS Book eq. 1.9 for the derivatives:
/// B′_{i,n} = n (B_{i−1,n−1} − B_{i,n−1})).
fn bernstein_jet(degree: usize, x: f64) -> [[f64; MAX_LATTICE_DEGREE + 1]; 3] {
    let n = degree;
    let mut out = [[0.0; MAX_LATTICE_DEGREE + 1]; 3];
    bernstein_all(x, &mut out[0][..=n]);
    let mut lower1 = [0.0; MAX_LATTICE_DEGREE + 2];
    bernstein_all(x, &mut lower1[1..=n]);
    let mut lower2 = [0.0; MAX_LATTICE_DEGREE + 3];
    if n >= 2 {
        bernstein_all(x, &mut lower2[2..=n]);
    }
    let (nf, nn) = (n as f64, (n * n.saturating_sub(1)) as f64);
    for i in 0..=n {
        // lower1[i + 1] = B_{i,n−1}, lower2[i + 2] = B_{i,n−2}; out of range entries are 0.
        out[1][i] = nf * (lower1[i] - lower1[i + 1]);
        let b = |k: isize| -> f64 {
            let at = i as isize + 2 - k;
            if at < 2 || at > n as isize {
                0.0
            } else {
                lower2[at as usize]
            }
        };
        out[2][i] = nn * (b(2) - 2.0 * b(1) + b(0));
    }
    out
}

impl Lattice {
    /// Checks the degrees (1..=[`MAX_LATTICE_DEGREE`]), that the box's edges are finite and
    /// span space (not flat), and the count and finiteness of the points.
    pub fn new(
        origin: DVec3,
        axes: [DVec3; 3],
        degrees: [usize; 3],
        points: Vec<DVec3>,
    ) -> Result<Self, GeometryError> {
        if let Some(d) = degrees
            .iter()
            .find(|d| !(1..=MAX_LATTICE_DEGREE).contains(d))
        {
            return Err(lattice_error(format!(
                "degree {d} is outside 1..={MAX_LATTICE_DEGREE}"
            )));
        }
        if !origin.is_finite() || axes.iter().any(|a| !a.is_finite()) {
            return Err(lattice_error("the box is not finite"));
        }
        let volume = axes[0].dot(axes[1].cross(axes[2])).abs();
        let scale = axes[0].length() * axes[1].length() * axes[2].length();
        if !(volume > 1e-9 * scale) || scale == 0.0 {
            return Err(lattice_error(
                "the box is flat (its edges do not span space)",
            ));
        }
        let expected = degrees.iter().map(|d| d + 1).product::<usize>();
        if points.len() != expected {
            return Err(lattice_error(format!(
                "{} points for degrees {degrees:?} (expected {expected})",
                points.len()
            )));
        }
        if let Some(k) = points.iter().position(|p| !p.is_finite()) {
            return Err(lattice_error(format!("point {k} is not finite")));
        }
        Ok(Self {
            frame: Box::new(Frame {
                origin,
                axes,
                degrees,
                group: 0,
            }),
            points,
        })
    }

    /// The undisturbed lattice (the identity map) on the box from corner `origin` along `axes`.
    pub fn undisturbed(
        origin: DVec3,
        axes: [DVec3; 3],
        degrees: [usize; 3],
    ) -> Result<Self, GeometryError> {
        let [l, m, n] = degrees;
        let mut points = Vec::with_capacity((l + 1) * (m + 1) * (n + 1));
        for i in 0..=l {
            for j in 0..=m {
                for k in 0..=n {
                    let at = |a: usize, d: usize| a as f64 / d.max(1) as f64;
                    points.push(
                        origin + axes[0] * at(i, l) + axes[1] * at(j, m) + axes[2] * at(k, n),
                    );
                }
            }
        }
        Self::new(origin, axes, degrees, points)
    }

    /// The undisturbed lattice on the axis-aligned box (lo, hi) widened by 5 % of its diagonal
    /// on every side (so that the objects lie inside, not on its faces); a flat box gets a
    /// thickness of 10 % of its diagonal.
    pub fn around(lo: DVec3, hi: DVec3, degrees: [usize; 3]) -> Result<Self, GeometryError> {
        if !lo.is_finite() || !hi.is_finite() {
            return Err(lattice_error("the objects' box is not finite"));
        }
        let diagonal = (hi - lo).length().max(1e-6);
        let margin = DVec3::splat(0.05 * diagonal);
        let origin = lo - margin;
        let edge = hi - lo + 2.0 * margin;
        Self::undisturbed(
            origin,
            [DVec3::X * edge.x, DVec3::Y * edge.y, DVec3::Z * edge.z],
            degrees,
        )
    }

    pub fn origin(&self) -> DVec3 {
        self.frame.origin
    }

    /// Which lattice this is among the document's: objects whose lattices are equal (the same
    /// group and the same points) share one lattice and move together. 0 unless set.
    pub fn group(&self) -> u64 {
        self.frame.group
    }

    /// The lattice as a member of group `group`.
    pub fn with_group(mut self, group: u64) -> Self {
        self.frame.group = group;
        self
    }

    pub fn axes(&self) -> [DVec3; 3] {
        self.frame.axes
    }

    /// (l, m, n).
    pub fn degrees(&self) -> [usize; 3] {
        self.frame.degrees
    }

    /// l + m + n: the total degree of the map, by which a baked patch's degree is multiplied.
    pub fn total_degree(&self) -> usize {
        self.frame.degrees.iter().sum()
    }

    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// The index of P_{ijk} in [`Self::points`].
    pub fn point_index(&self, i: usize, j: usize, k: usize) -> usize {
        let [_, m, n] = self.frame.degrees;
        (i * (m + 1) + j) * (n + 1) + k
    }

    /// Moves point `index` (refused for a bad index or a non-finite position).
    pub fn set_point(&mut self, index: usize, position: DVec3) -> Result<(), GeometryError> {
        if !position.is_finite() {
            return Err(lattice_error(format!("point {index}: not finite")));
        }
        let count = self.points.len();
        let slot = self
            .points
            .get_mut(index)
            .ok_or_else(|| lattice_error(format!("no point {index} (it has {count})")))?;
        *slot = position;
        Ok(())
    }

    /// Whether every point is where the undisturbed lattice has it (within `tolerance`).
    pub fn is_undisturbed(&self, tolerance: f64) -> bool {
        Self::undisturbed(self.frame.origin, self.frame.axes, self.frame.degrees).is_ok_and(|u| {
            u.points
                .iter()
                .zip(&self.points)
                .all(|(a, b)| a.distance(*b) <= tolerance)
        })
    }

    /// A: local coordinates from world ones, (s, t, u) = A (X − X₀).
    pub fn inverse_axes(&self) -> DMat3 {
        DMat3::from_cols(self.frame.axes[0], self.frame.axes[1], self.frame.axes[2]).inverse()
    }

    /// The map and its first and second derivatives at local coordinates `local`.
    #[allow(clippy::needless_range_loop)] // i, j, k index the three bases and the points
    pub fn jet(&self, local: DVec3) -> LatticeJet {
        let [l, m, n] = self.frame.degrees;
        let (bs, bt, bu) = (
            bernstein_jet(l, local.x),
            bernstein_jet(m, local.y),
            bernstein_jet(n, local.z),
        );
        let mut jet = LatticeJet {
            value: DVec3::ZERO,
            first: [DVec3::ZERO; 3],
            second: [[DVec3::ZERO; 3]; 3],
        };
        for i in 0..=l {
            for j in 0..=m {
                for k in 0..=n {
                    let p = self.points[self.point_index(i, j, k)];
                    let (s0, s1, s2) = (bs[0][i], bs[1][i], bs[2][i]);
                    let (t0, t1, t2) = (bt[0][j], bt[1][j], bt[2][j]);
                    let (u0, u1, u2) = (bu[0][k], bu[1][k], bu[2][k]);
                    jet.value += p * (s0 * t0 * u0);
                    jet.first[0] += p * (s1 * t0 * u0);
                    jet.first[1] += p * (s0 * t1 * u0);
                    jet.first[2] += p * (s0 * t0 * u1);
                    jet.second[0][0] += p * (s2 * t0 * u0);
                    jet.second[1][1] += p * (s0 * t2 * u0);
                    jet.second[2][2] += p * (s0 * t0 * u2);
                    jet.second[0][1] += p * (s1 * t1 * u0);
                    jet.second[0][2] += p * (s1 * t0 * u1);
                    jet.second[1][2] += p * (s0 * t1 * u1);
                }
            }
        }
        jet.second[1][0] = jet.second[0][1];
        jet.second[2][0] = jet.second[0][2];
        jet.second[2][1] = jet.second[1][2];
        jet
    }

    /// F(p).
    pub fn deform_point(&self, p: DVec3) -> DVec3 {
        self.jet_at(p).0.value
    }

    /// The jet at world point `p` and the inverse box matrix A it was taken with.
    fn jet_at(&self, p: DVec3) -> (LatticeJet, DMat3) {
        let a = self.inverse_axes();
        (self.jet(a * (p - self.frame.origin)), a)
    }

    /// The Jacobian ∂F/∂X from a jet and A.
    fn world_jacobian(jet: &LatticeJet, a: DMat3) -> DMat3 {
        DMat3::from_cols(jet.first[0], jet.first[1], jet.first[2]) * a
    }

    /// cof(J) N normalized (`normal` itself where J is singular).
    fn mapped_normal(jacobian: DMat3, normal: DVec3) -> DVec3 {
        cofactor(jacobian)
            .mul_vec3(normal)
            .try_normalize()
            .unwrap_or(normal)
    }

    /// The Jacobian ∂F/∂X at `p` (world coordinates).
    pub fn jacobian(&self, p: DVec3) -> DMat3 {
        let (jet, a) = self.jet_at(p);
        Self::world_jacobian(&jet, a)
    }

    /// The unit normal of the deformed surface at `p` from the undeformed unit normal `normal`:
    /// cof(J) N normalized (`normal` itself where J is singular there).
    pub fn deform_normal(&self, p: DVec3, normal: DVec3) -> DVec3 {
        Self::mapped_normal(self.jacobian(p), normal)
    }

    /// [`Self::deform_point`] and [`Self::deform_normal`] from one evaluation of the lattice.
    pub fn deform_vertex(&self, p: DVec3, normal: DVec3) -> (DVec3, DVec3) {
        let (jet, a) = self.jet_at(p);
        (
            jet.value,
            Self::mapped_normal(Self::world_jacobian(&jet, a), normal),
        )
    }

    /// [`Self::deform`] and [`Self::deform_normal`] (at `d.point`) from one evaluation of the
    /// lattice.
    pub fn deform_with_normal(
        &self,
        d: &SurfaceDerivatives,
        normal: DVec3,
    ) -> (SurfaceDerivatives, DVec3) {
        let (jet, a) = self.jet_at(d.point);
        (
            Self::chain_rule(&jet, a, d),
            Self::mapped_normal(Self::world_jacobian(&jet, a), normal),
        )
    }

    /// The deformed surface's point and derivatives from the surface's `d` (chain rule, see the
    /// module's text): with local derivatives a_u = A S_u and so on, (F∘S)_u = Σ F_a a_u^a and
    /// (F∘S)_uv = Σ F_a a_uv^a + Σ F_ab a_u^a a_v^b.
    pub fn deform(&self, d: &SurfaceDerivatives) -> SurfaceDerivatives {
        let (jet, a) = self.jet_at(d.point);
        Self::chain_rule(&jet, a, d)
    }

    /// The chain rule of [`Self::deform`] with the jet at `d.point` and A.
    fn chain_rule(jet: &LatticeJet, a: DMat3, d: &SurfaceDerivatives) -> SurfaceDerivatives {
        let [lu, lv, luu, luv, lvv] = [d.su, d.sv, d.suu, d.suv, d.svv].map(|x| a * x);
        let first = |x: DVec3| jet.first[0] * x.x + jet.first[1] * x.y + jet.first[2] * x.z;
        let hessian = |x: DVec3, y: DVec3| {
            let (xa, ya) = (x.to_array(), y.to_array());
            let mut sum = DVec3::ZERO;
            for (p, row) in jet.second.iter().enumerate() {
                for (q, h) in row.iter().enumerate() {
                    sum += *h * (xa[p] * ya[q]);
                }
            }
            sum
        };
        SurfaceDerivatives {
            point: jet.value,
            su: first(lu),
            sv: first(lv),
            suu: first(luu) + hessian(lu, lu),
            suv: first(luv) + hessian(lu, lv),
            svv: first(lvv) + hessian(lv, lv),
        }
    }

    /// The lattice mapped by an affine transformation (box and points).
    pub fn transformed(&self, transform: &glam::DAffine3) -> Result<Self, GeometryError> {
        let group = self.group();
        Self::new(
            transform.transform_point3(self.frame.origin),
            self.frame.axes.map(|a| transform.transform_vector3(a)),
            self.frame.degrees,
            self.points
                .iter()
                .map(|&p| transform.transform_point3(p))
                .collect(),
        )
        .map(|l| l.with_group(group))
    }

    /// The undisturbed lattice on the same box, of the same degrees and group.
    pub fn reset(&self) -> Result<Self, GeometryError> {
        Self::undisturbed(self.frame.origin, self.frame.axes, self.frame.degrees)
            .map(|l| l.with_group(self.group()))
    }

    /// Index pairs of the lattice's lines (between neighbours along each direction).
    pub fn net_lines(&self) -> Vec<u32> {
        let [l, m, n] = self.frame.degrees;
        let mut lines = Vec::new();
        for i in 0..=l {
            for j in 0..=m {
                for k in 0..=n {
                    let at = self.point_index(i, j, k) as u32;
                    if i < l {
                        lines.extend([at, self.point_index(i + 1, j, k) as u32]);
                    }
                    if j < m {
                        lines.extend([at, self.point_index(i, j + 1, k) as u32]);
                    }
                    if k < n {
                        lines.extend([at, self.point_index(i, j, k + 1) as u32]);
                    }
                }
            }
        }
        lines
    }

    /// The exact composition of the rational Bézier patch of degree (p, q) with homogeneous
    /// points `points` (row-major, i along u) with the lattice: the patch of degree (Dp, Dq)
    /// whose homogeneous points interpolate w^D (F(S), 1) at the (Dp + 1)(Dq + 1) uniform
    /// parameters. F∘S·w^D and w^D are polynomials of exactly that degree, so the
    /// interpolation reproduces them (up to the collocation's rounding).
    pub fn compose_patch(
        &self,
        degree: [usize; 2],
        points: &[DVec4],
    ) -> Result<([usize; 2], Vec<DVec4>), GeometryError> {
        let [p, q] = degree;
        if points.len() != (p + 1) * (q + 1) || p == 0 || q == 0 {
            return Err(lattice_error(
                "a patch's point count does not match its degree",
            ));
        }
        let big = self.total_degree();
        let [nu, nv] = [big * p, big * q];
        let patch = |u: f64, v: f64| bezier_patch_point([p, q], points, u, v);
        let mut samples = vec![DVec4::ZERO; (nu + 1) * (nv + 1)];
        for a in 0..=nu {
            for b in 0..=nv {
                let h = patch(a as f64 / nu as f64, b as f64 / nv as f64);
                let scale = h.w.powi(big as i32);
                let image = self.deform_point(h.truncate() / h.w);
                samples[a * (nv + 1) + b] = (image * scale).extend(scale);
            }
        }
        // Tensor interpolation: along u for every column, then along v for every row.
        let solve = |n: usize, values: Vec<DVec4>| -> Result<Vec<DVec4>, GeometryError> {
            super::vector::solve_linear(uniform_collocation(n), values)
                .ok_or_else(|| lattice_error("the collocation system is singular"))
        };
        let mut coefficients = samples.clone();
        for b in 0..=nv {
            let column = (0..=nu).map(|a| samples[a * (nv + 1) + b]).collect();
            for (a, c) in solve(nu, column)?.into_iter().enumerate() {
                coefficients[a * (nv + 1) + b] = c;
            }
        }
        for a in 0..=nu {
            let row = coefficients[a * (nv + 1)..(a + 1) * (nv + 1)].to_vec();
            let solved = solve(nv, row)?;
            coefficients[a * (nv + 1)..(a + 1) * (nv + 1)].copy_from_slice(&solved);
        }
        Ok(([nu, nv], coefficients))
    }

    /// The exact composition of a (polynomial) triangular Bézier patch with the lattice: the
    /// patch of degree D·n interpolating F at the uniform barycentric lattice of that degree
    /// ([`Self::interpolate_triangle`]; F∘T is a polynomial of that degree).
    pub fn compose_triangle(
        &self,
        patch: &super::triangle::TriangleBezier,
    ) -> Result<super::triangle::TriangleBezier, GeometryError> {
        self.interpolate_triangle(patch, self.total_degree() * patch.degree())
    }

    /// The triangular patch of degree `degree` interpolating F∘T at the uniform barycentric
    /// lattice of that degree (Farin, "Curves and Surfaces for CAGD", §18.7).
    pub fn interpolate_triangle(
        &self,
        patch: &super::triangle::TriangleBezier,
        degree: usize,
    ) -> Result<super::triangle::TriangleBezier, GeometryError> {
        use super::triangle::{TriangleBezier, bernstein_weights, lattice_index, point_count};
        let count = point_count(degree);
        let mut matrix = vec![vec![0.0; count]; count];
        let mut values = vec![DVec3::ZERO; count];
        for j in 0..=degree {
            for i in 0..=degree - j {
                let (u, v) = (i as f64 / degree as f64, j as f64 / degree as f64);
                let row = lattice_index(degree, i, j);
                for (c, w) in bernstein_weights(degree, u, v).iter().enumerate() {
                    matrix[row][c] = w[0];
                }
                values[row] = self.deform_point(patch.evaluate(u, v).point);
            }
        }
        let points = super::vector::solve_linear(matrix, values)
            .ok_or_else(|| lattice_error("the collocation system is singular"))?;
        TriangleBezier::new(degree, points)
    }
}

/// The point at (u, v) of the Bézier patch of degree (p, q) with points `points` (row-major,
/// i along u; homogeneous ones for a rational patch): Σ B_{i,p}(u) B_{j,q}(v) P_ij.
#[allow(clippy::needless_range_loop)] // i and j index both bases and the points
pub fn bezier_patch_point<V: super::vector::Vector>(
    degree: [usize; 2],
    points: &[V],
    u: f64,
    v: f64,
) -> V {
    let [p, q] = degree;
    let (mut bu, mut bv) = (vec![0.0; p + 1], vec![0.0; q + 1]);
    bernstein_all(u, &mut bu);
    bernstein_all(v, &mut bv);
    let mut sum = V::ZERO;
    for i in 0..=p {
        for j in 0..=q {
            sum = sum + points[i * (q + 1) + j] * (bu[i] * bv[j]);
        }
    }
    sum
}

/// The collocation matrix of the degree-n Bernstein basis at the parameters a / n.
fn uniform_collocation(n: usize) -> Vec<Vec<f64>> {
    (0..=n)
        .map(|a| {
            let mut row = vec![0.0; n + 1];
            bernstein_all(a as f64 / n as f64, &mut row);
            row
        })
        .collect()
}

/// The cofactor matrix cof(J) = det(J) J⁻ᵀ, column c = J_{c+1} × J_{c+2}.
pub fn cofactor(j: DMat3) -> DMat3 {
    DMat3::from_cols(
        j.y_axis.cross(j.z_axis),
        j.z_axis.cross(j.x_axis),
        j.x_axis.cross(j.y_axis),
    )
}

/// The 4 × 4 points of the bicubic Bézier cell with corner data `corners[c]` = (point, ∂/∂u,
/// ∂/∂v, ∂²/∂u∂v) at the cell's corners (0,0), (1,0), (0,1), (1,1) over a cell of parameter
/// size (hu, hv): the bicubic Hermite interpolant (Farin, "Curves and Surfaces for CAGD",
/// §16.4), whose inner points are b₁₁ = b₀₀ + (hu/3) S_u + (hv/3) S_v + (hu hv/9) S_uv and so on.
/// Row-major, i along u. Neighbouring cells share the data of their common corners, so their
/// common boundary curves agree.
pub fn hermite_cell(corners: [[DVec3; 4]; 4], (hu, hv): (f64, f64)) -> Vec<DVec3> {
    let mut out = vec![DVec3::ZERO; 16];
    // Corner c at grid (ci, cj) ∈ {0, 3}²; its inner neighbours step toward the cell's centre.
    for (c, &[p, pu, pv, puv]) in corners.iter().enumerate() {
        let (ci, cj) = ((c & 1) * 3, (c >> 1) * 3);
        let (su, sv) = (
            if ci == 0 { 1.0 } else { -1.0 },
            if cj == 0 { 1.0 } else { -1.0 },
        );
        let (du, dv) = (pu * (su * hu / 3.0), pv * (sv * hv / 3.0));
        let (ni, nj) = (if ci == 0 { 1 } else { 2 }, if cj == 0 { 1 } else { 2 });
        out[ci * 4 + cj] = p;
        out[ni * 4 + cj] = p + du;
        out[ci * 4 + nj] = p + dv;
        out[ni * 4 + nj] = p + du + dv + puv * (su * sv * hu * hv / 9.0);
    }
    out
}

/// Refits the deformed image of a surface piece over the parameter rectangle `domain` (u0, u1,
/// v0, v1) by `cells` × `cells` bicubic Hermite cells ([`hermite_cell`]), from `derivatives`
/// (the undeformed surface's point and derivatives at a parameter) deformed by `lattice`.
/// Returns the cells' points (cell (a, b) at index a · cells + b) and the largest distance, at
/// the cells' centres and edge midpoints, between a cell and the deformed surface.
pub fn hermite_cells(
    lattice: &Lattice,
    domain: [f64; 4],
    cells: usize,
    derivatives: &dyn Fn(f64, f64) -> Result<SurfaceDerivatives, GeometryError>,
) -> Result<(Vec<Vec<DVec3>>, f64), GeometryError> {
    let [u0, u1, v0, v1] = domain;
    let (hu, hv) = ((u1 - u0) / cells as f64, (v1 - v0) / cells as f64);
    let mut corners = Vec::with_capacity((cells + 1) * (cells + 1));
    for a in 0..=cells {
        for b in 0..=cells {
            let d = lattice.deform(&derivatives(u0 + hu * a as f64, v0 + hv * b as f64)?);
            corners.push([d.point, d.su, d.sv, d.suv]);
        }
    }
    let corner = |a: usize, b: usize| corners[a * (cells + 1) + b];
    let mut out = Vec::with_capacity(cells * cells);
    let mut error: f64 = 0.0;
    for a in 0..cells {
        for b in 0..cells {
            let cell = hermite_cell(
                [
                    corner(a, b),
                    corner(a + 1, b),
                    corner(a, b + 1),
                    corner(a + 1, b + 1),
                ],
                (hu, hv),
            );
            for (s, t) in [(0.5, 0.5), (0.5, 0.0), (0.0, 0.5), (0.25, 0.75)] {
                let (u, v) = (u0 + hu * (a as f64 + s), v0 + hv * (b as f64 + t));
                let exact = lattice.deform_point(derivatives(u, v)?.point);
                error = error.max(bezier_patch_point([3, 3], &cell, s, t).distance(exact));
            }
            out.push(cell);
        }
    }
    Ok((out, error))
}

/// How a bake turned out, for the user.
#[derive(Debug, Clone, PartialEq)]
pub enum Baked {
    /// The deformed surface represented exactly: patches of these degrees.
    Exact { degree: [usize; 2] },
    /// Refitted by bicubic cells (`cells` per span edge) within `error` (≤ the tolerance unless
    /// `within` is false, where the cell limit was reached first).
    Refit {
        cells: usize,
        error: f64,
        within: bool,
    },
    /// A triangular patch interpolated at `degree` (the exact one would be higher) within
    /// `error`.
    Interpolated {
        degree: usize,
        error: f64,
        within: bool,
    },
    /// A polygon mesh's or a cage's points moved through the lattice (`error`: the largest
    /// distance between the result's surface and the deformed one where measured; 0 for a mesh,
    /// whose vertices are its shape).
    Points { error: f64, within: bool },
}

impl Baked {
    /// "exact: degree (9, 9)" and the like.
    pub fn describe(&self) -> String {
        match self {
            Baked::Exact { degree } => format!(
                "exact: the deformed surface as patches of degree ({}, {})",
                degree[0], degree[1]
            ),
            Baked::Refit {
                cells,
                error,
                within,
            } => format!(
                "refitted: bicubic, {cells} × {cells} cells per span, largest deviation {error:.2e}{}",
                if *within {
                    ""
                } else {
                    " (over the tolerance: the cell limit was reached)"
                }
            ),
            Baked::Interpolated {
                degree,
                error,
                within,
            } => format!(
                "refitted: interpolated at degree {degree}, largest deviation {error:.2e}{}",
                if *within { "" } else { " (over the tolerance)" }
            ),
            Baked::Points { error, within } => {
                if *error == 0.0 {
                    "exact: the points moved through the lattice".to_string()
                } else {
                    format!(
                        "refitted: the cage's points solved for the deformed limit surface, largest deviation {error:.2e}{}",
                        if *within { "" } else { " (over the tolerance)" }
                    )
                }
            }
        }
    }
}

/// The bicubic cells of one span (each 16 points, row-major).
pub type SpanCells = Vec<Vec<DVec3>>;

/// Refits with [`hermite_cells`], doubling the cells per span from 1 until every span is
/// within `tolerance` or [`MAX_REFIT_CELLS`] is reached: the cells of every span (in the
/// order of `spans`), the cells used and the largest deviation.
pub fn refit_spans(
    lattice: &Lattice,
    spans: &[[f64; 4]],
    tolerance: f64,
    derivatives: &dyn Fn(usize, f64, f64) -> Result<SurfaceDerivatives, GeometryError>,
) -> Result<(Vec<SpanCells>, usize, f64), GeometryError> {
    let mut cells = 1;
    loop {
        let mut all = Vec::with_capacity(spans.len());
        let mut error: f64 = 0.0;
        for (k, &domain) in spans.iter().enumerate() {
            let (patches, e) = hermite_cells(lattice, domain, cells, &|u, v| derivatives(k, u, v))?;
            error = error.max(e);
            all.push(patches);
        }
        if error <= tolerance || cells >= MAX_REFIT_CELLS {
            return Ok((all, cells, error));
        }
        cells *= 2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bent() -> Lattice {
        let mut lattice =
            Lattice::around(DVec3::splat(-1.0), DVec3::splat(1.0), [2, 1, 3]).unwrap();
        let middle = lattice.point_index(1, 1, 2);
        let p = lattice.points()[middle];
        lattice
            .set_point(middle, p + DVec3::new(0.3, -0.2, 0.5))
            .unwrap();
        let corner = lattice.point_index(0, 0, 0);
        let p = lattice.points()[corner];
        lattice
            .set_point(corner, p + DVec3::new(-0.1, 0.2, 0.1))
            .unwrap();
        lattice
    }

    #[test]
    fn the_undisturbed_lattice_is_the_identity() {
        let lattice = Lattice::around(DVec3::ZERO, DVec3::new(2.0, 1.0, 0.0), [3, 2, 4]).unwrap();
        assert!(lattice.is_undisturbed(0.0));
        for p in [
            DVec3::new(0.3, 0.7, 0.0),
            DVec3::new(1.9, 0.1, 0.05),
            DVec3::new(2.5, -0.5, 0.3),
        ] {
            assert!(lattice.deform_point(p).distance(p) < 1e-10, "{p}");
            let j = lattice.jacobian(p);
            assert!((j - DMat3::IDENTITY).abs_diff_eq(DMat3::ZERO, 1e-9));
        }
    }

    #[test]
    fn the_jet_matches_central_differences() {
        let lattice = bent();
        let x = DVec3::new(0.37, 0.55, 0.41);
        let jet = lattice.jet(x);
        let h = 1e-5;
        for a in 0..3 {
            let e = DVec3::AXES[a] * h;
            let d = (lattice.jet(x + e).value - lattice.jet(x - e).value) / (2.0 * h);
            assert!(d.distance(jet.first[a]) < 1e-7, "first {a}");
            for b in 0..3 {
                let f = DVec3::AXES[b] * h;
                let dd = (lattice.jet(x + e + f).value
                    - lattice.jet(x + e - f).value
                    - lattice.jet(x - e + f).value
                    + lattice.jet(x - e - f).value)
                    / (4.0 * h * h);
                assert!(dd.distance(jet.second[a][b]) < 1e-4, "second {a}{b}");
            }
        }
    }

    #[test]
    fn an_affine_lattice_maps_a_surface_affinely() {
        // Every point of a degree-(1, 1, 1) lattice moved by one affine map: F is that map, and
        // the deformed derivatives are its linear part applied to the surface's.
        let map = glam::DAffine3::from_mat3_translation(
            DMat3::from_cols_array(&[1.2, 0.3, 0.0, -0.1, 0.9, 0.2, 0.4, 0.0, 1.5]),
            DVec3::new(0.5, -1.0, 2.0),
        );
        let base = Lattice::around(DVec3::ZERO, DVec3::ONE, [1, 2, 1]).unwrap();
        let lattice = Lattice::new(
            base.origin(),
            base.axes(),
            base.degrees(),
            base.points()
                .iter()
                .map(|&p| map.transform_point3(p))
                .collect(),
        )
        .unwrap();
        let d = SurfaceDerivatives {
            point: DVec3::new(0.2, 0.4, 0.6),
            su: DVec3::new(1.0, 0.0, 0.3),
            sv: DVec3::new(0.0, 1.0, -0.2),
            suu: DVec3::new(0.1, 0.2, 0.3),
            suv: DVec3::new(-0.3, 0.1, 0.0),
            svv: DVec3::new(0.0, 0.5, 0.1),
        };
        let out = lattice.deform(&d);
        let l = map.matrix3;
        assert!(out.point.distance(map.transform_point3(d.point)) < 1e-12);
        for (a, b) in [
            (out.su, d.su),
            (out.sv, d.sv),
            (out.suu, d.suu),
            (out.suv, d.suv),
            (out.svv, d.svv),
        ] {
            assert!(a.distance(l * b) < 1e-12);
        }
        // Normals by the cofactor: perpendicular to the mapped tangents.
        let n = d.su.cross(d.sv).normalize();
        let m = lattice.deform_normal(d.point, n);
        assert!(m.dot(l * d.su).abs() < 1e-12 && m.dot(l * d.sv).abs() < 1e-12);
        assert!(m.dot((l * d.su).cross(l * d.sv)) > 0.0);
    }

    #[test]
    fn composing_a_patch_is_exact() {
        // A rational biquadratic patch through a bent (2, 1, 3) lattice: degree 12 would be too
        // high to keep, but the composition itself is exact whatever the degree.
        let lattice = Lattice::around(DVec3::splat(-1.0), DVec3::splat(1.0), [1, 1, 1])
            .map(|mut l| {
                let k = l.point_index(1, 0, 1);
                let p = l.points()[k];
                l.set_point(k, p + DVec3::new(0.2, 0.3, -0.4)).unwrap();
                l
            })
            .unwrap();
        let points: Vec<DVec4> = (0..9)
            .map(|k| {
                let (i, j) = (k / 3, k % 3);
                let w = if k == 4 { 0.6 } else { 1.0 + 0.1 * i as f64 };
                (DVec3::new(
                    i as f64 * 0.5 - 0.5,
                    j as f64 * 0.5 - 0.5,
                    0.2 * (i * j) as f64,
                ) * w)
                    .extend(w)
            })
            .collect();
        let (degree, composed) = lattice.compose_patch([2, 2], &points).unwrap();
        assert_eq!(degree, [6, 6]);
        let original = NurbsPatch(2, 2, points);
        let result = NurbsPatch(6, 6, composed);
        for (u, v) in [(0.13, 0.71), (0.5, 0.5), (0.9, 0.05), (0.33, 0.2)] {
            let expected = lattice.deform_point(original.at(u, v));
            assert!(result.at(u, v).distance(expected) < 1e-11, "({u}, {v})");
        }
    }

    /// A rational Bézier patch for the tests.
    struct NurbsPatch(usize, usize, Vec<DVec4>);

    impl NurbsPatch {
        fn at(&self, u: f64, v: f64) -> DVec3 {
            let h = bezier_patch_point([self.0, self.1], &self.2, u, v);
            h.truncate() / h.w
        }
    }

    #[test]
    fn composing_a_triangle_is_exact() {
        let lattice = bent();
        let patch = crate::triangle::TriangleBezier::new(
            2,
            vec![
                DVec3::new(-0.5, -0.5, 0.0),
                DVec3::new(0.0, -0.5, 0.3),
                DVec3::new(0.5, -0.5, 0.0),
                DVec3::new(-0.5, 0.0, 0.2),
                DVec3::new(0.0, 0.0, 0.1),
                DVec3::new(-0.5, 0.5, 0.0),
            ],
        )
        .unwrap();
        let composed = Lattice::around(DVec3::splat(-1.0), DVec3::splat(1.0), [1, 1, 2])
            .map(|mut l| {
                let k = l.point_index(1, 1, 1);
                let p = l.points()[k];
                l.set_point(k, p + DVec3::new(0.1, 0.2, 0.3)).unwrap();
                l
            })
            .unwrap();
        for lattice in [lattice, composed] {
            let result = lattice.compose_triangle(&patch).unwrap();
            assert_eq!(result.degree(), lattice.total_degree() * 2);
            for (u, v) in [(0.1, 0.2), (0.6, 0.3), (0.0, 1.0), (0.25, 0.25)] {
                let expected = lattice.deform_point(patch.evaluate(u, v).point);
                assert!(
                    result.evaluate(u, v).point.distance(expected) < 1e-9,
                    "({u}, {v})"
                );
            }
        }
    }

    #[test]
    fn hermite_cells_converge_at_fourth_order() {
        // A cylinder piece through a bent lattice: halving the cells divides the error by ~16.
        let lattice = bent();
        let surface = |u: f64, v: f64| -> Result<SurfaceDerivatives, GeometryError> {
            Ok(SurfaceDerivatives {
                point: DVec3::new(u.cos() * 0.8, u.sin() * 0.8, v),
                su: DVec3::new(-u.sin() * 0.8, u.cos() * 0.8, 0.0),
                sv: DVec3::Z,
                suu: DVec3::new(-u.cos() * 0.8, -u.sin() * 0.8, 0.0),
                suv: DVec3::ZERO,
                svv: DVec3::ZERO,
            })
        };
        let domain = [0.0, 1.5, -0.8, 0.8];
        let (_, e2) = hermite_cells(&lattice, domain, 2, &surface).unwrap();
        let (_, e4) = hermite_cells(&lattice, domain, 4, &surface).unwrap();
        let (_, e8) = hermite_cells(&lattice, domain, 8, &surface).unwrap();
        assert!(e2 > 0.0 && e4 < e2 / 8.0 && e8 < e4 / 8.0, "{e2} {e4} {e8}");
    }

    #[test]
    fn bad_lattices_are_refused() {
        let axes = [DVec3::X, DVec3::Y, DVec3::Z];
        assert!(Lattice::undisturbed(DVec3::ZERO, axes, [0, 1, 1]).is_err());
        assert!(Lattice::undisturbed(DVec3::ZERO, axes, [5, 1, 1]).is_err());
        assert!(
            Lattice::undisturbed(DVec3::ZERO, [DVec3::X, DVec3::Y, DVec3::X], [1, 1, 1]).is_err()
        );
        assert!(Lattice::undisturbed(DVec3::NAN, axes, [1, 1, 1]).is_err());
        assert!(Lattice::new(DVec3::ZERO, axes, [1, 1, 1], vec![DVec3::ZERO; 7]).is_err());
        let mut lattice = Lattice::undisturbed(DVec3::ZERO, axes, [1, 1, 1]).unwrap();
        let before = lattice.clone();
        assert!(lattice.set_point(8, DVec3::ZERO).is_err());
        assert!(lattice.set_point(0, DVec3::NAN).is_err());
        assert_eq!(lattice, before);
        // A flat set of objects still gets a box with a thickness.
        let flat = Lattice::around(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), [1, 1, 1]).unwrap();
        assert!(flat.axes()[2].z > 0.1);
    }
}
