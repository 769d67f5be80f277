//! The fuzzing entry points of the readers that take files from users: a project (JSON), an
//! OBJ, a glTF (`.gltf` JSON or `.glb`), a STEP file, a PNG height map and a `knotwork
//! construct` request; and the boolean, on two primitive solids the bytes place. The cargo-fuzz targets in `fuzz/`, the stable
//! smoke harness (`examples/fuzz_smoke.rs`) and the regression test all call [`check`].
//!
//! Beyond "never panics", every input that opens must survive a round trip: the opened project,
//! written as a project file and read back, is the same scene; a decoded height map has its
//! heights in [0, 1], its sides within the limit, and reads back the same from the project
//! file's base64; a construction that succeeds prints an object that reads back the same.

use super::{height_image, project};
use crate::kernel::displace::MAX_IMAGE_SIDE;

/// The readers under fuzzing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Project,
    Obj,
    Gltf,
    HeightImage,
    Construct,
    Step,
    Boolean,
}

impl Target {
    pub const ALL: [Target; 7] = [
        Target::Project,
        Target::Obj,
        Target::Gltf,
        Target::HeightImage,
        Target::Construct,
        Target::Step,
        Target::Boolean,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::Project => "project",
            Target::Obj => "obj",
            Target::Gltf => "gltf",
            Target::HeightImage => "png",
            Target::Construct => "construct",
            Target::Step => "step",
            Target::Boolean => "boolean",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    /// The file name the input is opened under (the reader is chosen by name and content).
    fn file_name(self, data: &[u8]) -> &'static str {
        match self {
            Target::Project => "fuzz.knotwork.json",
            Target::Obj => "fuzz.obj",
            Target::Gltf if data.starts_with(b"glTF") => "fuzz.glb",
            Target::Gltf => "fuzz.gltf",
            Target::HeightImage => "fuzz.png",
            Target::Construct => "fuzz.construct.json",
            Target::Step => "fuzz.step",
            Target::Boolean => "fuzz.boolean",
        }
    }
}

/// Opens `data` as `target` would be opened in the editor (no files beside it). Panics only if
/// a reader panics or an opened file does not survive the round trip; errors are fine.
pub fn check(target: Target, data: &[u8]) {
    match target {
        Target::HeightImage => return check_height_image(data),
        Target::Construct => return check_construct(data),
        Target::Boolean => return check_boolean(data),
        _ => {}
    }
    let no_companions = |name: &str| Err(format!("{name}: no files beside a fuzz input"));
    let Ok(opened) = super::open(target.file_name(data), data, &no_companions) else {
        return;
    };
    let text = project::write(&opened);
    match project::read(&text) {
        Ok(again) => assert!(
            again.scene == opened.scene,
            "an opened {} file changed in a save and reopen",
            target.name()
        ),
        Err(e) => panic!(
            "an opened {} file could not be reopened after saving: {e}",
            target.name()
        ),
    }
}

/// Builds `data` as a `knotwork construct` request; panics only if the construction panics or
/// a built object, printed as `knotwork construct` prints it, does not read back the same.
fn check_construct(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(built) = super::construct::build(text) else {
        return;
    };
    let value = super::construct::geometry_value(built.geometry, built.name);
    match crate::scene::json::object_from_value("", value.clone()) {
        // Printed again it is the same object, up to the rounding of a rational point's
        // Cartesian form (w·P / w).
        Ok(again) => assert!(
            nearly_equal(
                &super::construct::geometry_value(again.geometry, built.name),
                &value
            ),
            "a constructed {} changed when printed and read back",
            built.name
        ),
        Err(e) => panic!("a constructed {} could not be read back: {e}", built.name),
    }
}

/// The two solids the bytes of `data` describe, in turn: a kind (block, capped cylinder, ball,
/// capped cone), its place and sizes on a quarter grid (so that faces share planes, touch and
/// cross as often as they miss), and for some a turn about an axis the bytes give.
fn primitive_solids(data: &[u8]) -> Option<[Vec<crate::kernel::TrimmedSurface>; 2]> {
    use crate::kernel::solids::{ball, block, capped_cone, capped_cylinder, transformed};
    use glam::{DAffine3, DQuat, DVec3};
    if data.is_empty() {
        return None;
    }
    let mut at = 0;
    let mut byte = || {
        let b = data[at % data.len()];
        at += 1;
        b
    };
    let mut solid = || {
        let kind = byte() % 4;
        let mut grid = || f64::from(byte() % 17) * 0.25 - 2.0;
        let place = DVec3::new(grid(), grid(), grid());
        let mut size = || 0.25 + f64::from(byte() % 12) * 0.25;
        let (sx, sy, sz) = (size(), size(), size());
        let faces = match kind {
            0 => block(place, DVec3::new(sx, sy, sz)),
            1 => capped_cylinder(place, DVec3::new(0.0, 0.0, sz), 0.5 * sx),
            2 => ball(place, 0.5 * sx),
            _ => capped_cone(place, DVec3::new(0.0, 0.0, sz), 0.5 * sx, 0.25 * sy),
        }
        .ok()?;
        let turn = byte();
        if turn % 3 == 0 {
            return Some(faces);
        }
        let axis = DVec3::new(
            f64::from(byte()) - 127.5,
            f64::from(byte()) - 127.5,
            f64::from(byte()) - 127.5,
        );
        let rotation = DQuat::from_axis_angle(axis.normalize(), f64::from(turn) * 0.0245);
        transformed(&faces, &DAffine3::from_quat(rotation)).ok()
    };
    Some([solid()?, solid()?])
}

/// Combines the two solids `data` describes ([`primitive_solids`]) in all three ways; panics
/// only if a boolean panics, returns a result that does not close (joined again from its faces
/// alone), or, where all three succeed, breaks vol(A ∪ B) + vol(A ∩ B) = vol(A) + vol(B) or
/// vol(A − B) + vol(A ∩ B) = vol(A) beyond 1e-6 of the volumes. A refusal is fine.
fn check_boolean(data: &[u8]) {
    use crate::kernel::boolean::{BooleanOp, boolean};
    use crate::kernel::join::{find_topology, validity};
    use crate::kernel::mass::signed_volume;
    let Some([a, b]) = primitive_solids(data) else {
        return;
    };
    let tolerance = 1e-6 * 8.0;
    check_split(&a, &b, data, tolerance);
    let mut volumes = Vec::new();
    for op in [
        BooleanOp::Union,
        BooleanOp::Difference,
        BooleanOp::Intersection,
    ] {
        let Ok(made) = boolean(op, &a, &b, tolerance) else {
            return;
        };
        let faces = made.faces();
        if faces.is_empty() {
            volumes.push(0.0);
            continue;
        }
        let topology = find_topology(&faces, 10.0 * tolerance)
            .unwrap_or_else(|e| panic!("the {} cannot be joined again: {e}", op.name()));
        let v = validity(faces.len(), &topology);
        assert!(
            v.is_closed_shell(),
            "the {} does not close: {} open, {} non-manifold, {} misoriented edges",
            op.name(),
            v.naked.len(),
            v.non_manifold.len(),
            v.misoriented.len()
        );
        let volume: f64 = made
            .solids
            .iter()
            .map(|s| s.volume())
            .sum::<Result<f64, _>>()
            .unwrap_or_else(|e| panic!("the {} has no volume: {e}", op.name()));
        assert!(
            volume.is_finite() && volume >= 0.0,
            "{}: volume {volume}",
            op.name()
        );
        volumes.push(volume);
    }
    let (Ok(va), Ok(vb)) = (signed_volume(&a), signed_volume(&b)) else {
        return;
    };
    let (va, vb) = (va.abs(), vb.abs());
    let scale = va + vb;
    assert!(
        (volumes[0] + volumes[2] - va - vb).abs() <= 1e-6 * scale,
        "vol(A ∪ B) + vol(A ∩ B) = {} for vol(A) + vol(B) = {}",
        volumes[0] + volumes[2],
        va + vb
    );
    assert!(
        (volumes[1] + volumes[2] - va).abs() <= 1e-6 * scale,
        "vol(A − B) + vol(A ∩ B) = {} for vol(A) = {va}",
        volumes[1] + volumes[2]
    );
}

/// Splits `a` by a flat sheet through the middle of `b`'s box, turned as the last bytes of
/// `data` say; panics only if the split panics, a piece does not close when joined again
/// from its faces alone, or the pieces' volumes do not add up to `a`'s (within 1e-6 of it
/// or the tolerance times its area). A refusal is fine.
fn check_split(
    a: &[crate::kernel::TrimmedSurface],
    b: &[crate::kernel::TrimmedSurface],
    data: &[u8],
    tolerance: f64,
) {
    use crate::kernel::boolean::split;
    use crate::kernel::join::{find_topology, validity};
    use crate::kernel::mass::signed_volume;
    use glam::DVec3;
    let (lo, hi) = b
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), f| {
            let (l, h) = f.surface().bounds();
            (lo.min(l), hi.max(h))
        });
    let byte = |k: usize| f64::from(data[data.len() - 1 - k % data.len()]) - 127.5;
    let normal = DVec3::new(byte(0), byte(1), byte(2) + 0.5);
    let Some(normal) = normal.try_normalize() else {
        return;
    };
    let u = normal.any_orthonormal_vector() * 20.0;
    let v = normal.cross(u);
    let centre = 0.5 * (lo + hi);
    let Ok(sheet) = crate::kernel::construct::plane(centre - 0.5 * (u + v), u, v) else {
        return;
    };
    let tool = [crate::kernel::TrimmedSurface::untrimmed(sheet)];
    let Ok(pieces) = split((a, None), &tool, tolerance) else {
        return;
    };
    let mut total = 0.0;
    for piece in &pieces {
        let faces = piece.faces();
        let topology = find_topology(&faces, 10.0 * tolerance)
            .unwrap_or_else(|e| panic!("a piece of the split cannot be joined again: {e}"));
        let v = validity(faces.len(), &topology);
        assert!(
            v.is_closed_shell(),
            "a piece of the split does not close: {} open, {} non-manifold, {} misoriented edges",
            v.naked.len(),
            v.non_manifold.len(),
            v.misoriented.len()
        );
        total += piece
            .volume()
            .unwrap_or_else(|e| panic!("a piece of the split has no volume: {e}"));
    }
    let (Ok(va), Ok(area)) = (signed_volume(a), crate::kernel::mass::area(a)) else {
        return;
    };
    // Each piece's cap and its body parts meet along cut curves fitted apart on each face
    // (within the tolerance): a piece's volume is as good as the tolerance times its area.
    assert!(
        (total - va.abs()).abs() <= (1e-6 * va.abs()).max(tolerance * area),
        "the split's pieces hold {total} of the body's {}",
        va.abs()
    );
}

/// Whether two JSON values are equal, numbers within 1e-12 relative.
fn nearly_equal(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => (x - y).abs() <= 1e-12 * x.abs().max(y.abs()).max(1.0),
            _ => x == y,
        },
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| nearly_equal(x, y))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len()
                && x.iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| nearly_equal(v, w)))
        }
        _ => a == b,
    }
}

/// Decodes `data` as a height map; panics only if the decoder panics or a decoded image breaks
/// its bounds or does not read back the same from base64.
fn check_height_image(data: &[u8]) {
    let Ok(image) = height_image::decode_png(data) else {
        return;
    };
    assert!(
        image.width() <= MAX_IMAGE_SIDE && image.height() <= MAX_IMAGE_SIDE,
        "a {} × {} height map was decoded",
        image.width(),
        image.height()
    );
    assert_eq!(image.values().len(), image.width() * image.height());
    assert!(
        image.values().iter().all(|v| (0.0..=1.0).contains(v)),
        "a height outside [0, 1]"
    );
    match height_image::from_base64(&height_image::to_base64(&image)) {
        Ok(again) => assert!(again == image, "a height map changed through base64"),
        Err(e) => panic!("a decoded height map could not be read back: {e}"),
    }
}
