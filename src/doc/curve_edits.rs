//! What the curve commands change: the knot, degree, direction and split commands on a curve
//! object and [`CurveEdit`]s (constructions on curve objects are the operation
//! [`crate::ops::construct`]). Worked out without touching the scene, as in [`super::plan`].

use super::parts::refuse;
use super::{Change, CurveEdit, EditError, geometry_error, object_at};
use crate::kernel::{GeometryError, SpaceCurve};
use crate::scene::{ObjectGeometry, Scene, SceneObject};

/// The object's curve, or the error naming `operation`.
pub(super) fn curve_of<'a>(
    object: &'a SceneObject,
    operation: &'static str,
) -> Result<&'a SpaceCurve, EditError> {
    object
        .kind()
        .space_curve()
        .ok_or_else(|| EditError::Geometry {
            name: object.name.clone(),
            source: GeometryError::Construction {
                what: operation,
                message: format!(
                    "needs a curve; this object is {}",
                    object.kind().kind_name()
                ),
            },
        })
}

/// Object `k` with its curve replaced by `map`'s result.
pub(super) fn map_curve(
    scene: &Scene,
    k: usize,
    operation: &'static str,
    map: impl FnOnce(&SpaceCurve) -> Result<SpaceCurve, GeometryError>,
) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    let curve = map(curve_of(object, operation)?).map_err(geometry_error(object))?;
    Ok(vec![Change::Replace {
        index: k,
        before: object.clone(),
        after: SceneObject {
            geometry: ObjectGeometry::new(curve),
            ..object.clone()
        },
    }])
}

/// Splits curve object `k` at parameter `value` into "name (a)" and "name (b)".
pub(super) fn split_curve(scene: &Scene, k: usize, value: f64) -> Result<Vec<Change>, EditError> {
    let object = object_at(scene, k)?;
    let (a, b) = curve_of(object, "split")?
        .split(value)
        .map_err(geometry_error(object))?;
    let parts = vec![ObjectGeometry::new(a), ObjectGeometry::new(b)];
    Ok(super::parts::split_parts(object, k, parts))
}

/// The changes of a [`CurveEdit`] of curve object `k`.
pub(super) fn edit_curve(
    scene: &Scene,
    k: usize,
    edit: &CurveEdit,
) -> Result<Vec<Change>, EditError> {
    match edit {
        CurveEdit::Close => map_curve(scene, k, "close", |c| {
            let (start, end) = c.ends()?;
            if start.distance(end) <= 1e-12 * (1.0 + start.length()) {
                return Err(refuse("close", "the curve is closed already"));
            }
            let last = c.count() - 1;
            c.with_point(last, c.control_point(0))
        }),
        CurveEdit::Open => map_curve(scene, k, "open", |c| {
            if crate::scene::periodic_twin(c, 0).is_none() {
                return Err(refuse(
                    "open",
                    "only a periodic curve opens; split a clamped one",
                ));
            }
            Ok(c.clamped())
        }),
        CurveEdit::RemovePoint { point } => {
            map_curve(scene, k, "remove point", |c| remove_point(c, *point))
        }
        CurveEdit::Join { other } => join(scene, k, *other),
    }
}

/// The curve without control point `point`, on evenly spaced clamped knots over its domain.
fn remove_point(curve: &SpaceCurve, point: usize) -> Result<SpaceCurve, GeometryError> {
    let n = curve.count();
    if point >= n {
        return Err(GeometryError::NoSuchPoint {
            index: point,
            count: n,
        });
    }
    let p = curve.degree();
    if n <= 2 {
        return Err(refuse("remove point", "a curve keeps at least two points"));
    }
    let degree = p.min(n - 2);
    let mut points = Vec::with_capacity(n - 1);
    let mut weights = Vec::with_capacity(n - 1);
    for i in (0..n).filter(|&i| i != point) {
        points.push(curve.control_point(i));
        weights.push(curve.weight(i));
    }
    let (a, b) = curve.domain();
    let count = points.len();
    let mut knots = vec![a; degree + 1];
    let spans = count - degree;
    knots.extend((1..spans).map(|k| a + (b - a) * k as f64 / spans as f64));
    knots.extend(std::iter::repeat_n(b, degree + 1));
    SpaceCurve::new(degree, knots, points, Some(weights))
}

/// Curve `k` followed by curve `other` (turned so that its nearer end meets `k`'s end), as
/// one curve in `k`'s place; `other` is removed.
fn join(scene: &Scene, k: usize, other: usize) -> Result<Vec<Change>, EditError> {
    let first = object_at(scene, k)?;
    let second = object_at(scene, other)?;
    if k == other {
        return Err(geometry_error(first)(refuse(
            "join",
            "a curve cannot join itself",
        )));
    }
    let (a, b) = (curve_of(first, "join")?, curve_of(second, "join")?);
    let size = crate::kernel::curve::control_box_size([a, b]);
    let (_, end) = a.ends().map_err(geometry_error(first))?;
    let (s0, s1) = b.ends().map_err(geometry_error(second))?;
    let (b, gap) = if end.distance(s0) <= end.distance(s1) {
        (b.clone(), end.distance(s0))
    } else {
        (b.reverse(), end.distance(s1))
    };
    if gap > 1e-6 * size.max(1e-300) {
        return Err(geometry_error(first)(refuse(
            "join",
            format!(
                "{} does not start where {} ends (the gap is {gap:.3e})",
                second.name, first.name
            ),
        )));
    }
    let joined = a.join(&b).map_err(geometry_error(first))?;
    let mut changes = vec![Change::Replace {
        index: k,
        before: first.clone(),
        after: SceneObject {
            geometry: ObjectGeometry::new(joined),
            ..first.clone()
        },
    }];
    changes.push(Change::Remove {
        index: other,
        object: second.clone(),
    });
    Ok(changes)
}

/// [`crate::ops::intersect`]: every branch where the faces of objects `a` and `b` meet
/// ([`crate::kernel::intersect`], tolerance 1e-6 and chords 1e-3 of the scene's size), each as
/// the cubic through its points (closed and C² for a loop; The NURBS Book §9.2), added as
/// curve objects; and the label, which counts them and any touching points.
pub(crate) fn intersection_curves(
    scene: &Scene,
    a: usize,
    b: usize,
) -> Result<(Vec<Change>, String), EditError> {
    use crate::kernel::intersect::IntersectOptions;
    let (oa, ob) = (object_at(scene, a)?, object_at(scene, b)?);
    let refuse_with = |object: &SceneObject, message: String| {
        geometry_error(object)(refuse("intersection", message))
    };
    if a == b {
        return Err(refuse_with(
            oa,
            "an object cannot be intersected with itself".into(),
        ));
    }
    for o in [oa, ob] {
        if o.faces().is_empty() {
            return Err(refuse_with(
                o,
                format!("{} has no faces", o.kind().kind_name()),
            ));
        }
    }
    let size = scene
        .bounds()
        .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-12));
    let options = IntersectOptions::for_size(size);
    let mut curves = Vec::new();
    let mut touching = 0;
    for found in
        super::surface_ops::object_intersections(oa, ob, &options).map_err(geometry_error(oa))?
    {
        touching += found.touching.len();
        for branch in found.curves {
            let curve = super::surface_ops::branch_curve(&branch.points, branch.closed);
            curves.push(curve.map_err(geometry_error(oa))?);
        }
    }
    if curves.is_empty() {
        let message = if touching > 0 {
            format!(
                "{} and {} only touch ({touching} point(s))",
                oa.name, ob.name
            )
        } else {
            format!("{} and {} do not meet", oa.name, ob.name)
        };
        return Err(refuse_with(oa, message));
    }
    let base = format!("{} × {}", oa.name, ob.name);
    let changes = super::surface_ops::insert_objects(
        scene,
        &base,
        curves.into_iter().map(ObjectGeometry::new),
    );
    let mut label = format!("intersect {}: {} curve(s)", base, changes.len());
    if touching > 0 {
        label.push_str(&format!(", {touching} touching point(s)"));
    }
    Ok((changes, label))
}
