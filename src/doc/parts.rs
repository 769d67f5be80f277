//! Small pieces the document's plans share: a refusal's error, and an object split into
//! parts (a split surface or curve, a copy's name).

use super::Change;
use crate::kernel::GeometryError;
use crate::scene::{MAX_NAME_LENGTH, ObjectGeometry, SceneObject};

/// The error of an operation `what` refused, with the reason.
pub(super) fn refuse(what: &'static str, message: impl Into<String>) -> GeometryError {
    GeometryError::Construction {
        what,
        message: message.into(),
    }
}

/// Object `k` (`object`) split into `parts`: the first in its place as "name (a)", the
/// others after it as "name (b)", … .
pub(super) fn split_parts(
    object: &SceneObject,
    k: usize,
    parts: Vec<ObjectGeometry>,
) -> Vec<Change> {
    parts
        .into_iter()
        .enumerate()
        .map(|(n, geometry)| {
            let suffix = char::from(b'a' + (n % 26) as u8).to_string();
            let part = SceneObject {
                name: split_name(&object.name, &suffix),
                geometry,
                ..object.clone()
            };
            if n == 0 {
                Change::Replace {
                    index: k,
                    before: object.clone(),
                    after: part,
                }
            } else {
                Change::Insert {
                    index: k + n,
                    object: part,
                }
            }
        })
        .collect()
}

/// "Name (a)", keeping the name within [`MAX_NAME_LENGTH`].
pub(super) fn split_name(name: &str, suffix: &str) -> String {
    let keep = MAX_NAME_LENGTH.saturating_sub(suffix.chars().count() + 3);
    let base: String = name.chars().take(keep).collect();
    format!("{base} ({suffix})")
}
