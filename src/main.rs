//! The desktop editor and the headless CLI. (The web page starts the same app from `web.rs`.)

#[cfg(not(target_arch = "wasm32"))]
mod cli {
    use std::io::Read;
    use std::process::ExitCode;

    use clap::{Parser, Subcommand, ValueEnum};

    /// knotwork: a freeform-surface editor (Bézier, B-spline, NURBS) evaluated on the GPU.
    /// Without a subcommand it opens the editor window.
    #[derive(Parser)]
    #[command(name = "knotwork", version, about, long_about = None)]
    pub struct Cli {
        /// Open the editor, draw N frames (and let a pending autosave finish), close, and print
        /// the status as JSON (a smoke test; exit code 1 if the status has an error).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
        pub exit_after_frames: Option<u64>,
        /// Start from the sample scene instead of the autosaved project, and do not autosave.
        #[arg(long)]
        pub fresh: bool,
        /// A project file to open at start (instead of the autosaved one).
        #[arg(long, value_name = "FILE")]
        pub open: Option<std::path::PathBuf>,
        #[command(subcommand)]
        pub command: Option<Command>,
    }

    #[derive(Subcommand)]
    pub enum Command {
        /// Evaluate a NURBS surface at parameters: reads {"surface": ..., "params": [[u, v], ...]}
        /// and prints {"results": [...]} with point, normal, derivatives and curvatures.
        Eval {
            /// The request file, or - for standard input.
            request: String,
            /// cpu: the f64 kernel; gpu: the WGSL compute shaders in f32 (headless, no window).
            #[arg(long, value_enum, default_value_t = Backend::Cpu)]
            backend: Backend,
        },
        /// Measure the GPU evaluator: vertices per second of the compute pass (teapot at 64 and
        /// 128 segments, a 32 × 32 bicubic B-spline at 16) and edit latency.
        Bench {
            /// Timed repetitions per figure (the median is printed).
            #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=10_000))]
            iterations: u64,
        },
    }

    /// Runs `knotwork bench`.
    pub fn bench(iterations: u64) -> ExitCode {
        let context = match knotwork::gpu::GpuContext::headless_blocking() {
            Ok(c) => c,
            Err(e) => {
                eprintln!("knotwork bench: {e}");
                return ExitCode::FAILURE;
            }
        };
        match knotwork::bench::run(&context, iterations as usize, &mut std::io::stdout()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("knotwork bench: {e}");
                ExitCode::FAILURE
            }
        }
    }

    #[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
    pub enum Backend {
        Cpu,
        Gpu,
    }

    /// Runs `knotwork eval`: exit code 0 with the results on stdout, 1 with the error on stderr.
    pub fn eval(path: &str, backend: Backend) -> ExitCode {
        let text = if path == "-" {
            let mut text = String::new();
            std::io::stdin()
                .read_to_string(&mut text)
                .map(|_| text)
                .map_err(|e| format!("cannot read standard input: {e}"))
        } else {
            std::fs::read_to_string(path).map_err(|e| format!("cannot read {path}: {e}"))
        };
        let text = match text {
            Ok(text) => text,
            Err(message) => {
                eprintln!("knotwork eval: {message}");
                return ExitCode::FAILURE;
            }
        };
        let response = match backend {
            Backend::Cpu => knotwork::io::eval::evaluate_request(&text).map_err(|e| e.to_string()),
            Backend::Gpu => eval_gpu(&text),
        };
        match response {
            Ok(response) => {
                println!("{response}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("knotwork eval: {e}");
                ExitCode::FAILURE
            }
        }
    }

    /// The request evaluated by the compute shaders on a headless device.
    fn eval_gpu(text: &str) -> Result<serde_json::Value, String> {
        use knotwork::io::eval;
        let request = eval::parse_request(text).map_err(|e| e.to_string())?;
        let context = knotwork::gpu::GpuContext::headless_blocking().map_err(|e| e.to_string())?;
        let mut failure = None;
        let response = eval::respond(&request, |surface, pairs| {
            match knotwork::gpu::point_eval::evaluate_points(
                &context.device,
                &context.queue,
                surface,
                pairs,
            ) {
                Ok(results) => results
                    .into_iter()
                    .map(|r| r.map_err(|e| e.to_string()))
                    .collect(),
                Err(e) => {
                    failure = Some(e.to_string());
                    Vec::new()
                }
            }
        });
        match failure {
            Some(e) => Err(e),
            None => Ok(response),
        }
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    use clap::Parser;
    use std::process::ExitCode;

    let cli = cli::Cli::parse();
    match &cli.command {
        Some(cli::Command::Eval { request, backend }) => return cli::eval(request, *backend),
        Some(cli::Command::Bench { iterations }) => return cli::bench(*iterations),
        None => {}
    }
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("knotwork=info,warn"),
    )
    .init();
    let exit_after_frames = cli.exit_after_frames;
    let restore = !cli.fresh;
    let open = match &cli.open {
        Some(path) => match knotwork::app::read_project_file(path) {
            Ok(text) => Some((path.display().to_string(), text)),
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
            if let Some((name, text)) = &open {
                app.open_project(name, text);
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
