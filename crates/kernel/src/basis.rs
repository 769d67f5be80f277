//! B-spline basis functions, their derivatives, knot spans, and knot-vector validation.
//!
//! A knot vector U = {u₀ ≤ … ≤ u_m} for n + 1 control points of degree p has m + 1 = n + p + 2
//! knots; the curve is defined on the domain [u_p, u_{n+1}]. Clamped vectors (first and last
//! knots repeated p + 1 times) make the curve interpolate its end points; unclamped ones are
//! accepted too.

use super::error::{GeometryError, Location};

/// The highest degree the kernel accepts in any direction. Higher degrees have no modelling use,
/// lose precision in the basis recurrences, and a hostile file could ask for millions.
pub const MAX_DEGREE: usize = 32;

/// Checks that `knots` is a valid knot vector for `count` control points of degree `degree`:
/// the degree is in 1..=[`MAX_DEGREE`], count ≥ degree + 1, length = count + degree + 1, every
/// knot finite and none smaller than the one before, the domain [u_p, u_{n+1}] non-empty,
/// end knots repeated at most degree + 1 times and interior knots at most degree times.
///
/// An interior multiplicity of degree + 1 would make the curve discontinuous (two separate
/// pieces in one object); knotwork does not represent that — split the object instead.
/// `field` names the knot vector in errors (for example `"knots[0]"`, the u knots of a surface).
pub fn validate_knots(
    field: &'static str,
    degree: usize,
    count: usize,
    knots: &[f64],
) -> Result<(), GeometryError> {
    if !(1..=MAX_DEGREE).contains(&degree) {
        return Err(GeometryError::Degree {
            at: Location::field(field),
            degree,
            max: MAX_DEGREE,
        });
    }
    if count < degree + 1 {
        return Err(GeometryError::TooFewControlPoints {
            at: Location::field(field),
            count,
            degree,
        });
    }
    let expected = count + degree + 1;
    if knots.len() != expected {
        return Err(GeometryError::KnotCount {
            at: Location::field(field),
            found: knots.len(),
            expected,
            count,
            degree,
        });
    }
    if let Some((index, &value)) = knots.iter().enumerate().find(|(_, k)| !k.is_finite()) {
        return Err(GeometryError::NonFiniteKnot {
            at: Location::field(field).index(index),
            value,
        });
    }
    if let Some(index) = (1..knots.len()).find(|&i| knots[i] < knots[i - 1]) {
        return Err(GeometryError::DecreasingKnot {
            at: Location::field(field).index(index),
            value: knots[index],
            previous: knots[index - 1],
        });
    }
    let mut start = 0;
    while start < knots.len() {
        let mut end = start + 1;
        while end < knots.len() && knots[end] == knots[start] {
            end += 1;
        }
        let multiplicity = end - start;
        let at_end = start == 0 || end == knots.len();
        let (max, reason) = if at_end {
            (degree + 1, "end knots may repeat at most degree + 1 times")
        } else {
            (
                degree,
                "interior knots may repeat at most degree times; more would disconnect the curve",
            )
        };
        if multiplicity > max {
            return Err(GeometryError::KnotMultiplicity {
                at: Location::field(field).index(start),
                value: knots[start],
                multiplicity,
                max,
                reason,
            });
        }
        start = end;
    }
    let (lo, hi) = (knots[degree], knots[count]);
    if lo >= hi {
        return Err(GeometryError::EmptyDomain {
            at: Location::field(field),
            start: lo,
            end: hi,
        });
    }
    Ok(())
}

/// The knot span index i with u_i ≤ u < u_{i+1}, p ≤ i ≤ n, for a parameter in the domain
/// (The NURBS Book, A2.1 "FindSpan", by binary search). At the domain end u = u_{n+1} it returns
/// the last non-empty span, so the end point is evaluated from the left. Parameters outside the
/// domain are clamped to it.
pub fn find_span(knots: &[f64], degree: usize, count: usize, u: f64) -> usize {
    let n = count - 1;
    if u >= knots[n + 1] {
        // The largest i with u_i < u_{n+1}: the last non-empty span.
        let end = knots[n + 1];
        return (knots.partition_point(|&k| k < end) - 1).clamp(degree, n);
    }
    (knots.partition_point(|&k| k <= u).saturating_sub(1)).clamp(degree, n)
}

/// Whether `value` lies in [start, end] up to rounding: at most 8 units in the last place of
/// the domain's magnitude outside it. A parameter computed as a + (b − a) t lands an ulp past
/// b as often as not, and the evaluation there (the end span extended by that rounding) is the
/// end's to the same rounding, so it is accepted rather than refused. NaN is not.
pub fn in_domain(value: f64, start: f64, end: f64) -> bool {
    let slack = 8.0 * f64::EPSILON * start.abs().max(end.abs()).max(end - start);
    value >= start - slack && value <= end + slack
}

/// The parameter domain [u_p, u_{n+1}] of a knot vector.
pub fn domain(knots: &[f64], degree: usize, count: usize) -> (f64, f64) {
    (knots[degree], knots[count])
}

/// The non-vanishing basis functions N_{span−p,p}(u) … N_{span,p}(u) written into
/// `out[0..=p]` (The NURBS Book, A2.2 "BasisFuns"). The book's `left[j]` = u − u_{span+1−j}
/// and `right[j]` = u_{span+j} − u are read from the knots where they are used, so nothing
/// is allocated or cleared; the arithmetic is the same, in the same order, as the first half
/// of A2.3 ([`basis_derivatives_into`] with order 0), so both give the same bits. `out` must
/// hold degree + 1 values.
pub fn basis_functions(knots: &[f64], degree: usize, span: usize, u: f64, out: &mut [f64]) {
    out[0] = 1.0;
    for j in 1..=degree {
        let mut saved = 0.0;
        for r in 0..j {
            let right = knots[span + r + 1] - u;
            let left = u - knots[span + 1 + r - j];
            let temp = out[r] / (right + left);
            out[r] = saved + right * temp;
            saved = left * temp;
        }
        out[j] = saved;
    }
}

/// Degrees up to this value use stack scratch space in [`basis_derivatives_into`].
const STACK_DEGREE: usize = 7;
const STACK_ORDER: usize = STACK_DEGREE + 1;

/// The non-vanishing basis functions and their derivatives up to `order` at `u`:
/// `out[k * (p + 1) + j]` = d^k/du^k N_{span−p+j,p}(u) (The NURBS Book, A2.3 "DersBasisFuns").
/// Derivatives of order above p are zero. `out` must hold (order + 1)(p + 1) values.
pub fn basis_derivatives_into(
    knots: &[f64],
    degree: usize,
    span: usize,
    u: f64,
    order: usize,
    out: &mut [f64],
) {
    let size = degree + 1;
    if degree <= STACK_DEGREE {
        let mut ndu = [0.0; STACK_ORDER * STACK_ORDER];
        let mut a = [0.0; 2 * STACK_ORDER];
        let mut left = [0.0; STACK_ORDER];
        let mut right = [0.0; STACK_ORDER];
        let scratch = Scratch {
            ndu: &mut ndu[..size * size],
            a: &mut a[..2 * size],
            left: &mut left[..size],
            right: &mut right[..size],
        };
        derivatives_with(knots, degree, span, u, order, scratch, out);
    } else {
        let mut ndu = vec![0.0; size * size];
        let mut a = vec![0.0; 2 * size];
        let mut left = vec![0.0; size];
        let mut right = vec![0.0; size];
        let scratch = Scratch {
            ndu: &mut ndu,
            a: &mut a,
            left: &mut left,
            right: &mut right,
        };
        derivatives_with(knots, degree, span, u, order, scratch, out);
    }
}

/// [`basis_derivatives_into`] returning `ders[k][j]`, for tests and one-off use.
pub fn basis_derivatives(
    knots: &[f64],
    degree: usize,
    span: usize,
    u: f64,
    order: usize,
) -> Vec<Vec<f64>> {
    let mut flat = vec![0.0; (order + 1) * (degree + 1)];
    basis_derivatives_into(knots, degree, span, u, order, &mut flat);
    flat.chunks(degree + 1).map(<[f64]>::to_vec).collect()
}

struct Scratch<'a> {
    /// ndu[j * size + r]: basis functions (upper triangle) and knot differences (lower).
    ndu: &'a mut [f64],
    /// Two rows of the derivative coefficients a_{k,j}.
    a: &'a mut [f64],
    left: &'a mut [f64],
    right: &'a mut [f64],
}

/// The body of A2.3, with the book's variable names.
fn derivatives_with(
    knots: &[f64],
    p: usize,
    span: usize,
    u: f64,
    order: usize,
    s: Scratch<'_>,
    out: &mut [f64],
) {
    let size = p + 1;
    let Scratch {
        ndu,
        a,
        left,
        right,
    } = s;
    ndu[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences.
            ndu[j * size + r] = right[r + 1] + left[j - r];
            let temp = ndu[r * size + j - 1] / ndu[j * size + r];
            // Upper triangle: basis functions.
            ndu[r * size + j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j * size + j] = saved;
    }
    for j in 0..=p {
        out[j] = ndu[j * size + p];
    }
    let top = order.min(p);
    for k in top + 1..=order {
        out[k * size..(k + 1) * size].fill(0.0);
    }
    let p_i = p as isize;
    for r in 0..=p {
        let ri = r as isize;
        let (mut s1, mut s2) = (0usize, size);
        a[0] = 1.0;
        for k in 1..=top {
            let ki = k as isize;
            let mut d = 0.0;
            let rk = ri - ki;
            let pk = p_i - ki;
            let pk1 = (pk + 1) as usize;
            if r >= k {
                let rk = rk as usize;
                a[s2] = a[s1] / ndu[pk1 * size + rk];
                d = a[s2] * ndu[rk * size + pk as usize];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if ri - 1 <= pk { k - 1 } else { p - r };
            for j in j1..=j2 {
                let col = (rk + j as isize) as usize;
                a[s2 + j] = (a[s1 + j] - a[s1 + j - 1]) / ndu[pk1 * size + col];
                d += a[s2 + j] * ndu[col * size + pk as usize];
            }
            if ri <= pk {
                a[s2 + k] = -a[s1 + k - 1] / ndu[pk1 * size + r];
                d += a[s2 + k] * ndu[r * size + pk as usize];
            }
            out[k * size + r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for k in 1..=top {
        for value in &mut out[k * size..(k + 1) * size] {
            *value *= factor;
        }
        factor *= (p - k) as f64;
    }
}

/// How often `value` occurs in `knots` (exact comparison).
pub fn multiplicity(knots: &[f64], value: f64) -> usize {
    knots.iter().filter(|&&k| k == value).count()
}

/// The distinct interior knots of a knot vector, with their multiplicities, in increasing order.
pub fn interior_knots(knots: &[f64], degree: usize, count: usize) -> Vec<(f64, usize)> {
    let (lo, hi) = domain(knots, degree, count);
    let mut result: Vec<(f64, usize)> = Vec::new();
    for &k in knots.iter().filter(|&&k| k > lo && k < hi) {
        match result.last_mut() {
            Some((value, m)) if *value == k => *m += 1,
            _ => result.push((k, 1)),
        }
    }
    result
}

/// Merges the interior knots `have` (values with multiplicities) into `union`, keeping each
/// value's highest multiplicity; values within `tolerance` are one knot. `union` stays sorted.
/// With [`missing_knots`], what brings several B-splines to one knot vector (The NURBS Book
/// §10.3).
pub fn merge_knots(union: &mut Vec<(f64, usize)>, have: &[(f64, usize)], tolerance: f64) {
    for &(k, m) in have {
        match union.iter_mut().find(|(u, _)| (*u - k).abs() <= tolerance) {
            Some(entry) => entry.1 = entry.1.max(m),
            None => union.push((k, m)),
        }
    }
    union.sort_by(|a, b| a.0.total_cmp(&b.0));
}

/// The knots to insert into a B-spline with interior knots `own` to reach `union` (as from
/// [`merge_knots`]), each value repeated as often as it is missing, in increasing order.
pub fn missing_knots(own: &[(f64, usize)], union: &[(f64, usize)], tolerance: f64) -> Vec<f64> {
    let mut missing = Vec::new();
    for &(k, m) in union {
        let have = own
            .iter()
            .find(|(u, _)| (*u - k).abs() <= tolerance)
            .map_or(0, |e| e.1);
        missing.extend(std::iter::repeat_n(k, m.saturating_sub(have)));
    }
    missing
}

/// A clamped knot vector on [0, 1] with uniformly spaced interior knots for `count` control
/// points of degree `degree` (the default for new surfaces). `count` must be ≥ degree + 1.
pub fn uniform_clamped_knots(degree: usize, count: usize) -> Vec<f64> {
    let spans = count - degree;
    let mut knots = vec![0.0; degree + 1];
    knots.extend((1..spans).map(|i| i as f64 / spans as f64));
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    knots
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The NURBS Book, Ex. 2.3: U = {0,0,0,1,2,3,4,4,5,5,5}, p = 2, u = 5/2 gives span 4 and
    /// N_{2,2} = 1/8, N_{3,2} = 6/8, N_{4,2} = 1/8.
    #[test]
    fn nurbs_book_example_2_3() {
        let knots = [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0, 5.0, 5.0, 5.0];
        let span = find_span(&knots, 2, 8, 2.5);
        assert_eq!(span, 4);
        let mut n = [0.0; 3];
        basis_functions(&knots, 2, span, 2.5, &mut n);
        for (got, want) in n.iter().zip([0.125, 0.75, 0.125]) {
            assert!((got - want).abs() < 1e-15, "{n:?}");
        }
        // Ex. 2.4 derivatives: N'_{2,2}(5/2) = −1/2, N'_{3,2} = 0, N'_{4,2} = 1/2.
        let d = basis_derivatives(&knots, 2, span, 2.5, 2);
        for (got, want) in d[1].iter().zip([-0.5, 0.0, 0.5]) {
            assert!((got - want).abs() < 1e-15, "{d:?}");
        }
        // Second derivatives: N''_{2,2} = 1, N''_{3,2} = −2, N''_{4,2} = 1.
        for (got, want) in d[2].iter().zip([1.0, -2.0, 1.0]) {
            assert!((got - want).abs() < 1e-14, "{d:?}");
        }
    }

    #[test]
    fn basis_functions_give_the_same_bits_as_the_first_row_of_a2_3() {
        // Clamped knots with repeated interior knots, degrees 1 to 9, many parameters.
        for p in 1..=9 {
            let mut knots = vec![0.0; p + 1];
            knots.extend([0.5, 1.0, 1.0, 2.25, 3.0, 3.0, 3.0, 4.5]);
            knots.extend(vec![6.0; p + 1]);
            let count = knots.len() - p - 1;
            for k in 0..=300 {
                let u = 6.0 * k as f64 / 300.0;
                let span = find_span(&knots, p, count, u);
                let mut fast = vec![0.0; p + 1];
                basis_functions(&knots, p, span, u, &mut fast);
                let reference = basis_derivatives(&knots, p, span, u, 0);
                assert_eq!(fast, reference[0], "degree {p}, u = {u}");
                let sum: f64 = fast.iter().sum();
                assert!((sum - 1.0).abs() < 1e-14, "partition of unity: {sum}");
            }
        }
    }

    #[test]
    fn span_at_domain_end_is_last_nonempty() {
        let knots = [0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0, 5.0, 5.0, 5.0];
        assert_eq!(find_span(&knots, 2, 8, 5.0), 7);
        assert_eq!(find_span(&knots, 2, 8, 0.0), 2);
        assert_eq!(find_span(&knots, 2, 8, 4.0), 7);
        assert_eq!(find_span(&knots, 2, 8, 3.999), 5);
    }
}
