//! Rational tensor-product Bézier patches sharing one pool of control points.
//!
//! A patch of degree (p, q) has (p + 1)(q + 1) control points P_ij with weights w_ij, stored as
//! indices into the set's point pool, row-major with i along u: `indices[i * (q + 1) + j]`.
//! Sharing the pool lets neighbouring patches (the Utah teapot's 32 patches use 290 points) move
//! together when one control point is dragged.
//!
//! S(u, v) = A(u, v) / w(u, v) with the homogeneous sum A = Σ_i Σ_j B_{i,p}(u) B_{j,q}(v) w_ij P_ij,
//! w = Σ_i Σ_j B_{i,p}(u) B_{j,q}(v) w_ij, and the derivatives of the quotient from
//! The NURBS Book, eq. 4.20 (the rational-surface derivative formula behind A4.4).

use std::collections::BTreeSet;

use glam::{DVec3, DVec4};

use super::MAX_BEZIER_DEGREE;
use super::bernstein::BernsteinBasis;
use super::diffgeo::{SurfaceDerivatives, rational_derivatives};
use super::error::{GeometryError, Location};

/// Capacity of the fixed-size basis arrays (degree + 1).
const BASIS_CAPACITY: usize = MAX_BEZIER_DEGREE + 1;

pub use super::diffgeo::{DEGENERATE_SIN2, NORMAL_NUDGE};

/// One patch: its degrees and the indices of its control points in the set's pool.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierPatch {
    degree_u: usize,
    degree_v: usize,
    indices: Vec<u32>,
}

impl BezierPatch {
    /// A patch of degree (`degree_u`, `degree_v`); `indices` row-major with i along u.
    /// Checked when it joins a [`BezierPatchSet`].
    pub fn new(degree_u: usize, degree_v: usize, indices: Vec<u32>) -> Self {
        Self {
            degree_u,
            degree_v,
            indices,
        }
    }

    pub fn degree_u(&self) -> usize {
        self.degree_u
    }

    pub fn degree_v(&self) -> usize {
        self.degree_v
    }

    /// Control point indices, row-major with i along u.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The pool index of control point (i, j).
    pub fn index(&self, i: usize, j: usize) -> u32 {
        self.indices[i * (self.degree_v + 1) + j]
    }
}

/// A set of rational Bézier patches over one shared pool of weighted control points.
/// The default is the empty set.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BezierPatchSet {
    points: Vec<DVec3>,
    weights: Vec<f64>,
    patches: Vec<BezierPatch>,
}

impl BezierPatchSet {
    /// Builds a set, checking every patch's degree (1..=[`MAX_BEZIER_DEGREE`]) and index count,
    /// that indices are in range, that coordinates are finite and that weights are finite and > 0.
    /// `weights = None` means every weight is 1 (a polynomial set).
    pub fn new(
        points: Vec<DVec3>,
        weights: Option<Vec<f64>>,
        patches: Vec<BezierPatch>,
    ) -> Result<Self, GeometryError> {
        let weights = super::curve::weights_or_ones(points.len(), weights)?;
        // One pass that only says whether all is well (large sets are mostly fine); the point
        // at fault is named by the second.
        let sound = points.iter().all(|p| p.is_finite())
            && weights.iter().all(|&w| w.is_finite() && w > 0.0);
        if !sound {
            for (index, (p, &w)) in points.iter().zip(&weights).enumerate() {
                super::curve::check_point(|| Location::point(index), &p.to_array(), w)?;
            }
        }
        for (patch_index, patch) in patches.iter().enumerate() {
            let (du, dv) = (patch.degree_u, patch.degree_v);
            for (d, degree) in [du, dv].into_iter().enumerate() {
                if !(1..=MAX_BEZIER_DEGREE).contains(&degree) {
                    return Err(GeometryError::Degree {
                        at: Location::patch(patch_index).then("degree").index(d),
                        degree,
                        max: MAX_BEZIER_DEGREE,
                    });
                }
            }
            let expected = (du + 1) * (dv + 1);
            if patch.indices.len() != expected {
                return Err(GeometryError::PointCount {
                    at: Location::patch(patch_index).then("indices"),
                    expected,
                    found: patch.indices.len(),
                });
            }
            if let Some((entry, &index)) = patch
                .indices
                .iter()
                .enumerate()
                .find(|&(_, &i)| i as usize >= points.len())
            {
                return Err(GeometryError::IndexOutOfRange {
                    at: Location::patch(patch_index).then("indices").index(entry),
                    index,
                    count: points.len(),
                });
            }
        }
        Ok(Self {
            points,
            weights,
            patches,
        })
    }

    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    pub fn patches(&self) -> &[BezierPatch] {
        &self.patches
    }

    /// The axis-aligned box of all control points; by the convex-hull property it contains every
    /// patch. `None` for an empty set.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.points.first()?;
        Some(
            self.points
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// Moves control point `index` to `position`. Rejects a non-finite position or an index out
    /// of range and leaves the set unchanged.
    pub fn set_point(&mut self, index: usize, position: DVec3) -> Result<(), GeometryError> {
        set_point_checked(&mut self.points, index, position)
    }

    /// Sets the weight of control point `index`, keeping its Cartesian position. Rejects a
    /// weight that is not finite and > 0, or an index out of range, and leaves the set unchanged.
    pub fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        if !(weight.is_finite() && weight > 0.0) {
            return Err(GeometryError::BadWeight {
                at: Location::point(index),
                weight,
            });
        }
        let count = self.weights.len();
        let slot = self
            .weights
            .get_mut(index)
            .ok_or(GeometryError::NoSuchPoint { index, count })?;
        *slot = weight;
        Ok(())
    }

    /// The set mapped by an affine transformation (applied to the control points; rational
    /// Bézier patches are affinely invariant). Fails if a point becomes non-finite.
    pub fn transformed(&self, transform: &glam::DAffine3) -> Result<Self, GeometryError> {
        let points = self
            .points
            .iter()
            .map(|&p| transform.transform_point3(p))
            .collect();
        Self::new(points, Some(self.weights.clone()), self.patches.clone())
    }

    fn patch(&self, patch: usize) -> Result<&BezierPatch, GeometryError> {
        self.patches.get(patch).ok_or(GeometryError::NoSuchPatch {
            patch,
            count: self.patches.len(),
        })
    }

    /// Position and partial derivatives up to order 2 of patch `patch` at (u, v) ∈ [0, 1]²
    /// (tensor-product Bernstein sums, then the rational quotient rule of The NURBS Book eq. 4.20).
    pub fn evaluate(
        &self,
        patch: usize,
        u: f64,
        v: f64,
    ) -> Result<SurfaceDerivatives, GeometryError> {
        let patch = self.patch(patch)?;
        let inside = |t: f64| crate::basis::in_domain(t, 0.0, 1.0);
        if !(inside(u) && inside(v)) {
            let (parameter, value) = if inside(u) { ("v", v) } else { ("u", u) };
            return Err(GeometryError::OutsideDomain {
                parameter,
                value,
                start: 0.0,
                end: 1.0,
            });
        }
        Ok(self.evaluate_in_domain(patch, u, v))
    }

    fn evaluate_in_domain(&self, patch: &BezierPatch, u: f64, v: f64) -> SurfaceDerivatives {
        let (p, q) = (patch.degree_u, patch.degree_v);
        // Degrees were checked against MAX_BEZIER_DEGREE in `new`, so both bases exist.
        let (Some(bu), Some(bv)) = (
            BernsteinBasis::<BASIS_CAPACITY>::new(p, u),
            BernsteinBasis::<BASIS_CAPACITY>::new(q, v),
        ) else {
            unreachable!("degree checked in BezierPatchSet::new");
        };
        // Row curves in v (value, ∂v, ∂²v) of the homogeneous points, one per row i.
        let mut rows = [[DVec4::ZERO; BASIS_CAPACITY]; 3];
        let mut row_points = [DVec4::ZERO; BASIS_CAPACITY];
        for i in 0..=p {
            for (j, h) in row_points.iter_mut().enumerate().take(q + 1) {
                let index = patch.index(i, j) as usize;
                let w = self.weights[index];
                *h = (self.points[index] * w).extend(w);
            }
            let sums = bv.sum_with_derivatives(&row_points[..=q]);
            for (row, sum) in rows.iter_mut().zip(sums) {
                row[i] = sum;
            }
        }
        // Then across the rows in u: a[k][l] = ∂^{k+l} A / ∂u^k ∂v^l.
        let [a00, a10, a20] = bu.sum_with_derivatives(&rows[0][..=p]);
        let [a01, a11, _] = bu.sum_with_derivatives(&rows[1][..=p]);
        let [a02, ..] = bu.sum_with_derivatives(&rows[2][..=p]);
        let zero = DVec4::ZERO;
        rational_derivatives(&[[a00, a01, a02], [a10, a11, zero], [a20, zero, zero]])
    }

    /// The unit normal Su × Sv / |Su × Sv| of patch `patch` at (u, v), defined everywhere:
    /// where the tangent plane degenerates (a collapsed edge or pole) it is the limit from the
    /// interior ([`SurfaceDerivatives::collapsed_edge_normal`]); if that fails too, the regular normal
    /// at a parameter moved [`NORMAL_NUDGE`] of the way toward the patch centre; never NaN.
    pub fn normal(&self, patch: usize, u: f64, v: f64) -> Result<DVec3, GeometryError> {
        let d = self.evaluate(patch, u, v)?;
        Ok(self.normal_from(self.patch(patch)?, &d, u, v))
    }

    /// The normal rule of [`Self::normal`] for derivatives `d` already evaluated at (u, v).
    pub fn normal_from(
        &self,
        patch: &BezierPatch,
        d: &SurfaceDerivatives,
        u: f64,
        v: f64,
    ) -> DVec3 {
        if let Some(n) = d.regular_normal().or_else(|| d.collapsed_edge_normal(u, v)) {
            return n;
        }
        let (un, vn) = (u + (0.5 - u) * NORMAL_NUDGE, v + (0.5 - v) * NORMAL_NUDGE);
        let nudged = self.evaluate_in_domain(patch, un, vn);
        nudged
            .regular_normal()
            .or_else(|| nudged.collapsed_edge_normal(un, vn))
            .unwrap_or(DVec3::Z)
    }
}

/// `points[index] = position`, refusing a non-finite position or an index out of range (and
/// leaving `points` unchanged then).
pub(crate) fn set_point_checked(
    points: &mut [DVec3],
    index: usize,
    position: DVec3,
) -> Result<(), GeometryError> {
    if let Some(coordinate) = position.to_array().iter().position(|c| !c.is_finite()) {
        return Err(GeometryError::NonFinitePoint {
            at: Location::point(index),
            coordinate,
        });
    }
    let count = points.len();
    let slot = points
        .get_mut(index)
        .ok_or(GeometryError::NoSuchPoint { index, count })?;
    *slot = position;
    Ok(())
}

/// Index pairs of the control net's lines: each patch's rows and columns, shared edges once.
pub fn net_line_indices(set: &BezierPatchSet) -> Vec<u32> {
    let mut edges = BTreeSet::new();
    for patch in set.patches() {
        let (p, q) = (patch.degree_u(), patch.degree_v());
        for i in 0..=p {
            for j in 0..=q {
                let a = patch.index(i, j);
                let mut add = |b: u32| {
                    if a != b {
                        edges.insert((a.min(b), a.max(b)));
                    }
                };
                if i < p {
                    add(patch.index(i + 1, j));
                }
                if j < q {
                    add(patch.index(i, j + 1));
                }
            }
        }
    }
    edges.into_iter().flat_map(|(a, b)| [a, b]).collect()
}
