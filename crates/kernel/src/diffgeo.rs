//! Differential geometry of parametric surfaces: derivatives, the unit normal (with its limit at
//! degenerate points), the first and second fundamental forms, and Gaussian, mean and principal
//! curvatures with principal directions.
//!
//! With n = Su × Sv / |Su × Sv|: E = Su·Su, F = Su·Sv, G = Sv·Sv; L = Suu·n, M = Suv·n,
//! N = Svv·n. Then K = (LN − M²)/(EG − F²), H = (EN − 2FM + GL) / (2(EG − F²)) and
//! k1,2 = H ± √(H² − K) (do Carmo, §3-3; The NURBS Book uses the same forms).
//! Sign convention: a normal curvature is positive where the surface bends toward n, so a sphere
//! with outward normals has k1 = k2 = −1/r, H = −1/r and K = 1/r².

use glam::{DVec3, DVec4};

/// Below this value of sin²(angle between Su and Sv) the tangent plane is taken as degenerate and
/// the normal comes from the limit rule ([`SurfaceDerivatives::collapsed_edge_normal`]). The WGSL
/// evaluator (`shaders/eval_bezier.wgsl`, `DEGENERATE_SIN2`) uses the same value.
pub const DEGENERATE_SIN2: f64 = 1e-10;

/// How far (as a fraction of the distance to the domain centre) the last-resort normal rule moves
/// the parameter inward. (The WGSL evaluator uses its one nudged evaluation, at
/// `CURVATURE_NUDGE` in `shaders/eval_bezier.wgsl`, for this rarely reached rule too.)
pub const NORMAL_NUDGE: f64 = 1e-3;

/// How far (as a fraction of the distance to the domain centre) curvature at a degenerate point
/// is sampled inward: the fundamental-form quotients are 0/0 at the point itself, and the limit
/// is approached within O(this) of the true value.
pub const CURVATURE_NUDGE: f64 = 1e-6;

/// Relative size of k1 − k2 = 2√(H² − K) below which a point counts as an umbilic (no principal
/// directions). H² − K cancels catastrophically at an umbilic (rounding of order ε·H² becomes
/// √ε·|H| ≈ 1.5e-8·|H| after the root), so the threshold sits well above that.
pub const UMBILIC_TOLERANCE: f64 = 1e-6;

/// Position and partial derivatives of a surface at one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfaceDerivatives {
    pub point: DVec3,
    pub su: DVec3,
    pub sv: DVec3,
    pub suu: DVec3,
    pub suv: DVec3,
    pub svv: DVec3,
}

/// Su × Sv normalized, or `None` where the tangent plane is degenerate (the tests of
/// [`SurfaceDerivatives::regular_normal`]).
pub fn regular_normal_of(su: DVec3, sv: DVec3) -> Option<DVec3> {
    let n = su.cross(sv);
    let n2 = n.length_squared();
    let (a, b) = (su.length_squared(), sv.length_squared());
    let scale = a * b;
    if n2 > DEGENERATE_SIN2 * scale && n2 > 0.0 && a.min(b) > DEGENERATE_SIN2 * a.max(b) {
        Some(n / n2.sqrt())
    } else {
        None
    }
}

impl SurfaceDerivatives {
    /// Σ w_k P_k over weighted points (a stencil's entries: point index, weights of position,
    /// Su, Sv, Suu, Suv, Svv); `None` where an index is past `points`.
    pub fn from_weights(
        points: &[DVec3],
        weights: impl IntoIterator<Item = (u32, [f64; 6])>,
    ) -> Option<Self> {
        let mut d = [DVec3::ZERO; 6];
        for (p, w) in weights {
            let point = *points.get(p as usize)?;
            for (sum, c) in d.iter_mut().zip(w) {
                *sum += point * c;
            }
        }
        let [point, su, sv, suu, suv, svv] = d;
        Some(Self {
            point,
            su,
            sv,
            suu,
            suv,
            svv,
        })
    }

    /// K, H, k1, k2 about the normal Su × Sv; `None` where the tangent plane is degenerate.
    pub fn curvature_values(&self) -> Option<CurvatureValues> {
        let normal = self.regular_normal()?;
        CurvatureValues::from_forms(&FundamentalForms::new(self, normal))
    }

    /// The unit normal's derivatives (N_u, N_v) by the Weingarten equations (do Carmo 3.3):
    /// with D = EG − F², N_u = ((MF − LG) S_u + (LF − ME) S_v) / D and N_v = ((NF − MG) S_u +
    /// (MF − NE) S_v) / D; zero where D ≤ 0. `normal` is the unit normal. WGSL:
    /// `normal_derivatives` in `shaders/diffgeo.wgsl`.
    pub fn normal_derivatives(&self, normal: DVec3) -> (DVec3, DVec3) {
        let FundamentalForms { e, f, g, l, m, n } = FundamentalForms::new(self, normal);
        let det = e * g - f * f;
        if det <= 0.0 {
            return (DVec3::ZERO, DVec3::ZERO);
        }
        (
            (self.su * (m * f - l * g) + self.sv * (l * f - m * e)) / det,
            (self.su * (n * f - m * g) + self.sv * (m * f - n * e)) / det,
        )
    }

    /// Su × Sv normalized, or `None` where the tangent plane is degenerate: sin² of the angle
    /// between Su and Sv below [`DEGENERATE_SIN2`], or one derivative vanishing against the
    /// other (|Su|² or |Sv|² below [`DEGENERATE_SIN2`] times the other). The second test catches
    /// poles of rational surfaces, where the derivative along the collapsed edge is rounding
    /// noise whose direction (and so the sin² test) means nothing.
    pub fn regular_normal(&self) -> Option<DVec3> {
        regular_normal_of(self.su, self.sv)
    }

    /// The normal at a point where one partial derivative vanishes (a collapsed edge or a pole),
    /// as the limit from the interior. Near an edge u = u₀ where Sv ≡ 0, Sv ≈ (u − u₀) Suv, so
    /// Su × Sv ≈ (u − u₀) Su × Suv; likewise for Su ≡ 0 near v = v₀. The sign follows from which
    /// end of the domain (`u`, `v` in [0, 1]) the collapsed edge is at.
    pub fn collapsed_edge_normal(&self, u: f64, v: f64) -> Option<DVec3> {
        let n = if self.sv.length_squared() <= self.su.length_squared() {
            let side = if u < 0.5 { 1.0 } else { -1.0 };
            side * self.su.cross(self.suv)
        } else {
            let side = if v < 0.5 { 1.0 } else { -1.0 };
            side * self.suv.cross(self.sv)
        };
        let n2 = n.length_squared();
        (n2 > 0.0 && n2.is_finite()).then(|| n / n2.sqrt())
    }
}

/// The first (E, F, G) and second (L, M, N) fundamental forms at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FundamentalForms {
    pub e: f64,
    pub f: f64,
    pub g: f64,
    pub l: f64,
    pub m: f64,
    pub n: f64,
}

impl FundamentalForms {
    /// The forms from the derivatives and the unit normal.
    pub fn new(d: &SurfaceDerivatives, normal: DVec3) -> Self {
        Self {
            e: d.su.dot(d.su),
            f: d.su.dot(d.sv),
            g: d.sv.dot(d.sv),
            l: d.suu.dot(normal),
            m: d.suv.dot(normal),
            n: d.svv.dot(normal),
        }
    }

    /// EG − F², the squared area element.
    pub fn determinant(&self) -> f64 {
        self.e * self.g - self.f * self.f
    }
}

/// Curvatures at a point: Gaussian K, mean H, principal k1 ≥ k2 and, away from umbilics, the
/// principal directions (unit tangent vectors in space, for k1 and k2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curvature {
    pub gaussian: f64,
    pub mean: f64,
    pub k1: f64,
    pub k2: f64,
    pub directions: Option<[DVec3; 2]>,
}

/// The curvature values without directions (what shading and tessellation need).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CurvatureValues {
    pub gaussian: f64,
    pub mean: f64,
    pub k1: f64,
    pub k2: f64,
}

impl CurvatureValues {
    /// K = (LN − M²)/(EG − F²), H = (EN − 2FM + GL)/(2(EG − F²)), k1,2 = H ± √(H² − K);
    /// `None` where EG − F² ≤ 0 (a degenerate parametrization, where they are undefined).
    pub fn from_forms(forms: &FundamentalForms) -> Option<Self> {
        let FundamentalForms { e, f, g, l, m, n } = *forms;
        let det = forms.determinant();
        if !(det > 0.0) || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let gaussian = (l * n - m * m) * inv;
        let mean = (e * n - 2.0 * f * m + g * l) * (0.5 * inv);
        let disc = (mean * mean - gaussian).max(0.0).sqrt();
        Some(Self {
            gaussian,
            mean,
            k1: mean + disc,
            k2: mean - disc,
        })
    }
}

impl Curvature {
    /// The curvatures from the fundamental forms ([`CurvatureValues::from_forms`]) plus the
    /// principal directions; `None` where EG − F² ≤ 0.
    pub fn from_forms(d: &SurfaceDerivatives, forms: &FundamentalForms) -> Option<Self> {
        let FundamentalForms { e, f, g, l, m, n } = *forms;
        let CurvatureValues {
            gaussian,
            mean,
            k1,
            k2,
        } = CurvatureValues::from_forms(forms)?;
        let disc = 0.5 * (k1 - k2);
        let scale = k1.abs().max(k2.abs());
        let directions = if 2.0 * disc <= UMBILIC_TOLERANCE * scale || scale == 0.0 {
            None
        } else {
            let direction = |k: f64| {
                // (L − kE) du + (M − kF) dv = 0 and (M − kF) du + (N − kG) dv = 0: take the
                // better conditioned row; its null vector is (du, dv).
                let (a1, b1) = (l - k * e, m - k * f);
                let (a2, b2) = (m - k * f, n - k * g);
                let (du, dv) = if a1.hypot(b1) >= a2.hypot(b2) {
                    (-b1, a1)
                } else {
                    (-b2, a2)
                };
                (d.su * du + d.sv * dv).normalize_or_zero()
            };
            Some([direction(k1), direction(k2)])
        };
        Some(Self {
            gaussian,
            mean,
            k1,
            k2,
            directions,
        })
    }

    /// The values without the directions.
    pub fn values(&self) -> CurvatureValues {
        CurvatureValues {
            gaussian: self.gaussian,
            mean: self.mean,
            k1: self.k1,
            k2: self.k2,
        }
    }
}

/// Cartesian derivatives of S = A / w from the homogeneous ones a[k][l] = ∂^{k+l}A/∂u^k∂v^l
/// (The NURBS Book, eq. 4.20):
/// S_{kl} = (A_{kl} − Σ_{(i,j) ≤ (k,l), (i,j) ≠ (0,0)} C(k,i) C(l,j) w_{ij} S_{k−i,l−j}) / w.
pub(crate) fn rational_derivatives(a: &[[DVec4; 3]; 3]) -> SurfaceDerivatives {
    let w = |k: usize, l: usize| a[k][l].w;
    let xyz = |k: usize, l: usize| a[k][l].truncate();
    let w0 = w(0, 0);
    let point = xyz(0, 0) / w0;
    let inv = 1.0 / w0;
    let su = (xyz(1, 0) - w(1, 0) * point) * inv;
    let sv = (xyz(0, 1) - w(0, 1) * point) * inv;
    let suu = (xyz(2, 0) - 2.0 * w(1, 0) * su - w(2, 0) * point) * inv;
    let svv = (xyz(0, 2) - 2.0 * w(0, 1) * sv - w(0, 2) * point) * inv;
    let suv = (xyz(1, 1) - w(1, 0) * sv - w(0, 1) * su - w(1, 1) * point) * inv;
    SurfaceDerivatives {
        point,
        su,
        sv,
        suu,
        suv,
        svv,
    }
}
