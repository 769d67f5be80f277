//! What the surface operations change: offsets (and the objects they add), worked out without
//! touching the scene, as in [`super::plan`]. The command line uses the same functions, so the
//! editor, the page and `knotwork offset` make the same surfaces.

use super::parts::refuse;
use super::{Change, EditError, geometry_error, object_at};
use crate::kernel::TrimmedSurface;
use crate::kernel::offset::{Offset, OffsetShape, offset_face, offset_nurbs};
use crate::scene::operation::{ObjectRef, Planned};
use crate::scene::polysurface::Polysurface;
use crate::scene::{ObjectGeometry, Scene, SceneObject};

/// The tolerance (a fraction of the scene's size) offsets and fillets keep in the editor.
pub const EDITOR_TOLERANCE: f64 = 1e-4;

/// The tolerance (a fraction of the scene's size) within which the editor joins edges: the
/// tolerance its operations keep ([`EDITOR_TOLERANCE`]), since the edges a fillet, a blend or
/// a trim makes agree only to within it (a fillet's edge and the trim it cut meet to a few
/// 1e-6 of the size on a cylinder). One modelling tolerance for making and joining, as in
/// Rhino.
pub const JOIN_TOLERANCE: f64 = EDITOR_TOLERANCE;

/// Spans per direction a face without knots of its own (a Bézier or subdivision patch) starts
/// its fitted offset from.
const FACE_OFFSET_SPANS: usize = 2;

/// The diagonal of the scene's box (1 for an empty scene): what relative tolerances scale by.
pub fn scene_size(scene: &Scene) -> f64 {
    scene
        .bounds()
        .map_or(1.0, |(lo, hi)| lo.distance(hi).max(1e-12))
}

/// Every intersection of a face of object `a` with a face of object `b`
/// ([`crate::kernel::intersect::intersect_face_sets`]: each face's cells made once), with
/// the branches of a loop across a seam joined into one closed branch
/// ([`crate::kernel::intersect::Intersection::joined_across_seams`], within 10 × the
/// tolerance).
pub fn object_intersections(
    a: &SceneObject,
    b: &SceneObject,
    options: &crate::kernel::intersect::IntersectOptions,
) -> Result<Vec<crate::kernel::intersect::Intersection>, crate::kernel::GeometryError> {
    let (fa, fb) = (a.faces(), b.faces());
    Ok(
        crate::kernel::intersect::intersect_face_sets(&face_refs(&fa), &face_refs(&fb), options)?
            .into_iter()
            .map(|(_, found)| found.joined_across_seams(10.0 * options.tolerance))
            .collect(),
    )
}

/// Faces as [`crate::scene::SceneObject::faces`] gives them.
type Faces<'a> = [(
    Option<usize>,
    Box<dyn crate::kernel::parametric::ParametricSurface + 'a>,
)];

/// The faces as references, for the kernel's functions over sets of faces.
pub fn face_refs<'a, 'b: 'a>(
    faces: &'a Faces<'b>,
) -> Vec<&'a (dyn crate::kernel::parametric::ParametricSurface + 'a)> {
    faces.iter().map(|(_, f)| f.as_ref() as _).collect()
}

/// Changes that add `objects` at the end of the scene, each under a name not yet taken
/// (`base`, `base 2`, …), cut to the longest name an object may have.
pub(super) fn insert_objects(
    scene: &Scene,
    base: &str,
    objects: impl IntoIterator<Item = ObjectGeometry>,
) -> Vec<Change> {
    insert_named_objects(scene, objects.into_iter().map(|g| (base, g)))
}

/// [`insert_objects`] with a base name for each object.
fn insert_named_objects<'a>(
    scene: &Scene,
    objects: impl IntoIterator<Item = (&'a str, ObjectGeometry)>,
) -> Vec<Change> {
    let mut next = scene.clone();
    let mut changes = Vec::new();
    for (base, geometry) in objects {
        let base: String = base
            .chars()
            .take(crate::scene::MAX_NAME_LENGTH - 4)
            .collect();
        let object = SceneObject::new(next.unique_name(&base), geometry);
        changes.push(Change::Insert {
            index: next.objects.len(),
            object: object.clone(),
        });
        next.objects.push(object);
    }
    changes
}

/// The offsets of object `k`'s faces by signed `distance` along the normal, each within
/// `tolerance` (a fraction of the scene's size): a NURBS or trimmed object (neither displaced
/// nor deformed) gives one surface, exact where its offset is an affine image of it
/// ([`offset_nurbs`]) and over the same domain with the same trims; any other kind one fitted
/// surface per face ([`offset_face`]).
pub fn offset_geometry(
    scene: &Scene,
    k: usize,
    distance: f64,
    tolerance: f64,
) -> Result<Vec<(ObjectGeometry, Offset)>, EditError> {
    let object = object_at(scene, k)?;
    let fail = geometry_error(object);
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(fail(refuse(
            "offset",
            format!("the tolerance must be a number above 0 (got {tolerance})"),
        )));
    }
    if !distance.is_finite() || distance == 0.0 {
        return Err(fail(refuse(
            "offset",
            format!("the distance must be a finite number other than 0 (got {distance})"),
        )));
    }
    let absolute = tolerance * scene_size(scene);
    let plain = object.displacement.is_none() && object.lattice.is_none();
    if let (true, Some(trimmed)) = (plain, object.geometry.as_trimmed()) {
        let offset = offset_nurbs(trimmed.surface(), distance, absolute).map_err(&fail)?;
        let result = trimmed
            .with_surface(offset.surface.clone())
            .map_err(&fail)?;
        return Ok(vec![(ObjectGeometry::from_trimmed(result), offset)]);
    }
    let faces = object.faces();
    if faces.is_empty() {
        return Err(fail(refuse(
            "offset",
            format!("{} has no faces", object.kind().kind_name()),
        )));
    }
    faces
        .iter()
        .map(|(_, face)| {
            let offset =
                offset_face(face.as_ref(), distance, absolute, FACE_OFFSET_SPANS).map_err(&fail)?;
            let geometry =
                ObjectGeometry::from_trimmed(TrimmedSurface::untrimmed(offset.surface.clone()));
            Ok((geometry, offset))
        })
        .collect()
}

/// One line about offsets: exact or fitted (with the largest deviation) and where they fold.
pub fn offset_summary(offsets: &[Offset], distance: f64) -> String {
    let exact = offsets.iter().filter(|o| o.is_exact()).count();
    let deviation = offsets.iter().map(|o| o.deviation).fold(0.0, f64::max);
    let mut text = if exact == offsets.len() {
        match offsets.first().map(|o| o.shape) {
            Some(OffsetShape::Plane) => "exact (a plane moved)".to_string(),
            Some(OffsetShape::Sphere { radius, .. }) => {
                format!("exact (a sphere of radius {radius:.6} scaled)")
            }
            Some(OffsetShape::Cylinder { radius, .. }) => {
                format!("exact (a cylinder of radius {radius:.6} scaled)")
            }
            Some(OffsetShape::Revolution { .. }) => {
                "exact (a surface of revolution, its meridian offset)".to_string()
            }
            _ => "exact".to_string(),
        }
    } else {
        format!("fitted, largest deviation {deviation:.3e}")
    };
    let folds: usize = offsets.iter().map(|o| o.fold_samples).sum();
    if folds > 0 {
        let smallest = offsets
            .iter()
            .flat_map(|o| &o.folds)
            .min_by(|a, b| a.radius.total_cmp(&b.radius));
        if let Some(f) = smallest {
            text.push_str(&format!(
                "; it folds where the radius of curvature is below {:.6} ({folds} sample(s), \
                 e.g. at ({:.4}, {:.4}, {:.4}), radius {:.6})",
                distance.abs(),
                f.point.x,
                f.point.y,
                f.point.z,
                f.radius
            ));
        }
    }
    text
}

/// [`crate::ops::offset`]: the offsets of object `k` added as "NAME offset" objects, and the
/// label.
pub(crate) fn offset(
    scene: &Scene,
    k: usize,
    distance: f64,
    tolerance: f64,
) -> Result<(Planned, Vec<Offset>), EditError> {
    let made = offset_geometry(scene, k, distance, tolerance)?;
    let name = format!("{} offset", scene.objects[k].name);
    let offsets: Vec<Offset> = made.iter().map(|(_, o)| o.clone()).collect();
    let changes = insert_objects(scene, &name, made.into_iter().map(|(g, _)| g));
    check_inserted(&changes)?;
    let label = format!(
        "offset {} by {distance}: {}",
        scene.objects[k].name,
        offset_summary(&offsets, distance)
    );
    Ok(((changes, label), offsets))
}

/// A fillet asked for: the operation `{"op": "fillet", "a": i, "b": j, "radius": r,
/// "radius_end": r1, "front_a": true, "front_b": true, "tolerance": t}` ([`crate::ops::fillet`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilletRequest {
    pub a: ObjectRef,
    pub b: ObjectRef,
    pub radius: f64,
    /// A radius that varies along the fillet, to this at its other end
    /// ([`crate::kernel::fillet::FilletOptions::radius_end`]).
    #[serde(default)]
    pub radius_end: Option<f64>,
    /// Whether the ball lies on the side each surface's normal points to (else the other).
    #[serde(default)]
    pub front_a: bool,
    #[serde(default)]
    pub front_b: bool,
    /// A fraction of the scene's size.
    #[serde(default = "editor_tolerance")]
    pub tolerance: f64,
}

fn editor_tolerance() -> f64 {
    EDITOR_TOLERANCE
}

fn edge_tolerance() -> f64 {
    EDITOR_TOLERANCE * 1e-2
}

fn unit_tension() -> [f64; 2] {
    [1.0; 2]
}

/// A fillet made: the fillet surface, A and B trimmed back where their kind can be trimmed
/// (a surface that can be trimmed but not along the fillet refuses the whole fillet), and
/// notes on what was left whole.
#[derive(Debug, Clone)]
pub struct FilletMade {
    pub fillet: crate::kernel::fillet::Fillet,
    /// The new A and B (`None` where the object was left as it was).
    pub trimmed: [Option<SceneObject>; 2],
    pub notes: Vec<String>,
}

/// The rolling-ball fillet between objects `a` and `b` ([`crate::kernel::fillet`]): over
/// every pair of their faces, the longest; A and B (NURBS or trimmed objects) trimmed back to
/// the contact curves on the side away from the fillet.
pub fn fillet_objects(scene: &Scene, request: &FilletRequest) -> Result<FilletMade, EditError> {
    use crate::kernel::fillet::{FilletOptions, fillet_surfaces};
    use crate::kernel::trim::cut::trim_along;
    let (a, b) = (scene.resolve(request.a)?, scene.resolve(request.b)?);
    let (oa, ob) = (object_at(scene, a)?, object_at(scene, b)?);
    let fail = geometry_error(oa);
    if a == b {
        return Err(fail(refuse(
            "fillet",
            "an object cannot be filleted with itself",
        )));
    }
    if !(request.tolerance.is_finite() && request.tolerance > 0.0) {
        return Err(fail(refuse(
            "fillet",
            format!(
                "the tolerance must be a number above 0 (got {})",
                request.tolerance
            ),
        )));
    }
    for o in [oa, ob] {
        if o.faces().is_empty() {
            return Err(geometry_error(o)(refuse(
                "fillet",
                format!("{} has no faces", o.kind().kind_name()),
            )));
        }
    }
    let size = scene_size(scene);
    let options = FilletOptions {
        radius: request.radius,
        radius_end: request.radius_end,
        side_a: if request.front_a { 1.0 } else { -1.0 },
        side_b: if request.front_b { 1.0 } else { -1.0 },
        tolerance: request.tolerance * size,
        size,
    };
    let (faces_a, faces_b) = (oa.faces(), ob.faces());
    let mut best: Option<(usize, usize, crate::kernel::fillet::Fillet)> = None;
    let mut last_error = None;
    for (i, (_, fa)) in faces_a.iter().enumerate() {
        for (j, (_, fb)) in faces_b.iter().enumerate() {
            match fillet_surfaces(fa.as_ref(), fb.as_ref(), &options) {
                Ok(f) => {
                    let better = best.as_ref().is_none_or(|(_, _, g)| {
                        spine_length(&f.centres) > spine_length(&g.centres)
                    });
                    if better {
                        best = Some((i, j, f));
                    }
                }
                Err(e) => last_error = Some(e),
            }
        }
    }
    let Some((_, _, fillet)) = best else {
        let e = last_error.unwrap_or_else(|| refuse("fillet", "the objects have no faces"));
        return Err(fail(e));
    };
    let mut notes = Vec::new();
    let mut trimmed = [None, None];
    for (slot, (object, contact, keep)) in [
        (oa, &fillet.contact_a, fillet.keep_a),
        (ob, &fillet.contact_b, fillet.keep_b),
    ]
    .into_iter()
    .enumerate()
    {
        let Some(surface) = object.geometry.as_trimmed() else {
            notes.push(format!(
                "{} is {}, which cannot be trimmed: left whole",
                object.name,
                object.kind().kind_name()
            ));
            continue;
        };
        // A contact curve whose ends meet on this surface closes here, even where the spine
        // was cut open (at the other surface's seam).
        let rect = crate::kernel::trim::domain_rect(surface.surface());
        let gap = 1e-6 * crate::kernel::trim::domain_size(rect);
        let ends_meet = contact.len() > 3 && contact[0].distance(contact[contact.len() - 1]) <= gap;
        let closed = fillet.closed || ends_meet;
        let points = if ends_meet && !fillet.closed {
            &contact[..contact.len() - 1]
        } else {
            &contact[..]
        };
        match trim_along(&surface, points, closed, keep) {
            Ok(t) => {
                let mut next = object.clone();
                next.geometry = ObjectGeometry::from_trimmed(t);
                next.recipe = None;
                trimmed[slot] = Some(next);
            }
            // Half a fillet (one side trimmed, the other not) is not a result: the whole
            // command is refused and nothing changes.
            Err(e) => {
                return Err(geometry_error(object)(refuse(
                    "fillet",
                    format!(
                        "it cannot be trimmed back along the fillet ({e}); nothing was changed: \
                         try the other side or another radius"
                    ),
                )));
            }
        }
    }
    Ok(FilletMade {
        fillet,
        trimmed,
        notes,
    })
}

fn spine_length(points: &[glam::DVec3]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// [`crate::ops::fillet`]: A and B trimmed back and the fillet added as "fillet", and what was
/// made (its trimmed objects moved into the changes).
pub(crate) fn fillet(
    scene: &Scene,
    request: &FilletRequest,
) -> Result<(Planned, FilletMade), EditError> {
    let mut made = fillet_objects(scene, request)?;
    let (a, b) = (scene.resolve(request.a)?, scene.resolve(request.b)?);
    let mut changes = Vec::new();
    // The trimmed objects go into the changes; what is returned keeps the fillet and notes.
    for (index, after) in [a, b].into_iter().zip(std::mem::take(&mut made.trimmed)) {
        if let Some(after) = after {
            after.decompose().map_err(geometry_error(&after))?;
            changes.push(Change::Replace {
                index,
                before: scene.objects[index].clone(),
                after,
            });
        }
    }
    let inserted = insert_objects(
        scene,
        "fillet",
        [ObjectGeometry::new(made.fillet.surface.clone())],
    );
    check_inserted(&inserted)?;
    changes.extend(inserted);
    let radius = match request.radius_end {
        Some(end) => format!("{} to {end}", request.radius),
        None => request.radius.to_string(),
    };
    let mut label = format!(
        "fillet {} and {}, radius {radius}: {} sections",
        scene.objects[a].name,
        scene.objects[b].name,
        made.fillet.centres.len()
    );
    for note in &made.notes {
        label.push_str("; ");
        label.push_str(note);
    }
    Ok(((changes, label), made))
}

/// Refuses objects a plan would insert that the GPU feed cannot take.
fn check_inserted(changes: &[Change]) -> Result<(), EditError> {
    for change in changes {
        if let Change::Insert { object, .. } = change {
            object.decompose().map_err(geometry_error(object))?;
        }
    }
    Ok(())
}

/// The faces of an object that can be joined: a NURBS or trimmed surface (one face), or a
/// polysurface's faces; `None` for any other kind (and for a displaced or deformed object,
/// whose shown faces are not its NURBS).
fn joinable_faces(object: &SceneObject) -> Option<Vec<TrimmedSurface>> {
    if object.displacement.is_some() || object.lattice.is_some() {
        return None;
    }
    if let Some(p) = object.geometry.as_polysurface() {
        return Some(p.faces().to_vec());
    }
    object.geometry.as_trimmed().map(|t| vec![t])
}

/// One polysurface a join makes: the objects it takes (in scene order) and the result.
#[derive(Debug, Clone)]
pub struct Joined {
    pub objects: Vec<usize>,
    pub polysurface: Polysurface,
}

/// The polysurfaces joining `objects` (all NURBS, trimmed and polysurface objects when empty)
/// where their faces share edges within `tolerance` × the scene's size
/// ([`crate::kernel::join`]); objects that share no edge with another are left out.
pub fn join_objects(
    scene: &Scene,
    objects: &[usize],
    tolerance: f64,
) -> Result<Vec<Joined>, EditError> {
    use crate::kernel::join::find_topology;
    let chosen: Vec<usize> = if objects.is_empty() {
        (0..scene.objects.len()).collect()
    } else {
        let mut o = objects.to_vec();
        o.sort_unstable();
        o.dedup();
        o
    };
    for &k in &chosen {
        object_at(scene, k)?;
    }
    // A failure of the whole join names every object it took part in.
    let all = objects_named(scene, &chosen, objects.is_empty());
    let fail_all = |source| EditError::Geometry {
        name: all.clone(),
        source,
    };
    let fail = |message: String| fail_all(refuse("join", message));
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(fail(format!(
            "the tolerance must be a number above 0 (got {tolerance})"
        )));
    }
    let absolute = tolerance * scene_size(scene);
    let mut faces = Vec::new();
    let mut owner = Vec::new();
    for &k in &chosen {
        let object = object_at(scene, k)?;
        match joinable_faces(object) {
            Some(f) => {
                owner.extend(std::iter::repeat_n(k, f.len()));
                faces.extend(f);
            }
            None if objects.is_empty() => {}
            None => {
                return Err(geometry_error(object)(refuse(
                    "join",
                    format!(
                        "{} cannot be joined (only NURBS, trimmed and polysurface objects, \
                         neither displaced nor deformed)",
                        object.kind().kind_name()
                    ),
                )));
            }
        }
    }
    let topology = find_topology(&faces, absolute).map_err(fail_all)?;
    let mut joined = Vec::new();
    for group in topology.components(faces.len()) {
        let mut members: Vec<usize> = group.iter().map(|&f| owner[f]).collect();
        members.dedup();
        // A group of one object joins nothing new (unless it was not a polysurface yet and
        // its own edges meet, as a cylinder's seam does).
        let single = members.len() == 1;
        if single {
            let object = &scene.objects[members[0]];
            let already = object.geometry.as_polysurface().is_some();
            let shares = topology
                .shared
                .iter()
                .any(|s| group.contains(&s.a.face) && group.contains(&s.b.face));
            if already || !shares || group.len() < 2 {
                continue;
            }
        }
        let group_faces = group.iter().map(|&f| faces[f].clone()).collect();
        let polysurface =
            Polysurface::new(group_faces, absolute).map_err(|source| EditError::Geometry {
                name: objects_named(scene, &members, false),
                source,
            })?;
        joined.push(Joined {
            objects: members,
            polysurface,
        });
    }
    if joined.is_empty() {
        return Err(fail(format!(
            "no edges meet within {absolute:.3e} (the tolerance × the scene's size): nothing \
             to join"
        )));
    }
    Ok(joined)
}

/// The names of objects `indices` for a message: "A", "A and B", "A, B and C", "A, B and 3
/// more"; `every` (all of the scene's, none picked): "the scene's objects".
fn objects_named(scene: &Scene, indices: &[usize], every: bool) -> String {
    if every && indices.len() > 1 {
        return "the scene's objects".into();
    }
    let names: Vec<&str> = indices
        .iter()
        .filter_map(|&k| scene.objects.get(k))
        .map(|o| o.name.as_str())
        .collect();
    match names.as_slice() {
        [] => "no objects".into(),
        [one] => (*one).to_owned(),
        [most @ .., last] if names.len() <= 3 => format!("{} and {last}", most.join(", ")),
        [a, b, rest @ ..] => format!("{a}, {b} and {} more", rest.len()),
    }
}

/// [`super::Command::Join`]: each polysurface replaces the first object it takes; the others
/// go.
pub(crate) fn join(
    scene: &Scene,
    objects: &[usize],
    tolerance: f64,
) -> Result<(Vec<Change>, String), EditError> {
    let joined = join_objects(scene, objects, tolerance)?;
    let mut changes = Vec::new();
    let mut removed = Vec::new();
    let mut summary = Vec::new();
    for j in &joined {
        let index = j.objects[0];
        let before = scene.objects[index].clone();
        let mut after = before.clone();
        after.geometry = ObjectGeometry::new(j.polysurface.clone());
        after.recipe = None;
        after.decompose().map_err(geometry_error(&after))?;
        summary.push(format!("{} ({})", after.name, after.describe()));
        changes.push(Change::Replace {
            index,
            before,
            after,
        });
        removed.extend(j.objects[1..].iter().copied());
    }
    removed.sort_unstable_by(|a, b| b.cmp(a));
    for index in removed {
        changes.push(Change::Remove {
            index,
            object: scene.objects[index].clone(),
        });
    }
    Ok((changes, format!("join: {}", summary.join("; "))))
}

/// [`super::Command::Explode`]: the polysurface's faces as objects of their own, the first in
/// its place.
pub(crate) fn explode(scene: &Scene, k: usize) -> Result<(Vec<Change>, String), EditError> {
    let object = object_at(scene, k)?;
    let Some(p) = object.geometry.as_polysurface() else {
        return Err(geometry_error(object)(refuse(
            "explode",
            format!(
                "needs a polysurface; this object is {}",
                object.kind().kind_name()
            ),
        )));
    };
    let mut faces = p.faces().iter().cloned().map(ObjectGeometry::from_trimmed);
    let Some(first) = faces.next() else {
        return Err(geometry_error(object)(refuse("explode", "it has no faces")));
    };
    let mut after = object.clone();
    after.geometry = first;
    let mut changes = vec![Change::Replace {
        index: k,
        before: object.clone(),
        after,
    }];
    changes.extend(insert_objects(scene, &object.name, faces));
    let label = format!("explode {} into {} faces", object.name, p.faces().len());
    Ok((changes, label))
}

/// The object's trimmed surface and the cuts that `cutters` make on it: where a surface
/// cutter meets it (marching, [`crate::kernel::intersect`]), and curve cutters that lie on it
/// (each point within 1e-4 of the scene's size of the surface) mapped into its domain.
pub fn cuts_on(
    scene: &Scene,
    object: usize,
    cutters: &[usize],
) -> Result<(TrimmedSurface, Vec<crate::kernel::trim::cut::Cut>), EditError> {
    use crate::kernel::intersect::IntersectOptions;
    use crate::kernel::trim::cut::Cut;
    let target = object_at(scene, object)?;
    let fail = geometry_error(target);
    let surface = match (
        target.displacement.is_none() && target.lattice.is_none(),
        target.geometry.as_trimmed(),
    ) {
        (true, Some(t)) => t,
        _ => {
            return Err(fail(refuse(
                "trim",
                format!(
                    "needs a NURBS or trimmed surface, neither displaced nor deformed; this \
                     object is {}",
                    target.kind().kind_name()
                ),
            )));
        }
    };
    if cutters.is_empty() {
        return Err(fail(refuse("trim", "no cutting objects were given")));
    }
    let size = scene_size(scene);
    let mut cuts = Vec::new();
    for &k in cutters {
        let cutter = object_at(scene, k)?;
        if k == object {
            return Err(fail(refuse("trim", "an object cannot cut itself")));
        }
        if let Some(curve) = cutter.kind().space_curve() {
            let (t0, t1) = curve.domain();
            let n = 400;
            let mut points = Vec::with_capacity(n + 1);
            for i in 0..=n {
                let p = curve
                    .point_at(t0 + (t1 - t0) * i as f64 / n as f64)
                    .map_err(geometry_error(cutter))?;
                let c = surface
                    .surface()
                    .closest_point(p)
                    .map_err(geometry_error(cutter))?;
                if c.distance > 1e-4 * size {
                    return Err(geometry_error(cutter)(refuse(
                        "trim",
                        format!(
                            "the curve is not on {} (off by {:.3e} near ({:.4}, {:.4}, {:.4})): \
                             project it onto the surface first",
                            target.name, c.distance, p.x, p.y, p.z
                        ),
                    )));
                }
                points.push(glam::DVec2::new(c.u, c.v));
            }
            cuts.extend(seam_pieces(points, surface.surface()));
            continue;
        }
        let faces = cutter.faces();
        if faces.is_empty() {
            return Err(geometry_error(cutter)(refuse(
                "trim",
                format!(
                    "{} has neither faces nor a curve",
                    cutter.kind().kind_name()
                ),
            )));
        }
        let options = IntersectOptions::for_size(size);
        let own: &dyn crate::kernel::parametric::ParametricSurface = surface.surface();
        let found_all =
            crate::kernel::intersect::intersect_face_sets(&[own], &face_refs(&faces), &options)
                .map_err(geometry_error(cutter))?;
        for (_, found) in found_all {
            for branch in found.curves {
                let mut points = branch.uv_a;
                if branch.closed {
                    points.pop();
                }
                if points.len() >= 2 {
                    cuts.push(Cut {
                        points,
                        closed: branch.closed,
                    });
                }
            }
        }
    }
    if cuts.is_empty() {
        return Err(fail(refuse("trim", "the cutting objects do not meet it")));
    }
    let rect = crate::kernel::trim::domain_rect(surface.surface());
    let gap = 1e-6 * crate::kernel::trim::domain_size(rect);
    Ok((surface, crate::kernel::trim::cut::chain_cuts(cuts, gap)))
}

/// A curve's (u, v) points as cuts: split where they jump across the surface's seam (a step
/// longer than a quarter of the domain), the pieces either side of the curve's own start
/// joined again when it is closed.
fn seam_pieces(
    mut points: Vec<glam::DVec2>,
    surface: &crate::kernel::NurbsSurface,
) -> Vec<crate::kernel::trim::cut::Cut> {
    use crate::kernel::trim::cut::Cut;
    let rect = crate::kernel::trim::domain_rect(surface);
    let size = crate::kernel::trim::domain_size(rect);
    let n = points.len() - 1;
    let closed = points[0].distance(points[n]) < 1e-9 * size;
    let mut pieces: Vec<Vec<glam::DVec2>> = vec![Vec::new()];
    for (k, &p) in points.iter().enumerate() {
        if k > 0 && points[k - 1].distance(p) > 0.25 * size {
            pieces.push(Vec::new());
        }
        if let Some(last) = pieces.last_mut() {
            last.push(p);
        }
    }
    if pieces.len() == 1 {
        if closed {
            points.pop();
        }
        return vec![Cut { points, closed }];
    }
    if closed {
        // The last piece runs on into the first.
        let mut head = pieces.remove(0);
        if let Some(last) = pieces.last_mut() {
            head.remove(0);
            last.extend(head);
        }
    }
    pieces
        .into_iter()
        .filter(|p| p.len() >= 2)
        .map(|points| Cut {
            points,
            closed: false,
        })
        .collect()
}

/// [`super::Command::TrimBy`]: the part of the object that the cutters leave around the
/// point nearest `keep`.
pub(crate) fn trim_by(
    scene: &Scene,
    object: usize,
    cutters: &[usize],
    keep: glam::DVec3,
) -> Result<(Vec<Change>, String), EditError> {
    use crate::kernel::trim::cut::keep_region;
    let (surface, cuts) = cuts_on(scene, object, cutters)?;
    let before = &scene.objects[object];
    let fail = geometry_error(before);
    let near = surface.surface().closest_point(keep).map_err(&fail)?;
    let kept = keep_region(&surface, &cuts, glam::DVec2::new(near.u, near.v)).map_err(&fail)?;
    let mut after = before.clone();
    after.geometry = ObjectGeometry::from_trimmed(kept);
    after.recipe = None;
    after.decompose().map_err(geometry_error(&after))?;
    let label = format!(
        "trim {} by {}",
        before.name,
        objects_named(scene, cutters, false)
    );
    Ok((
        vec![Change::Replace {
            index: object,
            before: before.clone(),
            after,
        }],
        label,
    ))
}

/// [`super::Command::SplitBy`]: the object cut into its parts, the first in its place.
pub(crate) fn split_by(
    scene: &Scene,
    object: usize,
    cutters: &[usize],
) -> Result<(Vec<Change>, String), EditError> {
    let (surface, cuts) = cuts_on(scene, object, cutters)?;
    let before = &scene.objects[object];
    let parts =
        crate::kernel::trim::cut::split_by(&surface, &cuts).map_err(geometry_error(before))?;
    let count = parts.len();
    let mut parts = parts.into_iter().map(ObjectGeometry::from_trimmed);
    let mut after = before.clone();
    after.geometry = parts
        .next()
        .ok_or_else(|| geometry_error(before)(refuse("split", "no parts")))?;
    after.recipe = None;
    after.decompose().map_err(geometry_error(&after))?;
    let mut changes = vec![Change::Replace {
        index: object,
        before: before.clone(),
        after,
    }];
    changes.extend(insert_objects(scene, &before.name, parts));
    Ok((changes, format!("split {} into {count} parts", before.name)))
}

/// The most levels one contour command makes.
pub const MAX_CONTOUR_LEVELS: usize = 1000;

/// The curves where planes through `origin + k · spacing · normal` (every k whose plane
/// crosses the object's box) meet the object's faces, as cubics through each branch
/// (closed for a loop; [`crate::kernel::intersect`] within 1e-6 of the scene's size).
pub fn contour_curves(
    scene: &Scene,
    object: usize,
    origin: glam::DVec3,
    normal: glam::DVec3,
    spacing: f64,
) -> Result<Vec<crate::kernel::SpaceCurve>, EditError> {
    use crate::kernel::construct;
    use crate::kernel::intersect::IntersectOptions;
    let target = object_at(scene, object)?;
    let fail = geometry_error(target);
    let n = normal.normalize_or_zero();
    if n == glam::DVec3::ZERO || !n.is_finite() || !origin.is_finite() {
        return Err(fail(refuse(
            "contour",
            "the planes need a finite point and a normal that is not zero",
        )));
    }
    let faces = target.faces();
    let Some((lo, hi)) = target.bounds().filter(|_| !faces.is_empty()) else {
        return Err(fail(refuse(
            "contour",
            format!("{} has no faces", target.kind().kind_name()),
        )));
    };
    let corners = (0..8).map(|k| {
        glam::DVec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    });
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    for c in corners {
        let h = (c - origin).dot(n);
        a = a.min(h);
        b = b.max(h);
    }
    if !(spacing.is_finite() && spacing > 0.0) || ((b - a) / spacing) as usize > MAX_CONTOUR_LEVELS
    {
        return Err(fail(refuse(
            "contour",
            format!(
                "the spacing must be above 0 and give at most {MAX_CONTOUR_LEVELS} planes across \
                 the object (got {spacing})"
            ),
        )));
    }
    let size = scene_size(scene);
    let options = IntersectOptions::for_size(size);
    let (x, y) = {
        let helper = if n.x.abs() < 0.9 {
            glam::DVec3::X
        } else {
            glam::DVec3::Y
        };
        let x = n.cross(helper).normalize();
        (x, n.cross(x))
    };
    let centre = 0.5 * (lo + hi);
    let half = lo.distance(hi).max(1e-9);
    let mut planes = Vec::new();
    let mut k = (a / spacing).ceil() as i64;
    while (k as f64) * spacing <= b {
        let level = origin + n * (k as f64 * spacing);
        let c = centre - n * (centre - level).dot(n);
        planes.push(
            construct::plane(c - (x + y) * half, x * 2.0 * half, y * 2.0 * half).map_err(&fail)?,
        );
        k += 1;
    }
    // Every level at once, so each face's cells are made once; in order of level, then face.
    let levels: Vec<&dyn crate::kernel::parametric::ParametricSurface> =
        planes.iter().map(|p| p as _).collect();
    let mut found =
        crate::kernel::intersect::intersect_face_sets(&face_refs(&faces), &levels, &options)
            .map_err(&fail)?;
    found.sort_by_key(|((face, level), _)| (*level, *face));
    let mut curves = Vec::new();
    for (_, found) in found {
        for branch in found.curves {
            curves.push(branch_curve(&branch.points, branch.closed).map_err(&fail)?);
        }
    }
    if curves.is_empty() {
        return Err(fail(refuse("contour", "no plane meets it")));
    }
    Ok(curves)
}

/// The cubic through a branch's points: closed and C² for a loop, clamped otherwise.
pub fn branch_curve(
    points: &[glam::DVec3],
    closed: bool,
) -> Result<crate::kernel::SpaceCurve, crate::kernel::GeometryError> {
    use crate::kernel::splines::{self, Parametrization};
    if closed && points.len() >= 4 {
        splines::interpolate_closed(&points[..points.len() - 1], 3, Parametrization::ChordLength)
    } else {
        let degree = 3.min(points.len().saturating_sub(1)).max(1);
        splines::interpolate_through(points, degree, Parametrization::ChordLength, None)
    }
}

/// [`crate::ops::contour`]: the contour curves added as "NAME contour" objects.
pub(crate) fn contour(
    scene: &Scene,
    object: usize,
    origin: glam::DVec3,
    normal: glam::DVec3,
    spacing: f64,
) -> Result<(Vec<Change>, String), EditError> {
    let curves = contour_curves(scene, object, origin, normal, spacing)?;
    let name = format!("{} contour", scene.objects[object].name);
    let count = curves.len();
    let changes = insert_objects(scene, &name, curves.into_iter().map(ObjectGeometry::new));
    Ok((
        changes,
        format!("contour {}: {count} curve(s)", scene.objects[object].name),
    ))
}

/// The curves `curves` projected onto object `onto` (a NURBS or trimmed surface): along
/// `direction`, or pulled to the nearest point when it is `None`; each curve sampled at 200
/// points, and each run of points that land on the kept surface the cubic through them.
pub fn projected_curves(
    scene: &Scene,
    curves: &[usize],
    onto: usize,
    direction: Option<glam::DVec3>,
) -> Result<Vec<(usize, crate::kernel::SpaceCurve)>, EditError> {
    use crate::kernel::intersect_curve::intersect_curves_surface;
    const SAMPLES: usize = 200;
    let target = object_at(scene, onto)?;
    let fail = geometry_error(target);
    let surface = own_trimmed(
        target,
        "project",
        "needs a NURBS or trimmed surface to project onto",
    )?;
    let dir = match direction {
        Some(d) if d.length() > 0.0 && d.is_finite() => Some(d.normalize()),
        Some(_) => {
            return Err(fail(refuse(
                "project",
                "the direction is zero or not finite",
            )));
        }
        None => None,
    };
    let size = scene_size(scene);
    let mut out = Vec::new();
    for &k in curves {
        let object = object_at(scene, k)?;
        let Some(curve) = object.kind().space_curve() else {
            return Err(geometry_error(object)(refuse(
                "project",
                format!("needs curves; this object is {}", object.kind().kind_name()),
            )));
        };
        let (t0, t1) = curve.domain();
        let points: Vec<glam::DVec3> = (0..=SAMPLES)
            .map(|i| curve.point_at(t0 + (t1 - t0) * i as f64 / SAMPLES as f64))
            .collect::<Result<_, _>>()
            .map_err(geometry_error(object))?;
        let landed: Vec<Option<glam::DVec3>> = match dir {
            None => points
                .iter()
                .map(|&p| {
                    let c = surface.surface().closest_point(p)?;
                    Ok(surface.contains(c.u, c.v).then_some(c.point))
                })
                .collect::<Result<_, crate::kernel::GeometryError>>()
                .map_err(&fail)?,
            Some(d) => {
                // Every sample's ray through the surface at once (its cells made once).
                let rays: Vec<crate::kernel::SpaceCurve> = points
                    .iter()
                    .map(|&p| {
                        crate::kernel::construct::line(p - d * 2.0 * size, p + d * 2.0 * size)
                    })
                    .collect::<Result<_, _>>()
                    .map_err(&fail)?;
                let rays: Vec<&crate::kernel::SpaceCurve> = rays.iter().collect();
                intersect_curves_surface(&rays, &surface, 1e-9 * size, 1e-2 * size)
                    .map_err(&fail)?
                    .into_iter()
                    .map(|hits| {
                        hits.into_iter()
                            .min_by(|a, b| (a.t - 0.5).abs().total_cmp(&(b.t - 0.5).abs()))
                            .map(|h| h.point)
                    })
                    .collect()
            }
        };
        let mut runs: Vec<Vec<glam::DVec3>> = vec![Vec::new()];
        for q in landed {
            match q {
                Some(q) => {
                    if let Some(run) = runs.last_mut()
                        && run
                            .last()
                            .is_none_or(|l: &glam::DVec3| l.distance(q) > 1e-12 * size)
                    {
                        run.push(q);
                    }
                }
                None => runs.push(Vec::new()),
            }
        }
        for run in runs.into_iter().filter(|r| r.len() >= 2) {
            let closed = run.len() > 4 && run[0].distance(run[run.len() - 1]) <= 1e-9 * size;
            let curve = branch_curve(&run, closed).map_err(geometry_error(object))?;
            out.push((k, curve));
        }
    }
    if out.is_empty() {
        return Err(fail(refuse("project", "no curve lands on the surface")));
    }
    Ok(out)
}

/// [`super::Command::Project`]: the projections added as "NAME projected" curve objects.
pub(crate) fn project(
    scene: &Scene,
    curves: &[usize],
    onto: usize,
    direction: Option<glam::DVec3>,
) -> Result<(Vec<Change>, String), EditError> {
    let made = projected_curves(scene, curves, onto, direction)?;
    let count = made.len();
    let names: Vec<String> = made
        .iter()
        .map(|(k, _)| format!("{} projected", scene.objects[*k].name))
        .collect();
    let changes = insert_named_objects(
        scene,
        names
            .iter()
            .zip(made)
            .map(|(name, (_, curve))| (name.as_str(), ObjectGeometry::new(curve))),
    );
    let how = if direction.is_some() {
        "projected"
    } else {
        "pulled"
    };
    Ok((
        changes,
        format!("{count} curve(s) {how} onto {}", scene.objects[onto].name),
    ))
}

/// An edge of an object: one of its faces (`face`, an index into [`SceneObject::faces`]) and a
/// side of that face's parameter rectangle.
pub type FaceSide = (usize, crate::kernel::continuity::Side);

/// A blend asked for: the operation `{"op": "blend", "a": i, "b": j, "edges": [[face, "u0"],
/// [face, "v1"]], "continuity": "G2", "tension": [1, 1], "tolerance": t}` ([`crate::ops::blend`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendRequest {
    pub a: ObjectRef,
    pub b: ObjectRef,
    /// The edge of A and the edge of B to blend; `None`: the pair that lie nearest each other.
    #[serde(default)]
    pub edges: Option<[FaceSide; 2]>,
    pub continuity: crate::kernel::blend::EdgeContinuity,
    /// The tension at A's and at B's edge (above 0; 1 is a natural bulge).
    #[serde(default = "unit_tension")]
    pub tension: [f64; 2],
    /// A fraction of the scene's size.
    #[serde(default = "edge_tolerance")]
    pub tolerance: f64,
}

/// A match asked for: the operation `{"op": "match", "object": i, "target": j, "edges": ...,
/// "continuity": "G2", "tolerance": t}` ([`crate::ops::matching`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MatchRequest {
    /// The object whose edge moves (a NURBS or trimmed surface).
    pub object: ObjectRef,
    /// The object it is matched to (any kind with faces; it does not change).
    pub target: ObjectRef,
    /// The side of the object and the target's edge; `None`: the pair nearest each other.
    #[serde(default)]
    pub edges: Option<[FaceSide; 2]>,
    pub continuity: crate::kernel::blend::EdgeContinuity,
    /// A fraction of the scene's size.
    #[serde(default = "edge_tolerance")]
    pub tolerance: f64,
}

/// The edge of `a` and the edge of `b` nearest each other over all their faces (sides shorter
/// than 1e-9 of the scene, poles, left out), or the pair asked for, checked.
fn edge_pair(
    scene: &Scene,
    a: usize,
    b: usize,
    asked: Option<[FaceSide; 2]>,
    what: &'static str,
) -> Result<[FaceSide; 2], EditError> {
    let (oa, ob) = (object_at(scene, a)?, object_at(scene, b)?);
    if a == b {
        return Err(geometry_error(oa)(refuse(
            what,
            "needs two different objects",
        )));
    }
    let (fa, fb) = (oa.faces(), ob.faces());
    for (object, faces) in [(oa, &fa), (ob, &fb)] {
        if faces.is_empty() || object.kind().space_curve().is_some() {
            return Err(geometry_error(object)(refuse(
                what,
                format!("{} has no faces", object.kind().kind_name()),
            )));
        }
    }
    if let Some(edges) = asked {
        for ((object, faces), (face, _)) in [(oa, &fa), (ob, &fb)].into_iter().zip(edges) {
            if face >= faces.len() {
                return Err(geometry_error(object)(refuse(
                    what,
                    format!("it has {} face(s), not a face {face}", faces.len()),
                )));
            }
        }
        return Ok(edges);
    }
    let degenerate = 1e-9 * scene_size(scene);
    let mut best: Option<([FaceSide; 2], f64)> = None;
    for (i, (_, x)) in fa.iter().enumerate() {
        for (j, (_, y)) in fb.iter().enumerate() {
            if let Some((sa, sb, d)) =
                crate::kernel::blend::nearest_sides(x.as_ref(), y.as_ref(), degenerate)
                && best.is_none_or(|(_, e)| d < e)
            {
                best = Some(([(i, sa), (j, sb)], d));
            }
        }
    }
    best.map(|(e, _)| e)
        .ok_or_else(|| geometry_error(oa)(refuse(what, "no edge of either is long enough")))
}

/// The blend between two objects' edges ([`crate::kernel::blend::blend_edges`]) and the
/// edges it joins.
pub fn blend_objects(
    scene: &Scene,
    request: &BlendRequest,
) -> Result<(crate::kernel::blend::Blend, [FaceSide; 2]), EditError> {
    use crate::kernel::blend::{BlendOptions, blend_edges};
    let (a, b) = (scene.resolve(request.a)?, scene.resolve(request.b)?);
    let edges = edge_pair(scene, a, b, request.edges, "blend")?;
    let (oa, ob) = (&scene.objects[a], &scene.objects[b]);
    let (fa, fb) = (oa.faces(), ob.faces());
    let options = BlendOptions {
        continuity: request.continuity,
        tension: request.tension,
        tolerance: request.tolerance * scene_size(scene),
    };
    let [(i, sa), (j, sb)] = edges;
    let blend = blend_edges(fa[i].1.as_ref(), sa, fb[j].1.as_ref(), sb, &options)
        .map_err(geometry_error(oa))?;
    Ok((blend, edges))
}

/// "Name face k side" for an object with several faces, "Name side" otherwise.
fn edge_name(object: &SceneObject, (face, side): FaceSide) -> String {
    if object.faces().len() > 1 {
        format!("{} face {face} {}", object.name, side.name())
    } else {
        format!("{} {}", object.name, side.name())
    }
}

/// [`crate::ops::blend`]: the blend added as "blend".
pub(crate) fn blend(
    scene: &Scene,
    request: &BlendRequest,
) -> Result<(Vec<Change>, String), EditError> {
    let (made, [ea, eb]) = blend_objects(scene, request)?;
    let (a, b) = (scene.resolve(request.a)?, scene.resolve(request.b)?);
    let changes = insert_objects(scene, "blend", [ObjectGeometry::new(made.surface)]);
    for change in &changes {
        if let Change::Insert { object, .. } = change {
            object.decompose().map_err(geometry_error(object))?;
        }
    }
    let label = format!(
        "{} blend from {} to {} ({} samples, deviation {:.1e})",
        request.continuity.name(),
        edge_name(&scene.objects[a], ea),
        edge_name(&scene.objects[b], eb),
        made.samples,
        made.deviation
    );
    Ok((changes, label))
}

/// The object of `request` with its edge matched to the target's
/// ([`crate::kernel::blend::match_edge`]), its trims kept, and the edges matched.
pub fn match_object(
    scene: &Scene,
    request: &MatchRequest,
) -> Result<(SceneObject, crate::kernel::blend::Matched, [FaceSide; 2]), EditError> {
    let (object, target) = (
        scene.resolve(request.object)?,
        scene.resolve(request.target)?,
    );
    let edges = edge_pair(scene, object, target, request.edges, "match")?;
    let before = &scene.objects[object];
    let fail = geometry_error(before);
    let trimmed = own_trimmed(
        before,
        "match",
        "moves the control points of a NURBS or trimmed surface",
    )?;
    let [(_, side), (j, target_side)] = edges;
    let target = scene.objects[target].faces();
    let matched = crate::kernel::blend::match_edge(
        trimmed.surface(),
        side,
        target[j].1.as_ref(),
        target_side,
        request.continuity,
        request.tolerance * scene_size(scene),
    )
    .map_err(&fail)?;
    let mut after = before.clone();
    after.geometry = ObjectGeometry::from_trimmed(
        trimmed
            .with_surface(matched.surface.clone())
            .map_err(&fail)?,
    );
    after.decompose().map_err(geometry_error(&after))?;
    Ok((after, matched, edges))
}

/// [`crate::ops::matching`]: the object's edge moved onto the target's.
pub(crate) fn match_edge(
    scene: &Scene,
    request: &MatchRequest,
) -> Result<(Vec<Change>, String), EditError> {
    let (after, matched, [ea, eb]) = match_object(scene, request)?;
    let (object, target) = (
        scene.resolve(request.object)?,
        scene.resolve(request.target)?,
    );
    let before = &scene.objects[object];
    let label = format!(
        "match {} to {} at {} (deviation {:.1e})",
        edge_name(before, ea),
        edge_name(&scene.objects[target], eb),
        request.continuity.name(),
        matched.deviation
    );
    Ok((
        vec![Change::Replace {
            index: object,
            before: before.clone(),
            after,
        }],
        label,
    ))
}

/// The NURBS or trimmed surface of an object that is neither displaced nor deformed (what it
/// shows is then its own surface), or `what` refused with `needs` and the object's kind.
fn own_trimmed(
    object: &SceneObject,
    what: &'static str,
    needs: &str,
) -> Result<TrimmedSurface, EditError> {
    match object.geometry.as_trimmed() {
        Some(t) if object.displacement.is_none() && object.lattice.is_none() => Ok(t),
        _ => Err(geometry_error(object)(refuse(
            what,
            format!("{needs}; this object is {}", object.kind().kind_name()),
        ))),
    }
}

/// The changes that hide the visible ones of `objects` (a boolean's inputs).
fn hidden(scene: &Scene, objects: &[usize]) -> Vec<Change> {
    objects
        .iter()
        .filter_map(|&k| {
            let before = scene.objects.get(k).filter(|o| o.visible)?;
            let mut after = before.clone();
            after.visible = false;
            Some(Change::Replace {
                index: k,
                before: before.clone(),
                after,
            })
        })
        .collect()
}

/// Two lists' closed bodies: their faces, and their shared edges where known.
type ClosedBodies = (
    [Vec<TrimmedSurface>; 2],
    [Option<crate::kernel::join::Topology>; 2],
);

/// The faces of the closed bodies in each list, with their shared edges numbered on through
/// the list where every body's are known; refused for an object that is not a closed body
/// or one in both lists.
fn closed_bodies(
    scene: &Scene,
    what: &'static str,
    lists: [&[usize]; 2],
) -> Result<ClosedBodies, EditError> {
    use crate::kernel::join::Topology;
    let mut faces = [Vec::new(), Vec::new()];
    let mut topologies: [Vec<(Topology, usize)>; 2] = [Vec::new(), Vec::new()];
    for (side, list) in lists.into_iter().enumerate() {
        for &k in list {
            let object = object_at(scene, k)?;
            if side == 1 && lists[0].contains(&k) {
                return Err(geometry_error(object)(refuse(
                    what,
                    "is in both lists: a body cannot be combined with itself",
                )));
            }
            let body = object.body().filter(|b| b.closed()).ok_or_else(|| {
                geometry_error(object)(refuse(
                    what,
                    format!(
                        "is not a closed body ({}); join its faces into a closed polysurface first",
                        object.kind().kind_name()
                    ),
                ))
            })?;
            let count = body.faces.len();
            faces[side].extend(body.faces);
            if let Some(t) = body.topology {
                topologies[side].push((t, count));
            }
        }
    }
    // Each body's own shared edges, numbered on through the list (known for every body, or
    // worked out again).
    let joined = [0, 1].map(|side| {
        (topologies[side].len() == lists[side].len())
            .then(|| Topology::concatenated(topologies[side].iter().map(|(t, n)| (t, *n))))
    });
    Ok((faces, joined))
}

/// The closed bodies `body` split by the faces of `tool` (surfaces or polysurfaces reaching
/// through them; [`crate::kernel::boolean::split`]) into closed pieces, each a new
/// polysurface named after the body, the body hidden, at `tolerance` (a fraction of the
/// scene's size). Refused, changing nothing, for an object that is not a closed body, a tool
/// without faces, or a surface that does not divide the body.
pub(crate) fn split_solid(
    scene: &Scene,
    body: &[usize],
    tool: &[usize],
    tolerance: f64,
) -> Result<Planned, EditError> {
    use crate::kernel::boolean::split;
    let what = "split";
    let first = *body.first().ok_or(EditError::BadParameter {
        operation: "boolean",
        field: "a",
        message: "needs a body to split".into(),
    })?;
    let ([faces, _], [joined, _]) = closed_bodies(scene, what, [body, &[]])?;
    let mut cutters = Vec::new();
    for &k in tool {
        let object = object_at(scene, k)?;
        if body.contains(&k) {
            return Err(geometry_error(object)(refuse(
                what,
                "is the body being split: pick another surface to split it with",
            )));
        }
        let cutter = object.body().map(|b| b.faces).unwrap_or_default();
        if cutter.is_empty() {
            return Err(geometry_error(object)(refuse(
                what,
                format!("has no faces to split with ({})", object.kind().kind_name()),
            )));
        }
        cutters.extend(cutter);
    }
    if cutters.is_empty() {
        return Err(EditError::BadParameter {
            operation: "boolean",
            field: "b",
            message: "needs a surface to split with".into(),
        });
    }
    let size = scene_size(scene);
    let pieces = split((&faces, joined.as_ref()), &cutters, tolerance * size)
        .map_err(geometry_error(&scene.objects[first]))?;
    let mut polysurfaces = Vec::with_capacity(pieces.len());
    for piece in &pieces {
        polysurfaces.push(ObjectGeometry::new(
            Polysurface::with_topology(
                piece.faces(),
                tolerance * size * 10.0,
                piece.topology.clone(),
            )
            .map_err(geometry_error(&scene.objects[first]))?,
        ));
    }
    let mut changes = hidden(scene, body);
    let name = objects_named(scene, body, false);
    changes.extend(insert_objects(scene, &name, polysurfaces));
    let label = format!(
        "split of {name} by {}: {} piece{}",
        objects_named(scene, tool, false),
        pieces.len(),
        if pieces.len() == 1 { "" } else { "s" },
    );
    Ok((changes, label))
}

/// A boolean of the scene's closed bodies ready to run a step at a time (the editor's long
/// booleans, with progress and Cancel): the job, and what it was made from, so that its
/// result can stand in for running it again when the same boolean is then applied
/// ([`PreparedBoolean::finished`]).
pub struct PreparedBoolean {
    pub job: crate::kernel::boolean::BooleanJob,
    key: BooleanKey,
    /// The first body's name, which a refusal names.
    name: String,
}

/// What a boolean's result follows from: the operation, its tolerance in model units and
/// both operands' faces.
#[derive(PartialEq)]
struct BooleanKey {
    op: crate::kernel::boolean::BooleanOp,
    tolerance: f64,
    faces: [Vec<TrimmedSurface>; 2],
}

thread_local! {
    /// The result of the last boolean the editor ran a step at a time, until it is applied.
    static FINISHED_BOOLEAN: std::cell::RefCell<Option<(BooleanKey, crate::kernel::boolean::BooleanResult)>> =
        const { std::cell::RefCell::new(None) };
}

impl PreparedBoolean {
    /// The finished job's result kept for the next [`boolean`] of the same operands (the
    /// operation applied as usual then takes it instead of running again; anything changed
    /// in between, and it runs again); a refusal as that boolean would give it.
    pub fn finished(self) -> Result<(), EditError> {
        let Self { job, key, name } = self;
        let made = job.finish().map_err(|source| refusal(&name, source))?;
        FINISHED_BOOLEAN.with(|slot| *slot.borrow_mut() = Some((key, made)));
        Ok(())
    }

    /// A refusal from the job's step, as the boolean would give it.
    pub fn refused(&self, source: crate::kernel::GeometryError) -> EditError {
        refusal(&self.name, source)
    }
}

/// The boolean's refusal `source`, naming its first body `name`.
fn refusal(name: &str, source: crate::kernel::GeometryError) -> EditError {
    EditError::Geometry {
        name: name.to_owned(),
        source,
    }
}

/// The operands of the boolean `op` of the closed bodies `a` and `b` at `tolerance` (a
/// fraction of the scene's size): what its result follows from, both operands' shared edges
/// where known, and the first body's name; refused, changing nothing, for an empty list or
/// an object that is not a closed body.
fn boolean_operands(
    scene: &Scene,
    op: crate::kernel::boolean::BooleanOp,
    a: &[usize],
    b: &[usize],
    tolerance: f64,
) -> Result<
    (
        BooleanKey,
        [Option<crate::kernel::join::Topology>; 2],
        String,
    ),
    EditError,
> {
    let first = *a.first().ok_or(EditError::BadParameter {
        operation: "boolean",
        field: "a",
        message: "needs at least one body".into(),
    })?;
    if b.is_empty() {
        return Err(EditError::BadParameter {
            operation: "boolean",
            field: "b",
            message: "needs at least one body".into(),
        });
    }
    let (faces, joined) = closed_bodies(scene, op.name(), [a, b])?;
    let key = BooleanKey {
        op,
        tolerance: tolerance * scene_size(scene),
        faces,
    };
    Ok((key, joined, scene.objects[first].name.clone()))
}

/// The boolean `op` of the closed bodies `a` and `b` at `tolerance` (a fraction of the
/// scene's size), ready to run ([`PreparedBoolean`]); refused as [`boolean_operands`] is.
pub(crate) fn prepare_boolean(
    scene: &Scene,
    op: crate::kernel::boolean::BooleanOp,
    a: &[usize],
    b: &[usize],
    tolerance: f64,
) -> Result<PreparedBoolean, EditError> {
    use crate::kernel::boolean::BooleanJob;
    let (key, [joined_a, joined_b], name) = boolean_operands(scene, op, a, b, tolerance)?;
    // The job takes its own copy: the key stays to be compared when the result is applied.
    let [faces_a, faces_b] = key.faces.clone();
    let job = BooleanJob::new(op, (faces_a, joined_a), (faces_b, joined_b), key.tolerance)
        .map_err(|source| refusal(&name, source))?;
    Ok(PreparedBoolean { job, key, name })
}

/// The boolean `op` of the bodies `a` and `b` (objects with closed faces; [`crate::kernel::
/// boolean`]) as one new polysurface named after them, the inputs hidden, at `tolerance` (a
/// fraction of the scene's size): the result the editor's step-at-a-time run of the same
/// boolean left ([`PreparedBoolean::finished`]), else run now. Refused, changing nothing,
/// for an object that is not a closed body, an object in both lists, or an empty result.
pub(crate) fn boolean(
    scene: &Scene,
    op: crate::kernel::boolean::BooleanOp,
    a: &[usize],
    b: &[usize],
    tolerance: f64,
) -> Result<Planned, EditError> {
    use crate::kernel::boolean::BooleanJob;
    use crate::kernel::boolean::BooleanOp;
    let what = op.name();
    let (key, [joined_a, joined_b], _) = boolean_operands(scene, op, a, b, tolerance)?;
    let first = a[0];
    let kept = FINISHED_BOOLEAN.with(|slot| {
        let mut slot = slot.borrow_mut();
        match slot.take() {
            Some((done, made)) if done == key => Some(made),
            other => {
                *slot = other;
                None
            }
        }
    });
    let made = match kept {
        Some(made) => made,
        None => {
            // Run now, the operands handed to the job rather than copied.
            let BooleanKey {
                faces: [faces_a, faces_b],
                tolerance,
                ..
            } = key;
            BooleanJob::new(op, (faces_a, joined_a), (faces_b, joined_b), tolerance)
                .and_then(BooleanJob::run)
                .map_err(geometry_error(&scene.objects[first]))?
        }
    };
    let size = scene_size(scene);
    let all = made.faces();
    if all.is_empty() {
        return Err(geometry_error(&scene.objects[first])(refuse(
            what,
            match op {
                BooleanOp::Intersection => "the bodies do not overlap: nothing is common to them",
                _ => "nothing is left",
            },
        )));
    }
    // Joined as the boolean joined them (within ten times its tolerance).
    let polysurface = Polysurface::with_topology(all, tolerance * size * 10.0, made.topology())
        .map_err(geometry_error(&scene.objects[first]))?;
    let symbol = match op {
        BooleanOp::Union => "∪",
        BooleanOp::Difference => "−",
        BooleanOp::Intersection => "∩",
    };
    let name = format!(
        "{} {symbol} {}",
        objects_named(scene, a, false),
        objects_named(scene, b, false)
    );
    let mut changes = hidden(scene, &[a, b].concat());
    changes.extend(insert_objects(
        scene,
        &name,
        [ObjectGeometry::new(polysurface)],
    ));
    let label = format!(
        "{what} of {} and {}: {} solid{}",
        objects_named(scene, a, false),
        objects_named(scene, b, false),
        made.solids.len(),
        if made.solids.len() == 1 { "" } else { "s" },
    );
    Ok((changes, label))
}

/// A fillet, chamfer or shell of a closed body ([`crate::kernel::features`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolidFeature {
    /// Rolling-ball fillets of this radius on the edges picked.
    Fillet { radius: f64 },
    /// Chamfers set back `distance` on one face and `other` on the other.
    Chamfer { distance: f64, other: f64 },
    /// Hollowed to this wall thickness (below 0 inward), the faces picked left open.
    Shell { thickness: f64 },
    /// The faces picked moved this far along their normals.
    OffsetFace { distance: f64 },
    /// The faces picked tilted by `angle` (radians) about where they meet the neutral plane
    /// through `origin` across `pull`.
    Draft {
        angle: f64,
        origin: glam::DVec3,
        pull: glam::DVec3,
    },
}

impl SolidFeature {
    /// The name the result and the undo step take.
    pub fn name(self) -> &'static str {
        match self {
            SolidFeature::Fillet { .. } => "fillet",
            SolidFeature::Chamfer { .. } => "chamfer",
            SolidFeature::Shell { .. } => "shell",
            SolidFeature::OffsetFace { .. } => "offset face",
            SolidFeature::Draft { .. } => "draft",
        }
    }
}

/// `feature` made of the closed body `object`: each of `points` picks the edge (or, for a
/// shell, an offset or a draft, the face) nearest it, none every edge (no face); a fillet's
/// `radii` set its radius at the picked edges' ends nearest them; the result a new polysurface
/// "NAME fillet" (chamfer, shell), the body hidden, at `tolerance` (a fraction of the
/// scene's size); and what it took and enclosed. Refused, changing nothing, for an object
/// that is not a closed body or a feature the kernel cannot build (the reason names the
/// edge or face).
pub(crate) fn solid_feature(
    scene: &Scene,
    object: usize,
    feature: SolidFeature,
    (points, radii): (&[glam::DVec3], &[(glam::DVec3, f64)]),
    tolerance: f64,
) -> Result<(Planned, crate::kernel::features::FeatureResult), EditError> {
    use crate::kernel::features::{
        EdgeFeature, EdgePick, draft_faces, offset_faces, round_edges, round_edges_varying, shell,
    };
    let what = feature.name();
    let ([faces, _], _) = closed_bodies(scene, what, [&[object], &[]])?;
    let target = object_at(scene, object)?;
    let size = scene_size(scene);
    let pick = if points.is_empty() {
        EdgePick::All
    } else {
        EdgePick::Near(points.to_vec())
    };
    let made = match feature {
        SolidFeature::Fillet { radius } => round_edges_varying(
            &faces,
            &pick,
            EdgeFeature::Fillet { radius },
            radii,
            tolerance * size,
        ),
        SolidFeature::Chamfer { distance, other } => round_edges(
            &faces,
            &pick,
            EdgeFeature::Chamfer { distance, other },
            tolerance * size,
        ),
        SolidFeature::Shell { thickness } => shell(&faces, thickness, points, tolerance * size),
        SolidFeature::OffsetFace { distance } => {
            offset_faces(&faces, points, distance, tolerance * size)
        }
        SolidFeature::Draft {
            angle,
            origin,
            pull,
        } => draft_faces(&faces, points, angle, (origin, pull), tolerance * size),
    }
    .map_err(geometry_error(target))?;
    let polysurface = Polysurface::with_topology(
        made.faces.clone(),
        tolerance * size * 10.0,
        made.topology.clone(),
    )
    .map_err(geometry_error(target))?;
    let mut changes = hidden(scene, &[object]);
    let name = format!("{} {what}", target.name);
    changes.extend(insert_objects(
        scene,
        &name,
        [ObjectGeometry::new(polysurface)],
    ));
    let label = match feature {
        SolidFeature::Shell { .. } => format!("shell of {}", target.name),
        SolidFeature::OffsetFace { .. } | SolidFeature::Draft { .. } => format!(
            "{what} of {} face{} of {}",
            made.picked,
            if made.picked == 1 { "" } else { "s" },
            target.name
        ),
        _ => format!(
            "{what} of {} edge{} of {}",
            made.picked,
            if made.picked == 1 { "" } else { "s" },
            target.name
        ),
    };
    Ok(((changes, label), made))
}
