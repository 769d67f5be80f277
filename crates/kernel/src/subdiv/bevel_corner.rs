//! The mesh that fills a bevel's corner where three or more beveled edges meet and the bevel
//! has more than one segment: Blender's "adj" vertex mesh, built as its bevel tool builds it.
//!
//! The corner is bounded by the profiles (arcs) of its n beveled edges, side i running from
//! boundary point i to boundary point i + 1. Its points are addressed (i, j, k): side i, ring j
//! counted in from the border (0 ..= ns/2), step k along side i (0 ..= ns). Points near where
//! two sides meet belong to both; one of the names is canonical and holds the point.
//!
//! The mesh starts as a two-segment net (the border points, each profile's middle and one
//! centre point), is refined by Catmull–Clark steps whose border rule keeps it on the profiles
//! (Levin, "Filling an n-sided hole using combined subdivision schemes", 1999; Sabin's variant
//! at the centre) until it has at least ns segments, then is resampled to exactly ns by
//! interpolation along the arcs' chord lengths. A corner where three faces meet nearly square
//! is instead the octant of a sphere mapped onto the corner, and a corner where two beveled
//! edges run on in line (a pipe) has its points pulled onto the pipe's round section.

use glam::{DMat3, DVec3};

/// Below this, Blender's bevel takes lengths and fractions as zero.
const EPSILON: f64 = 1e-6;

/// The points of a corner mesh of `n` sides and `ns` segments.
#[derive(Debug, Clone)]
pub(super) struct CornerGrid {
    pub n: usize,
    pub ns: usize,
    points: Vec<DVec3>,
}

impl CornerGrid {
    fn new(n: usize, ns: usize) -> Self {
        Self {
            n,
            ns,
            points: vec![DVec3::ZERO; n * (ns / 2 + 1) * (ns + 1)],
        }
    }

    fn slot(&self, i: usize, j: usize, k: usize) -> usize {
        (i * (self.ns / 2 + 1) + j) * (self.ns + 1) + k
    }

    /// The point (i, j, k), j ≤ ns/2.
    pub fn at(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.points[self.slot(i, j, k)]
    }

    fn set(&mut self, i: usize, j: usize, k: usize, p: DVec3) {
        let s = self.slot(i, j, k);
        self.points[s] = p;
    }

    /// The canonical name of (i, j, k) for j, k in 0 ..= ns: the lower-left quarter of side
    /// i's square, the rest named from the sides before and after it (and the centre, for
    /// even ns, from side 0).
    pub fn canonical(&self, i: usize, j: usize, k: usize) -> (usize, usize, usize) {
        let (n, ns) = (self.n, self.ns);
        let (half, odd) = (ns / 2, ns % 2);
        if odd == 0 && j == half && k == half {
            (0, j, k)
        } else if j < half + odd && k <= half {
            (i, j, k)
        } else if k <= half {
            ((i + n - 1) % n, k, ns - j)
        } else {
            ((i + 1) % n, ns - k, j)
        }
    }

    /// Whether (i, j, k) is its own canonical name.
    pub fn is_canonical(&self, i: usize, j: usize, k: usize) -> bool {
        self.canonical(i, j, k) == (i, j, k)
    }

    fn canon_at(&self, i: usize, j: usize, k: usize) -> DVec3 {
        let (a, b, c) = self.canonical(i, j, k);
        self.at(a, b, c)
    }

    fn set_canon(&mut self, i: usize, j: usize, k: usize, p: DVec3) {
        let (a, b, c) = self.canonical(i, j, k);
        self.set(a, b, c, p);
    }

    /// Copies every canonical point to its other names.
    fn copy_equivalents(&mut self) {
        for i in 0..self.n {
            for j in 0..=self.ns / 2 {
                for k in 0..=self.ns {
                    if !self.is_canonical(i, j, k) {
                        let p = self.canon_at(i, j, k);
                        self.set(i, j, k, p);
                    }
                }
            }
        }
    }

    fn map(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.points {
            *p = f(*p);
        }
    }
}

/// A side's profile: the point at fraction t in [0, 1] of side i's arc, from boundary point i
/// to boundary point i + 1.
pub(super) type SideProfile<'a> = &'a dyn Fn(usize, f64) -> DVec3;

fn mean4(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> DVec3 {
    (a + b + c + d) * 0.25
}

/// Sabin's γ for the centre of a Catmull–Clark step on n sides, which makes the limit smooth
/// there: the real root x of x³ + (4k² − 3)x − 2k = 0 with k = cos(π/n), and
/// γ = (kx + 2k² − 1) / (x²(kx + 1)).
fn sabin_gamma(n: usize) -> f64 {
    match n {
        0..=2 => 0.0,
        3 => 0.065247584,
        4 => 0.25,
        5 => 0.401983447,
        6 => 0.523423277,
        _ => sabin_gamma_solved(n),
    }
}

/// [`sabin_gamma`] from its cubic.
fn sabin_gamma_solved(n: usize) -> f64 {
    let k = (std::f64::consts::PI / n as f64).cos();
    let (k2, k4) = (k * k, k.powi(4));
    let k6 = k4 * k2;
    let y = (3f64.sqrt() * (64.0 * k6 - 144.0 * k4 + 135.0 * k2 - 27.0).sqrt() + 9.0 * k).cbrt();
    let x = 0.480749856769136 * y - (0.231120424783545 * (12.0 * k2 - 9.0)) / y;
    (k * x + 2.0 * k2 - 1.0) / (x * x * (k * x + 1.0))
}

/// How far a corner's centre starts from the boundary points' centroid towards the vertex,
/// for a circular profile of `segments` segments (Blender's fitted table, then its regression).
fn fullness(segments: usize) -> f64 {
    const CIRCLE: [f64; 11] = [
        0.0, 0.559, 0.642, 0.551, 0.646, 0.624, 0.646, 0.619, 0.647, 0.639, 0.647,
    ];
    match segments {
        1..=11 => CIRCLE[segments - 1],
        s if s % 2 == 0 => 2.4506 * 0.5 - 0.000003 * s as f64 - 0.6266,
        s => 2.3635 * 0.5 + 0.000152 * s as f64 - 0.6060,
    }
}

/// One Catmull–Clark step of a corner mesh with an even number of segments, doubling them.
/// Border points are smoothed by the cubic B-spline rule p − (p₋ + p₊ − 2p)/6 (the new ones
/// taken on the profile first); inner points follow Catmull–Clark with every border point
/// taken as of valence four; the centre takes Sabin's γ; the border is then set back on the
/// profiles.
fn cubic_step(input: &mut CornerGrid, profile: SideProfile) -> CornerGrid {
    let (n, ns_in) = (input.n, input.ns);
    let half = ns_in / 2;
    let ns_out = 2 * ns_in;
    let mut out = CornerGrid::new(n, ns_out);
    let smooth = |co: DVec3, before: DVec3, after: DVec3| co - (before + after - 2.0 * co) / 6.0;
    for i in 0..n {
        out.set(i, 0, 0, input.at(i, 0, 0));
        for k in 1..ns_in {
            let co = smooth(
                input.at(i, 0, k),
                input.at(i, 0, k - 1),
                input.at(i, 0, k + 1),
            );
            out.set_canon(i, 0, 2 * k, co);
        }
    }
    for i in 0..n {
        for k in (1..ns_out).step_by(2) {
            let on_profile = profile(i, k as f64 / ns_out as f64);
            let co = smooth(
                on_profile,
                out.canon_at(i, 0, k - 1),
                out.canon_at(i, 0, k + 1),
            );
            out.set_canon(i, 0, k, co);
        }
    }
    out.copy_equivalents();
    for i in 0..n {
        for k in 0..ns_in {
            let p = out.at(i, 0, 2 * k);
            input.set(i, 0, k, p);
        }
    }
    input.copy_equivalents();
    let g = &*input;
    // Face points.
    for i in 0..n {
        for j in 0..half {
            for k in 0..half {
                let co = mean4(
                    g.at(i, j, k),
                    g.at(i, j, k + 1),
                    g.at(i, j + 1, k),
                    g.at(i, j + 1, k + 1),
                );
                out.set(i, 2 * j + 1, 2 * k + 1, co);
            }
        }
    }
    // Edge points across the rings, then along them.
    for i in 0..n {
        for j in 0..half {
            for k in 1..=half {
                let co = mean4(
                    g.at(i, j, k),
                    g.at(i, j + 1, k),
                    out.canon_at(i, 2 * j + 1, 2 * k - 1),
                    out.canon_at(i, 2 * j + 1, 2 * k + 1),
                );
                out.set(i, 2 * j + 1, 2 * k, co);
            }
        }
    }
    for i in 0..n {
        for j in 1..half {
            for k in 0..half {
                let co = mean4(
                    g.at(i, j, k),
                    g.at(i, j, k + 1),
                    out.canon_at(i, 2 * j - 1, 2 * k + 1),
                    out.canon_at(i, 2 * j + 1, 2 * k + 1),
                );
                out.set(i, 2 * j, 2 * k + 1, co);
            }
        }
    }
    // Old inner points: edge mean − ¼ face mean + ¼ old point.
    for i in 0..n {
        for j in 1..half {
            for k in 1..=half {
                let edges = mean4(
                    out.canon_at(i, 2 * j, 2 * k - 1),
                    out.canon_at(i, 2 * j, 2 * k + 1),
                    out.canon_at(i, 2 * j - 1, 2 * k),
                    out.canon_at(i, 2 * j + 1, 2 * k),
                );
                let faces = mean4(
                    out.canon_at(i, 2 * j - 1, 2 * k - 1),
                    out.canon_at(i, 2 * j + 1, 2 * k - 1),
                    out.canon_at(i, 2 * j - 1, 2 * k + 1),
                    out.canon_at(i, 2 * j + 1, 2 * k + 1),
                );
                out.set(i, 2 * j, 2 * k, edges - 0.25 * faces + 0.25 * g.at(i, j, k));
            }
        }
    }
    out.copy_equivalents();
    let gamma = sabin_gamma(n);
    let (mut edges, mut faces) = (DVec3::ZERO, DVec3::ZERO);
    for i in 0..n {
        edges += out.at(i, ns_in, ns_in - 1);
        faces += out.at(i, ns_in - 1, ns_in - 1) + out.at(i, ns_in - 1, ns_in + 1);
    }
    let centre =
        edges / n as f64 - faces * (gamma / (2.0 * n as f64)) + g.at(0, half, half) * gamma;
    for i in 0..n {
        out.set(i, ns_in, ns_in, centre);
    }
    for i in 0..n {
        for k in 0..=ns_out {
            let co = profile(i, k as f64 / ns_out as f64);
            out.set(i, 0, k, co);
            if k >= ns_in && k < ns_out {
                out.set((i + 1) % n, ns_out - k, 0, co);
            }
        }
    }
    out.copy_equivalents();
    out
}

/// Fractions of the way along a polyline's length at each of its points.
fn chord_fractions(points: &[DVec3]) -> Vec<f64> {
    let mut fractions = vec![0.0; points.len()];
    let mut total = 0.0;
    for k in 1..points.len() {
        total += points[k].distance(points[k - 1]);
        fractions[k] = total;
    }
    if total > 0.0 {
        for f in &mut fractions[1..] {
            *f /= total;
        }
    } else if let Some(last) = fractions.last_mut() {
        *last = 1.0;
    }
    fractions
}

/// The step m with fractions[m] ≤ f ≤ fractions[m + 1] and how far f is between them.
fn locate(fractions: &[f64], f: f64) -> (usize, f64) {
    let n = fractions.len() - 1;
    for m in 0..n {
        if f <= fractions[m + 1] {
            let rest = f - fractions[m];
            let mut r = if rest == 0.0 {
                0.0
            } else {
                rest / (fractions[m + 1] - fractions[m])
            };
            let mut m = m;
            if m == n - 1 && r == 1.0 {
                m = n;
                r = 0.0;
            }
            return (m, r);
        }
    }
    (n, 0.0)
}

/// Resamples a corner mesh to `ns` segments: each new point is placed by the fractions of
/// the way along its side's arc and the side before's, bilinearly inside the old mesh.
fn resample(input: &CornerGrid, ns: usize, boundary: &[DVec3], profile: SideProfile) -> CornerGrid {
    let (n, ns_in) = (input.n, input.ns);
    let (half, odd) = (ns / 2, ns % 2);
    let mut out = CornerGrid::new(n, ns);
    let mesh_fractions = |i: usize| {
        let ring: Vec<DVec3> = (0..=ns_in).map(|k| input.at(i, 0, k)).collect();
        chord_fractions(&ring)
    };
    let profile_fractions = |i: usize| {
        let mut arc = vec![boundary[i]];
        arc.extend((1..=ns).map(|k| profile(i, k as f64 / ns as f64)));
        chord_fractions(&arc)
    };
    let mut previous = mesh_fractions(n - 1);
    let mut previous_new = profile_fractions(n - 1);
    for i in 0..n {
        let current = mesh_fractions(i);
        let current_new = profile_fractions(i);
        for j in 0..(half + odd) {
            for (k, &fraction) in current_new.iter().enumerate().take(half + 1) {
                let (k_in, rest_k) = locate(&current, fraction);
                let (k_prev, rest_prev) = locate(&previous, previous_new[ns - j]);
                let mut j_in = ns_in - k_prev;
                let mut rest_j = -rest_prev;
                if rest_j > -EPSILON {
                    rest_j = 0.0;
                } else {
                    j_in = j_in.saturating_sub(1);
                    rest_j += 1.0;
                }
                let co = if rest_j < EPSILON && rest_k < EPSILON {
                    input.canon_at(i, j_in, k_in)
                } else {
                    let dj = usize::from(!(rest_j < EPSILON || j_in == ns_in));
                    let dk = usize::from(!(rest_k < EPSILON || k_in == ns_in));
                    let q0 = input.canon_at(i, j_in, k_in);
                    let q1 = input.canon_at(i, j_in, k_in + dk);
                    let q2 = input.canon_at(i, j_in + dj, k_in + dk);
                    let q3 = input.canon_at(i, j_in + dj, k_in);
                    q0 * ((1.0 - rest_k) * (1.0 - rest_j))
                        + q1 * (rest_k * (1.0 - rest_j))
                        + q2 * (rest_k * rest_j)
                        + q3 * ((1.0 - rest_k) * rest_j)
                };
                out.set(i, j, k, co);
            }
        }
        previous = current;
        previous_new = current_new;
    }
    if odd == 0 {
        let h = ns_in / 2;
        let centre = if ns_in % 2 == 1 {
            (0..n).map(|i| input.at(i, h, h)).sum::<DVec3>() / n as f64
        } else {
            input.at(0, h, h)
        };
        out.set(0, half, half, centre);
    }
    out.copy_equivalents();
    out
}

/// Refines a two-segment net to `ns` segments.
fn refine(mut grid: CornerGrid, ns: usize, boundary: &[DVec3], profile: SideProfile) -> CornerGrid {
    while grid.ns < ns {
        grid = cubic_step(&mut grid, profile);
    }
    if grid.ns != ns {
        grid = resample(&grid, ns, boundary, profile);
    }
    grid
}

/// The corner mesh `grid` as faces over point ids: side i's first point is `corners[i]`, every
/// other point (by its canonical name) is appended to `points`. Returns the quads (ring by
/// ring, side by side; for odd segments the centre polygon last) and each side's border, the
/// ids of (i, 0, 0 ..= ns).
pub(super) fn corner_faces(
    grid: &CornerGrid,
    corners: &[u32],
    points: &mut Vec<DVec3>,
) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let (sides, ns) = (grid.n, grid.ns);
    let half = ns / 2;
    let slot = |i: usize, j: usize, k: usize| (i * (half + 1) + j) * (ns + 1) + k;
    let mut ids = vec![u32::MAX; sides * (half + 1) * (ns + 1)];
    for i in 0..sides {
        for j in 0..=half {
            for k in 0..=ns {
                if !grid.is_canonical(i, j, k) {
                    continue;
                }
                ids[slot(i, j, k)] = if j == 0 && k == 0 {
                    corners[i]
                } else {
                    points.push(grid.at(i, j, k));
                    (points.len() - 1) as u32
                };
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| {
        let (a, b, c) = grid.canonical(i, j, k);
        ids[slot(a, b, c)]
    };
    let borders = (0..sides)
        .map(|i| (0..=ns).map(|k| id(i, 0, k)).collect())
        .collect();
    let mut faces = Vec::new();
    let odd = ns % 2;
    for i in 0..sides {
        for j in 0..half {
            for k in 0..half + odd {
                faces.push(vec![
                    id(i, j, k),
                    id(i, j, k + 1),
                    id(i, j + 1, k + 1),
                    id(i, j + 1, k),
                ]);
            }
        }
    }
    if odd == 1 {
        faces.push((0..sides).map(|i| id(i, half, half)).collect());
    }
    (faces, borders)
}

/// The general corner: the net of the border points, the profiles' middles and a centre
/// placed from the boundary centroid towards the vertex by the profile's fullness, refined.
pub(super) fn general_corner(
    vertex: DVec3,
    boundary: &[DVec3],
    profile: SideProfile,
    ns: usize,
) -> CornerGrid {
    let n = boundary.len();
    let mut net = CornerGrid::new(n, 2);
    for (i, &b) in boundary.iter().enumerate() {
        net.set(i, 0, 0, b);
        net.set(i, 0, 1, profile(i, 0.5));
    }
    let centroid = boundary.iter().sum::<DVec3>() / n as f64;
    let towards = vertex - centroid;
    let centre = if towards.length_squared() > EPSILON * EPSILON {
        centroid + towards * fullness(ns)
    } else {
        centroid
    };
    net.set(0, 1, 1, centre);
    net.copy_equivalents();
    // Blender refines at least once here, even for two segments.
    let mut grid = cubic_step(&mut net, profile);
    grid = refine(grid, ns, boundary, profile);
    grid
}

/// The corner of three beveled edges whose faces meet nearly square (a box's corner): the
/// sphere octant through the unit points, its sides quarter circles, refined and put back on
/// the sphere, then mapped by the affine map taking the unit points to the boundary points
/// and (1, 1, 1) to the vertex.
pub(super) fn cube_corner(vertex: DVec3, boundary: [DVec3; 3], ns: usize) -> CornerGrid {
    let axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let quarter = |i: usize, t: f64| {
        let phi = std::f64::consts::FRAC_PI_2 * t;
        axes[i] * phi.cos() + axes[(i + 1) % 3] * phi.sin()
    };
    let mut net = CornerGrid::new(3, 2);
    for (i, &axis) in axes.iter().enumerate() {
        net.set(i, 0, 0, axis);
        net.set(i, 0, 1, quarter(i, 0.5));
    }
    let lift = if ns > 2 { 1.4 } else { 1.0 };
    net.set(0, 1, 1, DVec3::ONE * (lift / 3f64.sqrt()));
    net.copy_equivalents();
    let mut grid = refine(net, ns, &axes, &quarter);
    grid.map(|p| p.normalize_or_zero());
    let [a, b, c] = boundary;
    let columns = [
        (a - b - c + vertex) * 0.5,
        (b - a - c + vertex) * 0.5,
        (c - a - b + vertex) * 0.5,
    ];
    let origin = (a + b + c - vertex) * 0.5;
    grid.map(|p| origin + columns[0] * p.x + columns[1] * p.y + columns[2] * p.z);
    grid
}

/// The affine map taking the unit square's (0, 1) to `start`, (1, 1) to `middle` and (1, 0)
/// to `end`, with the unit normal as its third axis; `None` where the three are in line.
fn unit_square_map(start: DVec3, middle: DVec3, end: DVec3) -> Option<(DMat3, DVec3)> {
    let (to_start, to_end) = (middle - start, middle - end);
    if to_start == DVec3::ZERO || to_end == DVec3::ZERO {
        return None;
    }
    if (to_start.angle_between(to_end) - std::f64::consts::PI).abs() <= 2f64.to_radians() {
        return None;
    }
    let normal = to_end.cross(to_start).normalize_or_zero();
    Some((
        DMat3::from_cols(to_start, to_end, normal),
        start + end - middle,
    ))
}

/// The pipe corner: the general corner with its inner points pulled, in the plane square to
/// the pipe through each, onto the pipe profile's round section there.
pub(super) fn pipe_corner(
    vertex: DVec3,
    boundary: &[DVec3],
    profile: SideProfile,
    ns: usize,
    pipe: (DVec3, DVec3, DVec3, DVec3),
) -> CornerGrid {
    let mut grid = general_corner(vertex, boundary, profile, ns);
    let (start, middle, end, along) = pipe;
    let snap = |co: DVec3| -> DVec3 {
        if start.distance(end) <= EPSILON {
            return start;
        }
        let onto = |q: DVec3| q - along * ((q - co).dot(along) / along.length_squared());
        let (s, m, e) = (onto(start), onto(middle), onto(end));
        match unit_square_map(s, m, e) {
            Some((linear, origin)) if linear.determinant().abs() > 1e-300 => {
                let p = linear.inverse() * (co - origin);
                origin + linear * p.normalize_or_zero()
            }
            _ => {
                let d = e - s;
                let t = if d.length_squared() > 0.0 {
                    ((co - s).dot(d) / d.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                s + d * t
            }
        }
    };
    let half = ns / 2;
    for i in 0..grid.n {
        for j in 1..=half {
            for k in 0..=half {
                if grid.is_canonical(i, j, k) {
                    let p = snap(grid.at(i, j, k));
                    grid.set(i, j, k, p);
                }
            }
        }
    }
    grid.copy_equivalents();
    grid
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every name of a stored point (ring j ≤ ns/2) has a canonical name that is its own.
    #[test]
    fn canonical_names_are_closed() {
        for n in 3..6 {
            for ns in 2..9 {
                let grid = CornerGrid::new(n, ns);
                for i in 0..n {
                    for j in 0..=ns / 2 {
                        for k in 0..=ns {
                            let (a, b, c) = grid.canonical(i, j, k);
                            assert!(grid.is_canonical(a, b, c), "{n} {ns} ({i},{j},{k})");
                        }
                    }
                }
            }
        }
    }

    /// Sabin's γ from its cubic agrees with the table where both are given (for n = 3 the
    /// cubic's formula passes through complex numbers, hence the table).
    #[test]
    fn sabin_gamma_solves_its_cubic() {
        for n in 4..=6 {
            assert!((sabin_gamma_solved(n) - sabin_gamma(n)).abs() < 1e-6, "{n}");
        }
        assert!(sabin_gamma(7) > sabin_gamma(6) && sabin_gamma(7) < 1.0);
    }

    /// A cube corner of unit width lies on the sphere of radius 1 about the corner's centre,
    /// for every segment count, and its border runs along the three quarter circles.
    #[test]
    fn cube_corner_lies_on_its_sphere() {
        let vertex = DVec3::ONE;
        let boundary = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        for ns in 2..10 {
            let grid = cube_corner(vertex, boundary, ns);
            for i in 0..3 {
                for j in 0..=ns / 2 {
                    for k in 0..=ns {
                        let r = grid.at(i, j, k).length();
                        assert!((r - 1.0).abs() < 1e-12, "{ns} ({i},{j},{k}) {r}");
                    }
                }
            }
        }
    }
}
