//! The one table of file formats knotwork reads: each format's name, extensions, media types,
//! how its contents are recognized, and what opening it does. [`super::open`], the desktop's
//! open dialog and the page's file picker all read this table, so a new format is one module
//! plus one row here. Formats knotwork does not read but a user may well try (IGES,
//! Rhino, STL) are recognized too, so that the message names them.

/// Which reader a format has; all but a height image open as the document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reader {
    /// A knotwork project, or a bare surface in knotwork's JSON format ([`super::project`]).
    Project,
    /// glTF 2.0, binary or text ([`super::gltf_import`]).
    Gltf,
    /// Wavefront OBJ ([`super::obj`]).
    Obj,
    /// STEP, ISO 10303-21 ([`super::step`]).
    Step,
    /// A PNG that becomes the selected surface's displacement ([`super::height_image`]).
    HeightImage,
}

impl Reader {
    /// Whether a file of this format becomes the open document.
    pub fn opens_document(self) -> bool {
        self != Reader::HeightImage
    }
}

/// One format knotwork reads.
#[derive(Debug, Clone, Copy)]
pub struct Format {
    /// "glTF 2.0", for dialogs and messages.
    pub name: &'static str,
    /// Lower-case extensions without the dot.
    pub extensions: &'static [&'static str],
    /// Media types the browser's picker may offer.
    pub media_types: &'static [&'static str],
    /// Recognizes the format by its first bytes, whatever the file's name.
    pub magic: fn(&[u8]) -> bool,
    pub reader: Reader,
}

fn no_magic(_: &[u8]) -> bool {
    false
}

fn glb_magic(bytes: &[u8]) -> bool {
    bytes.starts_with(b"glTF")
}

fn step_magic(bytes: &[u8]) -> bool {
    knotwork_step::part21::looks_like_part21(&bytes[..bytes.len().min(4096)])
}

fn png_magic(bytes: &[u8]) -> bool {
    bytes.starts_with(b"\x89PNG\r\n\x1a\n")
}

/// The formats knotwork reads, the fallback (a project) first.
pub const FORMATS: [Format; 5] = [
    Format {
        name: "knotwork project",
        extensions: &["json", "knotwork"],
        media_types: &["application/json"],
        magic: no_magic,
        reader: Reader::Project,
    },
    Format {
        name: "glTF 2.0",
        extensions: &["glb", "gltf"],
        media_types: &["model/gltf-binary", "model/gltf+json"],
        magic: glb_magic,
        reader: Reader::Gltf,
    },
    Format {
        name: "Wavefront OBJ",
        extensions: &["obj"],
        media_types: &[],
        magic: no_magic,
        reader: Reader::Obj,
    },
    Format {
        name: "STEP",
        extensions: &["step", "stp", "p21"],
        media_types: &["model/step", "application/step"],
        magic: step_magic,
        reader: Reader::Step,
    },
    Format {
        name: "PNG height map",
        extensions: &["png"],
        media_types: &["image/png"],
        magic: png_magic,
        reader: Reader::HeightImage,
    },
];

/// Formats knotwork does not read, by extensions and leading bytes, for the message.
const FOREIGN: [(&str, &[&str], &[u8]); 4] = [
    ("IGES", &["igs", "iges"], b""),
    ("Rhino 3DM", &["3dm"], b"3D Geometry File Format"),
    ("STL", &["stl"], b""),
    ("FBX", &["fbx"], b"Kaydara FBX Binary"),
];

/// The lower-case extension of `name` (empty without one).
pub fn extension(name: &str) -> String {
    name.rsplit_once('.')
        .map(|(_, e)| e.to_ascii_lowercase())
        .unwrap_or_default()
}

/// The format of a file: by its leading bytes where a format has magic, else by its
/// extension; a project (the first row) otherwise.
pub fn format_of(name: &str, bytes: &[u8]) -> &'static Format {
    let extension = extension(name);
    FORMATS
        .iter()
        .find(|f| (f.magic)(bytes))
        .or_else(|| {
            FORMATS
                .iter()
                .find(|f| f.extensions.contains(&extension.as_str()))
        })
        .unwrap_or(&FORMATS[0])
}

/// The name of a format knotwork does not read that the file is (by its leading bytes or its
/// extension), if it is one.
pub fn foreign_format(name: &str, bytes: &[u8]) -> Option<&'static str> {
    let extension = extension(name);
    FOREIGN
        .iter()
        .find(|(_, extensions, magic)| {
            (!magic.is_empty() && bytes.starts_with(magic))
                || extensions.contains(&extension.as_str())
        })
        .map(|(name, _, _)| *name)
}

/// "knotwork projects (.json, .knotwork), glTF 2.0 (.glb, .gltf), …": what knotwork reads, for
/// messages.
pub fn readable_list() -> String {
    FORMATS
        .iter()
        .map(|f| {
            let extensions: Vec<String> = f.extensions.iter().map(|e| format!(".{e}")).collect();
            format!("{} ({})", f.name, extensions.join(", "))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every extension of the formats that open as the document (`documents`) or not.
pub fn extensions(documents: bool) -> Vec<&'static str> {
    FORMATS
        .iter()
        .filter(|f| f.reader.opens_document() == documents)
        .flat_map(|f| f.extensions.iter().copied())
        .collect()
}

/// The browser picker's `accept` list for every format: ".json,.knotwork,…,application/json,…".
pub fn accept_list() -> String {
    let extensions = FORMATS
        .iter()
        .flat_map(|f| f.extensions.iter().map(|e| format!(".{e}")));
    let media = FORMATS
        .iter()
        .flat_map(|f| f.media_types.iter().map(|m| m.to_string()));
    extensions.chain(media).collect::<Vec<_>>().join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contents_win_over_names_and_names_over_the_fallback() {
        let glb = b"glTF\x02\x00\x00\x00";
        let png = b"\x89PNG\r\n\x1a\n\x00\x00";
        assert_eq!(format_of("scene.json", glb).reader, Reader::Gltf);
        assert_eq!(format_of("bumps.dat", png).reader, Reader::HeightImage);
        assert_eq!(format_of("Cube.OBJ", b"v 0 0 0").reader, Reader::Obj);
        assert_eq!(format_of("model.gltf", b"{").reader, Reader::Gltf);
        assert_eq!(format_of("untitled", b"{}").reader, Reader::Project);
        assert!(!Reader::HeightImage.opens_document() && Reader::Obj.opens_document());
    }

    #[test]
    fn foreign_files_are_named_and_the_readable_ones_listed() {
        assert_eq!(format_of("part.STEP", b"").reader, Reader::Step);
        assert_eq!(
            format_of("noname", b"ISO-10303-21;\nHEADER;").reader,
            Reader::Step
        );
        assert_eq!(foreign_format("part.step", b""), None);
        assert_eq!(foreign_format("hull.igs", b""), Some("IGES"));
        assert_eq!(foreign_format("boat.3dm", b""), Some("Rhino 3DM"));
        assert_eq!(foreign_format("print.stl", b"solid x"), Some("STL"));
        assert_eq!(foreign_format("scene.json", b"{}"), None);
        let message = crate::io::open("part.igs", b"", &|_| Err(String::new()))
            .expect_err("an IGES file is refused")
            .to_string();
        assert!(message.contains("IGES"), "{message}");
        for format in FORMATS {
            assert!(message.contains(format.name), "{message}");
        }
        let message = crate::io::open("bumps.png", b"\x89PNG\r\n\x1a\n", &|_| Err(String::new()))
            .expect_err("a PNG is no document")
            .to_string();
        assert!(message.contains("height map"), "{message}");
    }

    #[test]
    fn the_pickers_offer_every_format() {
        let accept = accept_list();
        for format in FORMATS {
            for e in format.extensions {
                assert!(accept.split(',').any(|a| a == format!(".{e}")), "{accept}");
            }
        }
        assert!(accept.contains("image/png") && accept.contains("model/gltf-binary"));
        assert_eq!(
            extensions(true),
            [
                "json", "knotwork", "glb", "gltf", "obj", "step", "stp", "p21"
            ]
        );
        assert_eq!(extensions(false), ["png"]);
    }
}
