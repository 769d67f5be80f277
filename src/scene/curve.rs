//! NURBS curves in space as a scene object kind: any degree, knots and weights, open, closed or
//! periodic (exact circles, arcs, interpolants, polylines and splines are all NURBS curves).
//! They reach the GPU as their rational Bézier segments ([`CurveFeed`], The NURBS Book A5.6),
//! which a compute pass samples into line-strip vertices; a drag re-derives the feed and
//! re-evaluates the moved point's segments. A curve has no faces and no triangles: it exports
//! as a line strip.

use glam::{DAffine3, DVec3, DVec4};

use super::json::{self, FormatError, Geometry, NamedGeometry};
use super::kind::KindFace;
use super::record::KindEntry;
use super::{Decomposition, ObjectGeometry, ObjectKind, SceneObject};
use crate::kernel::tess::{Tessellation, TriangleMesh};
use crate::kernel::{GeometryError, NurbsSurface, SpaceCurve};

/// What a curve feeds the GPU: its rational Bézier segments, all of one degree, each
/// `degree + 1` homogeneous points (w·x, w·y, w·z, w) long, segment k at k·(degree + 1).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CurveFeed {
    pub degree: usize,
    pub points: Vec<DVec4>,
    /// Each segment's parameter interval in the curve's own domain.
    pub domains: Vec<[f64; 2]>,
}

impl CurveFeed {
    /// The segments of `curve` ([`SpaceCurve::bezier_segments`]).
    pub fn of(curve: &SpaceCurve) -> Self {
        let segments = curve.bezier_segments();
        Self {
            degree: curve.degree(),
            points: segments
                .iter()
                .flat_map(|s| s.homogeneous_points().iter().copied())
                .collect(),
            domains: segments
                .iter()
                .map(SpaceCurve::domain)
                .map(Into::into)
                .collect(),
        }
    }

    pub fn segment_count(&self) -> usize {
        self.domains.len()
    }

    /// The homogeneous points of segment `segment`.
    pub fn segment(&self, segment: usize) -> Option<&[DVec4]> {
        let n = self.degree + 1;
        self.points.get(segment * n..(segment + 1) * n)
    }

    /// The point of segment `segment` at local s ∈ [0, 1], by de Casteljau's algorithm on the
    /// homogeneous points (The NURBS Book A1.5, then the projection).
    pub fn point(&self, segment: usize, s: f64) -> Option<DVec3> {
        let mut q = self.segment(segment)?.to_vec();
        for r in 1..q.len() {
            for i in 0..q.len() - r {
                q[i] = q[i] * (1.0 - s) + q[i + 1] * s;
            }
        }
        let h = q.first()?;
        Some(h.truncate() / h.w)
    }
}

impl ObjectKind for SpaceCurve {
    fn kind_name(&self) -> &'static str {
        "a NURBS curve"
    }

    fn describe(&self) -> String {
        let kind = if self.is_polynomial() {
            "B-spline"
        } else {
            "NURBS"
        };
        let closed = match self.ends() {
            Ok((a, b)) if a.distance(b) <= 1e-9 * (1.0 + a.length()) => ", closed",
            _ => "",
        };
        format!(
            "{kind} curve degree {}, {} points{closed}",
            self.degree(),
            self.count()
        )
    }

    fn control_point_count(&self) -> usize {
        self.count()
    }

    fn control_points(&self) -> Vec<DVec3> {
        (0..self.count()).map(|i| self.control_point(i)).collect()
    }

    fn weights(&self) -> Vec<f64> {
        (0..self.count()).map(|i| self.weight(i)).collect()
    }

    /// The control polygon.
    fn net_lines(&self) -> Vec<u32> {
        (1..self.count() as u32).flat_map(|i| [i - 1, i]).collect()
    }

    fn bounds(&self) -> Option<(DVec3, DVec3)> {
        super::kind::points_box((0..self.count()).map(|i| self.control_point(i)))
    }

    /// The changed segments are the point's local support
    /// ([`SpaceCurve::segments_supported_by`]).
    fn move_control_point(
        &mut self,
        index: usize,
        position: DVec3,
    ) -> Result<Vec<usize>, GeometryError> {
        let twin = periodic_twin(self, index);
        let mut moved = self.with_point(index, position)?;
        let mut support = moved.segments_supported_by(index);
        if let Some(twin) = twin {
            moved = moved.with_point(twin, position)?;
            support.extend(moved.segments_supported_by(twin));
            support.sort_unstable();
            support.dedup();
        }
        *self = moved;
        Ok(support)
    }

    fn set_weight(&mut self, index: usize, weight: f64) -> Result<(), GeometryError> {
        let mut weighted = self.with_weight(index, weight)?;
        if let Some(twin) = periodic_twin(self, index) {
            weighted = weighted.with_weight(twin, weight)?;
        }
        *self = weighted;
        Ok(())
    }

    fn gpu_feed(&self) -> Result<Decomposition, GeometryError> {
        Ok(Decomposition {
            curve: Some(CurveFeed::of(self)),
            ..Default::default()
        })
    }

    /// The curve itself (The NURBS Book A4.1) at local s of segment `patch`; t is ignored.
    fn surface_point(&self, patch: usize, s: f64, _t: f64) -> Result<DVec3, GeometryError> {
        let breaks = self.span_breaks();
        let Some(span) = breaks.get(patch..patch + 2) else {
            return Err(GeometryError::NoSuchPatch {
                patch,
                count: breaks.len().saturating_sub(1),
            });
        };
        self.point_at((span[0] + (span[1] - span[0]) * s).clamp(span[0], span[1]))
    }

    /// The whole feed again: a curve's segments are few and cheap to derive.
    fn update_gpu_feed(
        &self,
        feed: &mut Decomposition,
        _patches: &[usize],
    ) -> Result<(), GeometryError> {
        feed.curve = Some(CurveFeed::of(self));
        Ok(())
    }

    /// None: a curve exports as a line strip ([`ObjectKind::space_curve`]).
    fn tessellate(
        &self,
        _tessellation: Tessellation,
        _curvature: bool,
    ) -> Result<Vec<TriangleMesh>, GeometryError> {
        Ok(Vec::new())
    }

    /// None: a curve bounds no surface for the analyses to sample.
    fn faces(&self) -> Vec<KindFace<'_>> {
        Vec::new()
    }

    fn transformed(&self, transform: &DAffine3) -> Result<ObjectGeometry, GeometryError> {
        SpaceCurve::transformed(self, transform).map(ObjectGeometry::new)
    }

    fn bake_lattice(
        &self,
        _lattice: &crate::kernel::ffd::Lattice,
        _tolerance: f64,
    ) -> Result<(ObjectGeometry, crate::kernel::ffd::Baked), GeometryError> {
        Err(GeometryError::Construction {
            what: "lattice",
            message: "a lattice deforms surfaces; a curve takes none".into(),
        })
    }

    fn same_layout(&self, other: &ObjectGeometry) -> bool {
        other
            .downcast_ref::<SpaceCurve>()
            .is_some_and(|b| b.degree() == self.degree() && b.knots() == self.knots())
    }

    fn displacement_domain(&self) -> Option<[f64; 4]> {
        None
    }

    fn nurbs_surface(&self) -> Option<&NurbsSurface> {
        None
    }

    fn space_curve(&self) -> Option<&SpaceCurve> {
        Some(self)
    }

    fn cage(&self) -> Option<&crate::kernel::PolygonMesh> {
        None
    }

    /// knotwork's JSON for curves ([`super::json`]), with homogeneous points so that a
    /// rational curve reads back bit for bit.
    fn record(&self) -> serde_json::Value {
        json::object_value(
            &NamedGeometry {
                name: None,
                geometry: Geometry::Curve(self.clone()),
            },
            true,
        )
    }
}

/// The other copy of control point `index` of a periodic curve (an unclamped knot vector
/// whose last p points repeat the first p, as a closed interpolant has), which must move with
/// it to keep the curve closed and smooth at its seam; `None` for any other point or curve.
pub fn periodic_twin(curve: &SpaceCurve, index: usize) -> Option<usize> {
    let (p, n) = (curve.degree(), curve.count());
    let knots = curve.knots();
    let clamped =
        knots[..=p].iter().all(|&k| k == knots[0]) || knots[n..].iter().all(|&k| k == knots[n + p]);
    if clamped || n < 2 * p + 1 {
        return None;
    }
    let same = |i: usize| curve.homogeneous_points()[i] == curve.homogeneous_points()[n - p + i];
    if !(0..p).all(same) {
        return None;
    }
    match index {
        i if i < p => Some(n - p + i),
        i if i >= n - p && i < n => Some(i + p - n),
        _ => None,
    }
}

/// NURBS curves.
pub(super) const ENTRY: KindEntry = KindEntry {
    record_type: "nurbs_curve",
    read: read_record,
    examples,
};

fn read_record(path: &str, record: serde_json::Value) -> Result<ObjectGeometry, FormatError> {
    match json::object_from_value(path, record)?.geometry {
        Geometry::Curve(c) => Ok(ObjectGeometry::new(c)),
        _ => Err(FormatError::new(
            format!("{path}.type"),
            "expected a NURBS curve",
        )),
    }
}

/// An exact circle (rational quadratic, closed), a quartic on uneven knots with uneven
/// weights, one segment of degree 20, and a closed (periodic) cubic interpolant.
fn examples() -> Vec<SceneObject> {
    use crate::kernel::{construct, splines};
    let mut objects = Vec::new();
    if let Ok(circle) = construct::circle(
        DVec3::new(0.5, -0.3, 0.2),
        DVec3::new(0.3, 0.2, 1.0),
        DVec3::X,
        1.5,
    ) {
        objects.push(SceneObject::new("circle", ObjectGeometry::new(circle)));
    }
    let points: Vec<DVec3> = (0..8)
        .map(|i| {
            let x = i as f64;
            DVec3::new(x, (1.1 * x).sin(), 0.4 * (0.7 * x).cos())
        })
        .collect();
    let weights: Vec<f64> = (0..8).map(|i| 1.0 + 0.5 * (1.9 * i as f64).sin()).collect();
    let knots = vec![
        0.0, 0.0, 0.0, 0.0, 0.0, 0.2, 0.45, 0.5, 1.0, 1.0, 1.0, 1.0, 1.0,
    ];
    if let Ok(quartic) = SpaceCurve::new(4, knots, points.clone(), Some(weights)) {
        objects.push(SceneObject::new(
            "rational quartic",
            ObjectGeometry::new(quartic),
        ));
    }
    // One Bézier segment of degree 20: the GPU's Bernstein sums at a high degree.
    let wave: Vec<DVec3> = (0..21)
        .map(|i| {
            let x = i as f64 * 0.3;
            DVec3::new(x, (1.7 * x).sin(), 0.2 * (0.9 * x).cos())
        })
        .collect();
    let mut knots = vec![0.0; 21];
    knots.extend([1.0; 21]);
    if let Ok(high) = SpaceCurve::new(20, knots, wave, None) {
        objects.push(SceneObject::new("degree 20", ObjectGeometry::new(high)));
    }
    let ring: Vec<DVec3> = (0..6)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 6.0;
            DVec3::new(2.0 * a.cos(), 1.2 * a.sin(), 0.3 * (2.0 * a).sin())
        })
        .collect();
    if let Ok(closed) = splines::interpolate_closed(&ring, 3, splines::Parametrization::Centripetal)
    {
        objects.push(SceneObject::new(
            "closed interpolant",
            ObjectGeometry::new(closed),
        ));
    }
    objects
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::splines;

    #[test]
    fn moving_a_periodic_curves_seam_point_keeps_it_closed_and_smooth() {
        let ring: Vec<DVec3> = (0..7)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 7.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let mut curve =
            splines::interpolate_closed(&ring, 3, splines::Parametrization::ChordLength).unwrap();
        let n = curve.count();
        assert_eq!(periodic_twin(&curve, 1), Some(n - 2));
        assert_eq!(periodic_twin(&curve, n - 1), Some(2));
        assert_eq!(periodic_twin(&curve, 4), None);
        let support = curve
            .move_control_point(1, DVec3::new(2.0, 1.0, 0.5))
            .unwrap();
        assert_eq!(curve.control_point(n - 2), DVec3::new(2.0, 1.0, 0.5));
        let (a, b) = curve.ends().unwrap();
        assert!(a.distance(b) < 1e-12, "{a} {b}");
        // The twin's segments are in the support: the last segments change too.
        assert!(support.contains(&0) && support.contains(&(curve.span_breaks().len() - 2)));
        let (t0, t1) = curve.domain();
        let (d0, d1) = (
            curve.derivatives(t0, 2).unwrap(),
            curve.derivatives(t1, 2).unwrap(),
        );
        assert!(d0[1].distance(d1[1]) < 1e-9 && d0[2].distance(d1[2]) < 1e-9);
        // A clamped curve's points have no twins.
        let open =
            splines::interpolate_through(&ring, 3, splines::Parametrization::ChordLength, None)
                .unwrap();
        assert_eq!(periodic_twin(&open, 0), None);
    }
}
