//! The desktop editor and the headless CLI. (The web page starts the same app from `web.rs`.)

#[cfg(not(target_arch = "wasm32"))]
mod cli;

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    use clap::Parser;
    use std::process::ExitCode;

    let cli = cli::Cli::parse();
    match &cli.command {
        Some(cli::Command::Eval { request, backend }) => return cli::eval(request, *backend),
        Some(cli::Command::Bench { iterations, only }) => return cli::bench(*iterations, only),
        Some(cli::Command::Construct { request, output }) => {
            return cli::construct(request, output.as_deref());
        }
        Some(cli::Command::Cage {
            input,
            output,
            tool,
        }) => return cli::cage(input, output, tool),
        Some(cli::Command::Subdivide {
            input,
            scheme,
            levels,
            limit,
            substitute,
            adaptive,
            boundary,
            creasing,
            backend,
            output,
        }) => {
            return cli::subdivide(cli::SubdivideArgs {
                input,
                output,
                scheme: *scheme,
                levels: *levels,
                limit: *limit,
                substitute: *substitute,
                adaptive: *adaptive,
                boundary: *boundary,
                creasing: *creasing,
                backend: *backend,
            });
        }
        Some(cli::Command::Intersect {
            project,
            objects,
            tolerance,
        }) => {
            return cli::intersect(project, objects, *tolerance);
        }
        Some(cli::Command::Offset {
            project,
            object,
            distance,
            tolerance,
            output,
        }) => {
            return cli::offset(project, object, *distance, *tolerance, output);
        }
        Some(cli::Command::Apply {
            operation,
            project,
            history,
            output,
        }) => {
            return cli::apply(operation, project, *history, output);
        }
        Some(cli::Command::Boolean {
            operation,
            a,
            b,
            output,
            tolerance,
        }) => {
            return cli::boolean((*operation).into(), a, b, output, *tolerance);
        }
        Some(cli::Command::FilletEdges {
            input,
            output,
            radius,
            near,
            radius_at,
        }) => {
            return cli::feature(
                cli::Feature::Fillet {
                    radius: *radius,
                    radius_at: radius_at.clone(),
                },
                input,
                near,
                output,
            );
        }
        Some(cli::Command::ChamferEdges {
            input,
            output,
            distance,
            near,
        }) => {
            let feature = cli::Feature::Chamfer {
                distance: *distance,
            };
            return cli::feature(feature, input, near, output);
        }
        Some(cli::Command::Shell {
            input,
            output,
            thickness,
            open,
        }) => {
            let feature = cli::Feature::Shell {
                thickness: *thickness,
            };
            return cli::feature(feature, input, open, output);
        }
        Some(cli::Command::OffsetFace {
            input,
            output,
            distance,
            face,
        }) => {
            let feature = cli::Feature::OffsetFace {
                distance: *distance,
            };
            return cli::feature(feature, input, face, output);
        }
        Some(cli::Command::DraftFace {
            input,
            output,
            angle,
            face,
            neutral,
            pull,
        }) => {
            let frame = cli::parse_point(neutral).and_then(|n| Ok((n, cli::parse_point(pull)?)));
            let (neutral, pull) = match frame {
                Ok(frame) => frame,
                Err(e) => {
                    eprintln!("knotwork draft-face: {e}");
                    return ExitCode::FAILURE;
                }
            };
            let feature = cli::Feature::Draft {
                angle: angle.to_radians(),
                neutral,
                pull,
            };
            return cli::feature(feature, input, face, output);
        }
        Some(cli::Command::Join {
            project,
            tolerance,
            output,
        }) => {
            return cli::join(project, *tolerance, output);
        }
        Some(cli::Command::Blend {
            project,
            objects,
            edges,
            continuity,
            tension,
            tolerance,
            output,
        }) => {
            return cli::blend(cli::EdgeArgs {
                input: project,
                names: [&objects[0], &objects[1]],
                edges: edges.as_deref(),
                continuity,
                tension,
                tolerance: *tolerance,
                output,
            });
        }
        Some(cli::Command::Match {
            project,
            object,
            to,
            edges,
            continuity,
            tolerance,
            output,
        }) => {
            return cli::match_edge(cli::EdgeArgs {
                input: project,
                names: [object, to],
                edges: edges.as_deref(),
                continuity,
                tension: &[],
                tolerance: *tolerance,
                output,
            });
        }
        Some(cli::Command::Fillet {
            project,
            objects,
            radius,
            radius_end,
            side_a,
            side_b,
            tolerance,
            output,
        }) => {
            return cli::fillet(cli::FilletArgs {
                input: project,
                names: objects,
                radius: *radius,
                radius_end: *radius_end,
                sides: [side_a, side_b],
                tolerance: *tolerance,
                output,
            });
        }
        Some(cli::Command::Continuity {
            project,
            objects,
            samples,
            distance,
            angle,
            curvature,
        }) => {
            return cli::continuity(project, objects, *samples, [*distance, *angle, *curvature]);
        }
        Some(cli::Command::Info {
            input,
            self_intersections,
        }) => return cli::info(input, *self_intersections),
        Some(cli::Command::Export {
            input,
            output,
            tolerance,
            segments,
            curvature,
            colors,
            backend,
        }) => {
            return cli::export(cli::ExportArgs {
                input,
                output,
                tolerance: *tolerance,
                segments: *segments,
                curvature: *curvature,
                colors: *colors,
                backend: *backend,
            });
        }
        None => {}
    }
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("knotwork=info,warn"),
    )
    .init();
    let exit_after_frames = cli.exit_after_frames;
    let restore = !cli.fresh;
    let open = match &cli.open {
        // A file that cannot be read stops here; one that cannot be parsed opens the editor
        // with the sample scene and the error shown, as opening it from the editor would.
        Some(path) => match std::fs::metadata(path) {
            Ok(_) => Some((path.display().to_string(), knotwork::app::open_path(path))),
            Err(e) => {
                eprintln!("knotwork: could not open {}: {e}", path.display());
                return ExitCode::FAILURE;
            }
        },
        None => None,
    };
    let options = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_title("knotwork")
            .with_inner_size([1280.0, 800.0]),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: knotwork::app::wgpu_configuration(false),
        ..Default::default()
    };
    let result = eframe::run_native(
        "knotwork",
        options,
        Box::new(move |cc| {
            let mut app = knotwork::app::KnotworkApp::new(cc, None, restore);
            if let Some((name, project)) = open {
                app.open_result(&name, project);
            }
            Ok(Box::new(match exit_after_frames {
                Some(frames) => app.exit_after_frames(frames),
                None => app,
            }))
        }),
    );
    if let Err(e) = result {
        eprintln!("knotwork: the editor could not start: {e}");
        return ExitCode::FAILURE;
    }
    if exit_after_frames.is_some() {
        let status = knotwork::status::current();
        println!("{}", status.to_json());
        if status.error.is_some() {
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}

#[cfg(target_arch = "wasm32")]
fn main() {}
