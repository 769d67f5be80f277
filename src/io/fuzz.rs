//! The fuzzing entry points of the readers that take files from users: a project (JSON), an
//! OBJ, and a glTF (`.gltf` JSON or `.glb`). The cargo-fuzz targets in `fuzz/`, the stable
//! smoke harness (`examples/fuzz_smoke.rs`) and the regression test all call [`check`].
//!
//! Beyond "never panics", every input that opens must survive a round trip: the opened project,
//! written as a project file and read back, is the same scene.

use super::project;

/// The readers under fuzzing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Project,
    Obj,
    Gltf,
}

impl Target {
    pub const ALL: [Target; 3] = [Target::Project, Target::Obj, Target::Gltf];

    pub fn name(self) -> &'static str {
        match self {
            Target::Project => "project",
            Target::Obj => "obj",
            Target::Gltf => "gltf",
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
        }
    }
}

/// Opens `data` as `target` would be opened in the editor (no files beside it). Panics only if
/// a reader panics or an opened file does not survive the round trip; errors are fine.
pub fn check(target: Target, data: &[u8]) {
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
