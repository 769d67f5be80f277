//! `knotwork construct`'s request ([`crate::ops::construct`]) on curves given in full: built
//! and printed as the `nurbs_surface` or `nurbs_curve` that `knotwork eval` and the file format
//! read.

use serde_json::Value;

use crate::ops::construct::{Construct, CurveInput};
use crate::scene::json::{FormatError, Geometry, NamedGeometry, object_to_value};

pub use crate::ops::construct::Built;

/// Builds the surface (or curve) the request `text` describes, and its name. A malformed
/// request names the offending JSON path; a construction that fails (curves that do not meet,
/// …) gives the kernel's reason. Its curves must be given in full: there is no scene here.
pub fn build(text: &str) -> Result<Built, FormatError> {
    let value: Value = serde_json::from_str(text)
        .map_err(|e| FormatError::new("", format!("not valid JSON: {e}")))?;
    let construct = Construct::read("", value)?;
    if construct.replace.is_some() {
        return Err(FormatError::new(
            "replace",
            "replaces an object of a scene, and knotwork construct has none",
        ));
    }
    construct.build(&|path, input| match input {
        CurveInput::Given(curve) => Ok((**curve).clone()),
        CurveInput::Object(_) => Err(FormatError::new(
            path,
            "expected a \"nurbs_curve\": knotwork construct has no scene whose objects it could \
             name (knotwork apply builds on a project's curves)",
        )),
    })
}

/// The built object as the JSON object (`nurbs_surface` or `nurbs_curve`) that `knotwork
/// eval` and the file format read.
pub fn geometry_value(geometry: Geometry, name: &str) -> Value {
    object_to_value(&NamedGeometry {
        name: Some(name.to_string()),
        geometry,
    })
}
