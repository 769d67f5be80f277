//! The fuzzing entry points of the readers that take files from users: a project (JSON), an
//! OBJ, a glTF (`.gltf` JSON or `.glb`), a STEP file, a PNG height map and a `knotwork
//! construct` request. The cargo-fuzz targets in `fuzz/`, the stable
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
}

impl Target {
    pub const ALL: [Target; 6] = [
        Target::Project,
        Target::Obj,
        Target::Gltf,
        Target::HeightImage,
        Target::Construct,
        Target::Step,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::Project => "project",
            Target::Obj => "obj",
            Target::Gltf => "gltf",
            Target::HeightImage => "png",
            Target::Construct => "construct",
            Target::Step => "step",
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
        }
    }
}

/// Opens `data` as `target` would be opened in the editor (no files beside it). Panics only if
/// a reader panics or an opened file does not survive the round trip; errors are fine.
pub fn check(target: Target, data: &[u8]) {
    match target {
        Target::HeightImage => return check_height_image(data),
        Target::Construct => return check_construct(data),
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
