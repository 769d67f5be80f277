//! Stencil tables larger than one binding, split into pages.
//!
//! A subdivision surface's stencil entries live in the control point buffer after the points
//! and the objects' displacement and lattice blocks (the *head*), two vec4s per entry
//! ([`super::records::PATCH_KIND_STENCIL_QUAD`]). At level 4 and beyond the entries of a large
//! cage outgrow what one storage binding may hold (WebGPU's default: 128 MiB; the 1,536-face torus
//! with every face as stencils needs 240 MB at level 4). Then the stencil patches are dealt,
//! in record order, into pages: each page is one buffer holding a copy of the head and the
//! entries its patches read, repacked after it, and each slot's first entry is rewritten to
//! its place in its page. The evaluator binds page k's buffer where it dispatches page k's
//! patches; page 0 is the buffer everything else (Bézier patches, the renderer) binds. A page
//! keeps one copy of entries its slots share.

use std::collections::{HashMap, HashSet};

use super::error::GpuError;
use super::records::{
    PATCH_KIND_STENCIL_QUAD, PATCH_KIND_STENCIL_TRIANGLE, PatchRecord, STENCIL_NO_CURVATURE,
};

/// The control point buffers of a paged layout.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StencilPages {
    /// Per page, the vec4s after the head: the entries its patches read, repacked.
    pub entries: Vec<Vec<[f32; 4]>>,
    /// Per record, its page (0 for records that read no entries).
    pub record_page: Vec<u32>,
}

/// Whether `record` is a stencil patch (its slots read entries).
fn reads_entries(record: &PatchRecord) -> bool {
    record.kind == PATCH_KIND_STENCIL_QUAD || record.kind == PATCH_KIND_STENCIL_TRIANGLE
}

/// Deals the stencil patches of `records` into pages of at most `capacity` vec4s each, each
/// page holding the head (its first `head` vec4s: the points and blocks) and then the entries
/// its patches read, copied from `tail` (the control point buffer from vec4 `tail_at` on).
/// Rewrites each stencil slot's first entry in `control_indices` to its place in its page.
/// Refuses a head that leaves no room, and a patch whose own entries do not fit one page.
pub(crate) fn paginate(
    records: &[PatchRecord],
    control_indices: &mut [u32],
    (tail, tail_at): (&[[f32; 4]], usize),
    head: usize,
    capacity: usize,
) -> Result<StencilPages, GpuError> {
    let too_large = |what: &'static str, vec4s: usize| GpuError::BufferTooLarge {
        what,
        bytes: vec4s as u64 * 16,
        limit: capacity as u64 * 16,
    };
    if head >= capacity {
        return Err(too_large("control point", head + 1));
    }
    let room = capacity - head;
    let mut pages = StencilPages {
        entries: vec![Vec::new()],
        record_page: vec![0; records.len()],
    };
    // Where each run of entries (by its first vec4 in the pool) went in the current page.
    let mut placed: HashMap<u32, u32> = HashMap::new();
    for (r, record) in records.iter().enumerate() {
        if !reads_entries(record) {
            continue;
        }
        let slots = (record.segments_u as usize + 1) * (record.segments_v as usize + 1);
        let first = record.control_offset as usize;
        let block = control_indices
            .get_mut(first..first + 2 * slots)
            .ok_or_else(|| GpuError::Geometry(format!("stencil patch {r} has no slots")))?;
        // The vec4s of the runs this patch adds to the current page; on overflow, a new page.
        let fresh = |placed: &HashMap<u32, u32>, block: &[u32]| {
            let mut seen = HashSet::new();
            block
                .chunks_exact(2)
                .filter(|s| !placed.contains_key(&s[0]) && seen.insert(s[0]))
                .map(|s| 2 * (s[1] & !STENCIL_NO_CURVATURE) as usize)
                .sum::<usize>()
        };
        let mut need = fresh(&placed, block);
        let current = pages.entries.len() - 1;
        if pages.entries[current].len() + need > room {
            placed.clear();
            need = fresh(&placed, block);
            if need > room {
                return Err(too_large("stencil patch", head + need));
            }
            pages.entries.push(Vec::with_capacity(room));
        }
        let page = pages.entries.len() - 1;
        let data = &mut pages.entries[page];
        for slot in block.chunks_exact_mut(2) {
            let (start, count) = (slot[0], 2 * (slot[1] & !STENCIL_NO_CURVATURE) as usize);
            let at = match placed.get(&start) {
                Some(&at) => at,
                None => {
                    let from = (start as usize).checked_sub(tail_at);
                    let run = from
                        .and_then(|from| tail.get(from..from + count))
                        .ok_or_else(|| {
                            GpuError::Geometry(format!(
                                "a slot of stencil patch {r} reads past the entries"
                            ))
                        })?;
                    let at = (head + data.len()) as u32;
                    data.extend_from_slice(run);
                    placed.insert(start, at);
                    at
                }
            };
            slot[0] = at;
        }
        pages.record_page[r] = page as u32;
    }
    Ok(pages)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::records::{PATCH_KIND_BEZIER, POINT_LIST_NONE};

    fn record(kind: u32, segments: u32, control_offset: u32) -> PatchRecord {
        PatchRecord {
            degree_u: 1,
            degree_v: 1,
            control_offset,
            vertex_offset: 0,
            segments_u: segments,
            segments_v: segments,
            index_offset: 0,
            object: 0,
            domain: [0.0, 1.0, 0.0, 1.0],
            kind,
            trim_offset: 0,
            trim_count: 0,
            level: 0,
            displacement: 0,
            lattice: 0,
            point_list: POINT_LIST_NONE,
            first_point: 0,
        }
    }

    /// Every slot reads in its page what it read in the pool, and no page outgrows the
    /// capacity; shared runs are copied once per page.
    #[test]
    fn every_slot_reads_its_own_entries_in_its_page() {
        let head = 3;
        // Points and blocks, then 40 entries of distinct values.
        let pool: Vec<[f32; 4]> = (0..head + 80).map(|k| [k as f32; 4]).collect();
        // A Bézier patch's four indices, then four stencil patches of one segment (4 slots):
        // slot runs of 1 to 5 entries; patch 3's slots all share one run.
        let mut indices = vec![0, 1, 2, 0];
        let mut records = vec![record(PATCH_KIND_BEZIER, 4, 0)];
        let mut next = head as u32;
        for p in 0..4u32 {
            records.push(record(PATCH_KIND_STENCIL_QUAD, 1, indices.len() as u32));
            for s in 0..4u32 {
                let count = if p == 3 { 2 } else { 1 + (p + s) % 5 };
                let start = if p == 3 { head as u32 + 60 } else { next };
                indices.extend([start, count | if s == 1 { STENCIL_NO_CURVATURE } else { 0 }]);
                if p != 3 {
                    next += 2 * count;
                }
            }
        }
        let original = indices.clone();
        let capacity = head + 30;
        let pages = paginate(&records, &mut indices, (&pool, 0), head, capacity).unwrap();
        assert!(pages.entries.len() > 1, "the test must make several pages");
        assert_eq!(pages.record_page[0], 0);
        assert_eq!(indices[..4], original[..4], "Bézier indices untouched");
        for page in &pages.entries {
            assert!(head + page.len() <= capacity);
        }
        for (r, record) in records.iter().enumerate().skip(1) {
            let page = &pages.entries[pages.record_page[r] as usize];
            let first = record.control_offset as usize;
            for s in 0..4 {
                let (before, after) = (&original[first + 2 * s..], &indices[first + 2 * s..]);
                assert_eq!(before[1], after[1], "counts and flags kept");
                let count = 2 * (before[1] & !STENCIL_NO_CURVATURE) as usize;
                let want = &pool[before[0] as usize..before[0] as usize + count];
                let at = after[0] as usize - head;
                assert_eq!(&page[at..at + count], want, "record {r} slot {s}");
            }
        }
    }

    #[test]
    fn a_patch_larger_than_a_page_or_a_head_that_fills_it_is_refused() {
        let pool: Vec<[f32; 4]> = vec![[0.0; 4]; 40];
        let records = [record(PATCH_KIND_STENCIL_QUAD, 1, 0)];
        let mut indices = vec![2, 4, 10, 4, 18, 4, 26, 4];
        let refused = paginate(&records, &mut indices.clone(), (&pool[1..], 1), 2, 20);
        assert!(matches!(
            refused,
            Err(GpuError::BufferTooLarge {
                what: "stencil patch",
                ..
            })
        ));
        let refused = paginate(&records, &mut indices, (&pool, 0), 20, 20);
        assert!(matches!(
            refused,
            Err(GpuError::BufferTooLarge {
                what: "control point",
                ..
            })
        ));
    }
}
