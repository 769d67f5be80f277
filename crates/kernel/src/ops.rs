//! Shape-preserving operations on B-spline control polygons: knot insertion, knot refinement,
//! Bézier decomposition, degree elevation, splitting, reversal and knot removal.
//!
//! Every function acts on one control polygon — degree p, knot vector U and (homogeneous)
//! control points — so the same code serves 2D and 3D curves and, applied row by row or column
//! by column, surfaces (the surface algorithms A5.3/A5.5/A5.7/A5.10 of The NURBS Book are the
//! curve algorithms applied to each row, with the coefficients computed once). Inputs are
//! assumed valid (the curve and surface types check them before calling).
//!
//! The loops keep the book's index arithmetic so each line can be checked against it.
#![allow(clippy::needless_range_loop, clippy::explicit_counter_loop)]

use super::basis::{domain, find_span, multiplicity};
use super::vector::{Vector, binomial};

/// A control polygon: degree, knots and control points (homogeneous for rational curves).
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon<V> {
    pub degree: usize,
    pub knots: Vec<f64>,
    pub points: Vec<V>,
}

/// Inserts knot `u` `times` times (The NURBS Book, A5.1 "CurveKnotIns"). The caller ensures the
/// resulting multiplicity does not exceed the degree and that u lies in the domain.
pub fn insert_knot<V: Vector>(poly: &Polygon<V>, u: f64, times: usize) -> Polygon<V> {
    if times == 0 {
        return poly.clone();
    }
    let p = poly.degree;
    let up = &poly.knots;
    let pw = &poly.points;
    let np = pw.len() - 1;
    let s = multiplicity(up, u);
    let k = find_span(up, p, pw.len(), u);
    let r = times;
    let mp = np + p + 1;
    let mut uq = Vec::with_capacity(up.len() + r);
    uq.extend_from_slice(&up[..=k]);
    uq.extend(std::iter::repeat_n(u, r));
    uq.extend_from_slice(&up[k + 1..=mp]);
    let mut qw = vec![V::ZERO; pw.len() + r];
    qw[..=k - p].copy_from_slice(&pw[..=k - p]);
    qw[k - s + r..=np + r].copy_from_slice(&pw[k - s..=np]);
    let mut rw: Vec<V> = pw[k - p..=k - s].to_vec();
    let mut last = k - p;
    for j in 1..=r {
        last = k - p + j;
        for i in 0..=p - j - s {
            let alpha = (u - up[last + i]) / (up[i + k + 1] - up[last + i]);
            rw[i] = rw[i + 1] * alpha + rw[i] * (1.0 - alpha);
        }
        qw[last] = rw[0];
        qw[k + r - j - s] = rw[p - j - s];
    }
    if last + 1 < k - s {
        qw[last + 1..k - s].copy_from_slice(&rw[1..k - s - last]);
    }
    Polygon {
        degree: p,
        knots: uq,
        points: qw,
    }
}

/// Inserts all knots of the non-decreasing list `x` at once (The NURBS Book, A5.4
/// "RefineKnotVectCurve"). The caller ensures every resulting multiplicity stays ≤ the degree
/// and that the knots lie in the domain.
pub fn refine_knots<V: Vector>(poly: &Polygon<V>, x: &[f64]) -> Polygon<V> {
    if x.is_empty() {
        return poly.clone();
    }
    let p = poly.degree;
    let u = &poly.knots;
    let pw = &poly.points;
    let n = pw.len() - 1;
    let m = n + p + 1;
    let r = x.len() - 1;
    let a = find_span(u, p, pw.len(), x[0]);
    let b = find_span(u, p, pw.len(), x[r]) + 1;
    let mut qw = vec![V::ZERO; pw.len() + r + 1];
    let mut ubar = vec![0.0; u.len() + r + 1];
    qw[..=a - p].copy_from_slice(&pw[..=a - p]);
    for j in b - 1..=n {
        qw[j + r + 1] = pw[j];
    }
    ubar[..=a].copy_from_slice(&u[..=a]);
    for j in b + p..=m {
        ubar[j + r + 1] = u[j];
    }
    // Signed indices: the book's loop counters can step below the arrays' starts only after
    // their last use.
    let mut i = (b + p - 1) as isize;
    let mut k = (b + p + r) as isize;
    let (a, p_i) = (a as isize, p as isize);
    for j in (0..=r).rev() {
        while x[j] <= u[i as usize] && i > a {
            qw[(k - p_i - 1) as usize] = pw[(i - p_i - 1) as usize];
            ubar[k as usize] = u[i as usize];
            k -= 1;
            i -= 1;
        }
        qw[(k - p_i - 1) as usize] = qw[(k - p_i) as usize];
        for l in 1..=p_i {
            let ind = (k - p_i + l) as usize;
            let mut alpha = ubar[(k + l) as usize] - x[j];
            if alpha.abs() == 0.0 {
                qw[ind - 1] = qw[ind];
            } else {
                alpha /= ubar[(k + l) as usize] - u[(i - p_i + l) as usize];
                qw[ind - 1] = qw[ind - 1] * alpha + qw[ind] * (1.0 - alpha);
            }
        }
        ubar[k as usize] = x[j];
        k -= 1;
    }
    Polygon {
        degree: p,
        knots: ubar,
        points: qw,
    }
}

/// The same polygon over a clamped knot vector: the domain ends are raised to multiplicity p + 1
/// and the control points outside the domain dropped. Clamped input is returned unchanged.
pub fn clamp<V: Vector>(poly: &Polygon<V>) -> Polygon<V> {
    let p = poly.degree;
    let n = poly.points.len();
    let clamped_at = |knots: &[f64]| multiplicity(knots, knots[0]) == p + 1;
    if clamped_at(&poly.knots) && multiplicity(&poly.knots, poly.knots[n + p]) == p + 1 {
        return poly.clone();
    }
    mirror(&clamp_start(&mirror(&clamp_start(poly))))
}

/// The polygon over the negated, reversed knot vector: the same curve run backwards with the
/// parameter negated. Exact in floating point (negation only), so two mirrors restore every knot.
fn mirror<V: Vector>(poly: &Polygon<V>) -> Polygon<V> {
    Polygon {
        degree: poly.degree,
        knots: poly.knots.iter().rev().map(|&k| -k).collect(),
        points: poly.points.iter().rev().copied().collect(),
    }
}

/// Clamps the start of the domain (see [`clamp`]): u_p is inserted until it has multiplicity p,
/// which makes one control point the curve's start point; the knot before is then set to u_p too
/// and everything before that point is dropped.
fn clamp_start<V: Vector>(poly: &Polygon<V>) -> Polygon<V> {
    let p = poly.degree;
    let lo = poly.knots[p];
    let s = multiplicity(&poly.knots, lo);
    let raised = if s < p {
        insert_knot(poly, lo, p - s)
    } else {
        poly.clone()
    };
    let first = raised.knots.partition_point(|&k| k < lo);
    let m = multiplicity(&raised.knots, lo);
    let start = first + m - (p + 1);
    let mut knots = raised.knots[start..].to_vec();
    knots[0] = lo;
    Polygon {
        degree: p,
        knots,
        points: raised.points[start..].to_vec(),
    }
}

/// The Bézier segments of a polygon, in order: each interior knot is raised to multiplicity p
/// by refinement (the decomposition of The NURBS Book, A5.6/A5.7), giving p + 1 control points
/// per segment; neighbouring segments share their end points. Returns the segments' control
/// points and parameter intervals.
pub fn bezier_segments<V: Vector>(poly: &Polygon<V>) -> Vec<(Vec<V>, [f64; 2])> {
    let p = poly.degree;
    let refined = refine_to_bezier(&clamp(poly));
    let breaks = distinct_breaks(&refined.knots, p, refined.points.len());
    breaks
        .windows(2)
        .enumerate()
        .map(|(segment, w)| {
            let start = segment * p;
            (refined.points[start..=start + p].to_vec(), [w[0], w[1]])
        })
        .collect()
}

/// A clamped polygon with every interior knot raised to multiplicity p: its control points are
/// the Bézier points of all segments, consecutive segments sharing one point.
pub fn refine_to_bezier<V: Vector>(poly: &Polygon<V>) -> Polygon<V> {
    let p = poly.degree;
    let (lo, hi) = domain(&poly.knots, p, poly.points.len());
    let mut x = Vec::new();
    let mut i = 0;
    while i < poly.knots.len() {
        let k = poly.knots[i];
        let s = multiplicity(&poly.knots, k);
        if k > lo && k < hi && s < p {
            x.extend(std::iter::repeat_n(k, p - s));
        }
        i += s;
    }
    refine_knots(poly, &x)
}

/// The distinct knot values of the domain, in order (the segment boundaries).
pub fn distinct_breaks(knots: &[f64], degree: usize, count: usize) -> Vec<f64> {
    let (lo, hi) = domain(knots, degree, count);
    let mut breaks: Vec<f64> = Vec::new();
    for &k in knots.iter().filter(|&&k| k >= lo && k <= hi) {
        if breaks.last() != Some(&k) {
            breaks.push(k);
        }
    }
    breaks
}

/// Raises the degree by `t` without changing the shape (The NURBS Book, A5.9
/// "DegreeElevateCurve"). Unclamped input is clamped first. Every interior knot's multiplicity
/// grows by t, keeping the continuity.
pub fn elevate_degree<V: Vector>(poly: &Polygon<V>, t: usize) -> Polygon<V> {
    if t == 0 {
        return poly.clone();
    }
    let clamped = clamp(poly);
    let p = clamped.degree;
    let u = &clamped.knots;
    let pw = &clamped.points;
    let n = pw.len() - 1;
    let m = n + p + 1;
    let ph = p + t;
    let ph2 = ph / 2;
    // Coefficients for elevating one Bézier segment.
    let mut bezalfs = vec![vec![0.0; p + 1]; ph + 1];
    bezalfs[0][0] = 1.0;
    bezalfs[ph][p] = 1.0;
    for i in 1..=ph2 {
        let inv = 1.0 / binomial(ph, i);
        for j in i.saturating_sub(t)..=p.min(i) {
            bezalfs[i][j] = inv * binomial(p, j) * binomial(t, i - j);
        }
    }
    for i in ph2 + 1..ph {
        for j in i.saturating_sub(t)..=p.min(i) {
            bezalfs[i][j] = bezalfs[ph - i][p - j];
        }
    }
    let segments = distinct_breaks(u, p, pw.len()).len() - 1;
    let mut uh = vec![0.0; u.len() + (segments + 1) * t];
    let mut qw = vec![V::ZERO; uh.len() - ph - 1];
    let mut bpts: Vec<V> = pw[..=p].to_vec();
    let mut next_bpts = vec![V::ZERO; p.max(1)];
    let mut ebpts = vec![V::ZERO; ph + 1];
    let mut alfs = vec![0.0; p.max(1)];
    let mut mh = ph;
    let mut kind = ph + 1;
    let mut r: isize = -1;
    let mut a = p;
    let mut b = p + 1;
    let mut cind = 1;
    let mut ua = u[0];
    qw[0] = pw[0];
    uh[..=ph].fill(ua);
    while b < m {
        let i0 = b;
        while b < m && u[b] == u[b + 1] {
            b += 1;
        }
        let mul = b - i0 + 1;
        mh += mul + t;
        let ub = u[b];
        let oldr = r;
        r = p as isize - mul as isize;
        let lbz = if oldr > 0 {
            ((oldr + 2) / 2) as usize
        } else {
            1
        };
        let rbz = if r > 0 {
            ph - ((r + 1) / 2) as usize
        } else {
            ph
        };
        if r > 0 {
            // Insert ub r times into the current segment's Bézier points.
            let numer = ub - ua;
            for k in (mul + 1..=p).rev() {
                alfs[k - mul - 1] = numer / (u[a + k] - ua);
            }
            for j in 1..=r as usize {
                let save = r as usize - j;
                let s = mul + j;
                for k in (s..=p).rev() {
                    bpts[k] = bpts[k] * alfs[k - s] + bpts[k - 1] * (1.0 - alfs[k - s]);
                }
                next_bpts[save] = bpts[p];
            }
        }
        // Elevate the segment.
        for (i, e) in ebpts.iter_mut().enumerate().skip(lbz) {
            *e = V::ZERO;
            for j in i.saturating_sub(t)..=p.min(i) {
                *e = *e + bpts[j] * bezalfs[i][j];
            }
        }
        if oldr > 1 {
            // Remove the knot ua oldr − 1 times.
            let mut first = kind - 2;
            let mut last = kind;
            let den = ub - ua;
            let bet = (ub - uh[kind - 1]) / den;
            for tr in 1..oldr as usize {
                let mut i = first;
                let mut j = last;
                let mut kj = j as isize - kind as isize + 1;
                while j - i > tr {
                    if i < cind {
                        let alf = (ub - uh[i]) / (ua - uh[i]);
                        qw[i] = qw[i] * alf + qw[i - 1] * (1.0 - alf);
                    }
                    if j >= lbz {
                        let kju = kj as usize;
                        if j as isize - tr as isize <= kind as isize - ph as isize + oldr {
                            let gam = (ub - uh[j - tr]) / den;
                            ebpts[kju] = ebpts[kju] * gam + ebpts[kju + 1] * (1.0 - gam);
                        } else {
                            ebpts[kju] = ebpts[kju] * bet + ebpts[kju + 1] * (1.0 - bet);
                        }
                    }
                    i += 1;
                    j -= 1;
                    kj -= 1;
                }
                first -= 1;
                last += 1;
            }
        }
        if a != p {
            // Load the knot ua.
            for _ in 0..(ph as isize - oldr) as usize {
                uh[kind] = ua;
                kind += 1;
            }
        }
        for e in &ebpts[lbz..=rbz] {
            qw[cind] = *e;
            cind += 1;
        }
        if b < m {
            let r_u = r.max(0) as usize;
            bpts[..r_u].copy_from_slice(&next_bpts[..r_u]);
            for j in r_u..=p {
                bpts[j] = pw[b - p + j];
            }
            a = b;
            b += 1;
            ua = ub;
        } else {
            for k in 0..=ph {
                uh[kind + k] = ub;
            }
        }
    }
    let nh = mh - ph - 1;
    uh.truncate(nh + ph + 2);
    qw.truncate(nh + 1);
    Polygon {
        degree: ph,
        knots: uh,
        points: qw,
    }
}

/// Splits at the interior parameter `u` into the pieces over [u_p, u] and [u, u_{n+1}]:
/// u is raised to multiplicity p, after which the control point at u is shared by both.
pub fn split<V: Vector>(poly: &Polygon<V>, u: f64) -> (Polygon<V>, Polygon<V>) {
    let clamped = clamp(poly);
    let p = clamped.degree;
    let s = multiplicity(&clamped.knots, u);
    let refined = insert_knot(&clamped, u, p.saturating_sub(s));
    let first = refined.knots.partition_point(|&k| k < u);
    let mut left_knots = refined.knots[..first].to_vec();
    left_knots.extend(std::iter::repeat_n(u, p + 1));
    let left_points = refined.points[..first].to_vec();
    let mut right_knots = vec![u; p + 1];
    right_knots.extend_from_slice(&refined.knots[first + p..]);
    let right_points = refined.points[first - 1..].to_vec();
    (
        Polygon {
            degree: p,
            knots: left_knots,
            points: left_points,
        },
        Polygon {
            degree: p,
            knots: right_knots,
            points: right_points,
        },
    )
}

/// The closed polygon `poly` with its seam moved to `u` (inside its domain [a, b]): split
/// there (A5.3), the part after `u`, then the part before it shifted by the period b − a, its
/// homogeneous points times `scale` (so that its first point meets the first part's last;
/// the same shape), joined at b by a knot of multiplicity p. The domain becomes
/// [u, u + b − a]. The first point of the part before `u` is dropped for the first part's
/// last, which the caller has checked coincide.
pub fn moved_seam<V: Vector>(poly: &Polygon<V>, u: f64, scale: f64) -> Polygon<V> {
    let p = poly.degree;
    let (lo, hi) = domain(&poly.knots, p, poly.points.len());
    let (before, after) = split(poly, u);
    let mut knots = after.knots[..after.knots.len() - 1].to_vec();
    knots.extend(before.knots[p + 1..].iter().map(|k| k + (hi - lo)));
    let mut points = after.points.clone();
    points.extend(before.points[1..].iter().map(|&h| h * scale));
    Polygon {
        degree: p,
        knots,
        points,
    }
}

/// The same curve traversed backwards over the same domain [a, b]: U'_i = a + b − U_{m−i},
/// points in reverse order (The NURBS Book, eq. 6.15 for the knots). Applying it twice gives the
/// original back.
pub fn reverse<V: Vector>(poly: &Polygon<V>) -> Polygon<V> {
    let (first, last) = domain(&poly.knots, poly.degree, poly.points.len());
    Polygon {
        degree: poly.degree,
        // The domain ends map onto each other exactly; interior knots to a + b − u.
        knots: poly
            .knots
            .iter()
            .rev()
            .map(|&k| {
                if k == first {
                    last
                } else if k == last {
                    first
                } else {
                    first + last - k
                }
            })
            .collect(),
        points: poly.points.iter().rev().copied().collect(),
    }
}

/// Tries to remove one occurrence of the interior knot `u` (The NURBS Book, A5.8
/// "RemoveCurveKnot" with num = 1). The new control points are solved from both ends; the
/// removal succeeds when the two solutions meet within `tolerance` (Euclidean distance of the
/// homogeneous points). Returns `None` where removing it would change the shape more than that.
pub fn remove_knot<V: Vector>(poly: &Polygon<V>, u: f64, tolerance: f64) -> Option<Polygon<V>> {
    let p = poly.degree;
    let knots = &poly.knots;
    let pw = &poly.points;
    let n = pw.len() - 1;
    let s = multiplicity(knots, u);
    if s == 0 {
        return None;
    }
    let r = knots.iter().rposition(|&k| k == u)?;
    let (lo, hi) = domain(knots, p, pw.len());
    if !(u > lo && u < hi) || r < p + 1 || r < s {
        return None;
    }
    let ord = p + 1;
    let first = r - p;
    let last = r - s;
    let off = first - 1;
    let mut temp = vec![V::ZERO; last + 2 - off];
    temp[0] = pw[off];
    temp[last + 1 - off] = pw[last + 1];
    let (mut i, mut j) = (first, last);
    let (mut ii, mut jj) = (1, last - off);
    while j > i {
        let alfi = (u - knots[i]) / (knots[i + ord] - knots[i]);
        let alfj = (u - knots[j]) / (knots[j + ord] - knots[j]);
        temp[ii] = (pw[i] - temp[ii - 1] * (1.0 - alfi)) / alfi;
        temp[jj] = (pw[j] - temp[jj + 1] * alfj) / (1.0 - alfj);
        i += 1;
        ii += 1;
        j -= 1;
        jj -= 1;
    }
    let removable = if j < i {
        (temp[ii - 1] - temp[jj + 1]).norm() <= tolerance
    } else {
        let alfi = (u - knots[i]) / (knots[i + ord] - knots[i]);
        (pw[i] - (temp[ii + 1] * alfi + temp[ii - 1] * (1.0 - alfi))).norm() <= tolerance
    };
    if !removable {
        return None;
    }
    let mut points = pw.clone();
    let (mut i, mut j) = (first, last);
    while j > i {
        points[i] = temp[i - off];
        points[j] = temp[j - off];
        i += 1;
        j -= 1;
    }
    let fout = (2 * r - s - p) / 2;
    points.remove(fout);
    let mut new_knots = knots.clone();
    new_knots.remove(r);
    debug_assert_eq!(points.len(), n);
    Some(Polygon {
        degree: p,
        knots: new_knots,
        points,
    })
}
