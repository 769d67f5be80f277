//! Stencil tables: each output point as a weighted sum of input points (compressed rows), and
//! the sparse accumulation that composes them (Gustavson's algorithm over flat arrays, row
//! blocks on every core).

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
        self.push_merged(row.merged());
    }

    /// Pushes a row already [`Row::merged`].
    pub fn push_merged(&mut self, row: Row) {
        for (i, w) in row.0 {
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

/// Gustavson's sparse accumulator: `N`-component weights gathered by index into a flat array
/// of the whole index range, the indices touched listed so that reading and clearing cost only
/// what was added (no maps, no sorting of repeated entries).
pub struct Accumulator<const N: usize> {
    values: Vec<[f64; N]>,
    seen: Vec<bool>,
    touched: Vec<u32>,
}

impl<const N: usize> Accumulator<N> {
    /// An empty accumulator over indices `0..size`.
    pub fn new(size: usize) -> Self {
        Self {
            values: vec![[0.0; N]; size],
            seen: vec![false; size],
            touched: Vec::new(),
        }
    }

    fn slot(&mut self, index: u32) -> &mut [f64; N] {
        let i = index as usize;
        if !self.seen[i] {
            self.seen[i] = true;
            self.touched.push(index);
        }
        &mut self.values[i]
    }

    /// Adds `weight` to component `component` of `index`.
    pub fn add(&mut self, index: u32, component: usize, weight: f64) {
        self.slot(index)[component] += weight;
    }

    /// Adds `scale · weights` to `index`.
    pub fn add_scaled(&mut self, index: u32, scale: f64, weights: &[f64; N]) {
        let slot = self.slot(index);
        for (s, w) in slot.iter_mut().zip(weights) {
            *s += scale * w;
        }
    }

    /// Appends the gathered entries to `out` by increasing index and clears the accumulator.
    pub fn drain_into(&mut self, out: &mut Vec<(u32, [f64; N])>) {
        self.touched.sort_unstable();
        for &i in &self.touched {
            let i = i as usize;
            out.push((i as u32, std::mem::replace(&mut self.values[i], [0.0; N])));
            self.seen[i] = false;
        }
        self.touched.clear();
    }
}

/// Rows of `N`-component weights (compressed: row r is `entries[offsets[r]..offsets[r + 1]]`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WideRows<const N: usize> {
    pub offsets: Vec<u32>,
    pub entries: Vec<(u32, [f64; N])>,
}

impl<const N: usize> WideRows<N> {
    /// Row `r`'s entries.
    pub fn row(&self, r: usize) -> &[(u32, [f64; N])] {
        &self.entries[self.offsets[r] as usize..self.offsets[r + 1] as usize]
    }
}

/// Rows built per block of this many, one block per task.
const ROW_BLOCK: usize = 512;

/// `count` rows over indices `0..size`, row r gathered by `row(r, accumulator)`, in blocks on
/// every core. Each row's entries come out sorted by index, and every sum is taken in the
/// order `row` adds, so the table is bit for bit the same whatever the number of threads.
pub fn build_rows<const N: usize>(
    count: usize,
    size: usize,
    row: impl Fn(usize, &mut Accumulator<N>) + Sync + Send,
) -> WideRows<N> {
    // Per block: each row's length and the entries.
    type Block<const N: usize> = (Vec<u32>, Vec<(u32, [f64; N])>);
    let blocks: Vec<Block<N>> = crate::par::map_init(
        count.div_ceil(ROW_BLOCK),
        // The worker's accumulator, and its last block's entry count: the next block's
        // room, so that its entries are not copied as they grow.
        || (Accumulator::new(size), 0),
        |(accumulator, last), b| {
            let rows = b * ROW_BLOCK..((b + 1) * ROW_BLOCK).min(count);
            let mut lengths = Vec::with_capacity(rows.len());
            let mut entries = Vec::with_capacity(*last + *last / 8);
            for r in rows {
                let before = entries.len();
                row(r, accumulator);
                accumulator.drain_into(&mut entries);
                lengths.push((entries.len() - before) as u32);
            }
            *last = entries.len();
            (lengths, entries)
        },
    );
    let mut offsets = Vec::with_capacity(count + 1);
    offsets.push(0u32);
    for (lengths, _) in &blocks {
        for length in lengths {
            let last = offsets[offsets.len() - 1];
            offsets.push(last + length);
        }
    }
    // The blocks' entries copied into one table on every core (a large table's fresh pages
    // are then touched by all of them).
    let total = offsets[offsets.len() - 1] as usize;
    let mut entries = vec![(0u32, [0.0; N]); total];
    let mut rest = entries.as_mut_slice();
    let mut parts = Vec::with_capacity(blocks.len());
    for (_, block) in &blocks {
        let (part, tail) = rest.split_at_mut(block.len());
        parts.push(part);
        rest = tail;
    }
    crate::par::for_each_owned(parts, |b, part| part.copy_from_slice(&blocks[b].1));
    WideRows { offsets, entries }
}
