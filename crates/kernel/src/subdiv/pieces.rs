//! What a subdivision surface's display is made of, below the modules that build it: the
//! display modes ([`Display`]), the pieces the exact limit shows ([`ExactPiece`],
//! [`ShownPiece`]), the substitutes' kinds and plans, and the GPU feed's records
//! ([`LimitFeed`]). [`super::display`], [`super::patches`], [`super::substitutes`] and
//! [`super::adaptive`] build on these, so that none of them needs another for its types.

use super::Scheme;
use super::level::{Level, Ring};
use super::stencil::{Row, Stencils};
use crate::GeometryError;

/// The flatness tolerance a new adaptive display starts with, as a fraction of the diagonal of
/// the cage's bounding box.
pub const DEFAULT_TOLERANCE: f64 = 0.002;

/// A piece of the surface as a stencil patch shows it: at `depth` (≤ the piece's own full
/// depth), each edge at `edge_depths[k]` (≤ `depth`; edge k runs from corner k to corner k + 1
/// of the piece's face; a triangle uses three).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShownPiece {
    pub piece: ExactPiece,
    pub depth: u32,
    pub edge_depths: [u32; 4],
}

/// What the surface shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Display {
    /// The limit surface at the level's vertices.
    #[default]
    Limit,
    /// The refined mesh itself ("cage level N").
    Refined,
    /// ACC: a bicubic patch per quad with tangent patches for the normals (Catmull-Clark).
    Acc,
    /// Gregory patches (ACC-2): a G¹ rational bicubic patch per quad (Catmull-Clark).
    Gregory,
    /// PN triangles: a cubic triangle per triangle with quadratic normals (Loop).
    PnTriangles,
    /// The limit surface with each piece refined only as deep as a flatness test asks, up to
    /// the level, crack-free ([`super::adaptive`]).
    Adaptive,
}

impl Display {
    /// The substitute this display shows, if it is one.
    pub fn substitute(self) -> Option<SubstituteKind> {
        match self {
            Self::Acc => Some(SubstituteKind::Acc),
            Self::Gregory => Some(SubstituteKind::Gregory),
            Self::PnTriangles => Some(SubstituteKind::PnTriangle),
            Self::Limit | Self::Refined | Self::Adaptive => None,
        }
    }
}

/// A substitute patch ([`super::substitutes`]): its kind, `segments` per edge, its control
/// points from `first_point` of the object's point pool (the cage's points, then the
/// substitutes' in the plan's order) and its grid's slots from `first_slot` (for
/// [`LimitFeed::vertex`]; they carry no entries).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubstitutePatch {
    pub cage_face: u32,
    pub kind: SubstituteKind,
    pub segments: u32,
    pub first_point: u32,
    pub first_slot: u32,
}

/// A grid of stencil vertices: `(segments + 1)²` slots from `first_slot`, slot (i, j) at
/// `first_slot + i (segments + 1) + j`, i along the patch's first edge. A triangle patch uses
/// the slots with i + j ≤ segments. `level`: the subdivision level its vertices come from (the
/// level it shows, for the refinement-level colours; [`NONE`](super::level::NONE) for a patch of no single level).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StencilPatch {
    pub cage_face: u32,
    pub triangle: bool,
    pub segments: u32,
    pub first_slot: u32,
    pub level: u32,
    /// The face it shows, as (level, face) of the hierarchy (a cage face, or a child of one);
    /// [`NONE`](super::level::NONE)s for a patch of no single face. Slot (0, 0) is that face's first corner and
    /// the first index runs to its second.
    pub piece: [u32; 2],
    /// Where its entries' points are: [`NONE`](super::level::NONE) where they are cage
    /// points, else the first of its list in [`LimitFeed::point_lists`], entry point `k`
    /// being cage point `point_lists[points + k]`. Patches of faces with the same
    /// neighbourhood share their entries this way ([`super::templates`]).
    pub points: u32,
}

/// One stencil entry: a cage point and its weights for position, Su, Sv, Suu, Suv, Svv.
pub type Entry = (u32, [f64; 6]);

/// The GPU feed of a subdivision surface at one level.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LimitFeed {
    /// Regular cage quads and their 4 × 4 B-spline points (cage indices, row-major with the
    /// first index along u).
    pub regular: Vec<(u32, [u32; 16])>,
    pub patches: Vec<StencilPatch>,
    /// Per slot: first entry and entry count.
    pub slots: Vec<[u32; 2]>,
    /// Per slot: the curvature is not defined by the stencils (irregular or sharp vertices).
    pub no_curvature: Vec<bool>,
    /// Per slot: the vertex of the level it shows (`u32::MAX` for unused triangle slots, and
    /// for slots of patches refined over a region of the cage only: [`super::region`]).
    pub vertex: Vec<u32>,
    pub entries: Vec<Entry>,
    /// Cage points of the patches whose entries number points of their own
    /// ([`StencilPatch::points`]).
    pub point_lists: Vec<u32>,
    /// Substitute patches, after the stencil patches.
    pub substitutes: Vec<SubstitutePatch>,
}

impl LimitFeed {
    /// Appends slots `slots` (their entries counted from `first_entry` on) with their curvature
    /// flags; they name no vertex of a level.
    pub(super) fn push_slots(
        &mut self,
        slots: &[[u32; 2]],
        no_curvature: &[bool],
        first_entry: u32,
    ) {
        self.slots.extend(
            slots
                .iter()
                .map(|&[first, count]| [first + first_entry, count]),
        );
        self.no_curvature.extend_from_slice(no_curvature);
        self.vertex.extend(slots.iter().map(|_| u32::MAX));
    }

    /// The entries of slot `slot` of `patch` with their cage points (through the patch's
    /// point list where it has one; `u32::MAX` for a point past the list, which no feed the
    /// kernel builds has). `None` where the slot or its entries lie past the tables.
    pub fn slot_entries<'a>(
        &'a self,
        patch: &StencilPatch,
        slot: usize,
    ) -> Option<impl Iterator<Item = (u32, [f64; 6])> + 'a> {
        let [first, count] = *self.slots.get(slot)?;
        let entries = self
            .entries
            .get(first as usize..first as usize + count as usize)?;
        let list = match patch.points {
            super::level::NONE => None,
            at => Some(self.point_lists.get(at as usize..).unwrap_or_default()),
        };
        Some(entries.iter().map(move |&(point, weights)| {
            let point = match list {
                None => point,
                Some(list) => list.get(point as usize).copied().unwrap_or(u32::MAX),
            };
            (point, weights)
        }))
    }
}

/// Each face's first child one level down: Catmull-Clark splits a face into as many quads as
/// it has corners, Loop into four triangles, numbered face by face.
pub(super) fn first_children(level: &Level, scheme: Scheme) -> Vec<u32> {
    let mut next = 0u32;
    level
        .faces()
        .map(|face| {
            let first = next;
            next += if scheme == Scheme::CatmullClark {
                face.len() as u32
            } else {
                4
            };
            first
        })
        .collect()
}

/// Which substitute a patch is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SubstituteKind {
    /// 16 geometry points (row-major, first index along u), 12 u-tangent points (3 along u ×
    /// 4 along v), 12 v-tangent points (4 × 3).
    Acc,
    /// The 16 points of a bicubic grid whose four interior points are the ones the edges
    /// v = 0 and v = 1 determine, then the four the edges u = 0 and u = 1 determine, for the
    /// interior points (1, 1), (2, 1), (1, 2), (2, 2).
    Gregory,
    /// The cubic triangle's b300, b030, b003, b210, b120, b021, b012, b102, b201, b111, then the
    /// quadratic normal triangle's n200, n020, n002, n110, n011, n101 (b_ijk weights corner 0
    /// by i, corner 1 by j, corner 2 by k).
    PnTriangle,
}

impl SubstituteKind {
    /// Control points per patch.
    pub const fn point_count(self) -> usize {
        match self {
            Self::Acc => 40,
            Self::Gregory => 20,
            Self::PnTriangle => 16,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Self::Acc => "ACC patches",
            Self::Gregory => "Gregory patches",
            Self::PnTriangle => "PN triangles",
        }
    }

    /// The subdivision scheme the substitute approximates.
    pub fn scheme(self) -> Scheme {
        match self {
            Self::Acc | Self::Gregory => Scheme::CatmullClark,
            Self::PnTriangle => Scheme::Loop,
        }
    }

    pub fn is_triangle(self) -> bool {
        self == Self::PnTriangle
    }

    /// Refuses a cage under another scheme than the one the substitute approximates.
    pub fn check_scheme(self, scheme: Scheme) -> Result<(), GeometryError> {
        if scheme == self.scheme() {
            return Ok(());
        }
        Err(GeometryError::Construction {
            what: "subdivision display",
            message: format!(
                "{} approximate {} subdivision; this cage uses {}",
                self.label(),
                self.scheme().label(),
                scheme.label()
            ),
        })
    }
}

/// One face replaced by a substitute: the face of the base mesh (the cage, or level 1) and the
/// cage face it lies in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlannedPatch {
    pub base_face: u32,
    pub cage_face: u32,
}

/// A face left to the exact limit: its face on level `level` of the hierarchy, the cage face
/// it lies in, and the refinement depth below that level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExactPiece {
    pub level: usize,
    pub face: u32,
    pub cage_face: u32,
    pub depth: u32,
}

/// How a cage's substitute is built: which faces become substitute patches, which stay exact,
/// and the topology the control points are computed on (built once per topology change).
#[derive(Debug, Clone)]
pub struct SubstitutePlan {
    pub kind: SubstituteKind,
    /// Cage faces shown as their bicubic B-spline patch (regular quads of a quad cage).
    pub regular: Vec<u32>,
    /// Faces shown by the exact limit stencils.
    pub exact: Vec<ExactPiece>,
    /// The substitute patches, in feed order.
    pub patches: Vec<PlannedPatch>,
    /// The level the patches live on (0: the cage).
    pub base_level: usize,
    pub(super) base: Level,
    /// Level 1's points from the cage's, when the patches live on level 1.
    pub(super) to_base: Option<Stencils>,
    pub(super) rings: Vec<Ring>,
    /// Per patch, each corner's place in its ring (the ring's face index of the patch's face).
    pub(super) corner_slots: Vec<[usize; 4]>,
    /// Per base vertex the limit position (PN triangles) and two limit tangents (PN triangles,
    /// Gregory); empty rows where not needed.
    pub(super) positions: Vec<Row>,
    pub(super) tangents: Vec<[Row; 2]>,
}
