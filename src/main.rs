//! The desktop editor. (The web page starts the same app from `web.rs` instead.)

#[cfg(not(target_arch = "wasm32"))]
fn main() -> std::process::ExitCode {
    use std::process::ExitCode;

    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("knotwork=info,warn"),
    )
    .init();
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        None => {}
        Some("--version" | "-V") => {
            println!("knotwork {}", env!("CARGO_PKG_VERSION"));
            return ExitCode::SUCCESS;
        }
        Some("--help" | "-h") => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Some(other) => {
            eprintln!("knotwork: unknown argument '{other}'\n\n{USAGE}");
            return ExitCode::from(2);
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
        Box::new(|cc| Ok(Box::new(knotwork::app::KnotworkApp::new(cc, None)))),
    );
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("knotwork: the editor could not start: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(not(target_arch = "wasm32"))]
const USAGE: &str = "\
usage: knotwork            open the editor window
       knotwork --help     this text
       knotwork --version  the version";

#[cfg(target_arch = "wasm32")]
fn main() {}
