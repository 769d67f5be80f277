//! 3MF for printing (3MF Core Specification 1.3): a ZIP package ([`super::zip`]) holding the
//! content types, the package relationship to the model part, and `3D/3dmodel.model`, whose
//! `<model>` names the document's unit and holds one `<object>` mesh per visible object (the
//! meshes STL gets, [`super::stl::printable_bodies`]) with its colour as a base material.
//!
//! The specification asks each mesh to be manifold and oriented: every vertex is written once
//! (points that round to the same f32 coordinates are one vertex, so the faces of a joined body
//! share their edges' vertices), a triangle whose corners became one vertex is dropped, and the
//! triangles are turned so that a closed body's normals point outward.

use std::collections::HashMap;
use std::fmt::Write as _;

use super::stl::{PrintBody, PrintError, printable_bodies};
use crate::kernel::LengthUnit;
use crate::kernel::tess::{GridSampler, Tessellation};
use crate::scene::Scene;

/// Why a 3MF file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ThreeMfError {
    #[error(transparent)]
    Mesh(#[from] PrintError),
    #[error(transparent)]
    Package(#[from] super::zip::ZipError),
}

/// What [`write`] made: the package's bytes and its counts.
pub struct ThreeMf {
    pub bytes: Vec<u8>,
    pub objects: usize,
    pub triangles: usize,
    pub vertices: usize,
}

/// The colour of an object without one: the editor's grey (sRGB).
const EDITOR_GREY: [f32; 3] = [0.72, 0.74, 0.78];

const CONTENT_TYPES: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
 <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
 <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"#;

const RELATIONSHIPS: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
 <Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"#;

/// The 3MF unit name of `unit`; a document without a unit is written in millimetres, as
/// printers assume.
pub fn unit_name(unit: Option<LengthUnit>) -> &'static str {
    match unit {
        None | Some(LengthUnit::Millimetre) => "millimeter",
        Some(LengthUnit::Centimetre) => "centimeter",
        Some(LengthUnit::Metre) => "meter",
        Some(LengthUnit::Inch) => "inch",
        Some(LengthUnit::Foot) => "foot",
    }
}

/// `text` with the five characters XML reserves written as entities.
fn xml_escaped(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// `color` (sRGB, 0 to 1) as 3MF's `#RRGGBBAA`.
fn display_color(color: [f32; 3]) -> String {
    let [r, g, b] = color.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
    format!("#{r:02X}{g:02X}{b:02X}FF")
}

/// One body's mesh with every position written once: the vertices (f32, as written) and
/// the triangles between them, without those whose corners coincide.
pub fn welded(body: &PrintBody<'_>) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut vertices: Vec<[f32; 3]> = Vec::new();
    let mut triangles = Vec::with_capacity(body.facets());
    for part in &body.parts {
        let ids: Vec<u32> = part
            .positions
            .iter()
            .map(|p| {
                let p = p.to_array().map(|x| x as f32);
                *index.entry(p.map(f32::to_bits)).or_insert_with(|| {
                    vertices.push(p);
                    (vertices.len() - 1) as u32
                })
            })
            .collect();
        for t in &part.triangles {
            let [a, b, c] = t.map(|k| ids[k as usize]);
            if a != b && b != c && c != a {
                triangles.push([a, b, c]);
            }
        }
    }
    (vertices, triangles)
}

/// The 3MF package of `scene`'s visible objects at `tessellation` (grids evaluated by
/// `sampler`).
pub fn write(
    scene: &Scene,
    tessellation: Tessellation,
    sampler: &dyn GridSampler,
) -> Result<ThreeMf, ThreeMfError> {
    let bodies = printable_bodies(scene, tessellation, sampler)?;
    let mut model = String::new();
    // Writing to a String cannot fail: the results of write! are ignored below.
    let _ = write!(
        model,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"{}\" xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n \
         <metadata name=\"Application\">knotwork</metadata>\n <resources>\n  \
         <basematerials id=\"1\">\n",
        unit_name(scene.unit)
    );
    for body in &bodies {
        let _ = writeln!(
            model,
            "   <base name=\"{}\" displaycolor=\"{}\"/>",
            xml_escaped(&body.object.name),
            display_color(body.object.color.unwrap_or(EDITOR_GREY))
        );
    }
    model.push_str("  </basematerials>\n");
    let (mut triangle_count, mut vertex_count) = (0, 0);
    for (k, body) in bodies.iter().enumerate() {
        let (vertices, triangles) = welded(body);
        triangle_count += triangles.len();
        vertex_count += vertices.len();
        let _ = writeln!(
            model,
            "  <object id=\"{}\" name=\"{}\" type=\"model\" pid=\"1\" pindex=\"{k}\">\n   \
             <mesh>\n    <vertices>",
            k + 2,
            xml_escaped(&body.object.name)
        );
        for [x, y, z] in &vertices {
            let _ = writeln!(model, "     <vertex x=\"{x}\" y=\"{y}\" z=\"{z}\"/>");
        }
        model.push_str("    </vertices>\n    <triangles>\n");
        for [a, b, c] in &triangles {
            let _ = writeln!(model, "     <triangle v1=\"{a}\" v2=\"{b}\" v3=\"{c}\"/>");
        }
        model.push_str("    </triangles>\n   </mesh>\n  </object>\n");
    }
    model.push_str(" </resources>\n <build>\n");
    for k in 0..bodies.len() {
        let _ = writeln!(model, "  <item objectid=\"{}\"/>", k + 2);
    }
    model.push_str(" </build>\n</model>\n");
    let bytes = super::zip::stored(&[
        ("[Content_Types].xml", CONTENT_TYPES.as_bytes()),
        ("_rels/.rels", RELATIONSHIPS.as_bytes()),
        ("3D/3dmodel.model", model.as_bytes()),
    ])?;
    Ok(ThreeMf {
        bytes,
        objects: bodies.len(),
        triangles: triangle_count,
        vertices: vertex_count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_colours_are_written_as_xml_and_3mf_want_them() {
        assert_eq!(
            xml_escaped("a<b & \"c\" 'd'>"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;"
        );
        assert_eq!(display_color([1.0, 0.0, 0.5]), "#FF0080FF");
        assert_eq!(unit_name(None), "millimeter");
        assert_eq!(unit_name(Some(LengthUnit::Inch)), "inch");
    }
}
