//! Displacement along the normal by a procedural or image height map (the lecture notes' seed
//! 003):
//! the surface S(u, v) becomes S + a h(x, y) N, where N is the unit normal, a the amplitude
//! and h ∈ [−1, 1] a pattern over the surface's normalized parameters (x, y) ∈ [0, 1]².
//!
//! The displaced surface's tangents are S_u + a (h_u N + h N_u) and the same in v, with N_u
//! and N_v from the Weingarten equations ([`SurfaceDerivatives::normal_derivatives`]), so the
//! displaced normal needs only the second derivatives the evaluators already have.
//! `shaders/eval_bezier.wgsl` computes the same in f32 (`displace`); the patterns' integer
//! hashing is the same on both sides.

use std::sync::Arc;

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
    /// A grey image ([`HeightImage`]) tiled f × f times: h = 2 g − 1 for its grey g ∈ [0, 1]
    /// (mid-grey stays put), between pixels a uniform cubic B-spline.
    Image,
}

impl Pattern {
    /// The procedural patterns (the image one needs an image).
    pub const ALL: [Pattern; 3] = [Pattern::Waves, Pattern::Ripples, Pattern::Noise];

    pub fn label(self) -> &'static str {
        match self {
            Pattern::Waves => "waves",
            Pattern::Ripples => "ripples",
            Pattern::Noise => "noise",
            Pattern::Image => "image",
        }
    }
}

/// A displacement: pattern, amplitude (model units, either sign) and frequency; the image of
/// an [`Pattern::Image`] displacement (kept out of the derived serialization: the project file
/// writes it as its PNG, `io::project`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Displacement {
    pub pattern: Pattern,
    pub amplitude: f64,
    pub frequency: f64,
    #[serde(skip)]
    pub image: Option<Arc<HeightImage>>,
}

/// The longest side a height image may have, in pixels.
pub const MAX_IMAGE_SIDE: usize = 1024;

/// A height image: grey values in [0, 1], row-major from the top row (the edge v = 1), and
/// the encoded file it came from (kept to save it as it was).
#[derive(Debug, Clone, PartialEq)]
pub struct HeightImage {
    width: usize,
    height: usize,
    values: Vec<f32>,
    source: Vec<u8>,
}

/// The uniform cubic B-spline's four weights at t ∈ [0, 1) (for the points i − 1 .. i + 2) and
/// their derivatives (de Boor; Farin §7.3).
fn cubic_bspline(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [
            s * s * s / 6.0,
            (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
            (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
            t * t * t / 6.0,
        ],
        [
            -s * s / 2.0,
            (3.0 * t * t - 4.0 * t) / 2.0,
            (-3.0 * t * t + 2.0 * t + 1.0) / 2.0,
            t * t / 2.0,
        ],
    )
}

impl HeightImage {
    /// Checks the size (2 to [`MAX_IMAGE_SIDE`] pixels a side), the value count and that every
    /// value lies in [0, 1].
    pub fn new(
        width: usize,
        height: usize,
        values: Vec<f32>,
        source: Vec<u8>,
    ) -> Result<Self, GeometryError> {
        let refuse = |message: String| {
            Err(GeometryError::Construction {
                what: "height image",
                message,
            })
        };
        if !(2..=MAX_IMAGE_SIDE).contains(&width) || !(2..=MAX_IMAGE_SIDE).contains(&height) {
            return refuse(format!(
                "{width} × {height} pixels (each side must be 2 to {MAX_IMAGE_SIDE})"
            ));
        }
        if values.len() != width * height {
            return refuse(format!("{} values for {width} × {height}", values.len()));
        }
        if values.iter().any(|v| !(0.0..=1.0).contains(v)) {
            return refuse("a grey value outside [0, 1]".into());
        }
        Ok(Self {
            width,
            height,
            values,
            source,
        })
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The grey values, row-major from the top row.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The encoded file the image came from.
    pub fn source(&self) -> &[u8] {
        &self.source
    }

    /// The grey at pixel (i, j) (column, row from the top), the image repeating in both
    /// directions.
    fn value(&self, i: i64, j: i64) -> f64 {
        let (w, h) = (self.width as i64, self.height as i64);
        f64::from(self.values[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize])
    }

    /// The tiled image's smooth grey and its derivatives (g, g_x, g_y) at tile coordinates
    /// (x, y) (one tile over [0, 1]², y up): the uniform cubic B-spline whose control points
    /// are the pixels, pixel column i at x = i / width, row j at y = 1 − j / height.
    /// `shaders/eval_bezier.wgsl` computes the same in f32 (`image_height`).
    pub fn sample(&self, x: f64, y: f64) -> [f64; 3] {
        let (w, h) = (self.width as f64, self.height as f64);
        let px = x.rem_euclid(1.0) * w;
        let py = (1.0 - y).rem_euclid(1.0) * h;
        let (i, j) = (px.floor(), py.floor());
        let ((bx, dx), (by, dy)) = (cubic_bspline(px - i), cubic_bspline(py - j));
        let (i, j) = (i as i64, j as i64);
        let mut out = [0.0; 3];
        for (b, (wy, dwy)) in by.iter().zip(dy).enumerate() {
            for (a, (wx, dwx)) in bx.iter().zip(dx).enumerate() {
                let g = self.value(i + a as i64 - 1, j + b as i64 - 1);
                out[0] += g * wx * wy;
                out[1] += g * dwx * wy;
                out[2] += g * wx * dwy;
            }
        }
        // d px / dx = w, d py / dy = −h.
        [out[0], out[1] * w, -out[2] * h]
    }
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
        if pattern == Pattern::Image {
            return refuse("pattern", "an image pattern needs an image".into());
        }
        Ok(Self {
            pattern,
            amplitude,
            frequency,
            image: None,
        })
    }

    /// A displacement by `image` tiled `frequency` times (checked as [`Self::new`]).
    pub fn with_image(
        image: Arc<HeightImage>,
        amplitude: f64,
        frequency: f64,
    ) -> Result<Self, GeometryError> {
        let mut checked = Self::new(Pattern::Waves, amplitude, frequency)?;
        checked.pattern = Pattern::Image;
        checked.image = Some(image);
        Ok(checked)
    }

    /// The same checks again (a displacement that came from a script or a file): the numbers,
    /// and an image exactly where the pattern is the image.
    pub fn checked(&self) -> Result<Self, GeometryError> {
        match (&self.pattern, &self.image) {
            (Pattern::Image, Some(image)) => {
                Self::with_image(Arc::clone(image), self.amplitude, self.frequency)
            }
            (Pattern::Image, None) => Self::new(Pattern::Image, self.amplitude, self.frequency),
            (pattern, _) => Self::new(*pattern, self.amplitude, self.frequency),
        }
    }

    /// Samples per cycle the pattern needs along each direction of the domain: 8 for a
    /// procedural pattern, one per pixel of the longer side (at least 8) for an image. The
    /// export and the view-adaptive tessellation give a displaced object at least this many
    /// segments per cycle.
    pub fn segments_per_cycle(&self) -> f64 {
        match &self.image {
            Some(image) if self.pattern == Pattern::Image => {
                image.width.max(image.height).max(8) as f64
            }
            _ => 8.0,
        }
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
            Pattern::Image => match &self.image {
                Some(image) => {
                    let [g, gx, gy] = image.sample(x * f, y * f);
                    [2.0 * g - 1.0, 2.0 * gx * f, 2.0 * gy * f]
                }
                None => [0.0; 3],
            },
        }
    }

    /// The displaced point P = S + a h N and its first derivatives
    /// P_u = S_u + a (h_x x_u N + h N_u), P_v = S_v + a (h_y y_v N + h N_v), where the surface has
    /// derivatives `d` (in its own (u, v)) and unit normal `normal`, at normalized (x, y) with
    /// x_u = `scale[0]`, y_v = `scale[1]`. N_u and N_v come from the Weingarten equations
    /// ([`SurfaceDerivatives::normal_derivatives`]; zero where the forms are degenerate).
    pub fn displaced_derivatives(
        &self,
        d: &SurfaceDerivatives,
        normal: DVec3,
        x: f64,
        y: f64,
        scale: [f64; 2],
    ) -> [DVec3; 3] {
        let [h, hx, hy] = self.height(x, y);
        let a = self.amplitude;
        let (nu, nv) = d.normal_derivatives(normal);
        [
            d.point + normal * (a * h),
            d.su + (normal * (hx * scale[0]) + nu * h) * a,
            d.sv + (normal * (hy * scale[1]) + nv * h) * a,
        ]
    }

    /// The displaced point and unit normal ([`Self::displaced_derivatives`]; see the module
    /// doc), the normal turned to the side of `normal`.
    pub fn apply(
        &self,
        d: &SurfaceDerivatives,
        normal: DVec3,
        x: f64,
        y: f64,
        scale: [f64; 2],
    ) -> (DVec3, DVec3) {
        let [point, pu, pv] = self.displaced_derivatives(d, normal, x, y, scale);
        let mut displaced = pu.cross(pv).normalize_or_zero();
        if displaced == DVec3::ZERO {
            displaced = normal;
        } else if displaced.dot(normal) < 0.0 {
            displaced = -displaced;
        }
        (point, displaced)
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

    /// A 5 × 4 image of smooth bumps.
    fn bumps() -> Arc<HeightImage> {
        let (w, h) = (5, 4);
        let values = (0..w * h)
            .map(|k| {
                let (i, j) = ((k % w) as f32, (k / w) as f32);
                0.5 + 0.4 * (1.3 * i).sin() * (0.9 * j + 0.2).cos()
            })
            .collect();
        Arc::new(HeightImage::new(w, h, values, Vec::new()).unwrap())
    }

    #[test]
    fn heights_have_the_derivatives_they_claim() {
        let image = Displacement::with_image(bumps(), 0.1, 3.0).unwrap();
        for d in Pattern::ALL
            .map(|pattern| Displacement::new(pattern, 0.1, 3.0).unwrap())
            .into_iter()
            .chain([image])
        {
            let pattern = d.pattern;
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
    fn an_image_is_a_periodic_cubic_bspline_of_its_pixels() {
        let image = bumps();
        // At a pixel's own position the B-spline is (g_{i−1} + 4 g_i + g_{i+1}) / 6 in each
        // direction (the uniform cubic B-spline at a knot).
        let (w, h) = (image.width() as i64, image.height() as i64);
        let at = |i: i64, j: i64| image.value(i, j);
        for (i, j) in [(0, 0), (2, 1), (4, 3)] {
            let row = |j: i64| (at(i - 1, j) + 4.0 * at(i, j) + at(i + 1, j)) / 6.0;
            let expected = (row(j - 1) + 4.0 * row(j) + row(j + 1)) / 6.0;
            let (x, y) = (i as f64 / w as f64, 1.0 - j as f64 / h as f64);
            let [g, _, _] = image.sample(x, y);
            assert!((g - expected).abs() < 1e-6, "({i}, {j}): {g} vs {expected}");
        }
        // Periodic: one tile further is the same.
        let a = image.sample(0.37, 0.61);
        let b = image.sample(1.37, -0.39);
        assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9));
        // A constant image displaces nothing where it is mid-grey.
        let flat = HeightImage::new(3, 3, vec![0.5; 9], Vec::new()).unwrap();
        let d = Displacement::with_image(Arc::new(flat), 1.0, 2.0).unwrap();
        assert!(d.height(0.3, 0.8).iter().all(|x| x.abs() < 1e-12));
        // Bad images are refused.
        assert!(HeightImage::new(1, 5, vec![0.0; 5], Vec::new()).is_err());
        assert!(HeightImage::new(2, 2, vec![0.0; 3], Vec::new()).is_err());
        assert!(HeightImage::new(2, 2, vec![0.0, 0.5, 1.5, 0.0], Vec::new()).is_err());
        assert!(Displacement::new(Pattern::Image, 0.1, 1.0).is_err());
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
