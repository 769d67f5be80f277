//! From the instance table to bodies: units, the assembly (representations placed in each
//! other by item-defined transformations and mapped items), product names, colours, and each
//! shell's faces built as trimmed NURBS ([`super::faces`]) with the shell's shared edges.

use std::collections::{HashMap, HashSet};
use std::rc::Rc;
use std::sync::Arc;

use crate::entities::Surface3;

use glam::{DAffine3, DVec3};

use super::entities::{Entities, EntityError, bad, real_of};
use super::faces::{Bound, CurveOrigin, EdgeGeometry, LoopEdge, build_face};
use super::part21::{Exchange, Instance, Record, Value};
use crate::FormatError;
use crate::kernel::TrimmedSurface;
use crate::kernel::join::{EdgeId, SharedEdge, Topology};

/// The most placed instances of bodies (an assembly that places parts in parts).
const MAX_PLACEMENTS: usize = 100_000;

/// One body read: a shell's faces placed in the model.
pub struct StepBody {
    pub name: String,
    pub color: Option<[f32; 3]>,
    pub faces: Vec<TrimmedSurface>,
    /// Each face's surface type in the file ("plane", "cylinder", ...).
    pub surface_types: Vec<&'static str>,
    /// The shared, naked and degenerate edges from the file's topology.
    pub topology: Topology,
    /// Whether the file calls the shell closed.
    pub closed: bool,
}

/// A STEP file read.
pub struct StepModel {
    pub bodies: Vec<StepBody>,
    /// Millimetres per length unit of the file.
    pub millimetres_per_unit: f64,
    /// The file's length unit as written ("millimetre", "inch", ...).
    pub unit_name: String,
    pub schema: String,
    /// Faces skipped, with why.
    pub warnings: Vec<String>,
    /// The trim tolerance used (mm).
    pub tolerance: f64,
    /// The files the model refers to for its parts (`DOCUMENT_FILE` names: an assembly
    /// written as one file per part keeps only the structure in its top file).
    pub external_files: Vec<String>,
}

/// Which step of reading is under way, for a progress bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    Parsing,
    BuildingFaces,
}

/// The length unit of a unit instance, in millimetres, and its name.
fn length_unit(x: &Exchange, id: u64, depth: usize) -> Option<(f64, String)> {
    if depth > 6 {
        return None;
    }
    let instance = x.get(id)?;
    if let Some(si) = instance.part("SI_UNIT") {
        // SI_UNIT(prefix, name) as a partial entity; a simple SI_UNIT has (*, prefix, name).
        let args: Vec<&Value> = si
            .args
            .iter()
            .filter(|v| !matches!(v, Value::Derived))
            .collect();
        let (prefix, name) = match args.as_slice() {
            [p, n] => (p, n),
            [n] => (&&Value::Null, n),
            _ => return None,
        };
        let Value::Enum(name) = name else { return None };
        if name != "METRE" {
            return None;
        }
        let factor = match prefix {
            Value::Enum(p) => match p.as_str() {
                "EXA" => 1e18,
                "PETA" => 1e15,
                "TERA" => 1e12,
                "GIGA" => 1e9,
                "MEGA" => 1e6,
                "KILO" => 1e3,
                "HECTO" => 1e2,
                "DECA" => 1e1,
                "DECI" => 1e-1,
                "CENTI" => 1e-2,
                "MILLI" => 1e-3,
                "MICRO" => 1e-6,
                "NANO" => 1e-9,
                "PICO" => 1e-12,
                _ => return None,
            },
            _ => 1.0,
        };
        let label = match prefix {
            Value::Enum(p) => format!("{}metre", p.to_ascii_lowercase()),
            _ => "metre".into(),
        };
        return Some((factor * 1000.0, label));
    }
    if let Some(c) = instance.part("CONVERSION_BASED_UNIT") {
        let name = match c.args.first() {
            Some(Value::Str(s)) => s.to_ascii_lowercase(),
            _ => "unit".into(),
        };
        let Some(Value::Ref(m)) = c.args.get(1) else {
            return None;
        };
        let measure = x.get(*m)?;
        let r = measure
            .part("LENGTH_MEASURE_WITH_UNIT")
            .or_else(|| measure.part("MEASURE_WITH_UNIT"))?;
        let value = match r.args.first()? {
            Value::Typed(_, v) => match **v {
                Value::Real(f) => f,
                Value::Integer(i) => i as f64,
                _ => return None,
            },
            Value::Real(f) => *f,
            _ => return None,
        };
        let Some(Value::Ref(unit)) = r.args.get(1) else {
            return None;
        };
        let (base, _) = length_unit(x, *unit, depth + 1)?;
        let mm = value * base;
        return (mm.is_finite() && mm > 0.0).then_some((mm, name));
    }
    None
}

/// The partial entities the reader finds by looking through the whole file (units,
/// uncertainty, documents, styles, shape representations and their relationships, bodies);
/// the rest it reaches by reference. Representations ([`is_representation`]) too.
const SCANNED: [&str; 14] = [
    "GLOBAL_UNIT_ASSIGNED_CONTEXT",
    "DOCUMENT_FILE",
    "UNCERTAINTY_MEASURE_WITH_UNIT",
    "STYLED_ITEM",
    "OVER_RIDING_STYLED_ITEM",
    "SHAPE_DEFINITION_REPRESENTATION",
    "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION",
    "REPRESENTATION_RELATIONSHIP",
    "MANIFOLD_SOLID_BREP",
    "BREP_WITH_VOIDS",
    "SHELL_BASED_SURFACE_MODEL",
    "ORIENTED_CLOSED_SHELL",
    "CLOSED_SHELL",
    "OPEN_SHELL",
];

/// Whether the reader looks at `instance` through [`Survey`]'s list: it has a partial entity
/// that [`SCANNED`] names or that is a representation. The reader's eleven looks through the
/// file (a tenth of a second each for a million instances) go through these few alone.
fn scanned_kind(instance: &Instance) -> bool {
    let parts = match instance {
        Instance::Simple(r) => std::slice::from_ref(r),
        Instance::Complex(p) => p.as_slice(),
    };
    parts
        .iter()
        .any(|r| is_representation(&r.name) || SCANNED.contains(&r.name.as_str()))
}

/// The instances at `places` ([`Survey`]'s list), in order.
fn scanned_instances<'a>(
    x: &'a Exchange,
    places: &'a [usize],
) -> impl Iterator<Item = &'a (u64, Instance)> + 'a {
    places.iter().filter_map(|&k| x.instances.get(k))
}

/// The file's length unit: the first representation context's, else millimetres.
fn file_unit(x: &Exchange, scan: &[usize]) -> (f64, String) {
    for (_, instance) in scanned_instances(x, scan) {
        let Some(ctx) = instance.part("GLOBAL_UNIT_ASSIGNED_CONTEXT") else {
            continue;
        };
        let Some(Value::List(units)) = ctx.args.first() else {
            continue;
        };
        for u in units {
            if let Value::Ref(id) = u
                && x.get(*id).is_some_and(|i| i.is("LENGTH_UNIT"))
                && let Some(found) = length_unit(x, *id, 0)
            {
                return found;
            }
        }
    }
    (1.0, "millimetre".into())
}

/// The names of the files the model refers to (`DOCUMENT_FILE`), in the order written.
fn external_files(x: &Exchange, scan: &[usize]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for (_, instance) in scanned_instances(x, scan) {
        if let Some(d) = instance.part("DOCUMENT_FILE")
            && let Some(Value::Str(name)) = d.args.first()
            && !name.is_empty()
            && !out.contains(name)
        {
            out.push(name.clone());
        }
    }
    out
}

/// The largest length uncertainty the file declares (`UNCERTAINTY_MEASURE_WITH_UNIT` with a
/// `LENGTH_MEASURE`), in millimetres; `None` when it declares none.
fn file_uncertainty(x: &Exchange, scan: &[usize], millimetres_per_unit: f64) -> Option<f64> {
    let mut largest: Option<f64> = None;
    for (_, instance) in scanned_instances(x, scan) {
        let Some(u) = instance.part("UNCERTAINTY_MEASURE_WITH_UNIT") else {
            continue;
        };
        let value = match u.args.first() {
            Some(Value::Typed(kind, v)) if kind == "LENGTH_MEASURE" => match **v {
                Value::Real(f) => f,
                Value::Integer(i) => i as f64,
                _ => continue,
            },
            _ => continue,
        };
        let mm = value * millimetres_per_unit;
        if mm.is_finite() && mm > 0.0 {
            largest = Some(largest.map_or(mm, |l: f64| l.max(mm)));
        }
    }
    largest
}

/// A colour found in a style's tree (`COLOUR_RGB`, or a pre-defined colour's name).
fn colour_in(x: &Exchange, value: &Value, depth: usize, seen: &mut usize) -> Option<[f32; 3]> {
    *seen += 1;
    if depth > 12 || *seen > 256 {
        return None;
    }
    match value {
        Value::Ref(id) => {
            let instance = x.get(*id)?;
            if let Some(c) = instance.part("COLOUR_RGB") {
                let get = |k: usize| match c.args.get(k) {
                    Some(Value::Real(f)) => Some(*f as f32),
                    Some(Value::Integer(i)) => Some(*i as f32),
                    _ => None,
                };
                let rgb = [get(1)?, get(2)?, get(3)?];
                return rgb.iter().all(|c| (0.0..=1.0).contains(c)).then_some(rgb);
            }
            if let Some(c) = instance.part("DRAUGHTING_PRE_DEFINED_COLOUR") {
                let Some(Value::Str(name)) = c.args.first() else {
                    return None;
                };
                return Some(match name.as_str() {
                    "red" => [1.0, 0.0, 0.0],
                    "green" => [0.0, 1.0, 0.0],
                    "blue" => [0.0, 0.0, 1.0],
                    "yellow" => [1.0, 1.0, 0.0],
                    "magenta" => [1.0, 0.0, 1.0],
                    "cyan" => [0.0, 1.0, 1.0],
                    "black" => [0.0, 0.0, 0.0],
                    "white" => [1.0, 1.0, 1.0],
                    _ => return None,
                });
            }
            let args: Vec<Value> = match instance {
                Instance::Simple(r) => r.args.clone(),
                Instance::Complex(parts) => parts.iter().flat_map(|r| r.args.clone()).collect(),
            };
            args.iter().find_map(|a| colour_in(x, a, depth + 1, seen))
        }
        Value::List(items) => items.iter().find_map(|a| colour_in(x, a, depth + 1, seen)),
        Value::Typed(_, v) => colour_in(x, v, depth + 1, seen),
        _ => None,
    }
}

/// Colours by the item they style.
fn colours(x: &Exchange, scan: &[usize]) -> HashMap<u64, [f32; 3]> {
    let mut out = HashMap::new();
    for (_, instance) in scanned_instances(x, scan) {
        let Some(r) = instance
            .part("STYLED_ITEM")
            .or_else(|| instance.part("OVER_RIDING_STYLED_ITEM"))
        else {
            continue;
        };
        let (Some(styles), Some(Value::Ref(item))) = (r.args.get(1), r.args.get(2)) else {
            continue;
        };
        let mut seen = 0;
        if let Some(c) = colour_in(x, styles, 0, &mut seen) {
            out.insert(*item, c);
        }
    }
    out
}

/// Representations and how they are placed in each other.
struct Assembly {
    /// Representation → its items.
    items: HashMap<u64, Vec<u64>>,
    /// Parent group → (child group, transform from the child's coordinates to the parent's).
    children: HashMap<u64, Vec<(u64, DAffine3)>>,
    /// Representation → its group (representations related without a transformation).
    group: HashMap<u64, u64>,
    /// Representation → product name.
    names: HashMap<u64, String>,
}

fn find(parent: &mut HashMap<u64, u64>, k: u64) -> u64 {
    let mut k = k;
    let mut steps = 0;
    while let Some(&p) = parent.get(&k) {
        if p == k || steps > 10_000 {
            break;
        }
        k = p;
        steps += 1;
    }
    k
}

fn is_representation(name: &str) -> bool {
    name.ends_with("REPRESENTATION")
        && !name.contains("RELATIONSHIP")
        && !name.contains("DEFINITION")
        && !name.starts_with("CONTEXT_DEPENDENT")
}

fn assembly(e: &Entities, scan: &[usize]) -> Result<Assembly, FormatError> {
    let x = e.x;
    let mut items: HashMap<u64, Vec<u64>> = HashMap::new();
    for (id, instance) in scanned_instances(x, scan) {
        let parts = match instance {
            Instance::Simple(r) => std::slice::from_ref(r),
            Instance::Complex(p) => p.as_slice(),
        };
        for r in parts {
            if is_representation(&r.name)
                && r.args.len() >= 3
                && let Some(Value::List(list)) = r.args.get(1)
            {
                let refs: Vec<u64> = list
                    .iter()
                    .filter_map(|v| {
                        if let Value::Ref(i) = v {
                            Some(*i)
                        } else {
                            None
                        }
                    })
                    .collect();
                items.entry(*id).or_default().extend(refs);
            }
        }
    }
    // Product names and the representations of product definitions.
    let mut pd_reps: HashMap<u64, Vec<u64>> = HashMap::new();
    let mut names: HashMap<u64, String> = HashMap::new();
    let product_name = |pd: u64| -> Option<String> {
        let r = x.get(pd)?.part("PRODUCT_DEFINITION")?;
        let Some(Value::Ref(pdf)) = r.args.get(2) else {
            return None;
        };
        let f = x.get(*pdf)?;
        let fr = f
            .part("PRODUCT_DEFINITION_FORMATION")
            .or_else(|| f.part("PRODUCT_DEFINITION_FORMATION_WITH_SPECIFIED_SOURCE"))?;
        let Some(Value::Ref(p)) = fr.args.get(2) else {
            return None;
        };
        let pr = x.get(*p)?.part("PRODUCT")?;
        match (pr.args.get(1), pr.args.first()) {
            (Some(Value::Str(n)), _) if !n.is_empty() => Some(n.clone()),
            (_, Some(Value::Str(n))) if !n.is_empty() => Some(n.clone()),
            _ => None,
        }
    };
    for (_, instance) in scanned_instances(x, scan) {
        let Some(sdr) = instance.part("SHAPE_DEFINITION_REPRESENTATION") else {
            continue;
        };
        let (Some(Value::Ref(pds)), Some(Value::Ref(rep))) = (sdr.args.first(), sdr.args.get(1))
        else {
            continue;
        };
        let Some(pdsr) = x.get(*pds).and_then(|i| i.part("PRODUCT_DEFINITION_SHAPE")) else {
            continue;
        };
        let Some(Value::Ref(pd)) = pdsr.args.get(2) else {
            continue;
        };
        pd_reps.entry(*pd).or_default().push(*rep);
        if let Some(n) = product_name(*pd) {
            names.insert(*rep, n);
        }
    }
    // Relations: identity links group representations; transformations place children.
    let mut parent: HashMap<u64, u64> = items.keys().map(|&k| (k, k)).collect();
    let mut placed: Vec<(u64, u64, DAffine3)> = Vec::new(); // (parent rep, child rep, child→parent)
    let mut child_of_nauo: HashMap<u64, u64> = HashMap::new(); // relation → child rep
    for (_, instance) in scanned_instances(x, scan) {
        let Some(cdsr) = instance.part("CONTEXT_DEPENDENT_SHAPE_REPRESENTATION") else {
            continue;
        };
        let (Some(Value::Ref(rel)), Some(Value::Ref(pds))) = (cdsr.args.first(), cdsr.args.get(1))
        else {
            continue;
        };
        let Some(pdsr) = x.get(*pds).and_then(|i| i.part("PRODUCT_DEFINITION_SHAPE")) else {
            continue;
        };
        let Some(Value::Ref(nauo)) = pdsr.args.get(2) else {
            continue;
        };
        let Some(n) = x
            .get(*nauo)
            .and_then(|i| i.part("NEXT_ASSEMBLY_USAGE_OCCURRENCE"))
        else {
            continue;
        };
        let Some(Value::Ref(child_pd)) = n.args.get(4) else {
            continue;
        };
        if let Some(reps) = pd_reps.get(child_pd) {
            if let Some(&r) = reps.first() {
                child_of_nauo.insert(*rel, r);
            }
            // Where the relation names one of the child product's representations, that one.
            if let Some(rel_inst) = x
                .get(*rel)
                .and_then(|i| i.part("REPRESENTATION_RELATIONSHIP"))
                && let (Some(Value::Ref(r1)), Some(Value::Ref(r2))) =
                    (rel_inst.args.get(2), rel_inst.args.get(3))
            {
                if reps.contains(r2) {
                    child_of_nauo.insert(*rel, *r2);
                } else if reps.contains(r1) {
                    child_of_nauo.insert(*rel, *r1);
                }
            }
        }
    }
    for (id, instance) in scanned_instances(x, scan) {
        let Some(rr) = instance.part("REPRESENTATION_RELATIONSHIP") else {
            continue;
        };
        let (Some(Value::Ref(r1)), Some(Value::Ref(r2))) = (rr.args.get(2), rr.args.get(3)) else {
            continue;
        };
        let transform = instance.part("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION");
        match transform.and_then(|t| t.args.first()) {
            Some(Value::Ref(idt)) => {
                let t = e.record(*idt, "ITEM_DEFINED_TRANSFORMATION", 4)?;
                let f1 = e.placement(e.reference(*idt, t, 2)?)?;
                let f2 = e.placement(e.reference(*idt, t, 3)?)?;
                // Maps rep_1's coordinates to rep_2's.
                let m = f2.to_affine() * f1.to_affine().inverse();
                let child = child_of_nauo.get(id).copied().unwrap_or(*r1);
                if child == *r2 {
                    placed.push((*r1, *r2, m.inverse()));
                } else {
                    placed.push((*r2, *r1, m));
                }
            }
            _ => {
                parent.entry(*r1).or_insert(*r1);
                parent.entry(*r2).or_insert(*r2);
                let (a, b) = (find(&mut parent, *r1), find(&mut parent, *r2));
                if a != b {
                    parent.insert(a.max(b), a.min(b));
                }
            }
        }
    }
    // Mapped items place a representation inside the one that holds them.
    for (rep, list) in &items {
        for item in list {
            let Some(mi) = x.get(*item).and_then(|i| i.part("MAPPED_ITEM")) else {
                continue;
            };
            let (Some(Value::Ref(map)), Some(Value::Ref(target))) =
                (mi.args.get(1), mi.args.get(2))
            else {
                continue;
            };
            let r = e.record(*map, "REPRESENTATION_MAP", 2)?;
            let origin = e.placement(e.reference(*map, r, 0)?)?;
            let mapped = e.reference(*map, r, 1)?;
            let target = e.placement(*target)?;
            placed.push((
                *rep,
                mapped,
                target.to_affine() * origin.to_affine().inverse(),
            ));
        }
    }
    let mut group = HashMap::new();
    let keys: Vec<u64> = parent.keys().copied().collect();
    for k in keys {
        let g = find(&mut parent, k);
        group.insert(k, g);
    }
    let mut children: HashMap<u64, Vec<(u64, DAffine3)>> = HashMap::new();
    for (p, c, t) in placed {
        let gp = *group.get(&p).unwrap_or(&p);
        let gc = *group.get(&c).unwrap_or(&c);
        if gp != gc {
            children.entry(gp).or_default().push((gc, t));
        }
    }
    Ok(Assembly {
        items,
        children,
        group,
        names,
    })
}

/// A body to build: a shell-holding item, where it is placed, its name.
struct Placement {
    item: u64,
    transform: DAffine3,
    name: Option<String>,
}

fn is_body(instance: &Instance) -> bool {
    [
        "MANIFOLD_SOLID_BREP",
        "BREP_WITH_VOIDS",
        "SHELL_BASED_SURFACE_MODEL",
        "CLOSED_SHELL",
        "OPEN_SHELL",
    ]
    .iter()
    .any(|n| instance.is(n))
}

/// A placement's key for finding the same place again: the linear map's entries to 1e-9 and
/// the translation to 1e-6 mm.
fn place_key(t: &DAffine3) -> [i64; 12] {
    let m = t.matrix3.to_cols_array();
    let mut key = [0; 12];
    for (k, v) in m.iter().enumerate() {
        key[k] = (v * 1e9).round() as i64;
    }
    for (k, v) in t.translation.to_array().iter().enumerate() {
        key[9 + k] = (v * 1e6).round() as i64;
    }
    key
}

fn placements(x: &Exchange, scan: &[usize], a: &Assembly) -> Vec<Placement> {
    let mut group_items: HashMap<u64, Vec<u64>> = HashMap::new();
    let mut group_names: HashMap<u64, String> = HashMap::new();
    for (rep, list) in &a.items {
        let g = *a.group.get(rep).unwrap_or(rep);
        group_items
            .entry(g)
            .or_default()
            .extend(list.iter().copied());
        if let Some(n) = a.names.get(rep) {
            group_names.entry(g).or_insert_with(|| n.clone());
        }
    }
    let mut is_child: HashSet<u64> = HashSet::new();
    for list in a.children.values() {
        for (c, _) in list {
            is_child.insert(*c);
        }
    }
    let in_components: HashSet<u64> = is_child
        .iter()
        .filter_map(|g| group_items.get(g))
        .flatten()
        .copied()
        .collect();
    let mut roots: Vec<u64> = group_items
        .keys()
        .copied()
        .filter(|g| !is_child.contains(g))
        .collect();
    roots.sort_unstable();
    let mut out = Vec::new();
    let mut stack: Vec<(u64, DAffine3, usize)> = roots
        .into_iter()
        .map(|g| (g, DAffine3::IDENTITY, 0))
        .collect();
    stack.reverse();
    let mut placed_at: HashSet<(u64, [i64; 12])> = HashSet::new();
    let mut placed_items: HashSet<u64> = HashSet::new();
    while let Some((g, t, depth)) = stack.pop() {
        if depth > 16 || out.len() >= MAX_PLACEMENTS {
            continue;
        }
        let mut items = group_items.get(&g).cloned().unwrap_or_default();
        items.sort_unstable();
        items.dedup();
        for item in items {
            // A body that a component of the assembly holds is placed there; a second
            // representation of it that nothing places (a bare advanced B-rep one beside the
            // product's) does not put it at the origin as well.
            if depth == 0 && in_components.contains(&item) {
                continue;
            }
            // A body held by two representations of one product (a shape representation and
            // an advanced B-rep one, say) reaches the same place twice: it is placed once.
            if !x.get(item).is_some_and(is_body) {
                continue;
            }
            if placed_at.insert((item, place_key(&t))) {
                placed_items.insert(item);
                out.push(Placement {
                    item,
                    transform: t,
                    name: group_names.get(&g).cloned(),
                });
            }
        }
        if let Some(children) = a.children.get(&g) {
            for (c, tc) in children.iter().rev() {
                stack.push((*c, t * *tc, depth + 1));
            }
        }
    }
    // Bodies no representation holds (or a file without representations): as they are.
    let held: HashSet<u64> = a.items.values().flatten().copied().collect();
    let mut inner_shells: HashSet<u64> = HashSet::new();
    for (_, instance) in scanned_instances(x, scan) {
        for name in [
            "MANIFOLD_SOLID_BREP",
            "BREP_WITH_VOIDS",
            "SHELL_BASED_SURFACE_MODEL",
            "ORIENTED_CLOSED_SHELL",
        ] {
            if let Some(r) = instance.part(name) {
                for v in &r.args[1.min(r.args.len())..] {
                    match v {
                        Value::Ref(s) => {
                            inner_shells.insert(*s);
                        }
                        Value::List(l) => inner_shells.extend(l.iter().filter_map(|v| {
                            if let Value::Ref(s) = v {
                                Some(*s)
                            } else {
                                None
                            }
                        })),
                        _ => {}
                    }
                }
            }
        }
    }
    for (id, instance) in scanned_instances(x, scan) {
        if is_body(instance)
            && !placed_items.contains(id)
            && !held.contains(id)
            && !inner_shells.contains(id)
        {
            out.push(Placement {
                item: *id,
                transform: DAffine3::IDENTITY,
                name: None,
            });
        }
    }
    out
}

/// A STEP file being read: parsed, with its units, assembly and colours worked out at once
/// ([`Self::new`]), then one placed body built per [`Self::step`], so that the editor can show
/// the progress, stay responsive between steps and cancel.
pub struct ReadJob {
    x: Exchange,
    /// The instances the reader looks through ([`Survey`]'s list).
    scan: Vec<usize>,
    schema: String,
    millimetres_per_unit: f64,
    unit_name: String,
    tolerance: f64,
    colour_of: HashMap<u64, [f32; 3]>,
    places: Vec<Placement>,
    /// Whether each of `places` is its item's last.
    last_place: Vec<bool>,
    /// How many of `places` are done.
    done: usize,
    /// The body of the next place, while its faces are built.
    building: Option<BodyBuild>,
    warnings: Vec<String>,
    bodies: Vec<StepBody>,
    edges: HashMap<u64, Arc<EdgeGeometry>>,
    built: HashMap<u64, Rc<BuiltBody>>,
    name_count: HashMap<String, usize>,
}

/// The first pass over a parsed file's instances, a share at a time: the places of the
/// instances the reader looks through ([`scanned_kind`]) and the box of the 3D points (not the
/// 2D points of p-curves, which are surface parameters), which sets the trim tolerance. Taken in
/// one go, a 1,000,000-instance file's pass held up one frame for 18–33 ms on the 2-core
/// machine; [`Self::step`] takes as many instances as it is given.
pub struct Survey {
    x: Exchange,
    /// How many instances are surveyed.
    next: usize,
    scan: Vec<usize>,
    /// The box of the points so far, in the file's unit.
    lo: DVec3,
    hi: DVec3,
}

impl Survey {
    pub fn new(x: Exchange) -> Self {
        Self {
            x,
            next: 0,
            scan: Vec::new(),
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
        }
    }

    /// The share of the instances surveyed, 0 to 1.
    pub fn progress(&self) -> f64 {
        self.next as f64 / self.x.instances.len().max(1) as f64
    }

    /// Surveys up to `count` more instances, on every core in shares of [`SURVEY_SHARE`] (the
    /// places are kept in the file's order, and the least and greatest coordinates are the
    /// same in any order); true once all are.
    pub fn step(&mut self, count: usize) -> bool {
        let x = &self.x;
        let first = self.next;
        let end = x.instances.len().min(first.saturating_add(count));
        let shares = crate::kernel::par::map((end - first).div_ceil(SURVEY_SHARE), |k| {
            let from = first + k * SURVEY_SHARE;
            let to = end.min(from + SURVEY_SHARE);
            let mut places = Vec::new();
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for (place, (_, instance)) in x.instances[from..to].iter().enumerate() {
                if scanned_kind(instance) {
                    places.push(from + place);
                }
                if let Some(p) = point_of(instance) {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
            (places, lo, hi)
        });
        for (places, lo, hi) in shares {
            self.scan.extend(places);
            self.lo = self.lo.min(lo);
            self.hi = self.hi.max(hi);
        }
        self.next = end;
        self.next >= x.instances.len()
    }

    /// The reading job: the rest surveyed, then the file's units, assembly and colours read.
    pub fn finish(mut self) -> Result<ReadJob, FormatError> {
        while !self.step(usize::MAX) {}
        ReadJob::from_survey(self)
    }
}

/// Instances surveyed by one thread at a time ([`Survey::step`]).
const SURVEY_SHARE: usize = 1 << 14;

/// A `CARTESIAN_POINT` of three finite coordinates, in the file's unit.
fn point_of(instance: &Instance) -> Option<DVec3> {
    if let Instance::Simple(r) = instance
        && r.name == "CARTESIAN_POINT"
        && let Some(Value::List(c)) = r.args.get(1)
        && let [a, b, c] = c.as_slice()
        && let (Some(a), Some(b), Some(c)) = (real_of(a), real_of(b), real_of(c))
    {
        let p = DVec3::new(a, b, c);
        return p.is_finite().then_some(p);
    }
    None
}

/// A Part 21 syntax error as the reader reports it.
pub fn syntax_error(e: super::part21::SyntaxError) -> FormatError {
    if e.message.starts_with("not an ISO-10303-21 file") || e.message == "cancelled" {
        FormatError::new("", e.message)
    } else {
        FormatError::new("", format!("not a valid STEP file: {e}"))
    }
}

impl ReadJob {
    /// Parses `bytes` (`progress(fraction)` now and then; where it returns false, parsing
    /// stops with "cancelled") and reads the file's units, assembly and colours.
    pub fn new(bytes: &[u8], progress: &mut dyn FnMut(f64) -> bool) -> Result<Self, FormatError> {
        let x = super::part21::parse(bytes, progress).map_err(syntax_error)?;
        Self::from_exchange(x)
    }

    /// The job for a parsed file: its units, assembly and colours read ([`Survey`] run to
    /// its end at once).
    pub fn from_exchange(x: Exchange) -> Result<Self, FormatError> {
        Survey::new(x).finish()
    }

    /// The job for a surveyed file.
    fn from_survey(survey: Survey) -> Result<Self, FormatError> {
        let Survey {
            x, scan, lo, hi, ..
        } = survey;
        let schema = x.schemas().join(", ");
        let (millimetres_per_unit, unit_name) = file_unit(&x, &scan);
        let e = Entities {
            x: &x,
            scale: millimetres_per_unit,
        };
        // The model's size, from its 3D points in the file's unit: scaled by a positive
        // factor, the least and greatest coordinates stay the least and greatest (rounding
        // keeps the order), so this is the box of the points in millimetres.
        let (lo, hi) = (lo * millimetres_per_unit, hi * millimetres_per_unit);
        let diagonal = if lo.is_finite() && hi.is_finite() {
            lo.distance(hi)
        } else {
            1.0
        };
        // The trim tolerance: a millionth of the model, or the file's own uncertainty where
        // that is larger (edges written within it), up to a thousandth of the model.
        let declared = file_uncertainty(&x, &scan, millimetres_per_unit).unwrap_or(0.0);
        let tolerance = (diagonal * 1e-6)
            .max(declared.min(diagonal * 1e-3))
            .max(1e-9);
        let a = assembly(&e, &scan)?;
        let colour_of = colours(&x, &scan);
        let places = placements(&x, &scan, &a);
        let mut seen = HashSet::new();
        let mut last_place: Vec<bool> = places.iter().rev().map(|p| seen.insert(p.item)).collect();
        last_place.reverse();
        Ok(Self {
            x,
            scan,
            schema,
            millimetres_per_unit,
            unit_name,
            tolerance,
            colour_of,
            places,
            last_place,
            done: 0,
            building: None,
            warnings: Vec::new(),
            bodies: Vec::new(),
            edges: HashMap::new(),
            built: HashMap::new(),
            name_count: HashMap::new(),
        })
    }

    /// The share of the placed bodies built so far, 0 to 1 (the body under way by its faces).
    pub fn progress(&self) -> f64 {
        let part = self
            .building
            .as_ref()
            .map_or(0.0, |b| b.next as f64 / b.to_build.len().max(1) as f64);
        (self.done as f64 + part) / self.places.len().max(1) as f64
    }

    /// Builds one face of the next placed body, or places the body once its faces are built
    /// (once per item however often it is placed); true when every body is done.
    pub fn step(&mut self) -> Result<bool, FormatError> {
        self.step_faces(1)
    }

    /// [`Self::step`] with up to `faces` faces of the body built at once, on every core (the
    /// model is the same whatever `faces` is).
    pub fn step_faces(&mut self, faces: usize) -> Result<bool, FormatError> {
        let Some(place) = self.places.get(self.done) else {
            return Ok(true);
        };
        let x = &self.x;
        let e = Entities {
            x,
            scale: self.millimetres_per_unit,
        };
        let body = match self.built.get(&place.item) {
            Some(b) => b.clone(),
            None => {
                let building = match &mut self.building {
                    Some(b) => b,
                    None => self.building.insert(start_body(&e, place.item)?),
                };
                if !building.done() {
                    building.build_next(
                        &e,
                        &mut self.edges,
                        self.tolerance,
                        &mut self.warnings,
                        &self.colour_of,
                        faces,
                    )?;
                    return Ok(false);
                }
                let Some(building) = self.building.take() else {
                    return Ok(false);
                };
                // The body's edges are read again by any other body that uses them: freed
                // here, a body's share at a time, rather than all at once at the end.
                self.edges.clear();
                let b = Rc::new(building.finish(&self.colour_of, self.tolerance));
                self.built.insert(place.item, b.clone());
                b
            }
        };
        // An item placed for the last time leaves the built bodies here, so that its faces
        // are moved into the model rather than copied, and what is left is freed now.
        let body = if self.last_place.get(self.done).copied().unwrap_or(true) {
            self.built.remove(&place.item);
            Rc::try_unwrap(body).unwrap_or_else(|shared| (*shared).clone())
        } else {
            (*body).clone()
        };
        self.done += 1;
        if !body.faces.is_empty() {
            let mut faces = Vec::with_capacity(body.faces.len());
            for f in body.faces {
                if place.transform == DAffine3::IDENTITY {
                    faces.push(f);
                } else {
                    let s = f
                        .surface()
                        .transformed(&place.transform)
                        .map_err(|err| bad(x, place.item, err))?;
                    faces.push(f.with_surface(s).map_err(|err| bad(x, place.item, err))?);
                }
            }
            let base = place
                .name
                .clone()
                .or_else(|| body.name.clone())
                .unwrap_or_else(|| "Body".to_string());
            let n = self.name_count.entry(base.clone()).or_insert(0);
            *n += 1;
            let name = if *n == 1 { base } else { format!("{base} {n}") };
            self.bodies.push(StepBody {
                name,
                color: body.color,
                faces,
                surface_types: body.surface_types,
                topology: body.topology,
                closed: body.closed,
            });
        }
        Ok(self.done == self.places.len())
    }

    /// The model read ([`Self::step`] run to the end; bodies not yet built are missing).
    pub fn finish(self) -> StepModel {
        self.finish_keeping_instances().0
    }

    /// [`Self::finish`], handing back the file's instances rather than dropping them: freeing
    /// a large file's millions of instances takes long enough to hold up a frame, so the
    /// caller can free them a share at a time.
    pub fn finish_keeping_instances(mut self) -> (StepModel, Vec<(u64, Instance)>) {
        let external_files = external_files(&self.x, &self.scan);
        let instances = std::mem::take(&mut self.x.instances);
        let summary = skipped_summary(&self.warnings);
        self.warnings.splice(0..0, summary);
        let model = StepModel {
            bodies: self.bodies,
            millimetres_per_unit: self.millimetres_per_unit,
            unit_name: self.unit_name,
            schema: self.schema,
            warnings: self.warnings,
            tolerance: self.tolerance,
            external_files,
        };
        (model, instances)
    }
}

/// Reads a STEP file. `progress(stage, fraction)` is called now and then; where it returns
/// false, reading stops with "cancelled".
pub fn read(
    bytes: &[u8],
    progress: &mut dyn FnMut(Stage, f64) -> bool,
) -> Result<StepModel, FormatError> {
    let mut job = ReadJob::new(bytes, &mut |f| progress(Stage::Parsing, f))?;
    loop {
        if !progress(Stage::BuildingFaces, job.progress()) {
            return Err(FormatError::new("", "cancelled"));
        }
        // A few faces per thread at a time: the faces are built on every core.
        if job.step_faces(16 * crate::kernel::par::threads())? {
            break;
        }
    }
    progress(Stage::BuildingFaces, 1.0);
    Ok(job.finish())
}

/// The warning for a face left out: `#id = ADVANCED_FACE (surface type) skipped: why`.
fn skipped_face(face_id: u64, surface_type: Option<&str>, why: &str) -> String {
    match surface_type {
        Some(t) => format!("#{face_id} = ADVANCED_FACE ({t}) skipped: {why}"),
        None => format!("#{face_id} = ADVANCED_FACE skipped: {why}"),
    }
}

/// One line per kind of entity that made faces be left out ([`skipped_face`] warnings whose
/// reason names an entity, `#id = NAME: …`), with how many faces it cost, most first:
/// "3 faces skipped on QUASI_UNIFORM_SURFACE: this kind of surface is not read".
fn skipped_summary(warnings: &[String]) -> Vec<String> {
    let mut by_entity: Vec<(String, usize, String)> = Vec::new();
    for w in warnings {
        let Some((_, why)) = w.split_once(" skipped: ") else {
            continue;
        };
        // The reason as `bad` writes it: `#id = ENTITY: message`.
        let Some((entity, message)) = why
            .strip_prefix('#')
            .and_then(|r| r.split_once(" = "))
            .and_then(|(_, r)| r.split_once(": "))
        else {
            continue;
        };
        match by_entity.iter_mut().find(|(e, _, _)| e == entity) {
            Some((_, n, _)) => *n += 1,
            None => by_entity.push((entity.to_string(), 1, message.to_string())),
        }
    }
    by_entity.sort_by_key(|b| std::cmp::Reverse(b.1));
    by_entity
        .into_iter()
        .map(|(entity, n, message)| {
            let faces = if n == 1 { "face" } else { "faces" };
            format!("{n} {faces} skipped on {entity}: {message}")
        })
        .collect()
}

/// A face's records read in order, before any geometry ([`face_plan`]).
struct FacePlan {
    face_id: u64,
    surface_id: u64,
    same_sense: bool,
    /// Each bound's orientation and its edges in order: (edge, used forward).
    bounds: Vec<(bool, Vec<(u64, bool)>)>,
    /// The error met reading the face's records after `bounds` (the read ends there, once
    /// the geometry before it is read).
    error: Option<FormatError>,
}

/// Face `face_id`'s surface, sense and bounds as its records give them (turned over where
/// `flip`); the first malformed record ends the plan with its error.
fn face_plan(e: &Entities, face_id: u64, flip: bool) -> FacePlan {
    let mut plan = FacePlan {
        face_id,
        surface_id: 0,
        same_sense: true,
        bounds: Vec::new(),
        error: None,
    };
    if let Err(err) = read_face_plan(e, &mut plan, flip) {
        plan.error = Some(err);
    }
    plan
}

/// The first partial entity of instance `id` among `names` (its types, in the order to try),
/// with at least `count` arguments.
fn record_of<'a>(
    e: &Entities<'a>,
    id: u64,
    names: &[&str],
    count: usize,
) -> Result<&'a Record, FormatError> {
    let instance = e.instance(id)?;
    let Some(name) = names.iter().find(|name| instance.is(name)) else {
        return Err(bad(e.x, id, format!("expected {}", names.join(" or "))));
    };
    e.record(id, name, count)
}

fn read_face_plan(e: &Entities, plan: &mut FacePlan, flip: bool) -> Result<(), FormatError> {
    let face_id = plan.face_id;
    let fr = record_of(e, face_id, &["ADVANCED_FACE", "FACE_SURFACE"], 4)?;
    let bound_ids = e.references(face_id, fr, 1)?;
    plan.surface_id = e.reference(face_id, fr, 2)?;
    plan.same_sense = e.boolean(face_id, fr, 3)? != flip;
    for b in bound_ids {
        let br = record_of(e, b, &["FACE_OUTER_BOUND", "FACE_BOUND"], 3)?;
        let loop_id = e.reference(b, br, 1)?;
        let orientation = e.boolean(b, br, 2)?;
        let li = e.instance(loop_id)?;
        // A vertex loop bounds a face that is a whole closed surface (a sphere, its poles
        // the vertex): it adds no edge.
        if li.is("VERTEX_LOOP") {
            continue;
        }
        let lr = e.record(loop_id, "EDGE_LOOP", 2)?;
        plan.bounds.push((orientation, Vec::new()));
        for oe in e.references(loop_id, lr, 1)? {
            let or = e.record(oe, "ORIENTED_EDGE", 5)?;
            let edge_id = e.reference(oe, or, 3)?;
            let forward = e.boolean(oe, or, 4)?;
            if let Some((_, uses)) = plan.bounds.last_mut() {
                uses.push((edge_id, forward));
            }
        }
    }
    Ok(())
}

/// Edge `edge_id` (an `EDGE_CURVE`): its vertices, its curve and the curve's p-curves.
fn edge_geometry(e: &Entities, edge_id: u64, tolerance: f64) -> Result<EdgeGeometry, EntityError> {
    let er = e.record(edge_id, "EDGE_CURVE", 5)?;
    let vertex = |k: usize| -> Result<DVec3, FormatError> {
        let v = e.reference(edge_id, er, k)?;
        let vr = e.record(v, "VERTEX_POINT", 2)?;
        e.point(e.reference(v, vr, 1)?)
    };
    let (start, end) = (vertex(1)?, vertex(2)?);
    let curve_id = e.reference(edge_id, er, 3)?;
    let curve = e.curve(curve_id)?;
    let same = e.boolean(edge_id, er, 4)?;
    let mut g = EdgeGeometry::new(curve, start, end, same, tolerance);
    g.pcurves = e.pcurves(curve_id);
    Ok(g)
}

#[derive(Clone)]
struct BuiltBody {
    name: Option<String>,
    color: Option<[f32; 3]>,
    faces: Vec<TrimmedSurface>,
    surface_types: Vec<&'static str>,
    topology: Topology,
    closed: bool,
}

/// The faces of a shell-holding item (`MANIFOLD_SOLID_BREP`, `BREP_WITH_VOIDS`,
/// `SHELL_BASED_SURFACE_MODEL`, or a shell).
fn start_body(e: &Entities, item: u64) -> Result<BodyBuild, FormatError> {
    let x = e.x;
    let instance = e.instance(item)?;
    let mut shells: Vec<u64> = Vec::new();
    let mut name = None;
    if let Some(r) = instance.part("MANIFOLD_SOLID_BREP") {
        let r = e.record(item, &r.name, 2)?;
        shells.push(e.reference(item, r, 1)?);
        name = Some(e.text(r, 0));
        if let Some(v) = instance.part("BREP_WITH_VOIDS")
            && let Some(Value::List(l)) = v.args.last()
        {
            shells.extend(l.iter().filter_map(|v| {
                if let Value::Ref(s) = v {
                    Some(*s)
                } else {
                    None
                }
            }));
        }
    } else if let Some(r) = instance.part("BREP_WITH_VOIDS") {
        let r = e.record(item, &r.name, 3)?;
        shells.push(e.reference(item, r, 1)?);
        shells.extend(e.references(item, r, 2)?);
        name = Some(e.text(r, 0));
    } else if let Some(r) = instance.part("SHELL_BASED_SURFACE_MODEL") {
        let r = e.record(item, &r.name, 2)?;
        shells.extend(e.references(item, r, 1)?);
        name = Some(e.text(r, 0));
    } else {
        shells.push(item);
    }
    let mut closed = true;
    let mut to_build = Vec::new();
    for mut shell in shells {
        // An ORIENTED_CLOSED_SHELL (name, *, shell, orientation), as a void is written, is
        // its shell, every face turned over where the orientation is .F..
        let mut turned = false;
        if let Some(r) = e.instance(shell)?.part("ORIENTED_CLOSED_SHELL") {
            let r = e.record(shell, &r.name, 4)?;
            turned = !e.boolean(shell, r, 3)?;
            shell = e.reference(shell, r, 2)?;
        }
        let si = e.instance(shell)?;
        let r = si
            .part("CLOSED_SHELL")
            .or_else(|| si.part("OPEN_SHELL"))
            .ok_or_else(|| bad(x, shell, "expected CLOSED_SHELL or OPEN_SHELL"))?;
        closed &= r.name != "OPEN_SHELL";
        let r = e.record(shell, &r.name, 2)?;
        for face_id in e.references(shell, r, 1)? {
            let (face, reversed) = match e.instance(face_id)?.part("ORIENTED_FACE") {
                Some(of) => {
                    let of = e.record(face_id, &of.name, 4)?;
                    (e.reference(face_id, of, 2)?, !e.boolean(face_id, of, 3)?)
                }
                None => (face_id, false),
            };
            to_build.push((face, reversed != turned));
        }
    }
    Ok(BodyBuild {
        item,
        name: name.filter(|n| !n.is_empty()),
        closed,
        to_build,
        next: 0,
        faces: Vec::new(),
        surface_types: Vec::new(),
        origins: Vec::new(),
        face_colours: HashMap::new(),
    })
}

/// A face whose edges and surface are read: ready to build, or the warning that skipped it.
enum Prepared {
    Skipped(String),
    Ready {
        face_id: u64,
        surface: Surface3,
        surface_id: u64,
        bounds: Vec<Bound>,
        same_sense: bool,
    },
}

/// A body being built a few faces at a time ([`start_body`], [`BodyBuild::build_next`]).
struct BodyBuild {
    item: u64,
    name: Option<String>,
    closed: bool,
    /// The faces, each with whether an `ORIENTED_FACE` turns it over.
    to_build: Vec<(u64, bool)>,
    /// How many of `to_build` are done.
    next: usize,
    faces: Vec<TrimmedSurface>,
    surface_types: Vec<&'static str>,
    origins: Vec<Vec<Vec<CurveOrigin>>>,
    face_colours: HashMap<[u32; 3], usize>,
}

impl BodyBuild {
    fn done(&self) -> bool {
        self.next >= self.to_build.len()
    }

    /// Builds the next `count` faces (or those left), on every core: their edges and surfaces
    /// read here in order (the edges shared through `edges`), the faces built in parallel, and
    /// each kept or warned about in order, so the body is the same for any `count` and any
    /// number of threads. A face that cannot be built is a warning, not an error.
    fn build_next(
        &mut self,
        e: &Entities,
        edges: &mut HashMap<u64, Arc<EdgeGeometry>>,
        tolerance: f64,
        warnings: &mut Vec<String>,
        colour_of: &HashMap<u64, [f32; 3]>,
        count: usize,
    ) -> Result<(), FormatError> {
        let prepared = self.prepare(e, edges, tolerance, count)?;
        let built = crate::kernel::par::map(prepared.len(), |k| match &prepared[k] {
            Prepared::Ready {
                surface,
                surface_id,
                bounds,
                same_sense,
                ..
            } => Some(build_face(
                surface,
                *surface_id,
                bounds,
                *same_sense,
                tolerance,
            )),
            Prepared::Skipped(_) => None,
        });
        for (face, built) in prepared.into_iter().zip(built) {
            let (face_id, surface) = match face {
                Prepared::Skipped(warning) => {
                    warnings.push(warning);
                    continue;
                }
                Prepared::Ready {
                    face_id, surface, ..
                } => (face_id, surface),
            };
            match built {
                Some(Ok(b)) => {
                    self.faces.push(b.face);
                    self.surface_types.push(surface.type_name());
                    self.origins.push(b.origins);
                    if let Some(c) = colour_of.get(&face_id) {
                        *self.face_colours.entry(c.map(f32::to_bits)).or_insert(0) += 1;
                    }
                }
                Some(Err(why)) => warnings.push(skipped_face(
                    face_id,
                    Some(surface.type_name()),
                    &why.to_string(),
                )),
                None => {}
            }
        }
        Ok(())
    }

    /// The next `count` faces' records read in order ([`face_plan`]), the geometry of their
    /// edges not in `edges` and their surfaces read on every core, and each face then
    /// made ready, or skipped, in order as one face at a time would be: the first edge that
    /// cannot be built skips its face, and the first error in the file's order (a record or
    /// an edge's geometry) ends the read.
    fn prepare(
        &mut self,
        e: &Entities,
        edges: &mut HashMap<u64, Arc<EdgeGeometry>>,
        tolerance: f64,
        count: usize,
    ) -> Result<Vec<Prepared>, FormatError> {
        let mut plans = Vec::with_capacity(count);
        while plans.len() < count.max(1) {
            let Some(&(face_id, flip)) = self.to_build.get(self.next) else {
                break;
            };
            self.next += 1;
            let plan = face_plan(e, face_id, flip);
            let stop = plan.error.is_some();
            plans.push(plan);
            if stop {
                break;
            }
        }
        // The edges first met in these faces, each once.
        let mut new_edges = Vec::new();
        let mut seen = HashSet::new();
        for plan in &plans {
            for (_, uses) in &plan.bounds {
                for &(id, _) in uses {
                    if !edges.contains_key(&id) && seen.insert(id) {
                        new_edges.push(id);
                    }
                }
            }
        }
        let built = crate::kernel::par::map(new_edges.len(), |k| {
            edge_geometry(e, new_edges[k], tolerance).map(Arc::new)
        });
        let surfaces = crate::kernel::par::map(plans.len(), |k| {
            let plan = &plans[k];
            plan.error.is_none().then(|| e.surface(plan.surface_id))
        });
        let mut failed = HashMap::new();
        for (id, g) in new_edges.into_iter().zip(built) {
            match g {
                Ok(g) => {
                    edges.insert(id, g);
                }
                Err(why) => {
                    failed.insert(id, why);
                }
            }
        }
        let mut prepared = Vec::with_capacity(plans.len());
        'faces: for (plan, surface) in plans.into_iter().zip(surfaces) {
            let mut bounds = Vec::with_capacity(plan.bounds.len());
            for (orientation, uses) in plan.bounds {
                let mut loop_edges = Vec::with_capacity(uses.len());
                for (id, forward) in uses {
                    let geometry = match (edges.get(&id), failed.get(&id)) {
                        (Some(g), _) => g.clone(),
                        (None, Some(EntityError::Unbuildable(err))) => {
                            prepared.push(Prepared::Skipped(skipped_face(
                                plan.face_id,
                                None,
                                &err.message,
                            )));
                            continue 'faces;
                        }
                        (None, Some(EntityError::Malformed(err))) => return Err(err.clone()),
                        (None, None) => {
                            return Err(bad(e.x, id, "an edge that was not read"));
                        }
                    };
                    loop_edges.push(LoopEdge {
                        id,
                        forward,
                        geometry,
                    });
                }
                if !loop_edges.is_empty() {
                    bounds.push(Bound {
                        edges: loop_edges,
                        orientation,
                    });
                }
            }
            let surface = match (plan.error, surface) {
                (Some(err), _) => return Err(err),
                (None, Some(Ok(s))) => s,
                (None, Some(Err(EntityError::Unbuildable(err)))) => {
                    prepared.push(Prepared::Skipped(skipped_face(
                        plan.face_id,
                        None,
                        &err.message,
                    )));
                    continue;
                }
                (None, Some(Err(EntityError::Malformed(err)))) => return Err(err),
                (None, None) => return Err(bad(e.x, plan.face_id, "a surface that was not read")),
            };
            prepared.push(Prepared::Ready {
                face_id: plan.face_id,
                surface,
                surface_id: plan.surface_id,
                bounds,
                same_sense: plan.same_sense,
            });
        }
        Ok(prepared)
    }

    /// The body: its faces, its colour (the item's, else its faces' most common) and the
    /// file's topology of its faces.
    fn finish(self, colour_of: &HashMap<u64, [f32; 3]>, tolerance: f64) -> BuiltBody {
        let color = colour_of.get(&self.item).copied().or_else(|| {
            self.face_colours
                .iter()
                .max_by_key(|&(_, n)| *n)
                .map(|(c, _)| c.map(f32::from_bits))
        });
        let topology = file_topology(&self.faces, &self.origins, tolerance);
        BuiltBody {
            name: self.name,
            color,
            faces: self.faces,
            surface_types: self.surface_types,
            topology,
            closed: self.closed,
        }
    }
}

/// The shared, naked and degenerate edges from which loop curves lie on which of the file's
/// edges (and the seams the reader closed).
fn file_topology(
    faces: &[TrimmedSurface],
    origins: &[Vec<Vec<CurveOrigin>>],
    tolerance: f64,
) -> Topology {
    let mut uses: HashMap<(u8, u64), Vec<(EdgeId, bool)>> = HashMap::new();
    let mut topology = Topology::default();
    // A face that is a whole closed surface (no edges in the file) has only its own seams and
    // poles: the kernel finds them on its domain's sides.
    for (f, face) in faces.iter().enumerate() {
        if face.is_trimmed() || origins.get(f).is_some_and(|o| !o.is_empty()) {
            continue;
        }
        if let Ok(own) = crate::kernel::join::find_topology(std::slice::from_ref(face), tolerance) {
            let at = |id: EdgeId| EdgeId { face: f, ..id };
            topology
                .shared
                .extend(own.shared.into_iter().map(|s| SharedEdge {
                    a: at(s.a),
                    b: at(s.b),
                    ..s
                }));
            topology.naked.extend(own.naked.into_iter().map(at));
            topology
                .degenerate
                .extend(own.degenerate.into_iter().map(at));
        }
    }
    for (f, loops) in origins.iter().enumerate() {
        for (l, curves) in loops.iter().enumerate() {
            for (c, origin) in curves.iter().enumerate() {
                let id = EdgeId {
                    face: f,
                    loop_index: l,
                    curve: c,
                };
                let length = edge_length(&faces[f], l, c);
                if length <= tolerance {
                    topology.degenerate.push(id);
                    continue;
                }
                match *origin {
                    CurveOrigin::Edge { id: e, forward } => {
                        uses.entry((0, e)).or_default().push((id, forward))
                    }
                    CurveOrigin::Seam(s) => uses
                        .entry((1, s as u64 + ((f as u64) << 32)))
                        .or_default()
                        .push((id, true)),
                    CurveOrigin::Added => topology.naked.push(id),
                }
            }
        }
    }
    let mut keys: Vec<_> = uses.keys().copied().collect();
    keys.sort_unstable();
    for key in keys {
        let list = &uses[&key];
        let mut k = 0;
        while k + 1 < list.len() {
            let (a, fa) = list[k];
            let (b, fb) = list[k + 1];
            // Seam connectors run opposite ways by construction.
            let reversed = if key.0 == 1 { true } else { fa != fb };
            topology.shared.push(SharedEdge {
                a,
                b,
                reversed,
                gap: edge_gap(faces, a, b, reversed),
            });
            k += 2;
        }
        if k < list.len() {
            topology.naked.push(list[k].0);
        }
    }
    topology
}

fn curve_point(face: &TrimmedSurface, l: usize, c: usize, t: f64) -> Option<DVec3> {
    let curve = face.loops().get(l)?.get(c)?;
    let (a, b) = curve.domain();
    let uv = curve.point_at(a + (b - a) * t).ok()?;
    face.surface().point_at_clamped(uv).ok()
}

fn edge_length(face: &TrimmedSurface, l: usize, c: usize) -> f64 {
    let points: Vec<DVec3> = (0..=4)
        .filter_map(|k| curve_point(face, l, c, k as f64 / 4.0))
        .collect();
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

fn edge_gap(faces: &[TrimmedSurface], a: EdgeId, b: EdgeId, reversed: bool) -> f64 {
    // The ends correspond exactly (inner points of polylines need not).
    let mut gap: f64 = 0.0;
    for k in [0, 4] {
        let t = k as f64 / 4.0;
        let tb = if reversed { 1.0 - t } else { t };
        if let (Some(p), Some(q)) = (
            curve_point(&faces[a.face], a.loop_index, a.curve, t),
            curve_point(&faces[b.face], b.loop_index, b.curve, tb),
        ) {
            gap = gap.max(p.distance(q));
        }
    }
    gap
}
