//! A boolean done a step at a time, so that an editor can draw its progress between steps and
//! stop it ([`BooleanJob`]); [`super::boolean_joined`] runs one to its end. The steps are the
//! module's stages: each operand turned outward, then one pair of faces intersected per step,
//! both operands' classifiers, one face split and classified per step, and the join of what
//! is kept.

use super::{
    BooleanOp, BooleanResult, Classifier, Cutter, Operand, assemble, classifier, keep_parts,
    outward_faces, outward_faces_joined, positive,
};
use crate::error::GeometryError;
use crate::join::Topology;
use crate::trim::TrimmedSurface;

/// An operand as given: its faces, and their shared edges where known.
pub type BooleanInput = (Vec<TrimmedSurface>, Option<Topology>);

/// Where a [`BooleanJob`] is.
enum Stage {
    /// Turning the first operand outward (then the second).
    Orient {
        a: BooleanInput,
        b: BooleanInput,
    },
    /// Turning the second operand outward.
    OrientSecond {
        a: Operand,
        b: BooleanInput,
    },
    /// Intersecting pairs of faces.
    Cut {
        a: Operand,
        b: Operand,
        cutter: Box<Cutter>,
    },
    /// Making the first operand's classifier (then the second's).
    Classify {
        a: Operand,
        b: Operand,
        cutter: Box<Cutter>,
        mesh_a: Option<Classifier>,
    },
    /// Splitting and classifying face `next.1` of side `next.0`.
    Trim(Box<Trimming>),
    /// Joining the kept parts.
    Assemble {
        pieces: Vec<TrimmedSurface>,
        split_faces: usize,
        branches: usize,
    },
    Done(BooleanResult),
    /// Taken by [`BooleanJob::finish`], or left after an error.
    Spent,
}

/// The operands, their cuts and classifiers while their faces are split and classified.
struct Trimming {
    a: Operand,
    b: Operand,
    cutter: Box<Cutter>,
    meshes: [Classifier; 2],
    next: (usize, usize),
    pieces: Vec<TrimmedSurface>,
    split_faces: usize,
}

/// A boolean of two solids done a step at a time ([`Self::step`]), with how far it is
/// ([`Self::progress`]) and what it is doing ([`Self::stage`]) between steps; dropping it
/// stops it. The result is [`super::boolean_joined`]'s exactly.
pub struct BooleanJob {
    op: BooleanOp,
    tolerance: f64,
    stage: Stage,
    /// The most cell pairs one pair of faces' intersection looks at
    /// ([`crate::intersect::MAX_CELL_PAIRS`] unless [`Self::with_cell_pairs`] says).
    cell_pairs: usize,
}

/// How much of the whole each stage takes, roughly (from a plate with 144 pins through it):
/// where each stage starts, from 0 to 1.
const ORIENT: f64 = 0.0;
const CUT: f64 = 0.15;
const CLASSIFY: f64 = 0.55;
const TRIM: f64 = 0.6;
const ASSEMBLE: f64 = 0.95;

impl BooleanJob {
    /// The boolean `op` of `a` and `b` at `tolerance` (model units), not started; refused at
    /// once for a tolerance that is not a number above 0.
    pub fn new(
        op: BooleanOp,
        a: BooleanInput,
        b: BooleanInput,
        tolerance: f64,
    ) -> Result<Self, GeometryError> {
        positive(tolerance)?;
        Ok(Self {
            op,
            tolerance,
            stage: Stage::Orient { a, b },
            cell_pairs: crate::intersect::MAX_CELL_PAIRS,
        })
    }

    /// The job with each pair of faces' intersection looking at up to `pairs` cell pairs
    /// before it takes the faces for coinciding: more for operands that cannot coincide
    /// over an area but may lie close along one (a solid and its thin offset, in a shell).
    pub fn with_cell_pairs(mut self, pairs: usize) -> Self {
        self.cell_pairs = pairs;
        self
    }

    /// Does the next step; true when the result is ready for [`Self::finish`]. An error ends
    /// the job (a refusal saying why, as [`super::boolean`] gives it).
    pub fn step(&mut self) -> Result<bool, GeometryError> {
        let stage = std::mem::replace(&mut self.stage, Stage::Spent);
        self.stage = self.next(stage)?;
        Ok(matches!(self.stage, Stage::Done(_)))
    }

    /// The stage after one step of `stage`.
    fn next(&self, stage: Stage) -> Result<Stage, GeometryError> {
        let tolerance = self.tolerance;
        let oriented = |(faces, topology): BooleanInput, label: &str| {
            let outward = match topology {
                Some(t) => outward_faces_joined(&faces, &t, label)?,
                None => outward_faces(&faces, tolerance, label)?,
            };
            Operand::new(outward, tolerance)
        };
        Ok(match stage {
            Stage::Orient { a, b } => Stage::OrientSecond {
                a: oriented(a, "the first body")?,
                b,
            },
            Stage::OrientSecond { a, b } => {
                let b = oriented(b, "the second body")?;
                // Equal bodies (a body and its copy): the union and the intersection are the
                // body, the difference is empty; their faces, lying on one another, are not
                // intersected.
                if a.faces.len() == b.faces.len() && a.faces.iter().all(|f| b.faces.contains(f)) {
                    let solids = match self.op {
                        BooleanOp::Difference => Vec::new(),
                        BooleanOp::Union | BooleanOp::Intersection => {
                            assemble(a.faces.clone(), tolerance)?
                        }
                    };
                    return Ok(Stage::Done(BooleanResult {
                        solids,
                        split_faces: 0,
                        branches: 0,
                    }));
                }
                let cutter = Box::new(Cutter::new(&a, &b, tolerance, self.cell_pairs));
                Stage::Cut { a, b, cutter }
            }
            Stage::Cut { a, b, mut cutter } => {
                if cutter.next_pair(&a, &b, tolerance)? {
                    Stage::Classify {
                        a,
                        b,
                        cutter,
                        mesh_a: None,
                    }
                } else {
                    Stage::Cut { a, b, cutter }
                }
            }
            Stage::Classify {
                a,
                b,
                cutter,
                mesh_a: None,
            } => {
                let mesh_a = Some(classifier(&a, cutter.cuts.size)?);
                Stage::Classify {
                    a,
                    b,
                    cutter,
                    mesh_a,
                }
            }
            Stage::Classify {
                a,
                b,
                cutter,
                mesh_a: Some(mesh_a),
            } => {
                let mesh_b = classifier(&b, cutter.cuts.size)?;
                Stage::Trim(Box::new(Trimming {
                    a,
                    b,
                    cutter,
                    meshes: [mesh_a, mesh_b],
                    next: (0, 0),
                    pieces: Vec::new(),
                    split_faces: 0,
                }))
            }
            Stage::Trim(mut t) => {
                let (side, k) = t.next;
                let (own, other) = if side == 0 {
                    (&t.a, &t.b)
                } else {
                    (&t.b, &t.a)
                };
                if k < own.faces.len() {
                    let cuts = if side == 0 {
                        &t.cutter.cuts.a[k]
                    } else {
                        &t.cutter.cuts.b[k]
                    };
                    let split = keep_parts(
                        self.op,
                        (side, k),
                        own,
                        cuts,
                        (other, &t.meshes[1 - side]),
                        &t.cutter.cuts.coplanar,
                        tolerance,
                        &mut t.pieces,
                    )?;
                    t.split_faces += usize::from(split);
                    t.next = (side, k + 1);
                    Stage::Trim(t)
                } else if side == 0 {
                    t.next = (1, 0);
                    Stage::Trim(t)
                } else {
                    Stage::Assemble {
                        pieces: t.pieces,
                        split_faces: t.split_faces,
                        branches: t.cutter.cuts.branches,
                    }
                }
            }
            Stage::Assemble {
                pieces,
                split_faces,
                branches,
            } => Stage::Done(BooleanResult {
                solids: assemble(pieces, tolerance)?,
                split_faces,
                branches,
            }),
            done @ Stage::Done(_) => done,
            Stage::Spent => Stage::Spent,
        })
    }

    /// How far the job is, from 0 to 1 (each stage's share estimated).
    pub fn progress(&self) -> f64 {
        let within = |start: f64, end: f64, fraction: f64| start + (end - start) * fraction;
        match &self.stage {
            Stage::Orient { .. } => ORIENT,
            Stage::OrientSecond { .. } => within(ORIENT, CUT, 0.5),
            Stage::Cut { b, cutter, .. } => within(CUT, CLASSIFY, cutter.progress(b)),
            Stage::Classify { mesh_a, .. } => {
                within(CLASSIFY, TRIM, if mesh_a.is_some() { 0.5 } else { 0.0 })
            }
            Stage::Trim(t) => {
                let all = (t.a.faces.len() + t.b.faces.len()).max(1);
                let done = if t.next.0 == 0 {
                    t.next.1
                } else {
                    t.a.faces.len() + t.next.1
                };
                within(TRIM, ASSEMBLE, done as f64 / all as f64)
            }
            Stage::Assemble { .. } => ASSEMBLE,
            Stage::Done(_) | Stage::Spent => 1.0,
        }
    }

    /// What it is doing, for a progress window.
    pub fn stage(&self) -> &'static str {
        match &self.stage {
            Stage::Orient { .. } | Stage::OrientSecond { .. } => "turning the bodies outward",
            Stage::Cut { .. } => "intersecting faces",
            Stage::Classify { .. } => "preparing the inside tests",
            Stage::Trim(_) => "trimming and sorting faces",
            Stage::Assemble { .. } => "joining the result",
            Stage::Done(_) | Stage::Spent => "done",
        }
    }

    /// Every step at once: the result, or the first refusal.
    pub fn run(mut self) -> Result<BooleanResult, GeometryError> {
        while !self.step()? {}
        self.finish()
    }

    /// The result, once [`Self::step`] has said it is ready; else a refusal.
    pub fn finish(self) -> Result<BooleanResult, GeometryError> {
        match self.stage {
            Stage::Done(result) => Ok(result),
            _ => Err(crate::error::construction(
                super::WHAT,
                "the boolean was not finished",
            )),
        }
    }
}
