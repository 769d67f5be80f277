//! The fuzzing entry points of the readers that take files from users: a project (JSON), an
//! OBJ, a glTF (`.gltf` JSON or `.glb`) and a PNG height map. The cargo-fuzz targets in `fuzz/`, the stable
//! smoke harness (`examples/fuzz_smoke.rs`) and the regression test all call [`check`].
//!
//! Beyond "never panics", every input that opens must survive a round trip: the opened project,
//! written as a project file and read back, is the same scene; a decoded height map has its
//! heights in [0, 1], its sides within the limit, and reads back the same from the project
//! file's base64.

use super::{height_image, project};
use crate::kernel::displace::MAX_IMAGE_SIDE;

/// The readers under fuzzing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Project,
    Obj,
    Gltf,
    HeightImage,
}

impl Target {
    pub const ALL: [Target; 4] = [
        Target::Project,
        Target::Obj,
        Target::Gltf,
        Target::HeightImage,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::Project => "project",
            Target::Obj => "obj",
            Target::Gltf => "gltf",
            Target::HeightImage => "png",
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
        }
    }
}

/// Opens `data` as `target` would be opened in the editor (no files beside it). Panics only if
/// a reader panics or an opened file does not survive the round trip; errors are fine.
pub fn check(target: Target, data: &[u8]) {
    if target == Target::HeightImage {
        check_height_image(data);
        return;
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
