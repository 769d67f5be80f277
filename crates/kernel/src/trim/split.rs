//! Cutting trim loops on a split line: a loop that crosses the line becomes, on each side,
//! runs of its own pieces joined by straight segments along the line. The loops are oriented
//! with the kept region on their left ([`super::TrimmedSurface`]), so walking the line in the
//! direction that keeps a side's region on the left, each run's exit is joined to the next
//! entry along the line.

use glam::DVec2;

use super::piece::{monotone_pieces, split_bezier};
use super::shapes::line;
use super::{TrimLoop, TrimProblem, refuse};
use crate::{Direction, GeometryError, TrimCurve};

/// One Bézier piece of a crossing loop and the side it lies on.
struct SidePiece {
    points: Vec<glam::DVec3>,
    low: bool,
}

fn piece_curve(points: &[glam::DVec3]) -> Result<TrimCurve, GeometryError> {
    let p = points.len() - 1;
    let mut knots = vec![0.0; p + 1];
    knots.extend(vec![1.0; p + 1]);
    TrimCurve::from_homogeneous(p, knots, points.to_vec())
}

fn end_point(points: &[glam::DVec3], last: bool) -> DVec2 {
    let h = if last {
        points[points.len() - 1]
    } else {
        points[0]
    };
    h.truncate() / h.z
}

/// The loops of the low side (coordinate < `value`) and of the high side.
pub fn split_loops(
    loops: &[TrimLoop],
    direction: Direction,
    value: f64,
) -> Result<(Vec<TrimLoop>, Vec<TrimLoop>), GeometryError> {
    let axis = direction.index();
    let mut sides: [Vec<TrimLoop>; 2] = [Vec::new(), Vec::new()];
    // Runs (consecutive same-side pieces) of the crossing loops, per side.
    let mut runs: [Vec<Vec<TrimCurve>>; 2] = [Vec::new(), Vec::new()];
    for (l, lp) in loops.iter().enumerate() {
        let mut pieces: Vec<SidePiece> = Vec::new();
        for (c, curve) in lp.iter().enumerate() {
            for piece in monotone_pieces(curve, (l, c)) {
                let [lo, hi] = [piece.bounds[2 * axis], piece.bounds[2 * axis + 1]];
                if lo == hi && lo == value {
                    return Err(refuse(
                        l,
                        c,
                        TrimProblem::Curve(
                            "the curve runs along the split line; split elsewhere".into(),
                        ),
                    ));
                }
                if lo < value && value < hi {
                    let t = piece.parameter_at(axis, value);
                    let (a, b) = split_bezier(&piece.points, t);
                    for half in [a, b] {
                        let mid = super::piece::bezier_point(&half, 0.5)[axis];
                        pieces.push(SidePiece {
                            points: half,
                            low: mid < value,
                        });
                    }
                } else {
                    let mid = 0.5 * (lo + hi);
                    pieces.push(SidePiece {
                        points: piece.points,
                        low: mid < value,
                    });
                }
            }
        }
        let crossing = pieces.iter().any(|p| p.low) && pieces.iter().any(|p| !p.low);
        if !crossing {
            let side = if pieces.first().is_some_and(|p| p.low) {
                0
            } else {
                1
            };
            sides[side].push(lp.clone());
            continue;
        }
        // Rotate so that the first piece starts a run.
        let n = pieces.len();
        let start = (0..n)
            .find(|&k| pieces[k].low != pieces[(k + n - 1) % n].low)
            .unwrap_or(0);
        pieces.rotate_left(start);
        let mut k = 0;
        while k < n {
            let low = pieces[k].low;
            let mut run = Vec::new();
            while k < n && pieces[k].low == low {
                run.push(piece_curve(&pieces[k].points)?);
                k += 1;
            }
            runs[if low { 0 } else { 1 }].push(run);
        }
    }
    for (side, side_runs) in runs.into_iter().enumerate() {
        sides[side].extend(close_runs(side_runs, axis, side == 0)?);
    }
    let [low, high] = sides;
    Ok((low, high))
}

/// Joins the runs of one side into loops along the line.
fn close_runs(
    runs: Vec<Vec<TrimCurve>>,
    axis: usize,
    low: bool,
) -> Result<Vec<TrimLoop>, GeometryError> {
    let along = 1 - axis;
    // Walking direction along the line that keeps the side on the left: the low side of a
    // u-line walks +v, the low side of a v-line walks −u.
    let forward = (axis == 0) == low;
    let key = |p: DVec2| if forward { p[along] } else { -p[along] };
    let first = |run: &Vec<TrimCurve>| end_point(run[0].homogeneous_points(), false);
    let last = |run: &Vec<TrimCurve>| {
        let c = &run[run.len() - 1];
        end_point(c.homogeneous_points(), true)
    };
    let mut used = vec![false; runs.len()];
    let mut out = Vec::new();
    for s in 0..runs.len() {
        if used[s] {
            continue;
        }
        let mut lp: TrimLoop = Vec::new();
        let mut r = s;
        loop {
            used[r] = true;
            lp.extend(runs[r].iter().cloned());
            let exit = last(&runs[r]);
            // The next entry along the walking direction.
            let next = (0..runs.len())
                .filter(|&q| key(first(&runs[q])) > key(exit))
                .min_by(|&a, &b| key(first(&runs[a])).total_cmp(&key(first(&runs[b]))))
                .ok_or_else(|| GeometryError::Construction {
                    what: "split",
                    message: "the trim loops do not close along the split line".into(),
                })?;
            lp.push(line(exit, first(&runs[next]))?);
            if next == s {
                break;
            }
            if used[next] {
                return Err(GeometryError::Construction {
                    what: "split",
                    message: "the trim loops do not close along the split line".into(),
                });
            }
            r = next;
        }
        out.push(lp);
    }
    Ok(out)
}
