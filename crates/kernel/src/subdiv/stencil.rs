//! Stencil tables: each output point as a weighted sum of input points (compressed rows).

use glam::DVec3;

/// Rows of weights over input points: row i is `indices[offsets[i]..offsets[i + 1]]` with the
/// matching `weights`. Applying it is a gather, so it runs the same on the CPU and the GPU.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stencils {
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
    pub weights: Vec<f64>,
}

/// Collects one row: repeated indices are summed when the row is pushed.
#[derive(Debug, Default, Clone)]
pub struct Row(pub Vec<(u32, f64)>);

impl Row {
    pub fn add(&mut self, index: u32, weight: f64) {
        self.0.push((index, weight));
    }

    /// Adds `weight` times `row`.
    pub fn add_row(&mut self, row: &Row, weight: f64) {
        self.0.extend(row.0.iter().map(|&(i, w)| (i, w * weight)));
    }

    /// Adds `weight / n` of each of the `n` points (a face's centroid).
    pub fn add_centroid(&mut self, points: &[u32], weight: f64) {
        let w = weight / points.len() as f64;
        self.0.extend(points.iter().map(|&i| (i, w)));
    }

    /// Sorted by index with repeats summed.
    pub fn merged(mut self) -> Row {
        self.0.sort_unstable_by_key(|&(i, _)| i);
        let mut out: Vec<(u32, f64)> = Vec::with_capacity(self.0.len());
        for (i, w) in self.0 {
            match out.last_mut() {
                Some(last) if last.0 == i => last.1 += w,
                _ => out.push((i, w)),
            }
        }
        Row(out)
    }

    /// `a · self + (1 − a) · other`.
    pub fn blend(self, other: Row, a: f64) -> Row {
        let mut row = Row(Vec::with_capacity(self.0.len() + other.0.len()));
        row.add_row(&self, a);
        row.add_row(&other, 1.0 - a);
        row.merged()
    }

    pub fn apply(&self, points: &[DVec3]) -> DVec3 {
        self.0
            .iter()
            .map(|&(i, w)| points[i as usize] * w)
            .fold(DVec3::ZERO, |a, b| a + b)
    }
}

impl Stencils {
    pub fn new() -> Self {
        Self {
            offsets: vec![0],
            ..Default::default()
        }
    }

    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn push(&mut self, row: Row) {
        for (i, w) in row.merged().0 {
            self.indices.push(i);
            self.weights.push(w);
        }
        self.offsets.push(self.indices.len() as u32);
    }

    /// Every row applied to `points`.
    pub fn apply(&self, points: &[DVec3]) -> Vec<DVec3> {
        (0..self.len())
            .map(|i| {
                let (s, e) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
                (s..e)
                    .map(|k| points[self.indices[k] as usize] * self.weights[k])
                    .fold(DVec3::ZERO, |a, b| a + b)
            })
            .collect()
    }
}
