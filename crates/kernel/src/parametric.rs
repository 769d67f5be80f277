//! One interface for every face the editor shows: a parametric surface over a rectangle of
//! parameters, with its derivatives to second order and the region its trims keep.
//!
//! Every kind with faces yields them through [`ParametricSurface`]: a NURBS surface, a trimmed
//! surface, each patch of a Bézier patch set ([`PatchFace`]), a triangular Bézier patch (over
//! its triangle, or over the square by [`TriangleAsSquare`]). [`ShownFace`] shows any of them
//! as the viewport does, displaced along the normal and deformed by a lattice. Continuity,
//! curvature combs and principal directions take the interface, never a concrete kind.

use std::borrow::Borrow;

use glam::DVec3;

use super::diffgeo::{Curvature, FundamentalForms, SurfaceDerivatives};
use super::displace::Displacement;
use super::ffd::Lattice;
use super::triangle::TriangleBezier;
use super::{BezierPatchSet, NurbsSurface, TrimmedSurface};

/// A surface over a rectangle of parameters: position and partial derivatives to second
/// order, and which parameters its trims keep.
pub trait ParametricSurface {
    /// ((u0, u1), (v0, v1)).
    fn domain(&self) -> [(f64, f64); 2];

    /// Position and partial derivatives at (u, v) in the domain; `None` where undefined.
    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives>;

    /// Whether (u, v) lies in the kept region (true for an untrimmed surface).
    fn keeps(&self, _u: f64, _v: f64) -> bool {
        true
    }

    /// The point at (u, v).
    fn point(&self, u: f64, v: f64) -> Option<DVec3> {
        self.derivatives(u, v).map(|d| d.point)
    }

    /// The unit normal Su × Sv / |Su × Sv| at (u, v); `None` where the tangent plane is
    /// degenerate.
    fn normal(&self, u: f64, v: f64) -> Option<DVec3> {
        self.derivatives(u, v)?.regular_normal()
    }

    /// Gaussian, mean and principal curvatures and the principal directions at (u, v), from the
    /// fundamental forms (do Carmo §3-3); `None` where the tangent plane is degenerate.
    fn curvature(&self, u: f64, v: f64) -> Option<Curvature> {
        let d = self.derivatives(u, v)?;
        let normal = d.regular_normal()?;
        Curvature::from_forms(&d, &FundamentalForms::new(&d, normal))
    }
}

impl<T: ParametricSurface + ?Sized> ParametricSurface for &T {
    fn domain(&self) -> [(f64, f64); 2] {
        (**self).domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        (**self).derivatives(u, v)
    }

    fn keeps(&self, u: f64, v: f64) -> bool {
        (**self).keeps(u, v)
    }
}

impl<T: ParametricSurface + ?Sized> ParametricSurface for Box<T> {
    fn domain(&self) -> [(f64, f64); 2] {
        (**self).domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        (**self).derivatives(u, v)
    }

    fn keeps(&self, u: f64, v: f64) -> bool {
        (**self).keeps(u, v)
    }
}

impl ParametricSurface for NurbsSurface {
    fn domain(&self) -> [(f64, f64); 2] {
        NurbsSurface::domain(self)
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        self.evaluate(u, v).ok()
    }
}

impl ParametricSurface for TrimmedSurface {
    fn domain(&self) -> [(f64, f64); 2] {
        self.surface().domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        self.surface().evaluate(u, v).ok()
    }

    fn keeps(&self, u: f64, v: f64) -> bool {
        self.contains(u, v)
    }
}

/// One patch of a Bézier patch set (borrowed, or shared: `&BezierPatchSet`,
/// `Arc<BezierPatchSet>`), over [0, 1]².
pub struct PatchFace<S> {
    pub set: S,
    pub patch: usize,
}

impl<S: Borrow<BezierPatchSet>> ParametricSurface for PatchFace<S> {
    fn domain(&self) -> [(f64, f64); 2] {
        [(0.0, 1.0), (0.0, 1.0)]
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        self.set.borrow().evaluate(self.patch, u, v).ok()
    }
}

/// A triangular patch over its own barycentric (u, v) (w = 1 − u − v), in [0, 1]² with the
/// triangle u + v ≤ 1 kept (the polynomial extends beyond it).
impl ParametricSurface for TriangleBezier {
    fn domain(&self) -> [(f64, f64); 2] {
        [(0.0, 1.0), (0.0, 1.0)]
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        Some(self.evaluate(u, v))
    }

    fn keeps(&self, u: f64, v: f64) -> bool {
        u + v <= 1.0
    }
}

/// A surface over the triangle u, v ≥ 0, u + v ≤ 1 (a triangular patch, possibly shown
/// displaced or deformed) as a face over the square (s, t) ∈ [0, 1]², by u = s (1 − t),
/// v = t. Its sides: t = 0 is the triangle's edge v = 0, s = 0 the edge u = 0, s = 1 the edge
/// w = 0, and t = 1 collapses to the corner (0, 1), a degenerate side.
pub struct TriangleAsSquare<S>(pub S);

impl<S: ParametricSurface> ParametricSurface for TriangleAsSquare<S> {
    fn domain(&self) -> [(f64, f64); 2] {
        [(0.0, 1.0), (0.0, 1.0)]
    }

    /// The chain rule with u_s = 1 − t, u_t = −s, u_st = −1, v_t = 1 (the other first and
    /// second derivatives of the map vanish): S_s = T_u (1 − t), S_t = T_v − s T_u,
    /// S_ss = (1 − t)² T_uu, S_st = (1 − t)(T_uv − s T_uu) − T_u,
    /// S_tt = s² T_uu − 2 s T_uv + T_vv.
    fn derivatives(&self, s: f64, t: f64) -> Option<SurfaceDerivatives> {
        let d = self.0.derivatives(s * (1.0 - t), t)?;
        let r = 1.0 - t;
        Some(SurfaceDerivatives {
            point: d.point,
            su: d.su * r,
            sv: d.sv - d.su * s,
            suu: d.suu * (r * r),
            suv: (d.suv - d.suu * s) * r - d.su,
            svv: d.suu * (s * s) - d.suv * (2.0 * s) + d.svv,
        })
    }

    fn keeps(&self, s: f64, t: f64) -> bool {
        self.0.keeps(s * (1.0 - t), t)
    }
}

/// A displacement as a face carries it: the map and the (u0, u1, v0, v1) its (x, y) ∈ [0, 1]²
/// spans.
#[derive(Debug, Clone, Copy)]
pub struct FaceDisplacement<'a> {
    pub map: &'a Displacement,
    pub domain: [f64; 4],
}

/// A face as the viewport shows it: displaced along its normal ([`Displacement`]), then
/// deformed by a lattice ([`Lattice::deform`], the chain rule to second order).
pub struct ShownFace<'a, S> {
    pub face: S,
    pub displacement: Option<FaceDisplacement<'a>>,
    pub lattice: Option<&'a Lattice>,
}

/// The step, as a share of the domain's side, of the differences that give a displaced face's
/// second derivatives.
const DISPLACED_STEP: f64 = 1e-4;

impl<S: ParametricSurface> ShownFace<'_, S> {
    /// The displaced point and first derivatives at (u, v): P = S + a h N,
    /// P_u = S_u + a (h_u N + h N_u), P_v likewise, with N_u, N_v from the Weingarten
    /// equations ([`Displacement::displaced_derivatives`]).
    fn displaced_first(&self, map: &FaceDisplacement, u: f64, v: f64) -> Option<[DVec3; 3]> {
        let d = self.face.derivatives(u, v)?;
        let normal = d.regular_normal()?;
        let [u0, u1, v0, v1] = map.domain;
        let (wu, wv) = (u1 - u0, v1 - v0);
        let (x, y) = ((u - u0) / wu, (v - v0) / wv);
        Some(
            map.map
                .displaced_derivatives(&d, normal, x, y, [1.0 / wu, 1.0 / wv]),
        )
    }

    /// The displaced surface's derivatives: the first ones exact, the second ones by
    /// differences of the first (central inside, second-order one-sided at the domain's sides).
    fn displaced(&self, map: &FaceDisplacement, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        let [point, pu, pv] = self.displaced_first(map, u, v)?;
        let [(u0, u1), (v0, v1)] = self.face.domain();
        // d/dx of the first derivatives along one parameter, at x in [lo, hi].
        let along = |x: f64, lo: f64, hi: f64, at: &dyn Fn(f64) -> Option<[DVec3; 3]>| {
            let h = DISPLACED_STEP * (hi - lo);
            let [_, a_u, a_v] = if x + h <= hi { at(x + h)? } else { at(x - h)? };
            if x - h >= lo && x + h <= hi {
                let [_, b_u, b_v] = at(x - h)?;
                Some([(a_u - b_u) / (2.0 * h), (a_v - b_v) / (2.0 * h)])
            } else {
                // −3 f(0) + 4 f(±h) − f(±2h), over ±2h.
                let sign = if x + h <= hi { 1.0 } else { -1.0 };
                let [_, c_u, c_v] = at(x + 2.0 * sign * h)?;
                let k = sign * 2.0 * h;
                Some([
                    (a_u * 4.0 - pu * 3.0 - c_u) / k,
                    (a_v * 4.0 - pv * 3.0 - c_v) / k,
                ])
            }
        };
        let [puu, pvu] = along(u, u0, u1, &|x| self.displaced_first(map, x, v))?;
        let [puv, pvv] = along(v, v0, v1, &|y| self.displaced_first(map, u, y))?;
        Some(SurfaceDerivatives {
            point,
            su: pu,
            sv: pv,
            suu: puu,
            suv: 0.5 * (puv + pvu),
            svv: pvv,
        })
    }
}

impl<S: ParametricSurface> ParametricSurface for ShownFace<'_, S> {
    fn domain(&self) -> [(f64, f64); 2] {
        self.face.domain()
    }

    fn derivatives(&self, u: f64, v: f64) -> Option<SurfaceDerivatives> {
        let d = match &self.displacement {
            Some(map) => self.displaced(map, u, v)?,
            None => self.face.derivatives(u, v)?,
        };
        Some(match self.lattice {
            Some(lattice) => lattice.deform(&d),
            None => d,
        })
    }

    fn keeps(&self, u: f64, v: f64) -> bool {
        self.face.keeps(u, v)
    }
}
