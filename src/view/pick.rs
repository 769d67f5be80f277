//! Screen-space picking and drag constraints: which control point is under the cursor, which
//! lie in a box, where a dragged point goes (free in the view plane, along an axis, in a plane),
//! and which surface point (object, (u, v)) a click hits.
//!
//! Screen positions are logical pixels with y down, (0, 0) at the viewport's top-left corner.

use glam::{DMat4, DVec2, DVec3, DVec4, Mat4};

use crate::kernel::BezierPatchSet;
use crate::kernel::trim::index::Coverage;
use crate::scene::Decomposition;

/// A point projected to the screen: position in pixels and depth (NDC z, 0 near .. 1 far).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projected {
    pub screen: DVec2,
    pub depth: f64,
}

/// The camera as picking needs it: world → clip and the viewport size in logical pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PickView {
    pub view_projection: DMat4,
    pub size: DVec2,
}

impl PickView {
    pub fn new(view_projection: Mat4, width: f32, height: f32) -> Self {
        Self {
            view_projection: view_projection.as_dmat4(),
            size: DVec2::new(f64::from(width), f64::from(height)),
        }
    }

    /// The point on the screen, or `None` behind the eye or outside the depth range.
    pub fn project(&self, p: DVec3) -> Option<Projected> {
        let clip = self.view_projection * p.extend(1.0);
        if !(clip.w > 1e-12) {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        if !(0.0..=1.0).contains(&ndc.z) {
            return None;
        }
        Some(Projected {
            screen: DVec2::new(
                (ndc.x + 1.0) * 0.5 * self.size.x,
                (1.0 - ndc.y) * 0.5 * self.size.y,
            ),
            depth: ndc.z,
        })
    }

    /// The ray through a screen position: origin on the near plane and unit direction.
    pub fn ray(&self, screen: DVec2) -> (DVec3, DVec3) {
        let ndc = DVec2::new(
            2.0 * screen.x / self.size.x.max(1.0) - 1.0,
            1.0 - 2.0 * screen.y / self.size.y.max(1.0),
        );
        let inverse = self.view_projection.inverse();
        let unproject = |z: f64| {
            let h: DVec4 = inverse * DVec4::new(ndc.x, ndc.y, z, 1.0);
            h.truncate() / h.w
        };
        let (near, far) = (unproject(0.0), unproject(0.5));
        (near, (far - near).normalize_or(DVec3::NEG_Z))
    }
}

/// The index of the point nearest to the eye among those within `radius` pixels of `cursor`
/// (ties in depth go to the one nearer the cursor).
pub fn pick_point(points: &[Option<Projected>], cursor: DVec2, radius: f64) -> Option<usize> {
    let r2 = radius * radius;
    points
        .iter()
        .enumerate()
        .filter_map(|(k, p)| {
            let p = (*p)?;
            let d2 = p.screen.distance_squared(cursor);
            (d2 <= r2).then_some((k, p.depth, d2))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.2.total_cmp(&b.2)))
        .map(|(k, ..)| k)
}

/// The segment (a pair of indices into `points`) nearest `cursor` on the screen, within
/// `radius`; of segments equally near, the one nearer the eye at its nearest point.
pub fn pick_segment(
    points: &[Option<Projected>],
    segments: &[(u32, u32)],
    cursor: DVec2,
    radius: f64,
) -> Option<usize> {
    segments
        .iter()
        .enumerate()
        .filter_map(|(k, &(a, b))| {
            let (p, q) = ((*points.get(a as usize)?)?, (*points.get(b as usize)?)?);
            let d = q.screen - p.screen;
            let t = if d.length_squared() > 0.0 {
                ((cursor - p.screen).dot(d) / d.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let distance = (p.screen + d * t).distance(cursor);
            let depth = p.depth + (q.depth - p.depth) * t;
            (distance <= radius).then_some((k, distance, depth))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.2.total_cmp(&b.2)))
        .map(|(k, ..)| k)
}

/// The indices of the points inside the screen rectangle spanned by corners `a` and `b`.
pub fn points_in_box(points: &[Option<Projected>], a: DVec2, b: DVec2) -> Vec<usize> {
    let (lo, hi) = (a.min(b), a.max(b));
    points
        .iter()
        .enumerate()
        .filter_map(|(k, p)| {
            let s = (*p)?.screen;
            (s.cmpge(lo).all() && s.cmple(hi).all()).then_some(k)
        })
        .collect()
}

/// Whether `p` lies inside the closed polygon `outline` (even–odd rule: a ray to +x crosses its
/// edges an odd number of times).
pub fn inside_polygon(outline: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    for k in 0..outline.len() {
        let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The indices of the points inside the lasso `outline` (screen pixels, closed).
pub fn points_in_lasso(points: &[Option<Projected>], outline: &[DVec2]) -> Vec<usize> {
    if outline.len() < 3 {
        return Vec::new();
    }
    points
        .iter()
        .enumerate()
        .filter_map(|(k, p)| inside_polygon(outline, (*p)?.screen).then_some(k))
        .collect()
}

/// The face (a loop of indices into `points`) under `cursor` nearest the eye: of the faces
/// whose projected outline holds the cursor, the one whose corners' mean depth is least. A
/// face with a corner off the screen is not picked.
pub fn pick_face(points: &[Option<Projected>], faces: &[Vec<u32>], cursor: DVec2) -> Option<usize> {
    faces
        .iter()
        .enumerate()
        .filter_map(|(k, face)| {
            let corners: Option<Vec<Projected>> =
                face.iter().map(|&v| *points.get(v as usize)?).collect();
            let corners = corners?;
            let outline: Vec<DVec2> = corners.iter().map(|c| c.screen).collect();
            let depth = corners.iter().map(|c| c.depth).sum::<f64>() / corners.len() as f64;
            inside_polygon(&outline, cursor).then_some((k, depth))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}

/// How a drag may move points, as in Blender: freely in the view plane, along one world axis
/// (X / Y / Z while dragging) or in the plane normal to one axis (Shift + X / Y / Z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Constraint {
    #[default]
    Free,
    /// Along the world axis 0 = X, 1 = Y, 2 = Z.
    Axis(usize),
    /// In the plane normal to the world axis (Shift + X is the YZ plane).
    Plane(usize),
}

impl Constraint {
    pub fn label(self) -> String {
        let axis = |a: usize| ["X", "Y", "Z"][a.min(2)];
        match self {
            Constraint::Free => "view plane".into(),
            Constraint::Axis(a) => format!("{} axis", axis(a)),
            Constraint::Plane(a) => format!("plane normal to {}", axis(a)),
        }
    }
}

/// Where a point grabbed at `anchor` goes when the cursor's ray is (`origin`, `direction`):
/// the ray's intersection with the view plane through the anchor (`view_dir` its normal), the
/// point of the axis line nearest to the ray, or the ray's intersection with the constraint
/// plane. Returns the anchor when the ray is parallel to the plane or the axis.
pub fn drag_position(
    anchor: DVec3,
    origin: DVec3,
    direction: DVec3,
    view_dir: DVec3,
    constraint: Constraint,
) -> DVec3 {
    let plane_hit = |normal: DVec3| {
        let denom = direction.dot(normal);
        if denom.abs() < 1e-9 {
            return anchor;
        }
        let t = (anchor - origin).dot(normal) / denom;
        origin + direction * t
    };
    match constraint {
        Constraint::Free => plane_hit(view_dir),
        Constraint::Plane(axis) => plane_hit(DVec3::AXES[axis.min(2)]),
        Constraint::Axis(axis) => {
            // Closest points of the lines anchor + s·a and origin + t·d.
            let a = DVec3::AXES[axis.min(2)];
            let w = anchor - origin;
            let (b, d, e) = (a.dot(direction), a.dot(w), direction.dot(w));
            let denom = 1.0 - b * b;
            if denom < 1e-9 {
                return anchor;
            }
            anchor + a * ((b * e - d) / denom)
        }
    }
}

/// `p` rounded to the nearest multiple of `step` in every coordinate (`step` ≤ 0: unchanged).
pub fn snap(p: DVec3, step: f64) -> DVec3 {
    if step > 0.0 && step.is_finite() {
        (p / step).round() * step
    } else {
        p
    }
}

/// A point of a surface under the cursor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    pub object: usize,
    /// The Bézier patch of the object's decomposition.
    pub patch: usize,
    /// Parameters in the object's own domain (the NURBS surface's (u, v)).
    pub u: f64,
    pub v: f64,
    pub point: DVec3,
    /// Distance from the ray's origin.
    pub distance: f64,
}

/// Samples per patch edge for the coarse ray test before refinement.
const HIT_GRID: usize = 8;

/// The nearest surface point on the ray (`origin`, `direction`) among the objects whose
/// `visible` entry is true: a ray–triangle test against an 8 × 8 grid of each Bézier patch,
/// refined by Gauss–Newton on the patch (minimizing the point's distance to the ray). Points a
/// trim loop cuts away are not hits: the ray goes on to whatever lies behind them.
pub fn pick_surface(
    objects: &[(&Decomposition, bool)],
    origin: DVec3,
    direction: DVec3,
) -> Option<SurfaceHit> {
    // Every coarse hit, nearest first: (distance, object, patch, s, t).
    let mut candidates = Vec::new();
    for (object, (decomposition, visible)) in objects.iter().enumerate() {
        if !visible {
            continue;
        }
        let set = &decomposition.set;
        for patch in 0..set.patches().len() {
            if let Some(trims) = &decomposition.trims
                && trims.coverage.get(patch) == Some(&Coverage::Outside)
            {
                continue;
            }
            for (s, t, distance) in coarse_hits(set, patch, origin, direction) {
                candidates.push((distance, object, patch, s, t));
            }
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, object, patch, s, t) in candidates {
        let decomposition = objects[object].0;
        let set = &decomposition.set;
        let (s, t) = refine(set, patch, s, t, origin, direction);
        let Ok(d) = set.evaluate(patch, s, t) else {
            continue;
        };
        let [u0, u1, v0, v1] = decomposition.domains[patch];
        let (u, v) = (u0 + (u1 - u0) * s, v0 + (v1 - v0) * t);
        if let Some(trims) = &decomposition.trims
            && !trims.keeps(patch, u, v)
        {
            continue;
        }
        return Some(SurfaceHit {
            object,
            patch,
            u,
            v,
            point: d.point,
            distance: (d.point - origin).dot(direction),
        });
    }
    None
}

/// The hits of the ray with the patch's coarse grid: (s, t) in the patch's (0, 1)² and the
/// distance along the ray.
fn coarse_hits(
    set: &BezierPatchSet,
    patch: usize,
    origin: DVec3,
    direction: DVec3,
) -> Vec<(f64, f64, f64)> {
    let n = HIT_GRID;
    let mut grid = Vec::with_capacity((n + 1) * (n + 1));
    for i in 0..=n {
        for j in 0..=n {
            let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
            match set.evaluate(patch, s, t) {
                Ok(d) => grid.push(d.point),
                Err(_) => return Vec::new(),
            }
        }
    }
    let at = |i: usize, j: usize| grid[i * (n + 1) + j];
    let mut hits = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let corners = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            for (tri, (a, b, c)) in [(0, 1, 2), (0, 2, 3)].into_iter().enumerate() {
                let Some((dist, beta, gamma)) =
                    ray_triangle(origin, direction, corners[a], corners[b], corners[c])
                else {
                    continue;
                };
                // Barycentric → grid parameters of the two triangles (0,0),(1,0),(1,1) and
                // (0,0),(1,1),(0,1) of the cell.
                let (ds, dt) = if tri == 0 {
                    (beta + gamma, gamma)
                } else {
                    (beta, beta + gamma)
                };
                hits.push(((i as f64 + ds) / n as f64, (j as f64 + dt) / n as f64, dist));
            }
        }
    }
    hits
}

/// Möller–Trumbore ray–triangle intersection: distance and barycentric (β, γ) of b and c.
fn ray_triangle(
    origin: DVec3,
    direction: DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = origin - a;
    let beta = s.dot(p) / det;
    let q = s.cross(e1);
    let gamma = direction.dot(q) / det;
    let t = e2.dot(q) / det;
    let eps = 1e-9;
    (beta >= -eps && gamma >= -eps && beta + gamma <= 1.0 + eps && t > 0.0)
        .then_some((t, beta, gamma))
}

/// Gauss–Newton on F(s, t) = P(S(s, t) − o), P projecting out the ray direction: the surface
/// point closest to the ray, from a start on the coarse grid. Stays in [0, 1]².
fn refine(
    set: &BezierPatchSet,
    patch: usize,
    mut s: f64,
    mut t: f64,
    origin: DVec3,
    direction: DVec3,
) -> (f64, f64) {
    let project = |v: DVec3| v - direction * v.dot(direction);
    for _ in 0..8 {
        let Ok(d) = set.evaluate(patch, s, t) else {
            break;
        };
        let f = project(d.point - origin);
        let (a, b) = (project(d.su), project(d.sv));
        // Normal equations of the 3 × 2 least-squares step.
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let det = aa * bb - ab * ab;
        if !(det.abs() > 1e-300) {
            break;
        }
        let (ra, rb) = (a.dot(f), b.dot(f));
        let ds = (bb * ra - ab * rb) / det;
        let dt = (aa * rb - ab * ra) / det;
        s = (s - ds).clamp(0.0, 1.0);
        t = (t - dt).clamp(0.0, 1.0);
        if ds.abs() + dt.abs() < 1e-12 {
            break;
        }
    }
    (s, t)
}

#[cfg(test)]
mod tests {
    #[test]
    fn lassos_and_faces_pick_what_lies_inside_them() {
        use super::*;
        let at = |x: f64, y: f64, depth: f64| {
            Some(Projected {
                screen: DVec2::new(x, y),
                depth,
            })
        };
        let points = [
            at(0.0, 0.0, 0.5),
            at(10.0, 0.0, 0.5),
            at(10.0, 10.0, 0.5),
            at(0.0, 10.0, 0.5),
            at(5.0, 5.0, 0.2),
            None,
        ];
        // An L-shaped lasso holds (5, 5) and (10, 10)'s neighbourhood but not the origin.
        let lasso = [
            DVec2::new(3.0, 3.0),
            DVec2::new(12.0, 3.0),
            DVec2::new(12.0, 12.0),
            DVec2::new(8.0, 12.0),
            DVec2::new(8.0, 6.0),
            DVec2::new(3.0, 6.0),
        ];
        assert_eq!(points_in_lasso(&points, &lasso), vec![2, 4]);
        assert!(points_in_lasso(&points, &lasso[..2]).is_empty());
        // Two faces over the cursor: the nearer wins; a face with a corner off screen is not
        // picked; outside every face nothing is.
        let faces = vec![vec![0, 1, 2, 3], vec![0, 1, 4], vec![1, 2, 5]];
        assert_eq!(pick_face(&points, &faces, DVec2::new(5.0, 2.0)), Some(1));
        assert_eq!(pick_face(&points, &faces, DVec2::new(5.0, 8.0)), Some(0));
        assert_eq!(pick_face(&points, &faces, DVec2::new(9.5, 5.0)), Some(0));
        assert_eq!(pick_face(&points, &faces, DVec2::new(20.0, 5.0)), None);
    }

    #[test]
    fn the_segment_nearest_the_cursor_is_picked_within_the_radius() {
        use super::*;
        let at = |x: f64, y: f64, depth: f64| {
            Some(Projected {
                screen: DVec2::new(x, y),
                depth,
            })
        };
        let points = [
            at(0.0, 0.0, 1.0),
            at(10.0, 0.0, 1.0),
            at(10.0, 10.0, 2.0),
            None,
        ];
        let segments = [(0, 1), (1, 2), (2, 3)];
        // 3 px below the middle of 0–1, 7 px left of 1–2.
        assert_eq!(
            pick_segment(&points, &segments, DVec2::new(5.0, 3.0), 5.0),
            Some(0)
        );
        // Past the end of 0–1 the distance is to its end point.
        assert_eq!(
            pick_segment(&points, &segments, DVec2::new(-4.0, 0.0), 5.0),
            Some(0)
        );
        assert_eq!(
            pick_segment(&points, &segments, DVec2::new(-6.0, 0.0), 5.0),
            None
        );
        assert_eq!(
            pick_segment(&points, &segments, DVec2::new(12.0, 6.0), 5.0),
            Some(1)
        );
        // A segment with an end off the screen is never picked.
        assert_eq!(
            pick_segment(&points, &[(2, 3)], DVec2::new(10.0, 10.0), 5.0),
            None
        );
    }

    use super::*;
    use crate::scene::{ObjectGeometry, SceneObject};

    fn front_view() -> PickView {
        // Looking down -Y from y = 10 at the origin, 90° field of view, 200 × 100 pixels.
        let view = glam::camera::rh::view::look_at_mat4(
            glam::Vec3::new(0.0, 10.0, 0.0),
            glam::Vec3::ZERO,
            glam::Vec3::Z,
        );
        let proj = glam::camera::rh::proj::directx::perspective(
            std::f32::consts::FRAC_PI_2,
            2.0,
            0.1,
            100.0,
        );
        PickView::new(proj * view, 200.0, 100.0)
    }

    #[test]
    fn projection_and_ray_agree() {
        let view = front_view();
        let p = view.project(DVec3::ZERO).unwrap();
        assert!(p.screen.distance(DVec2::new(100.0, 50.0)) < 1e-4);
        // Up is screen-up (smaller y); +X (seen from +Y) is screen-left.
        assert!(view.project(DVec3::Z).unwrap().screen.y < 50.0);
        assert!(view.project(DVec3::X).unwrap().screen.x < 100.0);
        let (o, d) = view.ray(DVec2::new(100.0, 50.0));
        assert!(
            d.distance(DVec3::NEG_Y) < 1e-5 && o.x.abs() < 1e-5,
            "{o} {d}"
        );
        assert!(
            view.project(DVec3::new(0.0, 20.0, 0.0)).is_none(),
            "behind the eye"
        );
    }

    #[test]
    fn the_nearest_point_to_the_eye_wins_within_the_radius() {
        let view = front_view();
        let points: Vec<_> = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 5.0, 0.0), // in front of the first, same screen position
            DVec3::new(3.0, 0.0, 0.0), // far to the side
        ]
        .iter()
        .map(|&p| view.project(p))
        .collect();
        assert_eq!(pick_point(&points, DVec2::new(102.0, 51.0), 6.0), Some(1));
        assert_eq!(pick_point(&points, DVec2::new(150.0, 10.0), 6.0), None);
        assert_eq!(
            points_in_box(&points, DVec2::new(200.0, 0.0), DVec2::new(90.0, 100.0)),
            vec![0, 1]
        );
    }

    #[test]
    fn constrained_drags_stay_on_their_axis_or_plane() {
        let anchor = DVec3::new(1.0, 2.0, 3.0);
        let origin = DVec3::new(0.0, 10.0, 0.0);
        let direction = DVec3::new(0.3, -1.0, 0.2).normalize();
        let view_dir = DVec3::NEG_Y;
        let free = drag_position(anchor, origin, direction, view_dir, Constraint::Free);
        assert!(
            (free.y - anchor.y).abs() < 1e-12,
            "free drags stay in the view plane"
        );
        let x = drag_position(anchor, origin, direction, view_dir, Constraint::Axis(0));
        assert!((x.y - 2.0).abs() < 1e-12 && (x.z - 3.0).abs() < 1e-12 && x.x != 1.0);
        let yz = drag_position(anchor, origin, direction, view_dir, Constraint::Plane(0));
        assert!((yz.x - 1.0).abs() < 1e-12);
        // On the axis, the result is the point nearest the ray: the residual is normal to the axis.
        let t = (x - origin).dot(direction);
        let residual = origin + direction * t - x;
        assert!(residual.x.abs() < 1e-9);
        assert_eq!(
            snap(DVec3::new(0.26, -0.74, 1.0), 0.25),
            DVec3::new(0.25, -0.75, 1.0)
        );
    }

    #[test]
    fn a_click_on_a_sphere_reports_its_parameters_and_point() {
        let sphere = crate::kernel::construct::sphere(DVec3::ZERO, 2.0).unwrap();
        let object = SceneObject::new("ball", ObjectGeometry::new(sphere.clone()));
        let d = object.decompose().unwrap();
        let origin = DVec3::new(0.3, 10.0, 0.4);
        let hit = pick_surface(&[(&d, true)], origin, DVec3::NEG_Y).unwrap();
        // Analytic: the ray x = 0.3, z = 0.4 meets the sphere at y = sqrt(4 - 0.25).
        let expected = DVec3::new(0.3, (4.0f64 - 0.25).sqrt(), 0.4);
        assert!(hit.point.distance(expected) < 1e-9, "{:?}", hit.point);
        assert!((hit.distance - (10.0 - expected.y)).abs() < 1e-9);
        // The reported (u, v) evaluates to the same point on the NURBS surface itself.
        let p = sphere.point_at(hit.u, hit.v).unwrap();
        assert!(p.distance(expected) < 1e-9);
        assert!(pick_surface(&[(&d, false)], origin, DVec3::NEG_Y).is_none());
        assert!(pick_surface(&[(&d, true)], origin, DVec3::Y).is_none());

        // A hole around the front hit: the ray passes through it to the back of the sphere.
        let hole = crate::kernel::trim::shapes::ellipse(
            glam::DVec2::new(hit.u, hit.v),
            glam::DVec2::splat(0.05),
        )
        .unwrap();
        let holed = crate::kernel::TrimmedSurface::untrimmed(sphere.clone())
            .add_loop(hole, false)
            .unwrap();
        assert!(!holed.contains(hit.u, hit.v));
        let object = SceneObject::new("holed", ObjectGeometry::from_trimmed(holed));
        let d = object.decompose().unwrap();
        let back = pick_surface(&[(&d, true)], origin, DVec3::NEG_Y).unwrap();
        let expected = DVec3::new(0.3, -(4.0f64 - 0.25).sqrt(), 0.4);
        assert!(back.point.distance(expected) < 1e-9, "{:?}", back.point);
    }
}
