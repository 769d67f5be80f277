//! Edge and face features on solids: rolling-ball fillets and chamfers of a solid's edges,
//! and shells (hollowing to a wall thickness), built on closed shells of trimmed faces.
//!
//! The solids these build on are polyhedra: every face flat, every edge straight
//! ([`polyhedron`]). There every feature is exact in closed form, and it is built face by face
//! rather than cut out by a boolean (a fillet touches its faces tangentially, which a surface
//! intersection cannot find reliably):
//!
//! - **Fillets** ([`rounds`]). A ball of radius r rolling in the angle ψ between two faces
//!   (ψ the angle between the faces' inward directions, on the side where the ball lies:
//!   inside the material at a convex edge, outside at a concave one) touches each face at
//!   r / tan(ψ/2) from the edge, and its centre runs along a line. The fillet is the cylinder
//!   of the arc between the contact lines (a rational quadratic, The NURBS Book §7.3) swept
//!   along it. Each face is cut back to the contact lines; where a fillet ends at a corner of
//!   three edges, it ends on a plane: the third face where only it is filleted there, the
//!   bisecting (mitre) plane of the two fillets' axes where two are, and the plane across its
//!   axis through the corner ball's centre where all three are, the corner then closed by the
//!   ball's spherical triangle (exact: a revolved quarter circle). A plane cuts the cylinder in
//!   a conic, exact as a rational quadratic in space and a rational cubic in the fillet's
//!   (u, v).
//! - **Chamfers**: the same with flat strips between lines set back by the distances, and a
//!   flat triangle at a corner of three chamfered edges.
//! - **Shells** ([`shell`]): every face's plane moved by the thickness and each corner put
//!   where its three moved planes meet (the intersection join), then the solid less its inner
//!   offset (inward) or the outer offset less the solid (outward), by the boolean; a face left
//!   open is moved the other way instead, so the offset body passes through it.
//!
//! Every result is joined and checked closed before it is returned; a feature that cannot be
//! built (a radius too large for an edge, a corner these constructions do not close, a wall
//! thicker than the body) is refused with the edge, corner or face and the reason.

pub mod extruded;
pub mod faces;
pub mod polyhedron;
pub mod revolved;
pub mod rims;
pub mod rounds;
pub mod shell;
pub mod smooth;

use glam::DVec3;

use crate::error::{GeometryError, construction};
use crate::join::{Topology, find_topology, validity};
use crate::mass::signed_volume;
use crate::surface::Direction;
use crate::trim::TrimmedSurface;

pub use faces::{draft_faces, offset_faces};
pub use polyhedron::Polyhedron;
pub use rounds::{EdgeFeature, round_edges, round_edges_varying};
pub use shell::shell;

const WHAT: &str = "edge feature";

/// A point as the messages print it.
pub(crate) fn point(p: DVec3) -> String {
    format!("({:.6}, {:.6}, {:.6})", p.x, p.y, p.z)
}

/// The face `face` turned, where needed, so that its normal at its domain's middle points
/// along `outward` there.
pub(crate) fn facing(
    face: TrimmedSurface,
    outward: impl Fn(DVec3) -> DVec3,
) -> Result<TrimmedSurface, GeometryError> {
    let s = face.surface();
    let [(u0, u1), (v0, v1)] = s.domain();
    let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let d = s.evaluate(u, v)?;
    if s.normal_from(&d, u, v).dot(outward(d.point)) < 0.0 {
        face.reverse(Direction::U)
    } else {
        Ok(face)
    }
}

/// Which edges a feature takes.
#[derive(Debug, Clone, PartialEq)]
pub enum EdgePick {
    /// Every edge of the solid.
    All,
    /// For each point, the one edge nearest it.
    Near(Vec<DVec3>),
}

/// A feature's result: one closed shell of outward faces and their shared edges.
#[derive(Debug, Clone)]
pub struct FeatureResult {
    pub faces: Vec<TrimmedSurface>,
    pub topology: Topology,
    /// The edges (or, for a shell, faces) the feature took.
    pub picked: usize,
}

impl FeatureResult {
    /// The volume enclosed.
    pub fn volume(&self) -> Result<f64, GeometryError> {
        signed_volume(&self.faces)
    }
}

/// `faces` joined at `tolerance` and refused unless they close into a shell enclosing
/// positive volume: the last check of every feature.
pub(crate) fn closed_result(
    faces: Vec<TrimmedSurface>,
    tolerance: f64,
    picked: usize,
    what: &str,
) -> Result<FeatureResult, GeometryError> {
    let topology = find_topology(&faces, tolerance)?;
    let v = validity(faces.len(), &topology);
    if !v.is_closed_shell() {
        return Err(construction(
            WHAT,
            format!(
                "the {what} does not close: {} open edge(s), {} edge(s) of more than two \
                 faces, {} misoriented; this case is not built yet",
                v.naked.len(),
                v.non_manifold.len(),
                v.misoriented.len()
            ),
        ));
    }
    let volume = signed_volume(&faces)?;
    if !(volume > 0.0) {
        return Err(construction(
            WHAT,
            format!("the {what} encloses no volume ({volume:.3e})"),
        ));
    }
    Ok(FeatureResult {
        faces,
        topology,
        picked,
    })
}

#[cfg(test)]
mod tests;
