//! A stable-Rust fuzzing harness for the file readers (no coverage guidance; cargo-fuzz in
//! `fuzz/` is the thorough one): mutates a seed corpus of valid and broken files — bit flips,
//! interesting bytes, cut, repeated and spliced ranges, extreme numbers in place of numbers —
//! and feeds every mutant to `knotwork::io::fuzz::check`, which panics on a crash or a file
//! that opens but does not survive a save and reopen. CI runs it briefly as a smoke test.
//!
//!   cargo run --example fuzz_smoke -- [--seconds S] [--executions N] [--seed X] [TARGET...]
//!   cargo run --example fuzz_smoke -- --write-seeds DIR      (a corpus for cargo-fuzz)
//!
//! TARGET: project, obj, gltf, png, construct, step, boolean (default: all). Each failing input is saved under
//! `fuzz/artifacts/` and the run exits 1.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use knotwork::io::fuzz::{Target, check};
use knotwork::io::gltf::{self, ExportOptions};
use knotwork::io::project::{self, Project};
use knotwork::kernel::tess::Tessellation;
use knotwork::scene::Scene;

/// A tiny glTF with its buffer embedded as a data: URI (one triangle, a translated node).
const TRIANGLE_GLTF: &str = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "translation": [1, 2, 3]}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}], "buffers": [{"byteLength": 44, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}], "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}, {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]}"#;

const CUBE_OBJ: &str = "# a cube\no cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvt 0 0\nvn 0 0 1\nf 1/1/1 4/1/1 3/1/1 2/1/1\nf 5//1 6//1 7//1 8//1\ng sides\nf -8 -7 -3 -4\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8 6 2\n";

/// The seed corpus of one target: valid files of every shape the reader takes and the test
/// suite's broken ones.
fn seeds(target: Target) -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let demo = Scene::demo().unwrap_or_default();
    let mut small = demo.clone();
    small.objects.truncate(2);
    let mut out = Vec::new();
    match target {
        Target::Project => {
            for scene in [&small, &demo] {
                out.push(
                    project::write(&Project {
                        scene: scene.clone(),
                        view: None,
                    })
                    .into_bytes(),
                );
            }
            if let Ok(dir) = std::fs::read_dir(root.join("tests/bad-projects")) {
                let mut files: Vec<PathBuf> = dir.filter_map(|e| Some(e.ok()?.path())).collect();
                files.sort();
                out.extend(files.iter().filter_map(|p| std::fs::read(p).ok()));
            }
        }
        Target::Obj => {
            out.push(CUBE_OBJ.as_bytes().to_vec());
            out.push(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec());
        }
        Target::Gltf => {
            let options = ExportOptions {
                tessellation: Tessellation::Segments(2),
                curvature: true,
                colors: None,
            };
            let project = Project {
                scene: small.clone(),
                view: None,
            };
            if let Ok(export) = gltf::export(&project, &options) {
                out.push(gltf::to_glb(&export));
            }
            out.push(TRIANGLE_GLTF.as_bytes().to_vec());
        }
        Target::Construct => out.extend(construct_requests().into_iter().map(String::into_bytes)),
        Target::Step => {
            // OpenCASCADE's files (a cut sphere; two bricks placed by an assembly) and a small
            // file of every entity the reader maps.
            for name in ["sphere-cut.step", "assembly.step"] {
                if let Ok(bytes) = std::fs::read(root.join("tests/reference/occ/step").join(name)) {
                    out.push(bytes);
                }
            }
        }
        Target::Boolean => {
            // Two blocks crossing, a block and a cylinder through it, blocks sharing a face
            // plane, a ball against a turned cone (kind, place on the grid, sizes, turn).
            out.push(vec![0, 8, 8, 8, 7, 7, 7, 0, 0, 9, 9, 9, 7, 7, 7, 0]);
            out.push(vec![0, 6, 6, 8, 9, 9, 3, 0, 1, 8, 8, 4, 2, 2, 11, 0]);
            out.push(vec![0, 8, 8, 8, 3, 3, 3, 0, 0, 11, 8, 8, 3, 3, 3, 0]);
            out.push(vec![
                2, 8, 8, 8, 5, 5, 5, 3, 3, 8, 8, 7, 6, 4, 6, 40, 20, 200, 90,
            ]);
        }
        Target::HeightImage => {
            // Grey 8 bits, RGB 16 bits, grey and alpha, a 2-bit palette, 1-bit grey, RGBA.
            let ramp = |n: usize, scale: usize| (0..n).map(|k| (k * scale % 256) as u8).collect();
            use png::{BitDepth, ColorType};
            let cases: [(u32, u32, ColorType, BitDepth, Vec<u8>); 6] = [
                (4, 3, ColorType::Grayscale, BitDepth::Eight, ramp(12, 21)),
                (3, 3, ColorType::Rgb, BitDepth::Sixteen, ramp(54, 37)),
                (
                    2,
                    5,
                    ColorType::GrayscaleAlpha,
                    BitDepth::Eight,
                    ramp(20, 13),
                ),
                (5, 4, ColorType::Indexed, BitDepth::Two, ramp(8, 91)),
                (
                    9,
                    2,
                    ColorType::Grayscale,
                    BitDepth::One,
                    vec![0b1010_1100, 0x80, 0x5f, 0x00],
                ),
                (6, 6, ColorType::Rgba, BitDepth::Eight, ramp(144, 7)),
            ];
            for (width, height, colour, depth, data) in cases {
                if let Some(bytes) = encode_png(width, height, colour, depth, &data) {
                    out.push(bytes);
                }
            }
        }
    }
    out
}

/// A request of every kind `knotwork construct` builds, on small curves.
fn construct_requests() -> Vec<String> {
    use glam::DVec3;
    use knotwork::kernel::SpaceCurve;
    use knotwork::kernel::construct::{circle, interpolate, line};
    use knotwork::scene::json::{Geometry, NamedGeometry, object_to_value};
    let value = |c: &SpaceCurve| {
        object_to_value(&NamedGeometry {
            name: None,
            geometry: Geometry::Curve(c.clone()),
        })
    };
    let curves = || -> Result<Vec<SpaceCurve>, knotwork::kernel::GeometryError> {
        Ok(vec![
            circle(DVec3::ZERO, DVec3::Z, DVec3::X, 1.0)?,
            circle(DVec3::Z, DVec3::Z, DVec3::X, 0.5)?,
            line(DVec3::ZERO, DVec3::new(0.0, 0.0, 3.0))?,
            line(DVec3::ZERO, DVec3::X)?,
            line(DVec3::Y, DVec3::new(1.0, 1.0, 0.2))?,
            line(DVec3::ZERO, DVec3::Y)?,
            line(DVec3::X, DVec3::new(1.0, 1.0, 0.2))?,
            interpolate(
                &[
                    DVec3::X,
                    DVec3::new(1.5, 0.0, 1.0),
                    DVec3::new(1.0, 0.0, 2.0),
                ],
                2,
            )?,
        ])
    };
    let Ok(c) = curves() else {
        return Vec::new();
    };
    let points = serde_json::json!([[0, 0, 0], [1, 2, 0.5], [3, 1, 0], [4, -1, 1], [6, 0, 0]]);
    [
        serde_json::json!({"construct": "loft", "curves": [value(&c[0]), value(&c[1])], "degree": 3}),
        serde_json::json!({"construct": "loft", "curves": [value(&c[0]), value(&c[1]), value(&c[0].transformed(&glam::DAffine3::from_translation(DVec3::Z * 2.0)).unwrap_or_else(|_| c[0].clone()))], "closed": true, "style": "loose"}),
        serde_json::json!({"construct": "network", "u_curves": [value(&c[3]), value(&c[4])], "v_curves": [value(&c[5]), value(&c[6])]}),
        serde_json::json!({"construct": "sweep1", "rail": value(&c[2]), "profiles": [value(&c[0])], "up": [1, 0, 0]}),
        serde_json::json!({"construct": "sweep2", "rails": [value(&c[5]), value(&c[6])], "profiles": [value(&c[3]), value(&c[4])]}),
        serde_json::json!({"construct": "revolve", "profile": value(&c[7]), "axis": {"origin": [0, 0, 0], "direction": [0, 0, 1]}, "angle": 270}),
        serde_json::json!({"construct": "planar", "boundary": [value(&c[0])]}),
        serde_json::json!({"construct": "interpolate", "points": points, "degree": 3, "closed": true}),
        serde_json::json!({"construct": "catmull_rom", "points": points, "alpha": 1.0}),
        serde_json::json!({"construct": "gordon", "u_curves": [value(&c[3]), value(&c[4])], "v_curves": [value(&c[5]), value(&c[6])]}),
        serde_json::json!({"construct": "edge", "curves": [value(&c[3]), value(&c[6]), value(&c[4]), value(&c[5])]}),
        serde_json::json!({"construct": "extrude", "curve": value(&c[0]), "path": value(&c[7])}),
        serde_json::json!({"construct": "circle", "center": [1, 2, 3], "normal": [0, 1, 1], "radius": 2}),
        serde_json::json!({"construct": "ellipse", "center": [0, 0, 0], "radii": [2, 1], "x_axis": [1, 1, 0]}),
        serde_json::json!({"construct": "arc", "points": [[1, 0, 0], [0, 1, 0], [-1, 0, 0.5]]}),
        serde_json::json!({"construct": "polyline", "points": points, "closed": true}),
        serde_json::json!({"construct": "hermite_spline", "points": [[0, 0, 0], [1, 1, 0]], "tangents": [[1, 0, 0], [0, 1, 0]]}),
        serde_json::json!({"construct": "rebuild", "curve": value(&c[0]), "points": 8, "degree": 3}),
        serde_json::json!({"construct": "fit", "curve": value(&c[7]), "tolerance": 0.001}),
        serde_json::json!({"construct": "offset", "curve": value(&c[0]), "distance": 0.25}),
        serde_json::json!({"construct": "project", "curve": value(&c[7]), "plane": {"origin": [0, 0, 0], "normal": [0, 1, 0]}}),
        serde_json::json!({"construct": "extend", "curve": value(&c[7]), "length": 0.5, "end": "start"}),
    ]
    .iter()
    .map(|r| r.to_string())
    .collect()
}

/// A PNG of the given shape with `data` as its packed rows (a grey palette for an indexed one).
fn encode_png(
    width: u32,
    height: u32,
    colour: png::ColorType,
    depth: png::BitDepth,
    data: &[u8],
) -> Option<Vec<u8>> {
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(colour);
        encoder.set_depth(depth);
        if colour == png::ColorType::Indexed {
            encoder.set_palette(vec![0, 0, 0, 90, 90, 90, 180, 180, 180, 255, 255, 255]);
        }
        let mut writer = encoder.write_header().ok()?;
        writer.write_image_data(data).ok()?;
    }
    Some(bytes)
}

/// SplitMix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const INTERESTING_BYTES: &[u8] = b"\x00\xff\x7f\x80\"[]{},:-.0e9\n/ ";
const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1e308",
    "-1e308",
    "1e-320",
    "4294967296",
    "-1",
    "NaN",
    "1e999",
    "65535",
    "2147483648",
    "0.5",
    "1024",
    "1025",
    "100000000",
];

/// One mutant of `seed` (one to four edits, sometimes spliced with `other`).
fn mutate(rng: &mut Rng, seed: &[u8], other: &[u8]) -> Vec<u8> {
    let mut data = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        let len = data.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                data[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                data[i] = INTERESTING_BYTES[rng.below(INTERESTING_BYTES.len())];
            }
            2 if len > 0 => {
                let (a, n) = (rng.below(len), 1 + rng.below(64));
                data.drain(a..(a + n).min(len));
            }
            3 if len > 0 => {
                let (a, n) = (rng.below(len), 1 + rng.below(256));
                let piece = data[a..(a + n).min(len)].to_vec();
                let at = rng.below(len + 1);
                data.splice(at..at, piece);
            }
            4 => data.truncate(rng.below(len + 1)),
            5 if !other.is_empty() => {
                let cut = rng.below(len + 1);
                let from = rng.below(other.len());
                data.truncate(cut);
                data.extend_from_slice(&other[from..]);
            }
            6 => {
                // A number replaced by an extreme one.
                let starts: Vec<usize> = (0..len)
                    .filter(|&i| {
                        data[i].is_ascii_digit() && (i == 0 || !data[i - 1].is_ascii_digit())
                    })
                    .collect();
                if !starts.is_empty() {
                    let a = starts[rng.below(starts.len())];
                    let mut b = a;
                    while b < len && (data[b].is_ascii_digit() || b".eE+-".contains(&data[b])) {
                        b += 1;
                    }
                    let number = EXTREME_NUMBERS[rng.below(EXTREME_NUMBERS.len())];
                    data.splice(a..b, number.bytes());
                }
            }
            _ => {
                let at = rng.below(len + 1);
                let n = 1 + rng.below(16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
                data.splice(at..at, bytes);
            }
        }
    }
    data
}

struct Options {
    seconds: f64,
    executions: Option<u64>,
    seed: u64,
    targets: Vec<Target>,
    write_seeds: Option<PathBuf>,
}

fn parse_args() -> Result<Options, String> {
    let mut options = Options {
        seconds: 10.0,
        executions: None,
        seed: 2026,
        targets: Vec::new(),
        write_seeds: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--seconds" => {
                options.seconds = value("--seconds")?
                    .parse()
                    .map_err(|e| format!("--seconds: {e}"))?
            }
            "--executions" => {
                options.executions = Some(
                    value("--executions")?
                        .parse()
                        .map_err(|e| format!("--executions: {e}"))?,
                )
            }
            "--seed" => {
                options.seed = value("--seed")?
                    .parse()
                    .map_err(|e| format!("--seed: {e}"))?
            }
            "--write-seeds" => options.write_seeds = Some(PathBuf::from(value("--write-seeds")?)),
            name => options
                .targets
                .push(Target::from_name(name).ok_or(format!("unknown target {name}"))?),
        }
    }
    if options.targets.is_empty() {
        options.targets = Target::ALL.to_vec();
    }
    Ok(options)
}

/// Fuzzes one target; returns (executions, failing inputs saved).
fn fuzz(target: Target, options: &Options, budget: Duration) -> (u64, Vec<PathBuf>) {
    let corpus = seeds(target);
    let mut rng = Rng(options.seed ^ target.name().len() as u64);
    let started = Instant::now();
    let mut executions = 0u64;
    let mut failures = Vec::new();
    let artifacts = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/artifacts");
    loop {
        if options.executions.is_some_and(|n| executions >= n)
            || (options.executions.is_none() && started.elapsed() >= budget)
        {
            break;
        }
        let input = if executions < corpus.len() as u64 {
            corpus[executions as usize].clone()
        } else {
            let seed = &corpus[rng.below(corpus.len())];
            let other = &corpus[rng.below(corpus.len())];
            mutate(&mut rng, seed, other)
        };
        executions += 1;
        // The input under test, where a run that hangs can be found.
        let _ = std::fs::create_dir_all(&artifacts);
        let _ = std::fs::write(artifacts.join(format!("{}-running", target.name())), &input);
        if std::panic::catch_unwind(|| check(target, &input)).is_err() {
            let _ = std::fs::create_dir_all(&artifacts);
            let path = artifacts.join(format!("{}-{executions}", target.name()));
            let _ = std::fs::write(&path, &input);
            eprintln!(
                "{}: failing input saved to {}",
                target.name(),
                path.display()
            );
            failures.push(path);
        }
    }
    (executions, failures)
}

fn main() -> std::process::ExitCode {
    let options = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("fuzz_smoke: {e}");
            return std::process::ExitCode::from(2);
        }
    };
    if let Some(dir) = &options.write_seeds {
        for target in &options.targets {
            let folder = dir.join(target.name());
            if let Err(e) = std::fs::create_dir_all(&folder) {
                eprintln!("fuzz_smoke: {}: {e}", folder.display());
                return std::process::ExitCode::FAILURE;
            }
            for (k, seed) in seeds(*target).iter().enumerate() {
                let _ = std::fs::write(folder.join(format!("seed-{k}")), seed);
            }
        }
        return std::process::ExitCode::SUCCESS;
    }
    // Panics are expected to be caught and counted; keep their messages short.
    std::panic::set_hook(Box::new(|info| eprintln!("fuzz_smoke: panic: {info}")));
    let budget = Duration::from_secs_f64(options.seconds / options.targets.len() as f64);
    let mut failed = 0;
    for &target in &options.targets {
        let started = Instant::now();
        let (executions, failures) = fuzz(target, &options, budget);
        let seconds = started.elapsed().as_secs_f64();
        println!(
            "fuzz {}: {executions} executions in {seconds:.1} s ({:.0}/s), {} failing",
            target.name(),
            executions as f64 / seconds.max(1e-9),
            failures.len()
        );
        failed += failures.len();
    }
    if failed == 0 {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
