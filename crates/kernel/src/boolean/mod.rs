//! Booleans of solids: union, difference and intersection of closed shells of trimmed faces,
//! in the kernel's f64, on its surface intersection, trimming and join (the boundary
//! evaluation of Requicha and Voelcker, 1985; Hoffmann, *Geometric and Solid Modeling*,
//! ch. 3):
//!
//! 1. **Orient.** Each operand's faces are joined ([`find_topology`]); an operand that does
//!    not close up is refused. Faces are turned to agree across their shared edges and then
//!    all outward (the enclosed volume, [`mass_properties`], positive).
//! 2. **Intersect.** Every face of one operand whose box meets a face of the other is
//!    intersected with it by marching ([`intersect_surfaces`], trims respected), or, for two
//!    flat faces, along their planes' line clipped to both, or, for a flat face and a ruled
//!    one (a cylinder, a cone, an extrusion), along the plane's section of the ruled surface
//!    ([`ruled`]); the (u, v) polylines are cuts on both faces. Two planar faces in one plane do not cross but
//!    overlap: each one's boundary curves, mapped into the other's plane, are its cuts.
//!    Branches that run along a face's boundary (an edge lying on a face) cut nothing.
//! 3. **Split.** Each face's boundary and cuts are arranged in its (u, v) domain
//!    ([`arrangement`]); every part the face keeps becomes a trimmed face: its boundary runs
//!    are pieces of the face's own trim curves, its cut runs cubics through the marched
//!    points (chord-length parameters, The NURBS Book §9.2.1), so the two faces that meet
//!    along a cut carry the same 3D edge.
//! 4. **Classify.** A point well inside each part is tested against the other operand: on a
//!    coplanar face of it (kept once, by the first operand, when the outward normals agree
//!    for union and intersection, when they are opposite for difference), or inside or
//!    outside by the winding number of its tessellation (the solid angles of its triangles,
//!    Van Oosterom and Strackee, 1983, over 4π).
//! 5. **Assemble.** Union keeps what lies outside the other operand, intersection what lies
//!    inside, difference A's parts outside B and B's parts inside A turned over. The parts are
//!    joined; a result that does not close is refused with where it is open, never returned.
//!    Each closed group of faces is a shell; one enclosing negative volume is a void of the
//!    smallest shell around it.

pub mod arrangement;
pub mod job;
mod ruled;
pub mod split;

pub use job::{BooleanInput, BooleanJob};
pub use split::split;

use glam::{DVec2, DVec3};

use crate::error::{GeometryError, construction};
use crate::intersect::{BranchEnd, IntersectionCurve};
use crate::intersect::{CachedTrees, IntersectOptions, Intersection, intersect_cached};
use crate::join::{Topology, face_loops, find_topology, validity};
use crate::mass::signed_volume;
use crate::splines::{Parametrization, interpolate_at_parameters, interpolate_through};
use crate::surface::Direction;
use crate::tess::{Tessellation, grid_for, triangulate};
use crate::trim::tess::tessellate_trimmed;
use crate::trim::{TrimLoop, TrimmedSurface, domain_rect, domain_size};
use crate::{NurbsSurface, TrimCurve};
use arrangement::{Polyline, Region, Source};
use ruled::plane_ruled_branches;

const WHAT: &str = "boolean";

/// A result's faces are joined within this many times the boolean's tolerance.
pub const JOIN_FACTOR: f64 = 10.0;

/// The three booleans.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BooleanOp {
    Union,
    Difference,
    Intersection,
}

impl BooleanOp {
    pub const ALL: [BooleanOp; 3] = [
        BooleanOp::Union,
        BooleanOp::Difference,
        BooleanOp::Intersection,
    ];

    /// The name the command line and the page use.
    pub fn name(self) -> &'static str {
        match self {
            BooleanOp::Union => "union",
            BooleanOp::Difference => "difference",
            BooleanOp::Intersection => "intersection",
        }
    }

    /// The operation named `name` (as [`Self::name`] gives it).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|op| op.name() == name)
    }
}

/// One closed solid of a result: its outer shell's faces, then each void's (outward normals
/// everywhere, so a void's face outward from the solid's material).
#[derive(Debug, Clone)]
pub struct ResultSolid {
    pub shells: Vec<Vec<TrimmedSurface>>,
    /// The shared edges of its faces as [`Self::faces`] numbers them, as the result was
    /// joined (within ten times the tolerance).
    pub topology: Topology,
}

impl ResultSolid {
    /// The volume it encloses, its voids' taken off (exact: [`signed_volume`]).
    pub fn volume(&self) -> Result<f64, GeometryError> {
        signed_volume(&self.faces())
    }

    /// Every face of every shell.
    pub fn faces(&self) -> Vec<TrimmedSurface> {
        self.shells.iter().flatten().cloned().collect()
    }
}

/// What a boolean made.
#[derive(Debug, Clone, Default)]
pub struct BooleanResult {
    pub solids: Vec<ResultSolid>,
    /// Faces split by the other operand.
    pub split_faces: usize,
    /// Intersection branches used as cuts.
    pub branches: usize,
}

impl BooleanResult {
    /// Every face of every solid.
    pub fn faces(&self) -> Vec<TrimmedSurface> {
        self.solids.iter().flat_map(ResultSolid::faces).collect()
    }

    /// The shared edges of [`Self::faces`], known from the join that made them.
    pub fn topology(&self) -> Topology {
        Topology::concatenated(
            self.solids
                .iter()
                .map(|s| (&s.topology, s.shells.iter().map(Vec::len).sum())),
        )
    }
}

/// A closed operand: faces turned outward, its shells (faces by index), their boxes, for a
/// plane its point and normal, and each face's boundary flattened (made once, read by every
/// branch and split of the face).
struct Operand {
    faces: Vec<TrimmedSurface>,
    shells: Vec<Vec<usize>>,
    boxes: Vec<(DVec3, DVec3)>,
    planes: Vec<Option<(DVec3, DVec3)>>,
    boundaries: Vec<Vec<Polyline>>,
}

fn union_box(boxes: &[(DVec3, DVec3)]) -> (DVec3, DVec3) {
    boxes.iter().fold(
        (DVec3::INFINITY, DVec3::NEG_INFINITY),
        |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)),
    )
}

/// `faces` turned to agree across shared edges, and all outward: the faces of one or more
/// closed shells (at `tolerance`). Refuses faces that do not close (naming the operand by
/// `label`).
pub fn outward_faces(
    faces: &[TrimmedSurface],
    tolerance: f64,
    label: &str,
) -> Result<(Vec<TrimmedSurface>, Vec<Vec<usize>>), GeometryError> {
    if faces.is_empty() {
        return Err(construction(WHAT, format!("{label} has no faces")));
    }
    outward_faces_joined(faces, &find_topology(faces, tolerance)?, label)
}

/// [`outward_faces`] for faces whose shared edges are already known (a polysurface's).
pub fn outward_faces_joined(
    faces: &[TrimmedSurface],
    topology: &Topology,
    label: &str,
) -> Result<(Vec<TrimmedSurface>, Vec<Vec<usize>>), GeometryError> {
    if faces.is_empty() {
        return Err(construction(WHAT, format!("{label} has no faces")));
    }
    let v = validity(faces.len(), topology);
    if !v.is_closed_shell() {
        return Err(construction(
            WHAT,
            format!(
                "{label} is not a closed solid: {} open edge(s), {} edge(s) shared by more \
                 than two faces, {} edge(s) whose faces cannot be turned to agree; join its \
                 faces into a closed body first",
                v.naked.len(),
                v.non_manifold.len(),
                v.misoriented.len()
            ),
        ));
    }
    // Each closed shell turned to enclose positive volume, unless it lies inside another
    // shell of the operand (a void), which then encloses negative volume.
    let (flipped, _) = crate::mass::outward_flips(faces, topology)?;
    let out = faces
        .iter()
        .zip(&flipped)
        .map(|(face, &f)| {
            if f {
                face.reverse(Direction::U)
            } else {
                Ok(face.clone())
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    let components = topology.components(out.len());
    Ok((out, components))
}

/// The plane of a planar face (a point and the unit normal), where every control point lies
/// within `tolerance` of it.
fn plane_of(face: &TrimmedSurface, tolerance: f64) -> Option<(DVec3, DVec3)> {
    face.surface().plane(tolerance)
}

impl Operand {
    fn new(
        (faces, shells): (Vec<TrimmedSurface>, Vec<Vec<usize>>),
        tolerance: f64,
    ) -> Result<Self, GeometryError> {
        let boxes = faces.iter().map(|f| f.surface().bounds()).collect();
        let planes = faces
            .iter()
            .map(|f| plane_of(f, tolerance * 1e-2))
            .collect();
        let boundaries = faces
            .iter()
            .map(|f| boundary_polylines(f, tolerance))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            faces,
            shells,
            boxes,
            planes,
            boundaries,
        })
    }
}

/// The tolerance refused unless it is a finite number above 0.
fn positive(tolerance: f64) -> Result<(), GeometryError> {
    if tolerance > 0.0 && tolerance.is_finite() {
        Ok(())
    } else {
        Err(construction(
            WHAT,
            format!("the tolerance must be a number above 0, got {tolerance}"),
        ))
    }
}

/// The boolean `op` of two solids (`a`'s and `b`'s faces; each may hold several closed
/// shells that do not overlap one another), joined and checked at `tolerance` (model units;
/// see the module documentation).
pub fn boolean(
    op: BooleanOp,
    a: &[TrimmedSurface],
    b: &[TrimmedSurface],
    tolerance: f64,
) -> Result<BooleanResult, GeometryError> {
    boolean_joined(op, (a, None), (b, None), tolerance)
}

/// [`boolean`] of operands whose shared edges may already be known (a polysurface's
/// topology, so that a live boolean does not join its inputs again on every drag step): a
/// [`BooleanJob`] run to its end.
pub fn boolean_joined(
    op: BooleanOp,
    (a, topology_a): (&[TrimmedSurface], Option<&Topology>),
    (b, topology_b): (&[TrimmedSurface], Option<&Topology>),
    tolerance: f64,
) -> Result<BooleanResult, GeometryError> {
    BooleanJob::new(
        op,
        (a.to_vec(), topology_a.cloned()),
        (b.to_vec(), topology_b.cloned()),
        tolerance,
    )?
    .run()
}

/// The parts of face `k` of operand `own` (side 0: the first) that the boolean `op` keeps,
/// turned where the difference keeps them inside out, added to `pieces`: the face split by
/// its `cuts` (or whole), each part classified against `other` (its faces in one plane with
/// the part's face, by `coplanar`'s pairs, else `other_mesh`'s winding number) before it is
/// made. True when the face was split.
#[allow(clippy::too_many_arguments)] // one face's part of the boolean: what it reads
fn keep_parts(
    op: BooleanOp,
    (side, k): (usize, usize),
    own: &Operand,
    cuts: &[Polyline],
    (other, other_mesh): (&Operand, &Classifier),
    coplanar: &[(usize, usize)],
    tolerance: f64,
    pieces: &mut Vec<TrimmedSurface>,
) -> Result<bool, GeometryError> {
    let face = &own.faces[k];
    // Each part's trim loops (none: the whole face) and a point well inside it; a part is
    // made (its loops validated) only where it is kept.
    let parts = if cuts.is_empty() {
        vec![(
            None,
            whole_face_points(face, &own.boundaries[k], tolerance)?,
        )]
    } else {
        split_face(face, &own.boundaries[k], cuts, tolerance)?
            .into_iter()
            .map(|part| (Some(part.loops), part.inside))
            .collect()
    };
    let partners: Vec<usize> = coplanar
        .iter()
        .filter_map(|&(i, j)| match side {
            0 if i == k => Some(j),
            1 if j == k => Some(i),
            _ => None,
        })
        .collect();
    for (part, uv) in parts {
        // A part lies on its face's surface: classified by that, before it is made.
        let place = classify(face, &uv, other, &partners, other_mesh, tolerance)?;
        let keep = match (op, side, place) {
            (_, 1, Place::OnSame | Place::OnOpposite) => Keep::No,
            (BooleanOp::Union, _, Place::Outside) => Keep::AsIs,
            (BooleanOp::Union, 0, Place::OnSame) => Keep::AsIs,
            (BooleanOp::Intersection, _, Place::Inside) => Keep::AsIs,
            (BooleanOp::Intersection, 0, Place::OnSame) => Keep::AsIs,
            (BooleanOp::Difference, 0, Place::Outside | Place::OnOpposite) => Keep::AsIs,
            (BooleanOp::Difference, 1, Place::Inside) => Keep::Turned,
            _ => Keep::No,
        };
        if keep == Keep::No {
            continue;
        }
        let part = match part {
            Some(loops) => TrimmedSurface::new(face.surface().clone(), loops).map_err(|e| {
                construction(
                    WHAT,
                    format!(
                        "a part of face {} of the {} body could not be trimmed ({e}): the \
                             cuts on it come too close to each other or to its edges, as where \
                             the bodies meet near a corner, a cone's apex or a ball's pole",
                        k + 1,
                        if side == 0 { "first" } else { "second" }
                    ),
                )
            })?,
            None => face.clone(),
        };
        pieces.push(match keep {
            Keep::Turned => part.reverse(Direction::U)?,
            _ => part,
        });
    }
    Ok(!cuts.is_empty())
}

/// Where two faces of one body cross: the faces (by index) and a point on the crossing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfIntersection {
    pub faces: (usize, usize),
    pub at: DVec3,
}

/// Where the faces of one body cross each other (a self-intersection), at `tolerance` (model
/// units): every pair of faces whose boxes meet intersected as in a boolean (see the module
/// documentation), the branches along either face's edges or seams (neighbours meeting along
/// their shared edge) left out; what remains is where the body passes through itself, one
/// point per branch. Faces in one plane are passed over.
pub fn self_intersections(
    faces: &[TrimmedSurface],
    tolerance: f64,
) -> Result<Vec<SelfIntersection>, GeometryError> {
    positive(tolerance)?;
    let body = Operand::new(
        (faces.to_vec(), vec![(0..faces.len()).collect()]),
        tolerance,
    )?;
    let (_, options) = marching_options(&[&body, &body], tolerance);
    // Two caches, so that a pair can borrow a tree from each.
    let mut trees_a = CachedTrees::new(body.faces.len());
    let mut trees_b = CachedTrees::new(body.faces.len());
    let grow = DVec3::splat(tolerance);
    let mut found = Vec::new();
    for i in 0..body.faces.len() {
        for j in i + 1..body.faces.len() {
            let (ba, bb) = (body.boxes[i], body.boxes[j]);
            if (ba.0 - grow).cmpgt(bb.1).any() || (bb.0 - grow).cmpgt(ba.1).any() {
                continue;
            }
            if let (Some((_, na)), Some((_, nb))) = (body.planes[i], body.planes[j])
                && na.cross(nb).length() < 1e-9
            {
                continue;
            }
            let pair = face_pair(
                (&body, &mut trees_a, i),
                (&body, &mut trees_b, j),
                &options,
                tolerance,
            )?;
            let Some(pair) = pair.filter(|p| !p.overlapping) else {
                continue;
            };
            for branch in pair.curves {
                let n = branch.points.len();
                if n == 0
                    || boundary_kind(&body.faces[i], &body.boundaries[i], &branch.uv_a, tolerance)
                        .is_some()
                    || boundary_kind(&body.faces[j], &body.boundaries[j], &branch.uv_b, tolerance)
                        .is_some()
                {
                    continue;
                }
                found.push(SelfIntersection {
                    faces: (i, j),
                    at: branch.points[n / 2],
                });
            }
        }
    }
    Ok(found)
}

/// Where face `i` of `a` and face `j` of `b` cross (their boxes meeting, their planes not
/// parallel): `None` where one lies wholly on one side of the other's plane (touching it at
/// most); else two flat faces along their planes' line clipped to both (exactly, and far
/// faster than marching), others by marching on their cell trees.
fn face_pair(
    (a, trees_a, i): (&Operand, &mut CachedTrees, usize),
    (b, trees_b, j): (&Operand, &mut CachedTrees, usize),
    options: &IntersectOptions,
    tolerance: f64,
) -> Result<Option<Intersection>, GeometryError> {
    if only_touches(a.planes[i], &b.faces[j], tolerance)
        || only_touches(b.planes[j], &a.faces[i], tolerance)
    {
        return Ok(None);
    }
    let straight = match (a.planes[i], b.planes[j]) {
        (Some(plane_a), Some(plane_b)) => plane_branches(
            (&a.faces[i], plane_a, &a.boundaries[i]),
            (&b.faces[j], plane_b, &b.boundaries[j]),
        ),
        _ => None,
    };
    // A flat face and a ruled one: the plane's section of the ruled surface.
    let straight = straight.or_else(|| match (a.planes[i], b.planes[j]) {
        (Some(plane), None) => {
            plane_ruled_branches(&a.faces[i], plane, &b.faces[j], options, tolerance)
        }
        (None, Some(plane)) => {
            plane_ruled_branches(&b.faces[j], plane, &a.faces[i], options, tolerance).map(
                |curves| {
                    curves
                        .into_iter()
                        .map(|mut c| {
                            std::mem::swap(&mut c.uv_a, &mut c.uv_b);
                            c
                        })
                        .collect()
                },
            )
        }
        _ => None,
    });
    Ok(Some(match straight {
        Some(curves) => Intersection {
            curves,
            ..Default::default()
        },
        None => intersect_cached(
            (&a.faces[i], trees_a, i),
            (&b.faces[j], trees_b, j),
            options,
        )?,
    }))
}

/// Where two operands' faces cross: each face's cuts (in its (u, v)), the pairs of faces
/// lying in one plane, how many branches cut, and the size of both operands' box.
struct Cuts {
    a: Vec<Vec<Polyline>>,
    b: Vec<Vec<Polyline>>,
    /// Coplanar partners: (face of a, face of b).
    coplanar: Vec<(usize, usize)>,
    branches: usize,
    size: f64,
}

/// The size of the operands' box and the marching's settings for it: points within 1e-5 of
/// the tolerance, chords within 2e-5 of the size (the tolerance at least), cells down to
/// 2e-3 of it.
fn marching_options(operands: &[&Operand], tolerance: f64) -> (f64, IntersectOptions) {
    let boxes: Vec<(DVec3, DVec3)> = operands.iter().map(|o| union_box(&o.boxes)).collect();
    let (lo, hi) = union_box(&boxes);
    let size = lo.distance(hi);
    let options = IntersectOptions {
        tolerance: tolerance * 1e-5,
        chord: (size * 2e-5).max(tolerance),
        smallest: size * 2e-3,
        cell_pairs: crate::intersect::MAX_CELL_PAIRS,
    };
    (size, options)
}

/// Step 2 of the module documentation: every pair of faces whose boxes meet intersected
/// (see there), the branches turned into cuts on both faces.
fn cut_faces(a: &Operand, b: &Operand, tolerance: f64) -> Result<Cuts, GeometryError> {
    let mut cutter = Cutter::new(a, b, tolerance, crate::intersect::MAX_CELL_PAIRS);
    while !cutter.next_pair(a, b, tolerance)? {}
    Ok(cutter.cuts)
}

/// The cuts of two operands' faces made a pair of faces at a time ([`cut_faces`]).
struct Cutter {
    options: IntersectOptions,
    /// Each face's cell tree, made once for all the pairs it is in.
    trees: (CachedTrees, CachedTrees),
    cuts: Cuts,
    /// The next pair: (face of a, face of b).
    next: (usize, usize),
}

impl Cutter {
    fn new(a: &Operand, b: &Operand, tolerance: f64, cell_pairs: usize) -> Self {
        let (size, options) = marching_options(&[a, b], tolerance);
        Self {
            options: IntersectOptions {
                cell_pairs,
                ..options
            },
            trees: (
                CachedTrees::new(a.faces.len()),
                CachedTrees::new(b.faces.len()),
            ),
            cuts: Cuts {
                a: vec![Vec::new(); a.faces.len()],
                b: vec![Vec::new(); b.faces.len()],
                coplanar: Vec::new(),
                branches: 0,
                size,
            },
            next: (0, 0),
        }
    }

    /// How far through the pairs it is, from 0 to 1.
    fn progress(&self, b: &Operand) -> f64 {
        let (i, j) = self.next;
        let all = self.cuts.a.len() * b.faces.len();
        if all == 0 {
            1.0
        } else {
            ((i * b.faces.len() + j) as f64 / all as f64).min(1.0)
        }
    }

    /// The pairs up to and including the next whose boxes meet, cut; true when none is left.
    fn next_pair(
        &mut self,
        a: &Operand,
        b: &Operand,
        tolerance: f64,
    ) -> Result<bool, GeometryError> {
        let grow = DVec3::splat(tolerance);
        while self.next.0 < a.faces.len() && !b.faces.is_empty() {
            let (i, j) = self.next;
            self.next = if j + 1 < b.faces.len() {
                (i, j + 1)
            } else {
                (i + 1, 0)
            };
            let (ba, bb) = (a.boxes[i], b.boxes[j]);
            if (ba.0 - grow).cmpgt(bb.1).any() || (bb.0 - grow).cmpgt(ba.1).any() {
                continue;
            }
            self.pair(a, b, (i, j), tolerance)?;
            return Ok(false);
        }
        Ok(true)
    }

    /// Face `i` of `a` and face `j` of `b`, whose boxes meet, cut.
    fn pair(
        &mut self,
        a: &Operand,
        b: &Operand,
        (i, j): (usize, usize),
        tolerance: f64,
    ) -> Result<(), GeometryError> {
        let Cuts {
            a: cuts_a,
            b: cuts_b,
            coplanar,
            branches,
            ..
        } = &mut self.cuts;
        let (trees_a, trees_b) = &mut self.trees;
        let options = &self.options;
        if let (Some((pa, na)), Some((pb, nb))) = (a.planes[i], b.planes[j])
            && na.cross(nb).length() < 1e-9
        {
            if (pb - pa).dot(na).abs() <= tolerance {
                coplanar.push((i, j));
                // Each face cut by the other's boundary mapped into its plane.
                for (list, (from, lines), onto) in [
                    (&mut cuts_a[i], (&b.faces[j], &b.boundaries[j]), &a.faces[i]),
                    (&mut cuts_b[j], (&a.faces[i], &a.boundaries[i]), &b.faces[j]),
                ] {
                    let k = list.len();
                    list.extend(mapped_boundary(from, lines, onto, k)?);
                }
            }
            return Ok(());
        }
        let Some(mut found) = face_pair((a, trees_a, i), (b, trees_b, j), options, tolerance)?
        else {
            return Ok(());
        };
        if found.overlapping {
            return Err(construction(
                WHAT,
                format!(
                    "face {} of the first body and face {} of the second lie on one another \
                     over an area of a curved surface (equal bodies, or a shared cylinder \
                     or sphere), which this boolean does not resolve yet",
                    i + 1,
                    j + 1
                ),
            ));
        }
        meet_at_tangent_points(&mut found.curves, 10.0 * options.chord);
        without_repeats(&mut found.curves, 4.0 * options.chord);
        for branch in found.curves {
            // A branch along an edge of either face (an edge lying on a face) cuts
            // nothing; one along a closed surface's seam, which is no edge of the body,
            // cuts the other face only.
            let edge_a = boundary_kind(&a.faces[i], &a.boundaries[i], &branch.uv_a, tolerance);
            let edge_b = boundary_kind(&b.faces[j], &b.boundaries[j], &branch.uv_b, tolerance);
            if edge_a == Some(Boundary::Edge) || edge_b == Some(Boundary::Edge) {
                continue;
            }
            *branches += 1;
            let closed = branch.closed;
            for (list, uv, face, on_seam) in [
                (&mut cuts_a[i], branch.uv_a, &a.faces[i], edge_a.is_some()),
                (&mut cuts_b[j], branch.uv_b, &b.faces[j], edge_b.is_some()),
            ] {
                if on_seam {
                    continue;
                }
                let mut points = uv;
                if closed {
                    points.pop();
                    without_overshoot(&mut points);
                }
                for (points, closed) in across_seams(points, closed, face) {
                    if points.len() >= 2 {
                        let k = list.len();
                        list.push(Polyline {
                            source: Source::Cut(k),
                            points,
                            params: Vec::new(),
                            closed,
                        });
                    }
                }
            }
        }
        Ok(())
    }
}

/// Whether the surface closes on itself across u = u0, u1 and across v = v0, v1 (its edges
/// there coincide at nine samples, within 1e-9 of its size).
fn seams(surface: &NurbsSurface) -> (bool, bool) {
    let [u0, u1, v0, v1] = domain_rect(surface);
    let gap = 1e-9 * surface.size();
    let meets = |a: (f64, f64), b: (f64, f64)| match (
        surface.point_at(a.0, a.1),
        surface.point_at(b.0, b.1),
    ) {
        (Ok(p), Ok(q)) => p.distance(q) <= gap,
        _ => false,
    };
    let fractions = (0..9).map(|k| (k as f64 + 0.5) / 9.0);
    let closed_u = fractions.clone().all(|f| {
        let v = v0 + (v1 - v0) * f;
        meets((u0, v), (u1, v))
    });
    let closed_v = fractions.clone().all(|f| {
        let u = u0 + (u1 - u0) * f;
        meets((u, v0), (u, v1))
    });
    (closed_u, closed_v)
}

/// A branch's (u, v) points cut where they jump across a closed surface's seam (a step of
/// more than a quarter of the domain in u or v), each piece carried on to the domain's edge
/// where the jump crosses it (v, or u, interpolated linearly across); a closed branch that
/// crosses the seam becomes open pieces, the one through its start joined up.
fn across_seams(
    points: Vec<DVec2>,
    closed: bool,
    face: &TrimmedSurface,
) -> Vec<(Vec<DVec2>, bool)> {
    let [u0, u1, v0, v1] = domain_rect(face.surface());
    let (w, h) = (u1 - u0, v1 - v0);
    let n = points.len();
    if n < 2 {
        return vec![(points, closed)];
    }
    let steps = if closed { n } else { n - 1 };
    let (seam_u, seam_v) = seams(face.surface());
    if !(seam_u || seam_v) {
        return vec![(points, closed)];
    }
    let jump = |p: DVec2, q: DVec2| {
        (seam_u && (q.x - p.x).abs() > 0.25 * w) || (seam_v && (q.y - p.y).abs() > 0.25 * h)
    };
    let first_jump = (0..steps).find(|&k| jump(points[k], points[(k + 1) % n]));
    let Some(start) = first_jump else {
        return vec![(points, closed)];
    };
    // A closed branch is walked from just after its first jump, round to it again.
    let order: Vec<usize> = if closed {
        (1..=n).map(|k| (start + k) % n).collect()
    } else {
        (0..n).collect()
    };
    // Where p → q crosses the seam: the ends on either edge.
    let crossing = |p: DVec2, q: DVec2| -> (DVec2, DVec2) {
        if seam_u && (q.x - p.x).abs() > 0.25 * w {
            let (pe, qe) = if p.x > q.x { (u1, u0) } else { (u0, u1) };
            let (dp, dq) = ((pe - p.x).abs(), (q.x - qe).abs());
            let t = dp / (dp + dq).max(1e-300);
            let v = p.y + (q.y - p.y) * t;
            (DVec2::new(pe, v), DVec2::new(qe, v))
        } else {
            let (pe, qe) = if p.y > q.y { (v1, v0) } else { (v0, v1) };
            let (dp, dq) = ((pe - p.y).abs(), (q.y - qe).abs());
            let t = dp / (dp + dq).max(1e-300);
            let u = p.x + (q.x - p.x) * t;
            (DVec2::new(u, pe), DVec2::new(u, qe))
        }
    };
    // A point on the seam itself is not repeated by its crossing.
    let push = |piece: &mut Vec<DVec2>, p: DVec2| {
        if piece.last() != Some(&p) {
            piece.push(p);
        }
    };
    let mut pieces: Vec<Vec<DVec2>> = vec![Vec::new()];
    for (m, &k) in order.iter().enumerate() {
        let p = points[k];
        if m > 0 {
            let prev = points[order[m - 1]];
            if jump(prev, p) {
                let (end, begin) = crossing(prev, p);
                if let Some(last) = pieces.last_mut() {
                    push(last, end);
                }
                pieces.push(vec![begin]);
            }
        }
        if let Some(last) = pieces.last_mut() {
            push(last, p);
        }
    }
    if closed {
        // The walk ends where it began: across the first jump again.
        let (p, q) = (points[start], points[(start + 1) % n]);
        let (end, begin) = crossing(p, q);
        if let Some(last) = pieces.last_mut() {
            push(last, end);
        }
        if let Some(first) = pieces.first_mut()
            && first.first() != Some(&begin)
        {
            first.insert(0, begin);
        }
    }
    pieces.into_iter().map(|p| (p, false)).collect()
}

/// A closed branch's points without those at its end that run on past its start (a loop is
/// closed where it comes back near its start, a step or so beyond it).
fn without_overshoot(points: &mut Vec<DVec2>) {
    // Three points at most, and only where the first step is a step along the curve (not a
    // jump across a seam, which is far longer than the one before the end).
    for _ in 0..3 {
        let n = points.len();
        if n <= 4 {
            return;
        }
        let (p0, p1, last) = (points[0], points[1], points[n - 1]);
        let step = p1 - p0;
        let before = points[n - 2].distance(last);
        if step.length() <= 4.0 * before
            && last.distance(p0) < step.length()
            && (last - p0).dot(step) > 0.0
        {
            points.pop();
        } else {
            return;
        }
    }
}

/// Whether the surface is an affine map of its domain (u, v ↦ o + u·U + v·V: degree one
/// each way, equal weights, a parallelogram of control points), so that a line in space is a
/// line in its (u, v).
fn affine(surface: &NurbsSurface) -> bool {
    surface.degree() == [1, 1] && surface.count() == [2, 2] && surface.is_polynomial() && {
        let p = |i, j| surface.control_point(i, j);
        (p(0, 0) + p(1, 1) - p(1, 0) - p(0, 1)).length() <= 1e-12 * surface.size()
    }
}

/// The branches where two flat faces (each with its plane and its boundary flattened) cross,
/// when both are affine ([`affine`]; else `None`, for marching): their planes' line (the
/// point on both planes, (h₁(n₂ × d) + h₂(d × n₁)) / |d|² with d = n₁ × n₂, for planes
/// n·x = h) clipped to each face in its (u, v), the spans both keep. Each is sampled at nine
/// points (straight in both domains), its ends on the faces' boundaries; where a face's edge
/// is shared, the neighbour's branch ends at the same three planes' point.
fn plane_branches(
    (face_a, (point_a, normal_a), lines_a): (&TrimmedSurface, (DVec3, DVec3), &[Polyline]),
    (face_b, (point_b, normal_b), lines_b): (&TrimmedSurface, (DVec3, DVec3), &[Polyline]),
) -> Option<Vec<IntersectionCurve>> {
    if !(affine(face_a.surface()) && affine(face_b.surface())) {
        return None;
    }
    let d = normal_a.cross(normal_b);
    let d2 = d.length_squared();
    if d2 < 1e-18 {
        return None;
    }
    let (h_a, h_b) = (normal_a.dot(point_a), normal_b.dot(point_b));
    let origin = (h_a * normal_b.cross(d) + h_b * d.cross(normal_a)) / d2;
    let direction = d / d2.sqrt();
    let spans_a = line_in_face(face_a, lines_a, origin, direction)?;
    let spans_b = line_in_face(face_b, lines_b, origin, direction)?;
    let (uv_a0, uv_a1) = (
        plane_uv(face_a.surface(), origin)?,
        plane_uv(face_a.surface(), origin + direction)?,
    );
    let (uv_b0, uv_b1) = (
        plane_uv(face_b.surface(), origin)?,
        plane_uv(face_b.surface(), origin + direction)?,
    );
    let shortest = 1e-9 * (face_a.surface().size() + face_b.surface().size());
    let mut curves = Vec::new();
    for &(a0, a1) in &spans_a {
        for &(b0, b1) in &spans_b {
            let (t0, t1) = (a0.max(b0), a1.min(b1));
            if t1 - t0 <= shortest {
                continue;
            }
            let ts: Vec<f64> = (0..=8)
                .map(|k| t0 + (t1 - t0) * f64::from(k) / 8.0)
                .collect();
            curves.push(IntersectionCurve {
                closed: false,
                points: ts.iter().map(|&t| origin + direction * t).collect(),
                uv_a: ts.iter().map(|&t| uv_a0 + (uv_a1 - uv_a0) * t).collect(),
                uv_b: ts.iter().map(|&t| uv_b0 + (uv_b1 - uv_b0) * t).collect(),
                ends: [Some(BranchEnd::Boundary); 2],
            });
        }
    }
    Some(curves)
}

/// The spans of the line `origin + t·direction` that an affine flat face keeps: where the
/// line crosses its boundary (flattened: `lines`) in its (u, v), the pieces between whose
/// middles the face contains, joined where they meet. `None` where the line cannot be put
/// into the face's (u, v).
fn line_in_face(
    face: &TrimmedSurface,
    lines: &[Polyline],
    origin: DVec3,
    direction: DVec3,
) -> Option<Vec<(f64, f64)>> {
    let q0 = plane_uv(face.surface(), origin)?;
    let e = plane_uv(face.surface(), origin + direction)? - q0;
    if e.length_squared() == 0.0 {
        return None;
    }
    let mut ts: Vec<f64> = Vec::new();
    for line in lines {
        let n = line.points.len();
        let steps = if line.closed { n } else { n.saturating_sub(1) };
        for k in 0..steps {
            let (w0, w1) = (line.points[k], line.points[(k + 1) % n]);
            let f = w1 - w0;
            let den = e.perp_dot(f);
            if den == 0.0 {
                continue;
            }
            let r = w0 - q0;
            let (t, s) = (r.perp_dot(f) / den, r.perp_dot(e) / den);
            if (0.0..=1.0).contains(&s) {
                ts.push(t);
            }
        }
    }
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    let rect = domain_rect(face.surface());
    let slack = 1e-12 * domain_size(rect);
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for pair in ts.windows(2) {
        let (t0, t1) = (pair[0], pair[1]);
        let middle = q0 + e * (0.5 * (t0 + t1));
        if t1 > t0 && inside_domain(face, middle, slack) && face.contains(middle.x, middle.y) {
            match spans.last_mut() {
                Some(last) if last.1 == t0 => last.1 = t1,
                _ => spans.push((t0, t1)),
            }
        }
    }
    Some(spans)
}

/// Whether `face` lies wholly on one side of the plane (within `tolerance`): it may touch the
/// plane along its edge (an edge lying on a face) but crosses no face in it.
fn only_touches(plane: Option<(DVec3, DVec3)>, face: &TrimmedSurface, tolerance: f64) -> bool {
    let Some((point, normal)) = plane else {
        return false;
    };
    let s = face.surface();
    let [n, m] = s.count();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..n {
        for j in 0..m {
            let d = (s.control_point(i, j) - point).dot(normal);
            lo = lo.min(d);
            hi = hi.max(d);
        }
    }
    lo >= -tolerance || hi <= tolerance
}

/// The branches without any that runs along another, longer one (within `reach` at its ends,
/// quarters and middle): marching finds a line along a closed surface's seam once from each
/// side, and the two copies would cut a face twice along one line.
fn without_repeats(curves: &mut Vec<IntersectionCurve>, reach: f64) {
    let near = |p: DVec3, polyline: &[DVec3]| {
        polyline.windows(2).any(|w| {
            let ab = w[1] - w[0];
            let t = ((p - w[0]).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
            p.distance(w[0] + ab * t) <= reach
        }) || polyline.first().is_some_and(|q| q.distance(p) <= reach)
    };
    let length = |c: &IntersectionCurve| {
        c.points
            .windows(2)
            .map(|w| w[0].distance(w[1]))
            .sum::<f64>()
    };
    let mut order: Vec<usize> = (0..curves.len()).collect();
    order.sort_by(|&x, &y| length(&curves[y]).total_cmp(&length(&curves[x])));
    let mut kept: Vec<usize> = Vec::new();
    for x in order {
        let c = &curves[x];
        let n = c.points.len();
        let covered = n > 0
            && kept.iter().any(|&y| {
                [0, n / 4, n / 2, 3 * n / 4, n - 1]
                    .iter()
                    .all(|&k| near(c.points[k], &curves[y].points))
            });
        if !covered {
            kept.push(x);
        }
    }
    kept.sort_unstable();
    let mut index = 0;
    curves.retain(|_| {
        let keep = kept.binary_search(&index).is_ok();
        index += 1;
        keep
    });
}

/// Branches that stop where the surfaces touch (two equal cylinders crossing: their curves
/// cross there) ended at one common point: the mean of the ends within `reach` of one
/// another, on both surfaces, so the cuts meet and divide the faces.
fn meet_at_tangent_points(curves: &mut [IntersectionCurve], reach: f64) {
    let mut ends: Vec<(usize, usize)> = Vec::new();
    for (k, c) in curves.iter().enumerate() {
        for end in 0..2 {
            if c.ends[end] == Some(BranchEnd::Tangent) && !c.points.is_empty() {
                ends.push((k, end));
            }
        }
    }
    let at = |c: &IntersectionCurve, end: usize| if end == 0 { 0 } else { c.points.len() - 1 };
    let mut used = vec![false; ends.len()];
    for x in 0..ends.len() {
        if used[x] {
            continue;
        }
        let (k, e) = ends[x];
        let p = curves[k].points[at(&curves[k], e)];
        let group: Vec<usize> = (x..ends.len())
            .filter(|&y| {
                let (m, f) = ends[y];
                !used[y] && curves[m].points[at(&curves[m], f)].distance(p) <= reach
            })
            .collect();
        if group.len() < 2 {
            continue;
        }
        let n = group.len() as f64;
        let (mut point, mut uv_a, mut uv_b) = (DVec3::ZERO, DVec2::ZERO, DVec2::ZERO);
        for &y in &group {
            used[y] = true;
            let (m, f) = ends[y];
            let i = at(&curves[m], f);
            point += curves[m].points[i] / n;
            uv_a += curves[m].uv_a[i] / n;
            uv_b += curves[m].uv_b[i] / n;
        }
        // Near the touching point the marched points wander (the normals are nearly parallel,
        // so the curve's direction is ill-defined): those within `reach` of it are dropped and
        // the end moved onto it, so the cubic through the rest runs smoothly into it.
        for &y in &group {
            let (m, f) = ends[y];
            let c = &mut curves[m];
            if f == 0 {
                c.points.reverse();
                c.uv_a.reverse();
                c.uv_b.reverse();
            }
            while c.points.len() > 2 && c.points[c.points.len() - 2].distance(point) <= reach {
                c.points.pop();
                c.uv_a.pop();
                c.uv_b.pop();
            }
            let i = c.points.len() - 1;
            c.points[i] = point;
            c.uv_a[i] = uv_a;
            c.uv_b[i] = uv_b;
            if f == 0 {
                c.points.reverse();
                c.uv_a.reverse();
                c.uv_b.reverse();
            }
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Keep {
    AsIs,
    Turned,
    No,
}

/// Where a part lies with respect to the other operand.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Place {
    Inside,
    Outside,
    /// On a coplanar face whose outward normal agrees.
    OnSame,
    /// On a coplanar face whose outward normal is opposite.
    OnOpposite,
}

/// The triangles of each shell of an operand, with the shell's box, for the winding number.
struct Classifier {
    shells: Vec<ShellTriangles>,
    /// How far a triangle may lie from its face.
    flatness: f64,
}

/// One shell's box, its triangles and its flat faces.
struct ShellTriangles {
    lo: DVec3,
    hi: DVec3,
    /// Triangles that lie on their face: the tessellations of curved faces.
    triangles: Vec<[DVec3; 3]>,
    /// The fans of flat faces: each face's signed area as a chain of triangles from one
    /// boundary point, which may reach past the face (where they cancel), so a point near
    /// them is tested against the face itself.
    fans: Vec<[DVec3; 3]>,
    /// The flat faces with a point and the unit normal of their planes.
    flat: Vec<(TrimmedSurface, DVec3, DVec3)>,
}

/// The winding-number classifier of an operand's shells. A flat affine face ([`affine`]) is
/// its boundary's fan: every chord of its loops (in their turn, outer loops anticlockwise in
/// (u, v)) with one boundary point, the face as a chain of signed triangles whose solid angles
/// add up to the face's. A curved face whose one loop is its domain's edge is its surface's
/// grid; any other face its trimmed tessellation.
fn classifier(operand: &Operand, size: f64) -> Result<Classifier, GeometryError> {
    let mut shells = Vec::with_capacity(operand.shells.len());
    for shell in &operand.shells {
        let mut made = ShellTriangles {
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
            triangles: Vec::new(),
            fans: Vec::new(),
            flat: Vec::new(),
        };
        for &k in shell {
            let face = &operand.faces[k];
            let surface = face.surface();
            let (lo, hi) = operand.boxes[k];
            made.lo = made.lo.min(lo);
            made.hi = made.hi.max(hi);
            if let (Some((point, normal)), true) = (operand.planes[k], affine(surface)) {
                let mut apex = None;
                for line in &operand.boundaries[k] {
                    let points = line
                        .points
                        .iter()
                        .map(|&q| surface.point_at_clamped(q))
                        .collect::<Result<Vec<_>, _>>()?;
                    let apex = *apex.get_or_insert(points[0]);
                    for w in points.windows(2) {
                        made.fans.push([apex, w[0], w[1]]);
                    }
                }
                made.flat.push((face.clone(), point, normal));
                continue;
            }
            let tolerance = (surface.size() * 2e-4).max(size * 1e-6);
            let mesh = match face.kept_rectangle() {
                Some([u0, u1, v0, v1]) => {
                    let grid = grid_for(surface, Tessellation::Tolerance(tolerance))?;
                    let grid = crate::tess::ParameterGrid {
                        us: crate::tess::values_within(&grid.us, u0, u1),
                        vs: crate::tess::values_within(&grid.vs, v0, v1),
                    };
                    triangulate(surface, &grid, false)?
                }
                None => tessellate_trimmed(face, Tessellation::Tolerance(tolerance), false)?,
            };
            for t in &mesh.triangles {
                made.triangles.push(t.map(|k| mesh.positions[k as usize]));
            }
        }
        shells.push(made);
    }
    // The most a face's tessellation strays from it (as above, with the tessellation's own
    // rounding), for telling a point on the body's boundary.
    let flatness = operand
        .faces
        .iter()
        .map(|f| (f.surface().size() * 2e-4).max(size * 1e-6))
        .fold(size * 1e-9, f64::max);
    Ok(Classifier { shells, flatness })
}

/// The solid angle of triangle `t` seen from `p`, with the triple product a·(b×c) and the
/// lengths (|a| + |b|)(|a| + |c|) that bound twice its area, where a, b, c run from `p` to its
/// corners (Van Oosterom and Strackee's formula, tan(Ω/2) =
/// a·(b×c) / (|a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|)).
fn solid_angle(t: &[DVec3; 3], p: DVec3) -> (f64, f64, f64) {
    let (a, b, c) = (t[0] - p, t[1] - p, t[2] - p);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    (
        2.0 * numerator.atan2(denominator),
        numerator,
        (la + lb) * (la + lc),
    )
}

impl Classifier {
    /// The winding number of the closed triangle sets about `p` (its sign follows the
    /// tessellation's turn, so the caller takes its size): the sum of the triangles' solid
    /// angles ([`solid_angle`]) over 4π. A shell whose box does not hold `p` winds zero times
    /// round it and is skipped.
    ///
    /// Also whether `p` lies within twice the tessellation's flatness of a triangle's plane
    /// over the triangle, or of a flat face: about on the body's boundary, where the winding
    /// number is no guide.
    fn winding(&self, p: DVec3) -> (f64, bool) {
        let mut total = 0.0;
        let mut on_boundary = false;
        let near = 2.0 * self.flatness;
        for shell in &self.shells {
            let margin = (shell.hi - shell.lo) * 1e-3 + near;
            if (p - shell.lo + margin).min_element() < 0.0
                || (shell.hi + margin - p).min_element() < 0.0
            {
                continue;
            }
            for t in &shell.fans {
                total += solid_angle(t, p).0;
            }
            for t in &shell.triangles {
                let (angle, numerator, bound) = solid_angle(t, p);
                total += angle;
                // Most triangles are ruled out before their normal is worked out.
                if !on_boundary && numerator.abs() <= near * bound {
                    // p's height over the triangle's plane is the triple product over twice its
                    // area; over the triangle where the three edge tests agree.
                    let (a, b, c) = (t[0] - p, t[1] - p, t[2] - p);
                    let normal = (b - a).cross(c - a);
                    if numerator.abs() <= near * normal.length() {
                        let sides = [a.cross(b), b.cross(c), c.cross(a)].map(|e| e.dot(normal));
                        on_boundary =
                            sides.iter().all(|&x| x >= 0.0) || sides.iter().all(|&x| x <= 0.0);
                    }
                }
            }
            if !on_boundary {
                on_boundary = shell.flat.iter().any(|(face, point, normal)| {
                    (p - *point).dot(*normal).abs() <= near
                        && plane_uv(face.surface(), p).is_some_and(|q| {
                            let slack = 1e-12 * domain_size(domain_rect(face.surface()));
                            inside_domain(face, q, slack) && face.contains(q.x, q.y)
                        })
                });
            }
        }
        (total / (4.0 * std::f64::consts::PI), on_boundary)
    }
}

/// The surface's derivatives at `uv` taken into its domain (a loop may stray past the
/// domain's edge by a rounding).
fn evaluate_clamped(
    surface: &NurbsSurface,
    uv: DVec2,
) -> Result<crate::diffgeo::SurfaceDerivatives, GeometryError> {
    let [u0, u1, v0, v1] = domain_rect(surface);
    surface.evaluate(uv.x.clamp(u0, u1), uv.y.clamp(v0, v1))
}

fn inside_domain(face: &TrimmedSurface, uv: DVec2, slack: f64) -> bool {
    let [u0, u1, v0, v1] = domain_rect(face.surface());
    uv.x >= u0 - slack && uv.x <= u1 + slack && uv.y >= v0 - slack && uv.y <= v1 + slack
}

/// Where the part (its points at `candidates`, all inside it) lies with respect to `other`:
/// as the first point says, unless that point lies about on the other body's boundary (a face
/// touching it along a line through the point), when the candidate the winding number is
/// surest of decides.
fn classify(
    part: &TrimmedSurface,
    candidates: &[DVec2],
    other: &Operand,
    coplanar: &[usize],
    mesh: &Classifier,
    tolerance: f64,
) -> Result<Place, GeometryError> {
    let mut best = (Place::Outside, -1.0);
    for &uv in candidates {
        let (place, sureness) = classify_at(part, uv, other, coplanar, mesh, tolerance)?;
        if sureness > best.1 {
            best = (place, sureness);
        }
        if sureness >= 0.25 {
            break;
        }
    }
    Ok(best.0)
}

/// Where the part's point at `uv` lies with respect to `other`, and how sure that is (1 on a
/// coplanar face; else how far the winding number is from the undecided ½).
fn classify_at(
    part: &TrimmedSurface,
    uv: DVec2,
    other: &Operand,
    coplanar: &[usize],
    mesh: &Classifier,
    tolerance: f64,
) -> Result<(Place, f64), GeometryError> {
    let d = evaluate_clamped(part.surface(), uv)?;
    let p = d.point;
    for &j in coplanar {
        let face = &other.faces[j];
        let Some(q) = plane_uv(face.surface(), p) else {
            continue;
        };
        let slack = 1e-12 * domain_size(domain_rect(face.surface()));
        if !(inside_domain(face, q, slack) && face.contains(q.x, q.y)) {
            continue;
        }
        let on = evaluate_clamped(face.surface(), q)?;
        if on.point.distance(p) > tolerance {
            continue;
        }
        let (Some(n_part), Some(n_other)) = (d.regular_normal(), on.regular_normal()) else {
            continue;
        };
        let place = if n_part.dot(n_other) > 0.0 {
            Place::OnSame
        } else {
            Place::OnOpposite
        };
        return Ok((place, 1.0));
    }
    let (winding, on_boundary) = mesh.winding(p);
    let place = if winding.abs() > 0.5 {
        Place::Inside
    } else {
        Place::Outside
    };
    let sureness = if on_boundary {
        0.0
    } else {
        (winding.abs() - 0.5).abs()
    };
    Ok((place, sureness))
}

/// The (u, v) of `p` on a planar surface, unclamped: the affine map through the domain's
/// centre inverted, then Newton's steps on the surface's tangent plane (exact for an affine
/// plane in one step).
fn plane_uv(surface: &NurbsSurface, p: DVec3) -> Option<DVec2> {
    let [(u0, u1), (v0, v1)] = surface.domain();
    let mut uv = DVec2::new(0.5 * (u0 + u1), 0.5 * (v0 + v1));
    for _ in 0..8 {
        let at = DVec2::new(uv.x.clamp(u0, u1), uv.y.clamp(v0, v1));
        let d = surface.evaluate(at.x, at.y).ok()?;
        // The point at uv by the tangent plane at the clamped point (outside the domain the
        // plane carries on affinely).
        let here = d.point + d.su * (uv.x - at.x) + d.sv * (uv.y - at.y);
        let r = p - here;
        let (a, b, c) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
        let det = a * c - b * b;
        if det.abs() < 1e-300 {
            return None;
        }
        let (x, y) = (d.su.dot(r), d.sv.dot(r));
        let step = DVec2::new((c * x - b * y) / det, (a * y - b * x) / det);
        uv += step;
        if step.length() <= 1e-14 * (u1 - u0).abs().max((v1 - v0).abs()) {
            break;
        }
    }
    uv.is_finite().then_some(uv)
}

/// The boundary curves of `from` (flattened: `lines`) as open cuts on the coplanar face
/// `onto` (each curve's ends corners), numbered from `first`.
fn mapped_boundary(
    from: &TrimmedSurface,
    lines: &[Polyline],
    onto: &TrimmedSurface,
    first: usize,
) -> Result<Vec<Polyline>, GeometryError> {
    let mut out = Vec::new();
    for line in lines {
        let mut points = Vec::with_capacity(line.points.len());
        for uv in &line.points {
            let p = from.surface().point_at_clamped(*uv)?;
            if let Some(q) = plane_uv(onto.surface(), p) {
                points.push(q);
            }
        }
        if points.len() >= 2 {
            out.push(Polyline {
                source: Source::Cut(first + out.len()),
                points,
                params: Vec::new(),
                closed: false,
            });
        }
    }
    Ok(out)
}

/// How far a chord of a flattened boundary may stray from its curve, in (u, v), and the
/// snap distance, for a face joined at `tolerance`.
fn face_scales(face: &TrimmedSurface, tolerance: f64) -> (f64, f64) {
    let rect = domain_rect(face.surface());
    let size = domain_size(rect);
    let speed = (face.surface().size() / size).max(1e-300);
    let snap = (tolerance / speed).max(1e-10 * size).min(1e-4 * size);
    let flat = (snap * 0.25).max(1e-9 * size);
    (flat, snap)
}

/// The face's boundary curves (its trim loops, or the domain's rectangle) flattened, with
/// each point's curve parameter: each curve's chords within the face's flatness of it
/// (midpoint bisection).
fn boundary_polylines(
    face: &TrimmedSurface,
    tolerance: f64,
) -> Result<Vec<Polyline>, GeometryError> {
    let (flat, _) = face_scales(face, tolerance);
    let mut out = Vec::new();
    for curve in face_loops(face)?.iter().flatten() {
        let (points, params) = flatten_curve(curve, flat)?;
        out.push(Polyline {
            source: Source::Boundary(out.len()),
            points,
            params,
            closed: false,
        });
    }
    Ok(out)
}

/// The curve's points where each chord lies within `flat` of the curve (checked at its
/// middle, bisected up to 2^14 pieces per span), with their parameters.
fn flatten_curve(curve: &TrimCurve, flat: f64) -> Result<(Vec<DVec2>, Vec<f64>), GeometryError> {
    let mut breaks = curve.span_breaks();
    breaks.dedup();
    if curve.degree() == 1 {
        let points = breaks
            .iter()
            .map(|&t| curve.point_at(t))
            .collect::<Result<Vec<_>, _>>()?;
        return Ok((points, breaks));
    }
    let mut points = vec![curve.point_at(breaks[0])?];
    let mut params = vec![breaks[0]];
    for w in breaks.windows(2) {
        // Four pieces per span first, then bisect where a chord strays.
        let mut stack: Vec<(f64, f64, u32)> = (0..4)
            .rev()
            .map(|k| {
                let (a, b) = (
                    w[0] + (w[1] - w[0]) * k as f64 / 4.0,
                    w[0] + (w[1] - w[0]) * (k + 1) as f64 / 4.0,
                );
                (a, b, 0)
            })
            .collect();
        while let Some((a, b, depth)) = stack.pop() {
            let (pa, pb) = (curve.point_at(a)?, curve.point_at(b)?);
            let pm = curve.point_at(0.5 * (a + b))?;
            if depth < 14 && pm.distance(0.5 * (pa + pb)) > flat {
                let m = 0.5 * (a + b);
                stack.push((m, b, depth + 1));
                stack.push((a, m, depth + 1));
                continue;
            }
            points.push(pb);
            params.push(b);
        }
    }
    Ok((points, params))
}

/// What part of a face's boundary a branch runs along.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Boundary {
    /// An edge of the face.
    Edge,
    /// The seam of a closed surface, along the boundary on both of its sides (no edge of the
    /// body: the surface runs smoothly across it).
    Seam,
}

/// Whether a branch (its (u, v) points on `face`, whose boundary flattened is `lines`) runs
/// along the face's boundary ([`along_boundary`]), and if so whether along an edge or a seam
/// (its points moved across to the seam's other side are along the boundary too).
fn boundary_kind(
    face: &TrimmedSurface,
    lines: &[Polyline],
    uv: &[DVec2],
    tolerance: f64,
) -> Option<Boundary> {
    if !along_boundary(face, lines, uv, tolerance) {
        return None;
    }
    let (seam_u, seam_v) = seams(face.surface());
    let [u0, u1, v0, v1] = domain_rect(face.surface());
    let (flat, snap) = face_scales(face, tolerance);
    let reach = (snap * 4.0).max(flat * 4.0);
    // All the branch's points on one side of a seam, moved to its other side.
    let across =
        |coordinate: fn(DVec2) -> f64, lo: f64, hi: f64, moved: fn(DVec2, f64) -> DVec2| {
            [(lo, hi), (hi, lo)].into_iter().find_map(|(from, to)| {
                uv.iter()
                    .all(|&p| (coordinate(p) - from).abs() <= reach)
                    .then(|| uv.iter().map(|&p| moved(p, to)).collect::<Vec<_>>())
            })
        };
    let mut sides: Vec<Vec<DVec2>> = Vec::new();
    if seam_u {
        sides.extend(across(|p| p.x, u0, u1, |p, u| DVec2::new(u, p.y)));
    }
    if seam_v {
        sides.extend(across(|p| p.y, v0, v1, |p, v| DVec2::new(p.x, v)));
    }
    let on_seam = sides
        .iter()
        .any(|other| along_boundary(face, lines, other, tolerance));
    Some(if on_seam {
        Boundary::Seam
    } else {
        Boundary::Edge
    })
}

/// Whether a branch runs along the face's boundary (flattened: `lines`; its points at a
/// quarter, half and three quarters of the way all within the snap distance of it).
fn along_boundary(face: &TrimmedSurface, lines: &[Polyline], uv: &[DVec2], tolerance: f64) -> bool {
    if uv.len() < 2 {
        return true;
    }
    let (flat, snap) = face_scales(face, tolerance);
    let reach = (snap * 4.0).max(flat * 4.0);
    [1, 2, 3].iter().all(|&q| {
        let p = uv[(uv.len() - 1) * q / 4];
        lines.iter().any(|l| {
            l.points.windows(2).any(|w| {
                let ab = w[1] - w[0];
                let t = ((p - w[0]).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
                p.distance(w[0] + ab * t) <= reach
            })
        })
    })
}

/// A point well inside an uncut face (its boundary flattened: `lines`): the domain's centre
/// for an untrimmed face; for a trimmed one the middle of the widest span a few lines across
/// its loops keep (the kept region is inside an odd number of loops); else the inside point of
/// the planar arrangement's region that the face keeps.
fn whole_face_points(
    face: &TrimmedSurface,
    lines: &[Polyline],
    tolerance: f64,
) -> Result<Vec<DVec2>, GeometryError> {
    let [u0, u1, v0, v1] = domain_rect(face.surface());
    if !face.is_trimmed() {
        // The centre, then points off its lines, in case the face touches the other body
        // along a line through the centre.
        return Ok([(0.5, 0.5), (0.3, 0.7), (0.7, 0.3), (0.2, 0.4), (0.8, 0.6)]
            .map(|(s, t)| DVec2::new(u0 + (u1 - u0) * s, v0 + (v1 - v0) * t))
            .to_vec());
    }
    let mut polygons = face.flattened_loops(face_scales(face, tolerance).0);
    // The outer loop first: each loop's area worked out once, not at every comparison.
    polygons.sort_by_cached_key(|p| std::cmp::Reverse(crate::trim::signed_area(p).abs().to_bits()));
    if let Some((outer, holes)) = polygons.split_first()
        && outer.len() >= 3
    {
        let holes: Vec<&Vec<DVec2>> = holes.iter().collect();
        let points = arrangement::points_inside(outer, &holes);
        if points[0] != outer[0] && points[0].is_finite() {
            return Ok(points);
        }
    }
    let regions = arrangement::regions(lines, face_scales(face, tolerance).1);
    regions
        .iter()
        .find(|r| face.contains(r.inside[0].x, r.inside[0].y))
        .map(|r| r.inside.clone())
        .ok_or_else(|| construction(WHAT, "a face keeps no part of its domain"))
}

/// A part of a split face: its trim loops and points well inside it, the surest first.
struct SplitPart {
    loops: Vec<TrimLoop>,
    inside: Vec<DVec2>,
    /// The middle in space of each of its edges that runs along a cut.
    cut_middles: Vec<DVec3>,
}

/// The parts of `face` (its boundary flattened: `boundary`) that `cuts` divide it into, each
/// as its trim loops on the face's surface (not yet validated) with a point well inside it.
fn split_face(
    face: &TrimmedSurface,
    boundary: &[Polyline],
    cuts: &[Polyline],
    tolerance: f64,
) -> Result<Vec<SplitPart>, GeometryError> {
    let (_, snap) = face_scales(face, tolerance);
    let loops = face_loops(face)?;
    let curves: Vec<&TrimCurve> = loops.iter().flatten().collect();
    let mut lines = boundary.to_vec();
    lines.extend(cuts.iter().cloned());
    let slack = 1e-9 * domain_size(domain_rect(face.surface()));
    let mut parts = Vec::new();
    for region in arrangement::regions(&lines, snap) {
        let Region {
            loops: runs,
            inside,
        } = region;
        let first = inside[0];
        if !(inside_domain(face, first, slack) && face.contains(first.x, first.y)) {
            continue;
        }
        let mut trim_loops: Vec<TrimLoop> = Vec::with_capacity(runs.len());
        let mut cut_middles = Vec::new();
        for l in runs {
            let mut curves_out = Vec::with_capacity(l.len());
            for run in &l {
                let curve = run_curve(run, &curves, face.surface(), tolerance)?;
                if let Source::Cut(_) = run.source {
                    let (t0, t1) = curve.domain();
                    let middle = curve.point_at(0.5 * (t0 + t1))?;
                    cut_middles.push(face.surface().point_at_clamped(middle)?);
                }
                curves_out.push(curve);
            }
            trim_loops.push(curves_out);
        }
        parts.push(SplitPart {
            loops: trim_loops,
            inside,
            cut_middles,
        });
    }
    Ok(parts)
}

/// The curve along one run on `surface`: a piece of the boundary curve it follows (its ends
/// set onto the run's ends), or a cubic through a cut's points within `tolerance` of every one
/// of them in space ([`sparse_cubic`]).
fn run_curve(
    run: &arrangement::Run,
    curves: &[&TrimCurve],
    surface: &NurbsSurface,
    tolerance: f64,
) -> Result<TrimCurve, GeometryError> {
    let rect = domain_rect(surface);
    // A twentieth of the tolerance, in (u, v).
    let hair = 0.05 * tolerance * domain_size(rect) / surface.size().max(1e-300);
    let (first, last) = (run.points[0], run.points[run.points.len() - 1]);
    if let Source::Boundary(c) = run.source
        && let Some(curve) = curves.get(c)
    {
        {
            let (t0, t1) = (run.params[0], run.params[run.params.len() - 1]);
            let (t0, t1) = (closest_on(curve, first, t0), closest_on(curve, last, t1));
            let forwards = t0 <= t1;
            let (lo, hi) = if forwards { (t0, t1) } else { (t1, t0) };
            let mut piece = (*curve).clone();
            let (d0, d1) = piece.domain();
            let eps = 1e-12 * (d1 - d0).abs().max(1e-300);
            if hi < d1 - eps && hi > d0 + eps {
                piece = piece.split(hi)?.0;
            }
            let (d0, d1) = piece.domain();
            if lo > d0 + eps && lo < d1 - eps {
                piece = piece.split(lo)?.1;
            }
            if !forwards {
                piece = piece.reverse();
            }
            let n = piece.count();
            piece = piece.with_point(0, first)?.with_point(n - 1, last)?;
            return inside_rect(piece, rect, hair, false);
        }
    }
    let mut points: Vec<DVec2> = Vec::with_capacity(run.points.len());
    for &p in &run.points {
        if points.last().is_none_or(|q: &DVec2| q.distance(p) > 0.0) {
            points.push(p);
        }
    }
    if run.closed && points.len() >= 2 && points[0] != points[points.len() - 1] {
        points.push(points[0]);
    }
    if points.len() <= 2 {
        return inside_rect(
            TrimCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![first, last], None)?,
            rect,
            hair,
            true,
        );
    }
    // The same curve whichever way the run goes (the regions on either side of a cut each
    // take it, one reversed): worked out in one order.
    let forwards = if run.closed {
        lexicographic(points[1], points[points.len() - 2]).is_le()
    } else {
        lexicographic(points[0], points[points.len() - 1]).is_le()
    };
    if !forwards {
        points.reverse();
    }
    let curve = sparse_cubic(&points, surface, SPARSE_FIT * tolerance)?;
    inside_rect(
        if forwards { curve } else { curve.reverse() },
        rect,
        hair,
        true,
    )
}

/// How close to the marched points a cut's curve keeps, as a fraction of the tolerance: the
/// cubic's error falls as the fourth power of its spans' length, so a tenth of the tolerance
/// costs under twice the spans and keeps volumes to about 1e-7 of a plate's.
const SPARSE_FIT: f64 = 0.05;

/// `a` against `b` by u, then by v.
fn lexicographic(a: DVec2, b: DVec2) -> std::cmp::Ordering {
    a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y))
}

/// A cubic in (u, v) through some of `points` (a cut's dense marched points on `surface`),
/// each at its chord-length parameter among all of them (The NURBS Book eq. 9.5, A9.1), such
/// that every point left out lies within `tolerance` in space of the curve's point at its
/// parameter: first every few points, then the middle point of each span that strays added
/// until none does. A circle marched at a fine tolerance keeps a few dozen of its hundreds of
/// points, so the trims that carry it (validated, integrated, written) are that much shorter.
fn sparse_cubic(
    points: &[DVec2],
    surface: &NurbsSurface,
    tolerance: f64,
) -> Result<TrimCurve, GeometryError> {
    let n = points.len();
    let mut length = vec![0.0; n];
    for k in 1..n {
        length[k] = length[k - 1] + points[k].distance(points[k - 1]);
    }
    let total = length[n - 1];
    if n <= 8 || !(total > 0.0) {
        return interpolate_through(points, 3, Parametrization::ChordLength, None);
    }
    let t: Vec<f64> = length.iter().map(|l| l / total).collect();
    let space: Vec<DVec3> = points
        .iter()
        .map(|&p| surface.point_at_clamped(p))
        .collect::<Result<_, _>>()?;
    let stride = ((n - 1) / 4).clamp(1, 12);
    let mut keep: Vec<bool> = (0..n).map(|k| k % stride == 0 || k == n - 1).collect();
    for _ in 0..32 {
        let kept: Vec<usize> = (0..n).filter(|&k| keep[k]).collect();
        let chosen: Vec<DVec2> = kept.iter().map(|&k| points[k]).collect();
        let at: Vec<f64> = kept.iter().map(|&k| t[k]).collect();
        let curve = interpolate_at_parameters(&chosen, &at, 3.min(kept.len() - 1))?;
        let mut refined = false;
        for w in kept.windows(2) {
            let (j, k) = (w[0], w[1]);
            let strays = (j + 1..k).any(|i| {
                !curve
                    .point_at(t[i])
                    .and_then(|uv| surface.point_at_clamped(uv))
                    .is_ok_and(|q| q.distance(space[i]) <= tolerance)
            });
            if strays {
                keep[(j + k) / 2] = true;
                refined = true;
            }
        }
        if !refined {
            return Ok(curve);
        }
    }
    interpolate_through(points, 3, Parametrization::ChordLength, None)
}

/// The curve with its control points kept in the domain `rect`: a cubic through points along
/// the domain's edge, or a node a rounding outside it, may stray a hair past the edge (the
/// curve stays in its points' hull). Control points further out than `hair` (a cubic through
/// points that touch the edge, bulging past it between them) are first brought in to the
/// curve by knot insertion, the spans they bear halved (The NURBS Book, A5.4: the control
/// polygon converges to the curve), so that clamping them moves the curve no more than `hair`.
/// A `cut`'s (not a boundary curve's) inner control points are clamped a rounding inside.
fn inside_rect(
    curve: TrimCurve,
    rect: [f64; 4],
    hair: f64,
    cut: bool,
) -> Result<TrimCurve, GeometryError> {
    let [u0, u1, v0, v1] = rect;
    let stray = |p: DVec2| (u0 - p.x).max(p.x - u1).max(v0 - p.y).max(p.y - v1);
    let mut curve = curve;
    for _ in 0..8 {
        let p = curve.degree();
        let knots = curve.knots().to_vec();
        let mut midpoints: Vec<f64> = Vec::new();
        for i in (0..curve.count()).filter(|&i| stray(curve.control_point(i)) > hair) {
            for j in i..=(i + p).min(knots.len() - 2) {
                let (a, b) = (knots[j], knots[j + 1]);
                if b > a {
                    midpoints.push(0.5 * (a + b));
                }
            }
        }
        if midpoints.is_empty() {
            break;
        }
        midpoints.sort_by(f64::total_cmp);
        midpoints.dedup();
        curve = curve.refine(&midpoints)?;
    }
    if !cut {
        return curve.map_points(|p| DVec2::new(p.x.clamp(u0, u1), p.y.clamp(v0, v1)));
    }
    // A cut's inner control points that were outside are set a rounding inside, so that a
    // cut touching the edge between its ends (a circle tangent to it) stays off it.
    let inset = 1e-9 * domain_size(rect);
    let n = curve.count();
    let mut out = curve.clone();
    for i in 0..n {
        let p = curve.control_point(i);
        let q = DVec2::new(p.x.clamp(u0, u1), p.y.clamp(v0, v1));
        let q = if i > 0 && i + 1 < n && q != p {
            DVec2::new(
                q.x.clamp(u0 + inset, u1 - inset),
                q.y.clamp(v0 + inset, v1 - inset),
            )
        } else {
            q
        };
        if q != p {
            out = out.with_point(i, q)?;
        }
    }
    Ok(out)
}

/// The parameter of the curve's point nearest `p`, by Newton's steps from `t`.
fn closest_on(curve: &TrimCurve, p: DVec2, mut t: f64) -> f64 {
    let (a, b) = curve.domain();
    for _ in 0..12 {
        let Ok(d) = curve.derivatives(t, 2) else {
            break;
        };
        let r = d[0] - p;
        let f = r.dot(d[1]);
        let df = d[1].dot(d[1]) + r.dot(d[2]);
        if df.abs() < 1e-300 {
            break;
        }
        let next = (t - f / df).clamp(a, b);
        if (next - t).abs() <= 1e-15 * (b - a).abs() {
            t = next;
            break;
        }
        t = next;
    }
    t
}

/// The 3D corners of every loop of every face.
fn corners(pieces: &[TrimmedSurface]) -> Result<Vec<DVec3>, GeometryError> {
    let mut out = Vec::new();
    for face in pieces {
        for curve in face_loops(face)?.iter().flatten() {
            let uv = curve.control_point(0);
            out.push(face.surface().point_at_clamped(uv)?);
        }
    }
    Ok(out)
}

/// The parameter of the (u, v) curve whose point on `surface` is nearest `p`, and the
/// distance: the three nearest local minima of 64 samples (a closed edge has two at its
/// meeting ends), each refined by a ternary search between its neighbours.
fn nearest_on_edge(
    surface: &NurbsSurface,
    curve: &TrimCurve,
    p: DVec3,
) -> Result<(f64, f64), GeometryError> {
    let (a, b) = curve.domain();
    let distance = |t: f64| -> Result<f64, GeometryError> {
        let uv = curve.point_at(t.clamp(a, b))?;
        Ok(surface.point_at_clamped(uv)?.distance(p))
    };
    let n = 64;
    let step = (b - a) / n as f64;
    let samples: Vec<f64> = (0..=n)
        .map(|k| distance(a + step * k as f64))
        .collect::<Result<_, _>>()?;
    let mut minima: Vec<usize> = (0..=n)
        .filter(|&k| {
            (k == 0 || samples[k] <= samples[k - 1]) && (k == n || samples[k] <= samples[k + 1])
        })
        .collect();
    minima.sort_by(|&x, &y| samples[x].total_cmp(&samples[y]));
    let mut best = (a, f64::INFINITY);
    for &k in minima.iter().take(3) {
        let (mut lo, mut hi) = (
            a + step * k.saturating_sub(1) as f64,
            (a + step * (k + 1) as f64).min(b),
        );
        for _ in 0..60 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if distance(m1)? < distance(m2)? {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        let t = 0.5 * (lo + hi);
        let d = distance(t)?;
        if d < best.1 {
            best = (t, d);
        }
    }
    Ok(best)
}

/// Open edges split where another face's corner lies on them (a T-junction: a face that
/// meets two faces along one straight edge, as a block standing over another's edge):
/// whether any was split.
fn imprint_vertices(
    pieces: &mut [TrimmedSurface],
    naked: &[crate::join::EdgeId],
    tolerance: f64,
) -> Result<bool, GeometryError> {
    let points = corners(pieces)?;
    let mut changed = false;
    let mut by_face: std::collections::BTreeMap<usize, Vec<&crate::join::EdgeId>> =
        Default::default();
    for e in naked {
        by_face.entry(e.face).or_default().push(e);
    }
    for (face_index, mut edges) in by_face {
        // From the last curve back, so replacing one by its parts moves none still to come.
        edges.sort_by_key(|e| std::cmp::Reverse((e.loop_index, e.curve)));
        let face = &pieces[face_index];
        let mut loops = face_loops(face)?;
        let mut face_changed = false;
        for e in edges {
            let Some(curve) = loops
                .get(e.loop_index)
                .and_then(|l| l.get(e.curve))
                .cloned()
            else {
                continue;
            };
            let (a, b) = curve.domain();
            let ends = [curve.point_at(a)?, curve.point_at(b)?]
                .map(|uv| face.surface().point_at_clamped(uv));
            let ends = [ends[0].clone()?, ends[1].clone()?];
            // The edge's box from samples along it (its ends alone say nothing of a closed
            // edge, a whole circle), grown by a tenth for what lies between the samples.
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for k in 0..=16 {
                let uv = curve.point_at(a + (b - a) * f64::from(k) / 16.0)?;
                let p = face.surface().point_at_clamped(uv)?;
                (lo, hi) = (lo.min(p), hi.max(p));
            }
            let reach = DVec3::splat(tolerance) + (hi - lo) * 0.6;
            let mut cuts: Vec<f64> = Vec::new();
            for &p in &points {
                if ends.iter().any(|e| e.distance(p) <= tolerance * 10.0)
                    || (p - 0.5 * (lo + hi)).abs().cmpgt(reach).any()
                {
                    continue;
                }
                let (t, d) = nearest_on_edge(face.surface(), &curve, p)?;
                let eps = 1e-9 * (b - a);
                if d <= tolerance && t > a + eps && t < b - eps {
                    cuts.push(t);
                }
            }
            if cuts.is_empty() {
                continue;
            }
            cuts.sort_by(f64::total_cmp);
            cuts.dedup_by(|x, y| (*x - *y).abs() <= 1e-9 * (b - a));
            let mut parts = Vec::new();
            let mut rest = curve;
            for &t in cuts.iter().rev() {
                let (left, right) = rest.split(t)?;
                parts.push(right);
                rest = left;
            }
            parts.push(rest);
            parts.reverse();
            let l = &mut loops[e.loop_index];
            l.splice(e.curve..=e.curve, parts);
            face_changed = true;
        }
        if face_changed {
            pieces[face_index] = TrimmedSurface::new(face.surface().clone(), loops)?;
            changed = true;
        }
    }
    Ok(changed)
}

/// The kept parts joined into closed shells and sorted into solids with their voids; refused
/// where they do not close.
fn assemble(
    pieces: Vec<TrimmedSurface>,
    tolerance: f64,
) -> Result<Vec<ResultSolid>, GeometryError> {
    if pieces.is_empty() {
        return Ok(Vec::new());
    }
    let mut pieces = pieces;
    // The parts meet along edges made from the same marched points on both faces; they are
    // paired within ten times the tolerance (the cubics through those points on the two faces
    // differ most near where the surfaces touch, where the points are least certain).
    let join = tolerance * JOIN_FACTOR;
    let mut topology = find_topology(&pieces, join)?;
    let mut v = validity(pieces.len(), &topology);
    if !v.is_closed_shell() && imprint_vertices(&mut pieces, &v.naked, join)? {
        topology = find_topology(&pieces, join)?;
        v = validity(pieces.len(), &topology);
    }
    if !v.is_closed_shell() {
        let place = v
            .naked
            .first()
            .or(v.non_manifold.first())
            .and_then(|e| {
                let face = pieces.get(e.face)?;
                let loops = face_loops(face).ok()?;
                let curve = loops.get(e.loop_index)?.get(e.curve)?;
                let (a, b) = curve.domain();
                let uv = curve.point_at(0.5 * (a + b)).ok()?;
                face.surface().point_at_clamped(uv).ok()
            })
            .map(|p| format!(" (near ({:.6}, {:.6}, {:.6}))", p.x, p.y, p.z))
            .unwrap_or_default();
        return Err(construction(
            WHAT,
            format!(
                "the result does not close: {} open edge(s), {} edge(s) shared by more than two \
                 faces, {} misoriented{place}; the inputs may touch in a way this boolean cannot \
                 resolve",
                v.naked.len(),
                v.non_manifold.len(),
                v.misoriented.len()
            ),
        ));
    }
    let components = topology.components(pieces.len());
    let solid = |shells: &[&Vec<usize>]| ResultSolid {
        shells: shells
            .iter()
            .map(|c| c.iter().map(|&k| pieces[k].clone()).collect())
            .collect(),
        topology: topology.restricted(
            &shells
                .iter()
                .copied()
                .flatten()
                .copied()
                .collect::<Vec<_>>(),
        ),
    };
    if components.len() == 1 {
        // One closed shell of outward faces: the solid (its volume is worked out on demand).
        return Ok(vec![solid(&[&components[0]])]);
    }
    let mut sorted: Vec<(&Vec<usize>, f64, (DVec3, DVec3))> = Vec::new();
    for c in &components {
        let faces: Vec<TrimmedSurface> = c.iter().map(|&k| pieces[k].clone()).collect();
        let volume = signed_volume(&faces)?;
        let bounds = union_box(
            &faces
                .iter()
                .map(|f| f.surface().bounds())
                .collect::<Vec<_>>(),
        );
        sorted.push((c, volume, bounds));
    }
    // Each outer shell with the voids it holds (the smallest outer shell around each).
    let (outer, voids): (Vec<_>, Vec<_>) = sorted.into_iter().partition(|s| s.1 > 0.0);
    let mut held: Vec<Vec<&Vec<usize>>> = outer.iter().map(|o| vec![o.0]).collect();
    for (c, _, (lo, hi)) in voids {
        let holder = outer
            .iter()
            .enumerate()
            .filter(|(_, (_, _, (a, b)))| a.cmple(lo).all() && b.cmpge(hi).all())
            .min_by(|x, y| x.1.1.total_cmp(&y.1.1));
        match holder {
            Some((k, _)) => held[k].push(c),
            None => {
                return Err(construction(
                    WHAT,
                    "the result has a shell turned inside out that no solid holds",
                ));
            }
        }
    }
    Ok(held.iter().map(|shells| solid(shells)).collect())
}

#[cfg(test)]
mod tests;
