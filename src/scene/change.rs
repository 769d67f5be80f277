//! What an edit changed in a scene, in the terms the GPU sync layer re-uploads by: the
//! document ([`crate::doc`]) says it, the GPU ([`crate::gpu::SceneSync`]) acts on it, and
//! neither needs the other.

/// How an edit affected an object, for the editor to re-upload as little as possible.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Touched {
    /// Only control point positions or weights of object `index` changed: same patch layout.
    Points(usize),
    /// Objects were added, removed or changed in structure: rebuild the GPU geometry.
    Structure,
    /// Only names or similar: nothing to re-upload.
    Nothing,
}

/// What a drag step or a move changed: the object and the Bézier patches of its decomposition
/// that must be re-derived and re-evaluated (the union of the moved points' supports).
/// `relaid`: the move ended with the object's layout changed (an adaptive refinement chose
/// other depths), so its GPU geometry must be rebuilt rather than updated. `linked`: other
/// objects whose shared lattice moved too (their lattices are uploaded again). `rebuilt`:
/// objects built from the moved curve (construction history), built again with it; `relaid`
/// also says when one of those came out in another layout.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PointsMoved {
    pub object: usize,
    pub patches: Vec<usize>,
    pub relaid: bool,
    pub linked: Vec<usize>,
    pub rebuilt: Vec<usize>,
}
