//! The web entry points, called from `index.html` through wasm-bindgen.

use std::cell::RefCell;

use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

use crate::app::{AppCommand, CommandQueue, CommandSender, KnotworkApp, wgpu_configuration};
use crate::doc::Command;
use crate::status;
use crate::view::ShadingMode;

thread_local! {
    /// The number of the page's next export request.
    static NEXT_EXPORT: std::cell::Cell<u32> = const { std::cell::Cell::new(1) };
    static RUNNER: RefCell<Option<eframe::WebRunner>> = const { RefCell::new(None) };
    /// The page's end of the editor's command channel, and the editor's end until it starts
    /// (what the page sends before then waits in the channel).
    static COMMANDS: RefCell<(CommandSender, Option<CommandQueue>)> = {
        let (sender, queue) = crate::app::channel();
        RefCell::new((sender, Some(queue)))
    };
}

/// Sends the editor one request from the page.
fn send(command: AppCommand) {
    COMMANDS.with(|c| c.borrow().0.send(command));
}

/// Starts the editor on the canvas with id `canvas_id`. `adapter_label` is the page's
/// description of the WebGPU adapter (the browser gives wgpu no name).
#[wasm_bindgen]
pub async fn start(canvas_id: String, adapter_label: String) -> Result<(), JsValue> {
    // A second call (a hot reload) keeps the first logger.
    let _ = eframe::WebLogger::init(log::LevelFilter::Info);
    let canvas = web_sys::window()
        .and_then(|w| w.document())
        .and_then(|d| d.get_element_by_id(&canvas_id))
        .ok_or_else(|| JsValue::from_str(&format!("no element with id '{canvas_id}'")))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| JsValue::from_str(&format!("'{canvas_id}' is not a canvas")))?;
    let options = eframe::WebOptions {
        wgpu_options: wgpu_configuration(true),
        ..Default::default()
    };
    let runner = eframe::WebRunner::new();
    let (sender, queue) = COMMANDS.with(|c| {
        let mut c = c.borrow_mut();
        (c.0.clone(), c.1.take())
    });
    let result = runner
        .start(
            canvas,
            options,
            Box::new(move |cc| {
                let app = KnotworkApp::new(cc, Some(adapter_label), true);
                // The first start takes the queue the page has filled; a later one (a hot
                // reload) keeps the editor's own channel, and the page sends there from now on.
                let app = match queue {
                    Some(queue) => app.with_commands(queue, sender),
                    None => app,
                };
                COMMANDS.with(|c| c.borrow_mut().0 = app.command_sender());
                Ok(Box::new(app))
            }),
        )
        .await;
    if let Err(e) = &result {
        status::publish_error(format!("the editor could not start: {e:?}"));
    }
    RUNNER.with(|r| *r.borrow_mut() = Some(runner));
    result
}

/// `window.knotwork.status()` as a JSON string.
#[wasm_bindgen]
pub fn status_json() -> String {
    let mut current = status::current();
    let panic = RUNNER.with(|r| {
        r.borrow()
            .as_ref()
            .and_then(|runner| runner.panic_summary())
            .map(|summary| summary.message())
    });
    if let Some(message) = panic {
        current.error = Some(format!("the editor crashed: {message}"));
    }
    current.to_json()
}

/// `window.knotwork.threads()`: the threads the kernel's parallel work runs on (1 in the
/// single-threaded bundle).
#[wasm_bindgen]
pub fn thread_count() -> usize {
    knotwork_kernel::par::threads()
}

/// Re-tessellates every object at `segments` per Bézier span edge (errors show in the status).
#[wasm_bindgen]
pub fn set_segments(segments: u32) {
    send(AppCommand::SetSegments(segments));
}

/// Sets the global quality factor (0.25..=4) on every object's segments.
#[wasm_bindgen]
pub fn set_quality(quality: f32) {
    send(AppCommand::SetQuality(quality));
}

/// Tessellates the patches for the view with `tolerance_px` pixels of error (adaptive), or at
/// each object's fixed segments.
#[wasm_bindgen]
pub fn set_tessellation(adaptive: bool, tolerance_px: f32) {
    send(AppCommand::SetTessellation {
        adaptive,
        tolerance_px,
    });
}

/// Sets the shading mode by name ("plain", "normals", "checker", "gaussian", "mean", "k1",
/// "k2", "zebra", "isophotes", "reflection", "draft", "level"); false for an unknown name.
#[wasm_bindgen]
pub fn set_shading(mode: String) -> bool {
    match ShadingMode::from_name(&mode) {
        Some(mode) => {
            send(AppCommand::SetShading(mode));
            true
        }
        None => false,
    }
}

/// Sets the analysis modes' settings from JSON, for example `{"zebra_pairs": 12,
/// "zebra_angle": 90, "zebra_frame": "world", "zebra_source": "normal", "isophote_spacing": 5,
/// "isophote_direction": [0, 0, 1], "pull_direction": [0, 0, 1], "draft_threshold": 3}`;
/// fields left out take their defaults. Returns the error for settings out of range.
#[wasm_bindgen]
pub fn set_analysis(json: String) -> Result<(), String> {
    let analysis: crate::view::AnalysisSettings =
        serde_json::from_str(&json).map_err(|e| e.to_string())?;
    analysis.validate()?;
    send(AppCommand::SetAnalysis(analysis));
    Ok(())
}

/// Turns the camera to a standard view by name ("top", "bottom", "front", "back", "right",
/// "left", "perspective"); false for an unknown name.
#[wasm_bindgen]
pub fn set_view(name: String) -> bool {
    match crate::app::StandardView::from_name(&name) {
        Some(view) => {
            send(AppCommand::SetView(view));
            true
        }
        None => false,
    }
}

/// The transform gizmo's mode by name ("off", "move", "rotate", "scale"); false for an unknown
/// name.
#[wasm_bindgen]
pub fn set_gizmo(mode: String) -> bool {
    match crate::app::GizmoMode::from_name(&mode) {
        Some(mode) => {
            send(AppCommand::SetGizmo(mode));
            true
        }
        None => false,
    }
}

/// Orthographic (true) or perspective (false) projection.
#[wasm_bindgen]
pub fn set_orthographic(on: bool) {
    send(AppCommand::SetOrthographic(on));
}

/// A manual colour range for the curvature modes.
#[wasm_bindgen]
pub fn set_range(low: f64, high: f64) {
    send(AppCommand::SetRange(Some((low, high))));
}

/// Back to the automatic (robust percentile) colour range.
#[wasm_bindgen]
pub fn auto_range() {
    send(AppCommand::SetRange(None));
}

/// Selects object `index` (negative: none).
#[wasm_bindgen]
pub fn select_object(index: i32) {
    send(AppCommand::Select(usize::try_from(index).ok()));
}

/// Moves control point `index` of `object` to (x, y, z).
#[wasm_bindgen]
pub fn move_control_point(object: u32, index: u32, x: f64, y: f64, z: f64) {
    send(AppCommand::Edit(Command::MovePoints {
        object: object as usize,
        moves: vec![(index as usize, glam::DVec3::new(x, y, z))],
    }));
}

/// Starts dragging control points `points` of `object`, as the mouse does on their handles
/// (errors show in the status).
#[wasm_bindgen]
pub fn begin_drag(object: u32, points: Vec<u32>) {
    send(AppCommand::Drag(crate::app::DragStep::Begin {
        object: object as usize,
        points: points.into_iter().map(|p| p as usize).collect(),
    }));
}

/// Moves the dragged points by (x, y, z) from where the drag started; only the Bézier patches
/// they support are re-evaluated.
#[wasm_bindgen]
pub fn drag_by(x: f64, y: f64, z: f64) {
    send(AppCommand::Drag(crate::app::DragStep::By(
        glam::DVec3::new(x, y, z),
    )));
}

/// Ends the drag as one undo step (`cancel`: puts the points back).
#[wasm_bindgen]
pub fn end_drag(cancel: bool) {
    send(AppCommand::Drag(if cancel {
        crate::app::DragStep::Cancel
    } else {
        crate::app::DragStep::End
    }));
}

/// Redraws every frame (true) or only on change (false).
#[wasm_bindgen]
pub fn set_continuous(on: bool) {
    send(AppCommand::SetContinuous(on));
}

/// Frames the model in the viewport.
#[wasm_bindgen]
pub fn frame_model() {
    send(AppCommand::FrameModel);
}

/// Undoes the newest step.
#[wasm_bindgen]
pub fn undo() {
    send(AppCommand::Undo);
}

/// Redoes the newest undone step.
#[wasm_bindgen]
pub fn redo() {
    send(AppCommand::Redo);
}

/// Selects control points of the selected object.
#[wasm_bindgen]
pub fn select_points(points: Vec<u32>) {
    send(AppCommand::SelectPoints(
        points.into_iter().map(|p| p as usize).collect(),
    ));
}

/// Opens a file's bytes as if a file called `name` were opened: a project, a glTF or an OBJ
/// (errors show in the page).
#[wasm_bindgen]
pub fn open_file(name: String, bytes: Vec<u8>) {
    send(AppCommand::Open { name, bytes });
}

/// Sets the sharpness of the cage edge between points `a` and `b` of subdivision surface
/// `object` (0 removes the crease; errors show in the status).
#[wasm_bindgen]
pub fn set_crease(object: u32, a: u32, b: u32, sharpness: f64) {
    send(AppCommand::SetCrease {
        object: object as usize,
        a,
        b,
        sharpness,
    });
}

/// Shows subdivision surface `object` as `display` ("limit", "refined", "acc", "gregory",
/// "pn-triangles" or "adaptive"), the adaptive display with flatness `tolerance` (a share of
/// the cage's diagonal; not a number: keep the object's); one undo step, errors in the status.
/// False for an unknown display name.
#[wasm_bindgen]
pub fn set_subdivision_display(object: u32, display: String, tolerance: f64) -> bool {
    let Ok(display) = serde_json::from_value(serde_json::Value::String(display)) else {
        return false;
    };
    send(AppCommand::SetSubdivisionDisplay {
        object: object as usize,
        display,
        tolerance: (!tolerance.is_nan()).then_some(tolerance),
    });
    true
}

/// Displaces `object` along its normal by `pattern` ("waves", "ripples", "noise"; "none"
/// removes the displacement) with `amplitude` and `frequency`; one undo step, errors (a bad
/// number, an object without a (u, v) domain) in the status. False for an unknown pattern.
#[wasm_bindgen]
pub fn set_displacement(object: u32, pattern: String, amplitude: f64, frequency: f64) -> bool {
    let displacement = if pattern == "none" {
        None
    } else {
        match serde_json::from_value(serde_json::Value::String(pattern)) {
            Ok(pattern) => Some(crate::kernel::displace::Displacement {
                pattern,
                amplitude,
                frequency,
                image: None,
            }),
            Err(_) => return false,
        }
    };
    send(AppCommand::Edit(Command::SetDisplacement {
        object: object as usize,
        displacement,
    }));
    true
}

/// Puts one free-form deformation lattice of degrees (l, m, n) (1 to 4 each) around
/// `objects` (they share it); its points become each object's handles (`moveControlPoint` on
/// any of them moves it for all). One undo step; errors in the status.
#[wasm_bindgen]
pub fn add_lattice(objects: Vec<u32>, l: u32, m: u32, n: u32) {
    send(AppCommand::AddLattice {
        objects: objects.into_iter().map(|o| o as usize).collect(),
        degrees: [l, m, n].map(|d| d as usize),
    });
}

/// Removes `object`'s lattice, and the same lattice from the objects sharing it: they are shown
/// undeformed again (one undo step).
#[wasm_bindgen]
pub fn release_lattice(object: u32) {
    send(AppCommand::ReleaseLattice {
        object: object as usize,
    });
}

/// Bakes `object`'s lattice into it: exactly where the degree allows, else refitted within
/// `tolerance` (a share of the object's size); the status's notice says which.
#[wasm_bindgen]
pub fn apply_lattice(object: u32, tolerance: f64) {
    send(AppCommand::Edit(Command::ApplyLattice {
        object: object as usize,
        tolerance,
    }));
}

/// Displaces `object` along its normal by the PNG `png` (grey; tiled `frequency` × `frequency`
/// times; h = 2 grey − 1) scaled by `amplitude`; one undo step. An unreadable image is refused
/// here with the reason; bad numbers and objects without a (u, v) domain in the status.
#[wasm_bindgen]
pub fn set_displacement_image(
    object: u32,
    png: Vec<u8>,
    amplitude: f64,
    frequency: f64,
) -> Result<(), String> {
    let image = crate::io::height_image::decode_png(&png)?;
    send(AppCommand::Edit(Command::SetDisplacement {
        object: object as usize,
        displacement: Some(crate::kernel::displace::Displacement {
            pattern: crate::kernel::displace::Pattern::Image,
            amplitude,
            frequency,
            image: Some(std::sync::Arc::new(image)),
        }),
    }));
    Ok(())
}

/// Chooses the trim tool for the selected NURBS surface: "circle", "rectangle", "hexagon",
/// "polyline", "curve", or "" for none; the next clicks on the surface draw the loop.
#[wasm_bindgen]
pub fn set_trim_tool(name: String) {
    send(AppCommand::SetTrimTool(name));
}

/// Adds a circular trim loop of (u, v) radius `r` around (u, v) to NURBS surface `object`: a
/// hole, or with `keep_inside` the region kept. A radius that makes no circle is refused here;
/// a loop the surface refuses (outside its domain, crossing another) in the status.
#[wasm_bindgen]
pub fn trim_circle(object: u32, u: f64, v: f64, r: f64, keep_inside: bool) -> Result<(), String> {
    let curves =
        crate::kernel::trim::shapes::ellipse(glam::DVec2::new(u, v), glam::DVec2::splat(r))
            .map_err(|e| e.to_string())?;
    send(AppCommand::Edit(Command::Trim {
        object: object as usize,
        edit: crate::doc::TrimEdit::Add {
            curves,
            keep_inside,
        },
    }));
    Ok(())
}

/// Starts drawing a curve: `kind` "control" (control points), "through" (points to pass
/// through), "polyline", "circle" (centre, then a point on it) or "arc" (start, a point on it,
/// end), of degree `degree`, on the plane "ground", "front", "right",
/// "view", "surface" (tangent at the last surface point clicked) or "points" (three selected
/// control points). The next clicks in the viewport place points. False for an unknown kind
/// or plane.
#[wasm_bindgen]
pub fn draw_curve(kind: String, degree: u32, plane: String) -> bool {
    use crate::app::curves::{DrawKind, DrawStep, PlaneChoice};
    let (Some(kind), Some(plane)) = (DrawKind::from_name(&kind), PlaneChoice::from_name(&plane))
    else {
        return false;
    };
    send(AppCommand::DrawCurve(DrawStep::Begin {
        kind,
        degree: degree as usize,
        plane,
    }));
    true
}

/// Places a point of the curve being drawn (moved onto its plane), as a click does.
#[wasm_bindgen]
pub fn place_point(x: f64, y: f64, z: f64) {
    send(AppCommand::DrawCurve(crate::app::curves::DrawStep::Point(
        glam::DVec3::new(x, y, z),
    )));
}

/// Ends the curve being drawn: adds it (closed or not, one undo step), or with `cancel` drops
/// it.
#[wasm_bindgen]
pub fn finish_curve(close: bool, cancel: bool) {
    use crate::app::curves::DrawStep;
    send(AppCommand::DrawCurve(if cancel {
        DrawStep::Cancel
    } else {
        DrawStep::Finish { close }
    }));
}

/// Picks curve objects for a construction, in order (as Shift + clicks do).
#[wasm_bindgen]
pub fn pick_curves(objects: Vec<u32>) {
    send(AppCommand::PickCurves(
        objects.into_iter().map(|k| k as usize).collect(),
    ));
}

/// Builds a `knotwork construct` request whose curves are `{"input": k}` references to
/// curve objects `objects[k]`: a new object that follows its curves when `keep_history`, or
/// with `replace` ≥ 0 that object's new geometry. Malformed JSON is refused here; a
/// construction the kernel refuses in the status.
#[wasm_bindgen]
pub fn construct(
    request: String,
    objects: Vec<u32>,
    keep_history: bool,
    replace: i32,
) -> Result<(), String> {
    let request: serde_json::Value =
        serde_json::from_str(&request).map_err(|e| format!("construct: not valid JSON: {e}"))?;
    send(AppCommand::ConstructFrom {
        request,
        objects: objects.into_iter().map(|k| k as usize).collect(),
        keep_history,
        replace: usize::try_from(replace).ok(),
    });
    Ok(())
}

/// Runs an operation (one undo step), without history.
fn send_operation(operation: impl crate::scene::operation::OperationParams) {
    send(AppCommand::Edit(Command::Apply {
        operation: crate::scene::operation::Operation::new(operation),
        keep_history: false,
    }));
}

/// Runs any registered operation given as its JSON value, `{"op": NAME, ...its fields}`
/// with objects by their index (`knotwork apply` takes the same; one undo step). With
/// `keep_history`, what it adds is made again whenever an object it reads changes. A value
/// no operation reads is refused here, naming the bad field; an operation the document refuses
/// says why in the status.
#[wasm_bindgen]
pub fn apply(operation: String, keep_history: bool) -> Result<(), String> {
    let operation = crate::ops::parse(&operation).map_err(|e| format!("apply: {e}"))?;
    send(AppCommand::Edit(Command::Apply {
        operation,
        keep_history,
    }));
    Ok(())
}

/// Edits the operation object `object` was made by with history: `operation` is the same
/// operation with other values, as `apply` takes it (`{"op": "fillet_edges", "object": 0,
/// "radius": 0.2}`, objects by index); the object is made again in place, with what follows
/// it, as one undo step. A refusal says why in the status and changes nothing.
#[wasm_bindgen]
pub fn edit_history(object: u32, operation: String) -> Result<(), String> {
    let operation = crate::ops::parse(&operation).map_err(|e| format!("editHistory: {e}"))?;
    send(AppCommand::Edit(Command::EditRecipe {
        object: object as usize,
        operation,
    }));
    Ok(())
}

/// Adds the curves where objects `a` and `b` meet as curve objects (one undo step); objects
/// that do not meet are refused in the status.
#[wasm_bindgen]
pub fn intersect(a: u32, b: u32) {
    send_operation(crate::ops::intersect::Intersect {
        a: (a as usize).into(),
        b: (b as usize).into(),
    });
}

/// Adds the offset of object `object` at signed `distance` along its normal as "NAME offset"
/// (one undo step; exact for planes, spheres, cylinders, cones, tori and other revolutions of
/// lines and arcs, within 1e-4 of the scene's size elsewhere).
#[wasm_bindgen]
pub fn offset(object: u32, distance: f64) {
    send_operation(crate::ops::offset::Offset {
        object: (object as usize).into(),
        distance,
        tolerance: crate::doc::surface_ops::EDITOR_TOLERANCE,
    });
}

/// Rolls a ball of `radius` between objects `a` and `b` on the chosen sides (front: where the
/// normal points): adds "fillet" and trims both back (one undo step). A `radius_end` that is a
/// number (not NaN) makes the radius run linearly along the fillet to it.
#[wasm_bindgen]
pub fn fillet(a: u32, b: u32, radius: f64, front_a: bool, front_b: bool, radius_end: f64) {
    send_operation(crate::doc::surface_ops::FilletRequest {
        a: (a as usize).into(),
        b: (b as usize).into(),
        radius,
        radius_end: (!radius_end.is_nan()).then_some(radius_end),
        front_a,
        front_b,
        tolerance: crate::doc::surface_ops::EDITOR_TOLERANCE,
    });
}

/// Joins `objects` (every surface when empty) where their edges meet into polysurfaces (one
/// undo step).
#[wasm_bindgen]
pub fn join(objects: Vec<u32>) {
    send_operation(crate::ops::join::Join {
        objects: objects.into_iter().map(|k| (k as usize).into()).collect(),
        tolerance: crate::doc::surface_ops::JOIN_TOLERANCE,
    });
}

/// Trims object `object` by the objects `cutters` (surfaces, or curves on it), keeping the part
/// nearest the point (x, y, z) (one undo step).
#[wasm_bindgen]
pub fn trim_by(object: u32, cutters: Vec<u32>, x: f64, y: f64, z: f64) {
    send_operation(crate::ops::trim::Trim {
        object: (object as usize).into(),
        cutters: cutters.into_iter().map(|k| (k as usize).into()).collect(),
        keep: [x, y, z],
    });
}

/// Splits object `object` into the parts the objects `cutters` cut it into (one undo step).
#[wasm_bindgen]
pub fn split_by(object: u32, cutters: Vec<u32>) {
    send_operation(crate::ops::split::Split {
        object: (object as usize).into(),
        cutters: cutters.into_iter().map(|k| (k as usize).into()).collect(),
    });
}

/// `[face, side, face, side]` (side: 0 u0, 1 u1, 2 v0, 3 v1) as two edges; empty: `None`.
fn edge_pair(edges: &[u32]) -> Option<[crate::doc::surface_ops::FaceSide; 2]> {
    use crate::kernel::continuity::Side;
    let side = |k: u32| Side::ALL.get(k as usize).copied();
    match edges {
        [fa, sa, fb, sb] => Some([(*fa as usize, side(*sa)?), (*fb as usize, side(*sb)?)]),
        _ => None,
    }
}

/// G0, G1 or G2 from 0, 1 or 2 (G2 above).
fn edge_continuity(order: u32) -> crate::kernel::blend::EdgeContinuity {
    use crate::kernel::blend::EdgeContinuity;
    match order {
        0 => EdgeContinuity::G0,
        1 => EdgeContinuity::G1,
        _ => EdgeContinuity::G2,
    }
}

/// Adds "blend" across the gap between an edge of object `a` and one of `b` at continuity
/// `continuity` (0, 1, 2: G0, G1, G2) with the tensions at each edge; `edges` as
/// `[face, side, face, side]`, or empty for the two nearest (one undo step).
#[wasm_bindgen]
pub fn blend(a: u32, b: u32, continuity: u32, tension_a: f64, tension_b: f64, edges: Vec<u32>) {
    send_operation(crate::doc::surface_ops::BlendRequest {
        a: (a as usize).into(),
        b: (b as usize).into(),
        edges: edge_pair(&edges),
        continuity: edge_continuity(continuity),
        tension: [tension_a, tension_b],
        tolerance: crate::doc::surface_ops::EDITOR_TOLERANCE * 1e-2,
    });
}

/// Moves an edge of object `object` onto an edge of `target` at continuity `continuity`
/// (edges as for [`blend`]; one undo step).
#[wasm_bindgen]
pub fn match_edge(object: u32, target: u32, continuity: u32, edges: Vec<u32>) {
    send_operation(crate::doc::surface_ops::MatchRequest {
        object: (object as usize).into(),
        target: (target as usize).into(),
        edges: edge_pair(&edges),
        continuity: edge_continuity(continuity),
        tolerance: crate::doc::surface_ops::EDITOR_TOLERANCE * 1e-2,
    });
}

/// Adds the sections of object `object` by the planes with normal (nx, ny, nz) through
/// (ox, oy, oz) + k · `spacing` · normal as curves (one undo step).
#[wasm_bindgen]
#[allow(clippy::too_many_arguments)]
pub fn contour(object: u32, spacing: f64, nx: f64, ny: f64, nz: f64, ox: f64, oy: f64, oz: f64) {
    send_operation(crate::ops::contour::Contour {
        object: (object as usize).into(),
        origin: [ox, oy, oz],
        normal: [nx, ny, nz],
        spacing,
    });
}

/// Adds the curves `curves` projected onto object `onto` along (x, y, z), or with `pull`
/// pulled to its nearest points, as curves (one undo step).
#[wasm_bindgen]
pub fn project_curves(curves: Vec<u32>, onto: u32, x: f64, y: f64, z: f64, pull: bool) {
    send_operation(crate::ops::project::ProjectCurves {
        curves: curves.into_iter().map(|k| (k as usize).into()).collect(),
        onto: (onto as usize).into(),
        direction: (!pull).then_some([x, y, z]),
    });
}

/// Object `object`, a polysurface, as its faces (one undo step).
#[wasm_bindgen]
pub fn explode(object: u32) {
    send_operation(crate::ops::explode::Explode {
        object: (object as usize).into(),
    });
}

/// Ends object `object`'s construction history (one undo step).
#[wasm_bindgen]
pub fn break_history(object: u32) {
    send(AppCommand::Edit(Command::BreakHistory {
        object: object as usize,
    }));
}

/// Starts again from the sample scene, or (`empty`) from no objects; one undo step (the
/// document before is also kept in the Recent list).
#[wasm_bindgen]
pub fn new_document(empty: bool) {
    send(AppCommand::NewDocument { empty });
}

/// Opens entry `index` (0: the newest) of the Recent list (`status().recent`); one undo step.
#[wasm_bindgen]
pub fn open_recent(index: u32) {
    send(AppCommand::OpenRecent(index as usize));
}

/// Where the selected object's control points are on the page, as JSON `[[x, y] | null, ...]`
/// in CSS pixels from the canvas's top-left corner.
#[wasm_bindgen]
pub fn handles_json() -> String {
    serde_json::to_string(&status::handles()).unwrap_or_else(|_| "[]".into())
}

/// The open document as project text (what Save would write, without the view).
#[wasm_bindgen]
pub fn project_json() -> String {
    status::project()
}

/// Starts exporting the document as a `.glb`, as it is once every call made before this one
/// has been carried out (an `openProject` just before is exported, not what it replaced), and
/// returns the request's number for [`export_result`]. `options` is JSON: `{"tolerance": t}` or
/// `{"segments": n}`, optionally `"curvature": true` and `"colors": "gaussian" | "mean" | "k1"
/// | "k2"`; bad options are refused here with the reason. The editor builds the file one object
/// per frame, with a progress bar and Cancel, so the page stays responsive.
#[wasm_bindgen]
pub fn start_export(options: String) -> Result<u32, String> {
    // Checked now against an empty scene, so the caller hears of a bad option at once; the
    // editor reads them again against the document (for the colours' automatic range).
    crate::io::gltf::options_from_json(&options, &Default::default(), Vec::new())?;
    let request = next_export_request();
    send(AppCommand::Export { request, options });
    Ok(request)
}

/// The `.glb` of export request `request` once it is done (undefined while it runs); throws
/// why it failed or that it was cancelled. A result is handed out once.
#[wasm_bindgen]
pub fn export_result(request: u32) -> Result<Option<Vec<u8>>, String> {
    status::take_export(request).transpose()
}

/// Starts writing the document's visible objects with faces as STEP (AP214), as it is once
/// every call made before this one has been carried out; returns the request's number for
/// [`export_result`], whose bytes are the file's text.
#[wasm_bindgen]
pub fn start_step_export() -> u32 {
    let request = next_export_request();
    send(AppCommand::ExportFile {
        request,
        format: crate::app::export::FileExport::Step,
    });
    request
}

/// Starts writing the document's visible objects as a file for printing, `format` "stl"
/// (binary STL) or "3mf", as [`start_step_export`] does; the request's bytes are the file.
#[wasm_bindgen]
pub fn start_print_export(format: &str) -> Result<u32, String> {
    use crate::app::export::FileExport;
    let format = FileExport::from_name(format)
        .filter(|f| *f != FileExport::Step)
        .ok_or_else(|| format!("no print format {format:?}: \"stl\" or \"3mf\""))?;
    let request = next_export_request();
    send(AppCommand::ExportFile { request, format });
    Ok(request)
}

/// The next export request's number.
fn next_export_request() -> u32 {
    NEXT_EXPORT.with(|n| {
        let request = n.get();
        n.set(request.wrapping_add(1));
        request
    })
}

/// Opens STEP `bytes` as the editor does, all at once (not into the document), and returns
/// how long it took as JSON: `{first_step_ms, steps_ms, longest_step_ms, steps, faces}`, for
/// comparing the page with `knotwork bench --only step`.
#[wasm_bindgen]
pub fn bench_step_open(bytes: Vec<u8>) -> Result<String, String> {
    let timing = crate::io::step::timed_open(bytes, &crate::app::platform::now_ms)
        .map_err(|e| e.to_string())?;
    serde_json::to_string(&timing).map_err(|e| e.to_string())
}

/// Reads STEP `bytes` and meshes every body at 1e-4 of the model's diagonal, all at once (not
/// into the document), and returns how long it took as JSON: `{read_ms, mesh_ms, tolerance,
/// triangles, faces}`, the figures `knotwork bench --only step` prints natively.
#[wasm_bindgen]
pub fn bench_step_mesh(bytes: Vec<u8>) -> Result<String, String> {
    let timing = crate::io::step::timed_read_and_mesh(&bytes, &crate::app::platform::now_ms)
        .map_err(|e| e.to_string())?;
    serde_json::to_string(&timing).map_err(|e| e.to_string())
}

/// `benchThreads(indices)`: a loop of pure arithmetic (no memory shared but the results) over
/// `indices` indices on the kernel's threads, timed; returns `{threads, ms, checksum}` as
/// JSON. The checksum is the same on any number of threads.
#[wasm_bindgen]
pub fn bench_threads(indices: u32) -> String {
    let started = crate::app::platform::now_ms();
    let values = knotwork_kernel::par::map(indices as usize, |i| {
        (0..20_000).fold(i as f64, |x, k| (x * 1.000_001 + k as f64).sin() + x * 0.5)
    });
    let ms = crate::app::platform::now_ms() - started;
    let checksum = values
        .iter()
        .fold(0u64, |h, v| h.rotate_left(5) ^ v.to_bits());
    format!(
        "{{\"threads\":{},\"ms\":{ms},\"checksum\":\"{checksum:016x}\"}}",
        knotwork_kernel::par::threads()
    )
}

/// Runs a boolean as the editor's Union, Difference and Intersection buttons do: a step at a
/// time, a frame's budget each, with a progress window and Cancel (`status().boolean_progress`
/// is its progress while it runs), then applied as `apply` would (one undo step). `boolean` is
/// `{"operation": "union" | "difference" | "intersection" | "split", "a": [i], "b": [j, ...],
/// "tolerance": t}` (as `apply`'s boolean without `"op"`). Calls made meanwhile wait for it.
#[wasm_bindgen]
pub fn run_boolean(boolean: String, keep_history: bool) -> Result<(), String> {
    let params: crate::ops::boolean::Boolean =
        serde_json::from_str(&boolean).map_err(|e| format!("boolean: {e}"))?;
    send(AppCommand::Boolean {
        params,
        keep_history,
    });
    Ok(())
}

/// Stops the boolean `run_boolean` or the editor started; the document stays as it was.
#[wasm_bindgen]
pub fn cancel_boolean() {
    send(AppCommand::CancelBoolean);
}

/// Stops opening the STEP file being opened (`status().open_progress` is its progress); the
/// document stays as it was.
#[wasm_bindgen]
pub fn cancel_open() {
    send(AppCommand::CancelOpen);
}

/// Cancels the running export.
#[wasm_bindgen]
pub fn cancel_export() {
    send(AppCommand::CancelExport);
}
