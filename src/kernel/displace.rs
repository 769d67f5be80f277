//! Displacement along the normal by a procedural height map (the lecture notes' seed 003):
//! the surface S(u, v) becomes S + a h(x, y) N, where N is the unit normal, a the amplitude
//! and h ∈ [−1, 1] a pattern over the surface's normalized parameters (x, y) ∈ [0, 1]².
//!
//! The displaced surface's tangents are S_u + a (h_u N + h N_u) and the same in v, with N_u
//! and N_v from the Weingarten equations ([`SurfaceDerivatives::normal_derivatives`]), so the
//! displaced normal needs only the second derivatives the evaluators already have.
//! `shaders/eval_bezier.wgsl` computes the same in f32 (`displace`); the patterns' integer
//! hashing is the same on both sides.

use glam::DVec3;

use super::GeometryError;
use super::diffgeo::SurfaceDerivatives;

/// The largest frequency (cycles over the parameter range) a displacement may have.
pub const MAX_FREQUENCY: f64 = 256.0;

/// The height patterns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Pattern {
    /// h = sin(2π f x) sin(2π f y): an egg-crate.
    Waves,
    /// h = cos(2π f r), r the distance from the middle (0.5, 0.5): rings.
    Ripples,
    /// Value noise on an f × f lattice, smoothly (quintic) interpolated: a hammered look.
    Noise,
}

impl Pattern {
    pub const ALL: [Pattern; 3] = [Pattern::Waves, Pattern::Ripples, Pattern::Noise];

    /// The code the GPU reads (`DISPLACE_*` in `shaders/eval_bezier.wgsl`); 0 is none.
    pub fn code(self) -> u32 {
        match self {
            Pattern::Waves => 1,
            Pattern::Ripples => 2,
            Pattern::Noise => 3,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Pattern::Waves => "waves",
            Pattern::Ripples => "ripples",
            Pattern::Noise => "noise",
        }
    }
}

/// A displacement: pattern, amplitude (model units, either sign) and frequency.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Displacement {
    pub pattern: Pattern,
    pub amplitude: f64,
    pub frequency: f64,
}

/// The lattice value of noise at integer (i, j): a 32-bit integer hash (a multiply-xorshift
/// mix) mapped to [−1, 1]. The GPU computes the same bits.
fn lattice_value(i: i32, j: i32) -> f64 {
    let mut h = (i as u32).wrapping_mul(0x8da6_b343) ^ (j as u32).wrapping_mul(0xd816_3841);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    f64::from(h & 0xffff) / 32767.5 - 1.0
}

/// The quintic fade 6t⁵ − 15t⁴ + 10t³ and its derivative (Perlin 2002).
fn fade(t: f64) -> (f64, f64) {
    (
        t * t * t * (t * (t * 6.0 - 15.0) + 10.0),
        30.0 * t * t * (t * (t - 2.0) + 1.0),
    )
}

impl Displacement {
    /// Checks the amplitude (finite) and the frequency (in (0, [`MAX_FREQUENCY`]]).
    pub fn new(pattern: Pattern, amplitude: f64, frequency: f64) -> Result<Self, GeometryError> {
        let refuse = |field: &str, message: String| {
            Err(GeometryError::Construction {
                what: "displacement",
                message: format!("{field}: {message}"),
            })
        };
        if !amplitude.is_finite() {
            return refuse("amplitude", format!("{amplitude} is not a finite number"));
        }
        if !(frequency.is_finite() && frequency > 0.0 && frequency <= MAX_FREQUENCY) {
            return refuse(
                "frequency",
                format!("{frequency} is outside (0, {MAX_FREQUENCY}]"),
            );
        }
        Ok(Self {
            pattern,
            amplitude,
            frequency,
        })
    }

    /// h and its partial derivatives (h, h_x, h_y) at normalized (x, y).
    pub fn height(&self, x: f64, y: f64) -> [f64; 3] {
        let f = self.frequency;
        let w = std::f64::consts::TAU * f;
        match self.pattern {
            Pattern::Waves => {
                let (sx, cx) = (w * x).sin_cos();
                let (sy, cy) = (w * y).sin_cos();
                [sx * sy, w * cx * sy, w * sx * cy]
            }
            Pattern::Ripples => {
                let (dx, dy) = (x - 0.5, y - 0.5);
                let r = (dx * dx + dy * dy).sqrt();
                let (s, c) = (w * r).sin_cos();
                if r == 0.0 {
                    return [c, 0.0, 0.0];
                }
                [c, -w * s * dx / r, -w * s * dy / r]
            }
            Pattern::Noise => {
                let (px, py) = (x * f, y * f);
                let (i, j) = (px.floor(), py.floor());
                let (tx, ty) = (px - i, py - j);
                let (i, j) = (i as i32, j as i32);
                let (a, b, c, d) = (
                    lattice_value(i, j),
                    lattice_value(i + 1, j),
                    lattice_value(i, j + 1),
                    lattice_value(i + 1, j + 1),
                );
                let ((sx, dsx), (sy, dsy)) = (fade(tx), fade(ty));
                let bottom = a + (b - a) * sx;
                let top = c + (d - c) * sx;
                let h = bottom + (top - bottom) * sy;
                let hx = ((b - a) + ((d - c) - (b - a)) * sy) * dsx * f;
                let hy = (top - bottom) * dsy * f;
                [h, hx, hy]
            }
        }
    }

    /// The displaced point and unit normal where the surface has derivatives `d` (in its own
    /// (u, v)) and unit normal `normal`, at normalized (x, y) with dx/du = `scale[0]`, dy/dv =
    /// `scale[1]` (see the module doc). Where the fundamental forms are degenerate the normal's
    /// derivatives are taken as 0.
    pub fn apply(
        &self,
        d: &SurfaceDerivatives,
        normal: DVec3,
        x: f64,
        y: f64,
        scale: [f64; 2],
    ) -> (DVec3, DVec3) {
        let [h, hx, hy] = self.height(x, y);
        let a = self.amplitude;
        let (nu, nv) = d.normal_derivatives(normal);
        let pu = d.su + (normal * (hx * scale[0]) + nu * h) * a;
        let pv = d.sv + (normal * (hy * scale[1]) + nv * h) * a;
        let mut displaced = pu.cross(pv).normalize_or_zero();
        if displaced == DVec3::ZERO {
            displaced = normal;
        } else if displaced.dot(normal) < 0.0 {
            displaced = -displaced;
        }
        (d.point + normal * (a * h), displaced)
    }

    /// The four floats the GPU reads: pattern code (as a float), amplitude, frequency, 0.
    pub fn gpu_words(&self) -> [f32; 4] {
        [
            self.pattern.code() as f32,
            self.amplitude as f32,
            self.frequency as f32,
            0.0,
        ]
    }
}

/// Displaces an export mesh by `map` (its (u, v) normalized to [0, 1], as the tessellation
/// writes them): each point moves along its normal by a h, then the normals are those of the
/// displaced triangles (area-weighted, turned to the side of the old normal). The curvature
/// attributes are dropped: the displaced surface's are not computed.
pub fn displace_mesh(mesh: &mut super::tess::TriangleMesh, map: &Displacement) {
    if mesh.uvs.len() != mesh.positions.len() {
        return;
    }
    for ((p, n), uv) in mesh.positions.iter_mut().zip(&mesh.normals).zip(&mesh.uvs) {
        *p += *n * (map.amplitude * map.height(uv[0], uv[1])[0]);
    }
    let mut sums = vec![DVec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
        let face = (b - a).cross(c - a);
        for &k in t {
            sums[k as usize] += face;
        }
    }
    for (n, sum) in mesh.normals.iter_mut().zip(sums) {
        let m = sum.normalize_or_zero();
        if m != DVec3::ZERO {
            *n = if m.dot(*n) < 0.0 { -m } else { m };
        }
    }
    mesh.curvatures.clear();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heights_have_the_derivatives_they_claim() {
        for pattern in Pattern::ALL {
            let d = Displacement::new(pattern, 0.1, 3.0).unwrap();
            for (x, y) in [(0.13, 0.71), (0.52, 0.33), (0.9, 0.05)] {
                let [h, hx, hy] = d.height(x, y);
                assert!((-1.0..=1.0).contains(&h), "{pattern:?}: {h}");
                let e = 1e-6;
                let fx = (d.height(x + e, y)[0] - d.height(x - e, y)[0]) / (2.0 * e);
                let fy = (d.height(x, y + e)[0] - d.height(x, y - e)[0]) / (2.0 * e);
                assert!(
                    (fx - hx).abs() < 1e-5 * (1.0 + hx.abs()),
                    "{pattern:?} hx {hx} vs {fx}"
                );
                assert!(
                    (fy - hy).abs() < 1e-5 * (1.0 + hy.abs()),
                    "{pattern:?} hy {hy} vs {fy}"
                );
            }
        }
    }

    #[test]
    fn a_displaced_plane_has_the_heights_normal() {
        // The plane z = 0 over (u, v) ∈ [0, 2]²: x = u / 2.
        let d = Displacement::new(Pattern::Waves, 0.2, 2.0).unwrap();
        let (u, v) = (0.3, 1.1);
        let plane = SurfaceDerivatives {
            point: DVec3::new(u, v, 0.0),
            su: DVec3::X,
            sv: DVec3::Y,
            suu: DVec3::ZERO,
            suv: DVec3::ZERO,
            svv: DVec3::ZERO,
        };
        let (p, n) = d.apply(&plane, DVec3::Z, u / 2.0, v / 2.0, [0.5, 0.5]);
        let [h, hx, hy] = d.height(u / 2.0, v / 2.0);
        assert!((p - DVec3::new(u, v, 0.2 * h)).length() < 1e-15);
        // z = a h(u/2, v/2): normal (−a h_x/2, −a h_y/2, 1) normalized.
        let expected = DVec3::new(-0.2 * hx * 0.5, -0.2 * hy * 0.5, 1.0).normalize();
        assert!((n - expected).length() < 1e-14, "{n} vs {expected}");
    }

    #[test]
    fn bad_displacements_are_refused() {
        assert!(Displacement::new(Pattern::Waves, f64::NAN, 1.0).is_err());
        assert!(Displacement::new(Pattern::Waves, 0.1, 0.0).is_err());
        assert!(Displacement::new(Pattern::Noise, 0.1, 1e9).is_err());
    }
}
