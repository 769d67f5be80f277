//! Construction history: how a surface was built from curve objects (a loft, a sweep, a
//! network, …), kept with the surface so that it is built again when one of those curves
//! changes. The recipe is the `knotwork construct` request with each input curve replaced by a
//! reference `{"input": k}` to the k-th name of [`Construction::inputs`]; the document fills the
//! references in with the curves' current records and builds the request again
//! ([`crate::doc`]). Saved in projects as `"construction": {"request": …, "inputs": […]}`.

use serde_json::Value;

use super::json::FormatError;
use super::{Scene, SceneObject};

/// How an object was built from curve objects of the same scene.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Construction {
    /// A construct request whose curves are references `{"input": k}`.
    pub request: Value,
    /// The names of the input curve objects, in reference order.
    pub inputs: Vec<String>,
}

/// Why a construction's inputs could not be gathered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    #[error("its input curve \"{0}\" is no longer in the scene")]
    Missing(String),
    #[error("its input \"{0}\" is no longer a curve")]
    NotACurve(String),
    #[error("the request refers to input {index}; it has {count}")]
    BadReference { index: usize, count: usize },
}

impl Construction {
    /// A construction of `request` (with `{"input": k}` references) on `inputs`; refused when a
    /// reference has no input or an input is not referred to.
    pub fn new(request: Value, inputs: Vec<String>) -> Result<Self, FormatError> {
        let mut used = vec![false; inputs.len()];
        let mut bad = None;
        visit_references(&request, &mut |k| match used.get_mut(k) {
            Some(u) => *u = true,
            None => bad = Some(k),
        });
        if let Some(k) = bad {
            return Err(FormatError::new(
                "construction.request",
                format!("refers to input {k}; there are {}", inputs.len()),
            ));
        }
        if let Some(k) = used.iter().position(|u| !u) {
            return Err(FormatError::new(
                format!("construction.inputs[{k}]"),
                "is not used by the request",
            ));
        }
        Ok(Self { request, inputs })
    }

    /// Whether object `name` is one of the inputs.
    pub fn uses(&self, name: &str) -> bool {
        self.inputs.iter().any(|n| n == name)
    }

    /// The construction with input `from` renamed to `to`.
    pub fn renamed(&self, from: &str, to: &str) -> Self {
        let mut renamed = self.clone();
        for name in &mut renamed.inputs {
            if name == from {
                *name = to.to_owned();
            }
        }
        renamed
    }

    /// What the request's command is ("loft", "sweep1", …), for labels.
    pub fn command(&self) -> &str {
        self.request
            .get("construct")
            .and_then(Value::as_str)
            .unwrap_or("construction")
    }

    /// The request with every reference replaced by its input curve's record, taken from
    /// `scene` (the first object of each name).
    pub fn request_with(&self, scene: &Scene) -> Result<Value, InputError> {
        let mut records = Vec::with_capacity(self.inputs.len());
        for name in &self.inputs {
            let object = scene
                .objects
                .iter()
                .find(|o| &o.name == name)
                .ok_or_else(|| InputError::Missing(name.clone()))?;
            if object.kind().space_curve().is_none() {
                return Err(InputError::NotACurve(name.clone()));
            }
            records.push(object.kind().record());
        }
        let mut request = self.request.clone();
        fill_references(&mut request, &records)?;
        Ok(request)
    }
}

/// The index of a reference `{"input": k}`.
fn reference(value: &Value) -> Option<usize> {
    let map = value.as_object()?;
    if map.len() != 1 {
        return None;
    }
    map.get("input")?.as_u64().map(|k| k as usize)
}

fn visit_references(value: &Value, f: &mut impl FnMut(usize)) {
    if let Some(k) = reference(value) {
        return f(k);
    }
    match value {
        Value::Array(items) => items.iter().for_each(|v| visit_references(v, f)),
        Value::Object(map) => map.values().for_each(|v| visit_references(v, f)),
        _ => {}
    }
}

fn fill_references(value: &mut Value, records: &[Value]) -> Result<(), InputError> {
    if let Some(k) = reference(value) {
        *value = records.get(k).cloned().ok_or(InputError::BadReference {
            index: k,
            count: records.len(),
        })?;
        return Ok(());
    }
    match value {
        Value::Array(items) => items
            .iter_mut()
            .try_for_each(|v| fill_references(v, records)),
        Value::Object(map) => map
            .values_mut()
            .try_for_each(|v| fill_references(v, records)),
        _ => Ok(()),
    }
}

impl SceneObject {
    /// The object with construction history `construction`.
    pub fn with_construction(mut self, construction: Construction) -> Self {
        self.construction = Some(construction);
        self
    }
}
