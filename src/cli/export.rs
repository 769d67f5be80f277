//! `knotwork export`: a project or a file exported as glTF, STEP, binary STL or 3MF.

use std::process::ExitCode;

use std::sync::Arc;

use knotwork::gpu::export_grids::GpuGrids;
use knotwork::kernel::tess::{GridSampler, KernelGrids};

use super::*;

/// The options of `knotwork export`.
pub struct ExportArgs<'a> {
    pub input: &'a std::path::Path,
    pub output: &'a std::path::Path,
    pub tolerance: Option<f64>,
    pub segments: Option<u32>,
    pub curvature: bool,
    pub colors: Option<ColorMode>,
    pub backend: GridBackend,
}

/// Who evaluates the grids of an export (`--backend`): the sampler, the GPU one when it is
/// (to ask afterwards whether it fell back), and the words for the summary.
struct Grids {
    sampler: Arc<dyn GridSampler + Send>,
    gpu: Option<Arc<GpuGrids>>,
    how: String,
}

impl Grids {
    fn choose(backend: GridBackend) -> Result<Self, String> {
        let cpu = |why: &str| Self {
            sampler: Arc::new(KernelGrids),
            gpu: None,
            how: format!("grids on the CPU{why}"),
        };
        if backend == GridBackend::Cpu {
            return Ok(cpu(""));
        }
        match knotwork::gpu::GpuContext::headless_blocking() {
            Ok(context) => {
                if backend == GridBackend::Auto
                    && knotwork::render::is_software(&context.adapter.get_info())
                {
                    return Ok(cpu(" (the adapter is a software one)"));
                }
                let gpu = Arc::new(GpuGrids::new(&context.device, &context.queue));
                Ok(Self {
                    sampler: gpu.clone(),
                    gpu: Some(gpu),
                    how: format!("grids on the GPU ({})", context.describe()),
                })
            }
            Err(e) if backend == GridBackend::Gpu => Err(format!("--backend gpu: {e}")),
            Err(_) => Ok(cpu(" (no GPU with compute shaders)")),
        }
    }

    /// The summary's words, with the batches the GPU refused.
    fn summary(&self) -> String {
        match self.gpu.as_ref().map(|g| g.fallbacks()) {
            Some(n) if n > 0 => format!("{}, {n} batches fell back to the CPU", self.how),
            _ => self.how.clone(),
        }
    }
}

/// Runs `knotwork export`: exit code 0 with a summary on stdout, 1 with the error on stderr.
pub fn export(args: ExportArgs<'_>) -> ExitCode {
    match export_files(&args) {
        Ok(summary) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("knotwork export: {e}");
            ExitCode::FAILURE
        }
    }
}

fn export_files(args: &ExportArgs<'_>) -> Result<String, String> {
    use knotwork::io::gltf;
    use knotwork::kernel::tess::Tessellation;
    let started = std::time::Instant::now();
    let input = args.input.display().to_string();
    let project =
        knotwork::app::open_path(args.input).map_err(|e| format!("cannot open {input}: {e}"))?;
    let extension = knotwork::io::formats::extension(&args.output.display().to_string());
    if extension == "step" || extension == "stp" {
        let tolerance = args
            .tolerance
            .unwrap_or_else(|| knotwork::io::step::default_tolerance(&project.scene));
        let name = args
            .output
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let knotwork::io::step::StepExport {
            text,
            left_out,
            approximated,
        } = knotwork::io::step::export_scene(&project.scene, &name, tolerance)
            .map_err(|e| e.to_string())?;
        for note in &approximated {
            eprintln!("knotwork export: {note}");
        }
        std::fs::write(args.output, &text)
            .map_err(|e| format!("cannot write {}: {e}", args.output.display()))?;
        for why in &left_out {
            eprintln!("knotwork export: left out {why}");
        }
        return Ok(format!(
            "wrote {} ({} bytes), in {:.0} ms",
            args.output.display(),
            text.len(),
            started.elapsed().as_secs_f64() * 1e3
        ));
    }
    let grids = Grids::choose(args.backend)?;
    if extension == "stl" {
        let tolerance = args
            .tolerance
            .unwrap_or_else(|| gltf::default_tolerance(&project.scene));
        let (bytes, facets) = knotwork::io::stl::write(
            &project.scene,
            Tessellation::Tolerance(tolerance),
            grids.sampler.as_ref(),
        )
        .map_err(|e| e.to_string())?;
        std::fs::write(args.output, &bytes)
            .map_err(|e| format!("cannot write {}: {e}", args.output.display()))?;
        return Ok(format!(
            "wrote {} ({} bytes): {facets} facets, tolerance {tolerance:.3e}, {}, in {:.0} ms",
            args.output.display(),
            bytes.len(),
            grids.summary(),
            started.elapsed().as_secs_f64() * 1e3
        ));
    }
    if extension == "3mf" {
        let tolerance = args
            .tolerance
            .unwrap_or_else(|| gltf::default_tolerance(&project.scene));
        let package = knotwork::io::threemf::write(
            &project.scene,
            Tessellation::Tolerance(tolerance),
            grids.sampler.as_ref(),
        )
        .map_err(|e| e.to_string())?;
        std::fs::write(args.output, &package.bytes)
            .map_err(|e| format!("cannot write {}: {e}", args.output.display()))?;
        return Ok(format!(
            "wrote {} ({} bytes): {} objects, {} triangles, {} vertices, unit {}, tolerance \
             {tolerance:.3e}, {}, in {:.0} ms",
            args.output.display(),
            package.bytes.len(),
            package.objects,
            package.triangles,
            package.vertices,
            knotwork::io::threemf::unit_name(project.scene.unit),
            grids.summary(),
            started.elapsed().as_secs_f64() * 1e3
        ));
    }
    let tessellation = match (args.tolerance, args.segments) {
        (_, Some(n)) => Tessellation::Segments(n),
        (Some(t), None) => Tessellation::Tolerance(t),
        (None, None) => Tessellation::Tolerance(gltf::default_tolerance(&project.scene)),
    };
    let colors = args.colors.map(|mode| {
        gltf::CurvatureColors::automatic(
            &project.scene,
            mode as usize,
            knotwork::gpu::records::curvature_ramp_rgb(),
        )
    });
    let options = gltf::ExportOptions {
        tessellation,
        curvature: args.curvature,
        colors,
    };
    let export =
        gltf::export_with(&project, &options, grids.sampler.clone()).map_err(|e| e.to_string())?;
    let output = args.output.display().to_string();
    let mut written = Vec::new();
    for (path, bytes) in gltf::files(&export, &output) {
        std::fs::write(&path, &bytes).map_err(|e| format!("cannot write {path}: {e}"))?;
        written.push(format!("{path} ({} bytes)", bytes.len()));
    }
    let how = match tessellation {
        Tessellation::Tolerance(t) => format!("tolerance {t:.3e}"),
        Tessellation::Segments(n) => format!("{n} segments per span"),
    };
    Ok(format!(
        "wrote {}: {} objects, {} triangles, {} vertices, {how}, {}, in {:.0} ms",
        written.join(", "),
        project.scene.objects.iter().filter(|o| o.visible).count(),
        export.triangles,
        export.vertices,
        grids.summary(),
        started.elapsed().as_secs_f64() * 1e3
    ))
}
