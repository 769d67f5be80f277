//! `knotwork blend` and `knotwork match`: operations on an edge of each of two surfaces.

use std::process::ExitCode;

use super::*;

/// Applies `command` to the project at `input`, writes it to `output` and prints the
/// command's label with `what` of the scene after it.
fn apply_and_write(
    name: &str,
    input: &std::path::Path,
    output: &std::path::Path,
    command: impl FnOnce(&knotwork::scene::Scene) -> Result<knotwork::doc::Command, String>,
    what: impl FnOnce(&knotwork::scene::Scene) -> serde_json::Value,
) -> ExitCode {
    let run = || -> Result<serde_json::Value, String> {
        let mut project = open_project(input)?;
        let command = command(&project.scene)?;
        let started = std::time::Instant::now();
        let edit = knotwork::doc::apply(&mut project.scene, &command).map_err(|e| e.to_string())?;
        let millis = started.elapsed().as_secs_f64() * 1e3;
        write_project(&project, output)?;
        eprintln!(
            "{} in {millis:.1} ms; wrote {}",
            edit.label,
            output.display()
        );
        let mut json = what(&project.scene);
        json["summary"] = edit.label.into();
        Ok(json)
    };
    finish(name, run())
}

/// The options of `knotwork blend` and `knotwork match`.
pub struct EdgeArgs<'a> {
    pub input: &'a std::path::Path,
    /// The two objects (for a match: the one that moves first).
    pub names: [&'a str; 2],
    pub edges: Option<&'a [String]>,
    pub continuity: &'a str,
    pub tension: &'a [f64],
    pub tolerance: f64,
    pub output: &'a std::path::Path,
}

/// `knotwork blend`: the project with the blend between two objects' edges added.
pub fn blend(args: EdgeArgs) -> ExitCode {
    use knotwork::doc::surface_ops::BlendRequest;
    let tension = [
        args.tension.first().copied().unwrap_or(1.0),
        args.tension
            .get(1)
            .or(args.tension.first())
            .copied()
            .unwrap_or(1.0),
    ];
    apply_and_write(
        "blend",
        args.input,
        args.output,
        |scene| {
            Ok(knotwork::doc::Command::operation(BlendRequest {
                a: surface_named(scene, args.names[0])?.into(),
                b: surface_named(scene, args.names[1])?.into(),
                edges: parse_edges(args.edges)?,
                continuity: parse_continuity(args.continuity)?,
                tension,
                tolerance: args.tolerance,
            }))
        },
        |scene| {
            let name = scene.objects.last().map(|o| o.name.clone());
            serde_json::json!({ "blend": name })
        },
    )
}

/// `knotwork match`: the project with one object's edge matched to another's.
pub fn match_edge(args: EdgeArgs) -> ExitCode {
    use knotwork::doc::surface_ops::MatchRequest;
    apply_and_write(
        "match",
        args.input,
        args.output,
        |scene| {
            Ok(knotwork::doc::Command::operation(MatchRequest {
                object: surface_named(scene, args.names[0])?.into(),
                target: surface_named(scene, args.names[1])?.into(),
                edges: parse_edges(args.edges)?,
                continuity: parse_continuity(args.continuity)?,
                tolerance: args.tolerance,
            }))
        },
        |_| serde_json::json!({ "matched": args.names[0] }),
    )
}
