//! The desktop editor. (The web page starts the same app from `web.rs` instead.)

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    use std::process::ExitCode;

    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("knotwork=info,warn"),
    )
    .init();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut exit_after_frames = None;
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        match arg.as_str() {
            "--version" | "-V" => {
                println!("knotwork {}", env!("CARGO_PKG_VERSION"));
                return ExitCode::SUCCESS;
            }
            "--help" | "-h" => {
                println!("{USAGE}");
                return ExitCode::SUCCESS;
            }
            "--exit-after-frames" => match rest.next().map(|n| n.parse::<u64>()) {
                Some(Ok(n)) if n > 0 => exit_after_frames = Some(n),
                _ => {
                    eprintln!("knotwork: --exit-after-frames needs a positive number\n\n{USAGE}");
                    return ExitCode::from(2);
                }
            },
            other => {
                eprintln!("knotwork: unknown argument '{other}'\n\n{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
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
            let app = knotwork::app::KnotworkApp::new(cc, None);
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

#[cfg(not(target_arch = "wasm32"))]
const USAGE: &str = "\
usage: knotwork                          open the editor window
       knotwork --exit-after-frames N   open it, draw N frames, close, print the status as JSON
                                        (a smoke test; exit code 1 if the status has an error)
       knotwork --help                  this text
       knotwork --version               the version";

#[cfg(target_arch = "wasm32")]
fn main() {}
