//! Two small pieces of plain data every file format of knotwork shares, here below them all:
//! why a file could not be read ([`FormatError`], with the path of the offending value) and
//! the length unit a model's coordinates are in ([`LengthUnit`]).

use crate::GeometryError;

/// Why a file could not be read. `path` is the path of the offending value (a JSON path, or a
/// STEP instance and argument; empty for the whole document).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{message}", if path.is_empty() { String::new() } else { format!("{path}: ") })]
pub struct FormatError {
    pub path: String,
    pub message: String,
}

impl FormatError {
    pub fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            message: message.into(),
        }
    }

    /// A kernel error about the object at `path`: its location inside the object (for example
    /// `knots[0][3]`) joins the path, the rest is the message.
    pub fn geometry(path: &str, error: GeometryError) -> Self {
        match error.location() {
            Some(at) => Self::new(join_path(path, at.as_str()), error.detail()),
            None => Self::new(path, error.to_string()),
        }
    }
}

/// `path` and `field` as one path: `a.b`, `a[3]`, or `field` alone under the root.
pub fn join_path(path: &str, field: &str) -> String {
    if path.is_empty() {
        field.to_string()
    } else if field.starts_with('[') {
        format!("{path}{field}")
    } else {
        format!("{path}.{field}")
    }
}

/// A length unit a document's coordinates are in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    Millimetre,
    Centimetre,
    Metre,
    Inch,
    Foot,
}

impl LengthUnit {
    /// Every unit, in the order a menu lists them.
    pub const ALL: [LengthUnit; 5] = [
        LengthUnit::Millimetre,
        LengthUnit::Centimetre,
        LengthUnit::Metre,
        LengthUnit::Inch,
        LengthUnit::Foot,
    ];

    /// The unit's symbol, as project files write it: "mm", "cm", "m", "in", "ft".
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Centimetre => "cm",
            LengthUnit::Metre => "m",
            LengthUnit::Inch => "in",
            LengthUnit::Foot => "ft",
        }
    }

    /// The unit of symbol `symbol`, if it is one of [`Self::ALL`]'s.
    pub fn from_symbol(symbol: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|u| u.symbol() == symbol)
    }

    /// Metres in one unit (the inch is 25.4 mm exactly, the foot 12 inches).
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 1e-3,
            LengthUnit::Centimetre => 1e-2,
            LengthUnit::Metre => 1.0,
            LengthUnit::Inch => 0.0254,
            LengthUnit::Foot => 0.3048,
        }
    }
}
