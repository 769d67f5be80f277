//! Grid tessellation four rows at a time: [`NurbsSurface::tessellate_grid`] and
//! [`NurbsSurface::curvature_grid`] for v-degrees 1 to 5.
//!
//! Four grid rows (four values of u) share every column's v-span and v-basis, so the rows are
//! lanes of [`F4`]: per row the control net is reduced to the homogeneous isoparametric curve
//! (and its u-derivatives) once (The NURBS Book, A4.3 split into its two sums), and per column
//! each derivative is one (q + 1)-term sum over four rows at once, with the same scalar basis
//! value in every lane. The rational derivatives (eq. 4.20), the normal and the curvature
//! (diffgeo) follow lane by lane with the scalar formulas in the same order, so a lane gives the
//! bits the scalar code would. Points where the tangent plane degenerates leave the lanes and
//! take the scalar limit rules.

use glam::DVec4;

use super::{GridSample, NurbsSurface, ParameterBasis};
use crate::diffgeo::{CurvatureValues, DEGENERATE_SIN2, SurfaceDerivatives, rational_derivatives};
use crate::lanes::{F4, H4, V3, and, weighted_sum};

/// What a grid evaluation writes per point.
pub(crate) trait GridOutput: Copy + Default {
    /// Whether second derivatives and the curvature values are wanted.
    const CURVATURE: bool;
    fn from_parts(sample: GridSample, curvature: CurvatureValues) -> Self;
}

impl GridOutput for GridSample {
    const CURVATURE: bool = false;
    fn from_parts(sample: GridSample, _: CurvatureValues) -> Self {
        sample
    }
}

impl GridOutput for (GridSample, CurvatureValues) {
    const CURVATURE: bool = true;
    fn from_parts(sample: GridSample, curvature: CurvatureValues) -> Self {
        (sample, curvature)
    }
}

/// The Cartesian derivatives of four points (eq. 4.20 lane by lane; second ones only when
/// asked for, else zero).
#[derive(Clone, Copy, Default)]
struct Derivatives4 {
    point: V3,
    su: V3,
    sv: V3,
    suu: V3,
    suv: V3,
    svv: V3,
}

impl Derivatives4 {
    fn lane(&self, l: usize) -> SurfaceDerivatives {
        SurfaceDerivatives {
            point: self.point.lane(l),
            su: self.su.lane(l),
            sv: self.sv.lane(l),
            suu: self.suu.lane(l),
            suv: self.suv.lane(l),
            svv: self.svv.lane(l),
        }
    }
}

impl NurbsSurface {
    /// Appends the grid `us` × `vs` (row-major, i along u) to `out`; the v-order `Q` = q + 1
    /// is known at compile time and the parameters are already checked. Runs the AVX2 build of
    /// the loop where the CPU has it.
    pub(super) fn grid_lanes<const Q: usize, T: GridOutput>(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<T>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the function only enables AVX2, which the CPU was just found to have.
            unsafe { self.grid_lanes_avx2::<Q, T>(us, vs, out) };
            return;
        }
        self.grid_lanes_body::<Q, T>(us, vs, out);
    }

    /// [`Self::grid_lanes_body`] compiled with AVX2: each [`F4`] operation one instruction.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn grid_lanes_avx2<const Q: usize, T: GridOutput>(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<T>,
    ) {
        self.grid_lanes_body::<Q, T>(us, vs, out);
    }

    /// The baseline build of the loop (what a CPU without AVX2, or WebAssembly, runs).
    #[cfg(test)]
    pub(crate) fn grid_lanes_baseline<const Q: usize, T: GridOutput>(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<T>,
    ) {
        self.grid_lanes_body::<Q, T>(us, vs, out);
    }

    #[inline(always)]
    fn grid_lanes_body<const Q: usize, T: GridOutput>(
        &self,
        us: &[f64],
        vs: &[f64],
        out: &mut Vec<T>,
    ) {
        let [p, q] = self.degree;
        debug_assert_eq!(q + 1, Q);
        let order = if T::CURVATURE { 2 } else { 1 };
        let basis_u = ParameterBasis::new(&self.knots[0], p, self.count[0], us, order);
        let basis_v = ParameterBasis::new(&self.knots[1], q, self.count[1], vs, order);
        let fixed_v: Vec<(usize, [[f64; Q]; 3])> = (0..vs.len())
            .map(|t| {
                let mut d = [[0.0; Q]; 3];
                for (k, row) in d.iter_mut().enumerate().take(order + 1) {
                    row.copy_from_slice(basis_v.at(t, k, Q));
                }
                (basis_v.spans[t] - q, d)
            })
            .collect();
        let cv = self.count[1];
        let nv = vs.len();
        // iso[k][j]: ∂^k/∂u^k of the homogeneous isoparametric curve's point j, for four rows.
        let mut iso = [
            vec![H4::default(); cv],
            vec![H4::default(); cv],
            vec![H4::default(); cv],
        ];
        out.reserve(us.len() * nv);
        for first_row in (0..us.len()).step_by(4) {
            let live = (us.len() - first_row).min(4);
            // Lanes past the last row repeat it, and are not written out.
            let rows_of_lanes: [usize; 4] = std::array::from_fn(|l| first_row + l.min(live - 1));
            for (k, iso_k) in iso.iter_mut().enumerate().take(order + 1) {
                for (l, &i) in rows_of_lanes.iter().enumerate() {
                    let span_u = basis_u.spans[i];
                    let bu = basis_u.at(i, k, p + 1);
                    let net = &self.points[(span_u - p) * cv..(span_u + 1) * cv];
                    for (j, slot) in iso_k.iter_mut().enumerate() {
                        let mut acc = DVec4::ZERO;
                        for (r, &b) in bu.iter().enumerate() {
                            acc += net[r * cv + j] * b;
                        }
                        slot.set_lane(l, acc);
                    }
                }
            }
            // The group's rows are the next `live` × `nv` slots of `out`.
            let rows = &mut out.spare_capacity_mut()[..live * nv];
            for (j, (first, bv)) in fixed_v.iter().enumerate() {
                let window = |k: usize| -> &[H4; Q] {
                    iso[k][*first..*first + Q]
                        .try_into()
                        .unwrap_or_else(|_| unreachable!("span window has Q points"))
                };
                let (p0, p1) = (window(0), window(1));
                let a00 = weighted_sum(p0, &bv[0]);
                let a01 = weighted_sum(p0, &bv[1]);
                let a10 = weighted_sum(p1, &bv[0]);
                let v = vs[j];
                if T::CURVATURE {
                    let p2 = window(2);
                    let a02 = weighted_sum(p0, &bv[2]);
                    let a11 = weighted_sum(p1, &bv[1]);
                    let a20 = weighted_sum(p2, &bv[0]);
                    let d = second_derivatives(a00, a01, a02, a10, a11, a20);
                    let (normal, regular) = regular_normal(&d);
                    let (values, finite) = curvature_values(&d, normal);
                    let good = and(regular, finite);
                    let mut samples: [T; 4] = std::array::from_fn(|l| {
                        T::from_parts(
                            GridSample {
                                point: d.point.lane(l),
                                normal: normal.lane(l),
                            },
                            values[l],
                        )
                    });
                    for l in (0..live).filter(|&l| !good[l]) {
                        let (u, dl) = (us[first_row + l], d.lane(l));
                        let n = self.normal_from(&dl, u, v);
                        samples[l] = T::from_parts(
                            GridSample {
                                point: dl.point,
                                normal: n,
                            },
                            self.curvature_from(&dl, n, u, v).values(),
                        );
                    }
                    store(rows, nv, j, live, samples);
                } else {
                    let w = a00.w;
                    let point = a00.xyz.div(w);
                    // Su and Sv scaled by w² > 0: same directions, no divisions.
                    let tu = a10.xyz.scale(w) - a00.xyz.scale(a10.w);
                    let tv = a01.xyz.scale(w) - a00.xyz.scale(a01.w);
                    let n = tu.cross(tv);
                    let n2 = n.length_squared();
                    // Both tests of `regular_normal`: at a pole of a rational surface the
                    // derivative along the collapsed edge is rounding noise that can pass the
                    // sin² test alone.
                    let regular = regular_lanes(n2, tu.length_squared(), tv.length_squared());
                    let normal = n.scale(F4::splat(1.0) / n2.sqrt());
                    let mut samples: [T; 4] = std::array::from_fn(|l| {
                        T::from_parts(
                            GridSample {
                                point: point.lane(l),
                                normal: normal.lane(l),
                            },
                            CurvatureValues::default(),
                        )
                    });
                    for l in (0..live).filter(|&l| !regular[l]) {
                        let u = us[first_row + l];
                        let d = rational_derivatives(&self.homogeneous_derivatives(u, v));
                        samples[l] = T::from_parts(
                            GridSample {
                                point: point.lane(l),
                                normal: self.normal_from(&d, u, v),
                            },
                            CurvatureValues::default(),
                        );
                    }
                    store(rows, nv, j, live, samples);
                }
            }
            let written = out.len() + live * nv;
            // SAFETY: the loop over the columns wrote every one of the group's `live` × `nv`
            // slots (`store` writes each column's `live` rows), so they are initialized.
            unsafe { out.set_len(written) };
        }
    }
}

/// Writes the first `live` lanes' samples into column `j` of the group's rows.
#[inline(always)]
fn store<T: Copy>(
    rows: &mut [std::mem::MaybeUninit<T>],
    nv: usize,
    j: usize,
    live: usize,
    samples: [T; 4],
) {
    for (l, sample) in samples.into_iter().enumerate().take(live) {
        rows[l * nv + j].write(sample);
    }
}

/// Eq. 4.20 for four points, in the order of [`rational_derivatives`].
#[inline(always)]
fn second_derivatives(a00: H4, a01: H4, a02: H4, a10: H4, a11: H4, a20: H4) -> Derivatives4 {
    let w0 = a00.w;
    let point = a00.xyz.div(w0);
    let inv = F4::splat(1.0) / w0;
    let su = (a10.xyz - point.scale(a10.w)).scale(inv);
    let sv = (a01.xyz - point.scale(a01.w)).scale(inv);
    let suu = (a20.xyz - su.scale(a10.w * 2.0) - point.scale(a20.w)).scale(inv);
    let svv = (a02.xyz - sv.scale(a01.w * 2.0) - point.scale(a02.w)).scale(inv);
    let suv = (a11.xyz - sv.scale(a10.w) - su.scale(a01.w) - point.scale(a11.w)).scale(inv);
    Derivatives4 {
        point,
        su,
        sv,
        suu,
        suv,
        svv,
    }
}

/// [`SurfaceDerivatives::regular_normal`] for four points: the unit normals and which lanes
/// are regular.
#[inline(always)]
fn regular_normal(d: &Derivatives4) -> (V3, [bool; 4]) {
    let n = d.su.cross(d.sv);
    let n2 = n.length_squared();
    let regular = regular_lanes(n2, d.su.length_squared(), d.sv.length_squared());
    (n.div(n2.sqrt()), regular)
}

/// The lanes where the tangent plane is regular, by the tests of
/// [`SurfaceDerivatives::regular_normal`] from |n|² = |a × b|², |a|² and |b|²: sin² of the
/// angle above [`DEGENERATE_SIN2`], and neither vector vanishing against the other. The tests
/// are scale-free, so a and b may be Su and Sv scaled alike (by w²).
#[inline(always)]
fn regular_lanes(n2: F4, a: F4, b: F4) -> [bool; 4] {
    let limit = F4::splat(DEGENERATE_SIN2);
    and(
        and(n2.gt(limit * (a * b)), n2.gt(F4::splat(0.0))),
        a.min(b).gt(limit * a.max(b)),
    )
}

/// [`CurvatureValues::from_forms`] of [`crate::diffgeo::FundamentalForms::new`] for four
/// points: the values and which lanes have EG − F² > 0 and finite.
#[inline(always)]
fn curvature_values(d: &Derivatives4, normal: V3) -> ([CurvatureValues; 4], [bool; 4]) {
    let (e, f, g) = (d.su.dot(d.su), d.su.dot(d.sv), d.sv.dot(d.sv));
    let (l, m, n) = (d.suu.dot(normal), d.suv.dot(normal), d.svv.dot(normal));
    let det = e * g - f * f;
    let valid = and(det.gt(F4::splat(0.0)), det.is_finite());
    let inv = F4::splat(1.0) / det;
    let gaussian = (l * n - m * m) * inv;
    let mean = (e * n - f * 2.0 * m + g * l) * (inv * 0.5);
    let disc = (mean * mean - gaussian).max(F4::splat(0.0)).sqrt();
    let (k1, k2) = (mean + disc, mean - disc);
    let values = std::array::from_fn(|lane| CurvatureValues {
        gaussian: gaussian.0[lane],
        mean: mean.0[lane],
        k1: k1.0[lane],
        k2: k2.0[lane],
    });
    (values, valid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::construct;
    use glam::{DAffine3, DQuat, DVec3};

    /// xorshift64: the tests need no random-number crate.
    struct Random(u64);

    impl Random {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn below(&mut self, n: usize) -> usize {
            (self.next() * n as f64) as usize % n
        }

        /// A clamped knot vector with random interior knots (one of them doubled when
        /// `degree` > 1) on a random interval.
        fn knots(&mut self, degree: usize, count: usize) -> Vec<f64> {
            let (start, length) = (self.next() * 4.0 - 2.0, 0.5 + 3.0 * self.next());
            let mut interior: Vec<f64> = (0..count - degree - 1)
                .map(|_| start + length * (0.05 + 0.9 * self.next()))
                .collect();
            interior.sort_by(f64::total_cmp);
            if degree > 1 && interior.len() > 2 {
                interior[1] = interior[0];
            }
            let mut knots = vec![start; degree + 1];
            knots.extend(interior);
            knots.extend(vec![start + length; degree + 1]);
            knots
        }

        /// `count` parameters over `range`, the ends included, in random order of spacing.
        fn params(&mut self, (a, b): (f64, f64), count: usize) -> Vec<f64> {
            let mut t: Vec<f64> = (0..count - 2).map(|_| a + (b - a) * self.next()).collect();
            t.extend([a, b]);
            t.sort_by(f64::total_cmp);
            t
        }
    }

    /// A random rational surface of degree (p, q) in general position: random control
    /// points, weights in [0.3, 2.3], non-uniform knots, then a random rotation, scale and
    /// translation.
    fn random_surface(random: &mut Random, degree: [usize; 2]) -> NurbsSurface {
        let count = [
            degree[0] + 2 + random.below(4),
            degree[1] + 2 + random.below(4),
        ];
        let motion = DAffine3::from_scale_rotation_translation(
            DVec3::splat(0.1 + 10.0 * random.next()),
            DQuat::from_euler(
                glam::EulerRot::XYZ,
                6.0 * random.next(),
                6.0 * random.next(),
                6.0 * random.next(),
            ),
            DVec3::new(random.next(), random.next(), random.next()) * 200.0 - 100.0,
        );
        let points = (0..count[0] * count[1])
            .map(|_| {
                motion.transform_point3(
                    DVec3::new(random.next(), random.next(), random.next()) * 4.0 - 2.0,
                )
            })
            .collect();
        let weights = (0..count[0] * count[1])
            .map(|_| 0.3 + 2.0 * random.next())
            .collect();
        NurbsSurface::new(
            degree,
            [
                random.knots(degree[0], count[0]),
                random.knots(degree[1], count[1]),
            ],
            count,
            points,
            Some(weights),
        )
        .unwrap_or_else(|e| panic!("test surface: {e}"))
    }

    fn same_bits<const Q: usize, T: GridOutput + PartialEq + std::fmt::Debug>(
        s: &NurbsSurface,
        us: &[f64],
        vs: &[f64],
    ) {
        let (mut wide, mut baseline) = (Vec::<T>::new(), Vec::<T>::new());
        s.grid_lanes::<Q, T>(us, vs, &mut wide);
        s.grid_lanes_baseline::<Q, T>(us, vs, &mut baseline);
        assert_eq!(wide.len(), us.len() * vs.len());
        assert_eq!(wide, baseline);
    }

    #[test]
    fn the_avx2_and_baseline_builds_give_the_same_bits() {
        let mut random = Random(0x9e37_79b9_7f4a_7c15);
        for _ in 0..4 {
            for q in [2, 5] {
                let p = 1 + random.below(5);
                let s = random_surface(&mut random, [p, q]);
                let [du, dv] = s.domain();
                // 11 rows: two full groups of four lanes and a group of three.
                let (us, vs) = (random.params(du, 11), random.params(dv, 9));
                if q == 2 {
                    same_bits::<3, GridSample>(&s, &us, &vs);
                    same_bits::<3, (GridSample, CurvatureValues)>(&s, &us, &vs);
                } else {
                    same_bits::<6, GridSample>(&s, &us, &vs);
                    same_bits::<6, (GridSample, CurvatureValues)>(&s, &us, &vs);
                }
            }
        }
    }

    /// Every grid point against the pointwise evaluation (A3.6 and eq. 4.20 at one parameter,
    /// a separate code path): random degrees 1 to 6 in both directions (6 in v takes the
    /// unspecialized loop), grids of every row count modulo four.
    #[test]
    fn grids_equal_pointwise_evaluation_in_general_position() {
        let mut random = Random(0x2545_f491_4f6c_dd1d);
        for case in 0..60 {
            let degree = [1 + random.below(6), 1 + random.below(6)];
            let s = random_surface(&mut random, degree);
            let [du, dv] = s.domain();
            let rows_v = 2 + random.below(12);
            let (us, vs) = (random.params(du, 2 + case % 9), random.params(dv, rows_v));
            let size = s
                .points
                .iter()
                .map(|h| (h.truncate() / h.w).length())
                .fold(1.0, f64::max);
            let fast = s
                .tessellate_grid(&us, &vs)
                .unwrap_or_else(|e| panic!("{e}"));
            let full = s.curvature_grid(&us, &vs).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                (fast.len(), full.len()),
                (us.len() * vs.len(), us.len() * vs.len())
            );
            for (i, &u) in us.iter().enumerate() {
                for (j, &v) in vs.iter().enumerate() {
                    let at = i * vs.len() + j;
                    let g = s.local_geometry(u, v).unwrap_or_else(|e| panic!("{e}"));
                    let (sample, curvature) = full[at];
                    let context = || format!("case {case}, degree {degree:?}, ({u}, {v})");
                    assert!(
                        fast[at].point.distance(g.derivatives.point) <= 1e-12 * size,
                        "{}",
                        context()
                    );
                    assert_eq!(fast[at].point, sample.point, "{}", context());
                    assert!(fast[at].normal.distance(g.normal) < 1e-8, "{}", context());
                    assert!(sample.normal.distance(g.normal) < 1e-8, "{}", context());
                    let c = g.curvature;
                    for (a, b) in [
                        (curvature.gaussian, c.gaussian),
                        (curvature.mean, c.mean),
                        (curvature.k1, c.k1),
                        (curvature.k2, c.k2),
                    ] {
                        let scale = 1.0 + c.k1.abs().max(c.k2.abs());
                        assert!(
                            (a - b).abs() <= 1e-7 * scale * scale,
                            "{}: {a} vs {b}",
                            context()
                        );
                    }
                }
            }
        }
    }

    /// A sphere's poles are degenerate points in the middle of a four-lane group: they leave
    /// the lanes for the limit rules, and every point keeps the closed form (the normal is
    /// radial, K = 1/r²).
    #[test]
    fn degenerate_lanes_take_the_limit_rules_on_a_sphere() {
        let (center, radius) = (DVec3::new(3.0, -1.0, 2.0), 1.7);
        let s = construct::sphere(center, radius).unwrap_or_else(|e| panic!("{e}"));
        let [du, dv] = s.domain();
        for (su, sv) in [(9, 13), (13, 9), (6, 7)] {
            let us: Vec<f64> = (0..su)
                .map(|k| du.0 + (du.1 - du.0) * k as f64 / (su - 1) as f64)
                .collect();
            let vs: Vec<f64> = (0..sv)
                .map(|k| dv.0 + (dv.1 - dv.0) * k as f64 / (sv - 1) as f64)
                .collect();
            let fast = s
                .tessellate_grid(&us, &vs)
                .unwrap_or_else(|e| panic!("{e}"));
            let full = s.curvature_grid(&us, &vs).unwrap_or_else(|e| panic!("{e}"));
            for (k, (a, (b, c))) in fast.iter().zip(&full).enumerate() {
                let radial = (a.point - center) / radius;
                assert!((radial.length() - 1.0).abs() < 1e-12);
                // One orientation throughout (the sphere's normals all point the same way).
                let sign = fast[0]
                    .normal
                    .dot((fast[0].point - center).normalize())
                    .signum();
                assert!(a.normal.distance(sign * radial) < 1e-6, "{a:?}");
                assert!(b.normal.distance(sign * radial) < 1e-6, "{b:?}");
                // At the poles K is the limit sampled just inside (CURVATURE_NUDGE), the same
                // as the pointwise evaluation's.
                assert!((c.gaussian * radius * radius - 1.0).abs() < 1e-3, "{c:?}");
                let (u, v) = (us[k / vs.len()], vs[k % vs.len()]);
                let g = s.local_geometry(u, v).unwrap_or_else(|e| panic!("{e}"));
                assert!(
                    (c.gaussian - g.curvature.gaussian).abs() < 1e-9,
                    "{c:?} {g:?}"
                );
            }
        }
    }
}
