//! Every shader in `shaders/` is parsed and validated by naga (at WebGPU's baseline capabilities,
//! so what passes here also compiles in the browser), and the records shared by Rust and WGSL are
//! checked against each other by naga reflection.

use std::collections::BTreeSet;
use std::mem::{offset_of, size_of};

use knotwork::gpu::packing::pattern_code;
use knotwork::gpu::records::{
    AdaptiveSlot, AdaptiveView, EVAL_WORKGROUP_SIZE, GPU_CURVATURE_NUDGE, GPU_MAX_DEGREE,
    PatchRecord, PointResult, PointSample, RAMP_STOPS, SceneUniform, SurfaceVertex,
    VERTEX_IRREGULAR, VERTEX_NO_CURVATURE,
};
use knotwork::kernel::bezier::DEGENERATE_SIN2;
use knotwork::shaders;
use knotwork::view::ShadingMode;

fn parse_and_validate(name: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    module
}

#[test]
fn every_shader_file_is_registered_and_valid() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let on_disk: BTreeSet<String> = std::fs::read_dir(&dir)
        .expect("shaders/ exists")
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".wgsl"))
        .collect();
    let mut registered: BTreeSet<String> = shaders::PIPELINE_SHADERS
        .iter()
        .map(|shader| shader.name.to_string())
        .chain(shaders::MODULES.iter().map(|(name, _)| name.to_string()))
        .chain(shaders::EVAL_PARTS.iter().map(|(name, _)| name.to_string()))
        .collect();
    registered.insert("common.wgsl".to_owned());
    assert_eq!(
        on_disk, registered,
        "shaders/ and src/shaders.rs list the same files"
    );

    // What the binary embeds (and the device compiles), composed with the shared module.
    parse_and_validate("common.wgsl", shaders::COMMON);
    for (name, module) in shaders::MODULES {
        let (needs, host) = shaders::module_host(name);
        let mut parts = needs.to_vec();
        parts.push(module);
        parse_and_validate(name, &shaders::compose_parts(&parts, host));
    }
    for shader in shaders::PIPELINE_SHADERS {
        parse_and_validate(shader.name, &shaders::compose(&shader));
    }
    // The evaluator's parts are validated inside it: each is in its body, whole.
    for (name, part) in shaders::EVAL_PARTS {
        assert!(
            shaders::EVAL_BEZIER_SHADER.body.contains(part),
            "{name} is part of the evaluator"
        );
    }
}

#[test]
fn a_broken_shader_is_caught_by_the_validation() {
    // The check above can fail: an undeclared identifier, a type error and a bad binding are
    // each refused by the same parse-and-validate step.
    for (what, broken) in [
        ("undeclared", "fn f() -> f32 { return missing; }"),
        ("type error", "fn f() -> f32 { return vec3<f32>(1.0); }"),
        (
            "runtime-sized uniform",
            "@group(3) @binding(9) var<uniform> y: array<f32>;",
        ),
    ] {
        let source = shaders::compose_parts(&[], broken);
        let refused = std::panic::catch_unwind(|| parse_and_validate(what, &source));
        assert!(refused.is_err(), "{what}: accepted");
    }
}

/// (member name, offset) pairs and the span of the WGSL struct `name`.
fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
    let ty = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name} in common.wgsl"))
        .1;
    match &ty.inner {
        naga::TypeInner::Struct { members, span } => (
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                .collect(),
            *span,
        ),
        other => panic!("{name} is not a struct: {other:?}"),
    }
}

macro_rules! rust_layout {
    ($ty:ty { $($field:ident),* $(,)? }) => {
        (
            vec![$((stringify!($field).to_owned(), offset_of!($ty, $field) as u32)),*],
            size_of::<$ty>() as u32,
        )
    };
}

#[test]
fn shared_records_have_the_same_layout_on_both_sides() {
    let module = parse_and_validate("common.wgsl", shaders::COMMON);
    assert_eq!(
        wgsl_layout(&module, "PatchRecord"),
        rust_layout!(PatchRecord {
            degree_u,
            degree_v,
            control_offset,
            vertex_offset,
            segments_u,
            segments_v,
            index_offset,
            object,
            domain,
            kind,
            trim_offset,
            trim_count,
            level,
            displacement,
            lattice,
            point_list,
            first_point
        })
    );
    assert_eq!(
        wgsl_layout(&module, "SurfaceVertex"),
        rust_layout!(SurfaceVertex {
            position,
            u,
            normal,
            v,
            gaussian_mean,
            record,
            tag
        })
    );
    assert_eq!(
        wgsl_layout(&module, "PointSample"),
        rust_layout!(PointSample {
            patch_index,
            s,
            t,
            reserved
        })
    );
    assert_eq!(
        wgsl_layout(&module, "PointResult"),
        rust_layout!(PointResult {
            point,
            normal,
            su,
            sv,
            suu,
            suv,
            svv,
            curvature,
            flags
        })
    );
    assert_eq!(
        wgsl_layout(&module, "SceneUniform"),
        rust_layout!(SceneUniform {
            view_proj,
            eye,
            viewport,
            surface_color,
            back_color,
            net_color,
            point_color,
            shading,
            range,
            ramp,
            view_right,
            view_up,
            view_back,
            analysis,
            isophote_direction,
            pull_direction,
            analysis_flags
        })
    );
    assert_eq!(
        wgsl_layout(&module, "AdaptiveView"),
        rust_layout!(AdaptiveView {
            view_proj,
            eye,
            forward,
            error,
            counts,
            bases
        })
    );
    assert_eq!(
        wgsl_layout(&module, "AdaptiveSlot"),
        rust_layout!(AdaptiveSlot {
            edges,
            inner,
            record,
            culled,
            vertex_offset,
            index_offset,
            vertex_count,
            triangle_count
        })
    );
    use knotwork::gpu::records::{CurveRecord, CurveVertex};
    assert_eq!(
        wgsl_layout(&module, "CurveRecord"),
        rust_layout!(CurveRecord {
            degree,
            control_offset,
            vertex_offset,
            segments,
            object,
            reserved0,
            reserved1,
            reserved2
        })
    );
    assert_eq!(
        wgsl_layout(&module, "CurveVertex"),
        rust_layout!(CurveVertex {
            position,
            object,
            record,
            s,
            reserved
        })
    );
    // The curve pipeline reads a CurveVertex's position and object as attributes 0 and 1.
    let curve_offsets: Vec<u64> = CurveVertex::ATTRIBUTES.iter().map(|a| a.offset).collect();
    assert_eq!(
        curve_offsets,
        [
            offset_of!(CurveVertex, position) as u64,
            offset_of!(CurveVertex, object) as u64
        ]
    );
    assert_eq!(
        wgsl_constant(&module, "CURVE_MAX_DEGREE"),
        f64::from(knotwork::gpu::records::CURVE_MAX_DEGREE)
    );
    assert_eq!(
        wgsl_constant(&module, "CURVE_WORKGROUP_SIZE"),
        f64::from(knotwork::gpu::records::CURVE_WORKGROUP_SIZE)
    );
    assert_eq!(
        knotwork::gpu::records::CURVE_MAX_DEGREE as usize,
        knotwork::kernel::basis::MAX_DEGREE
    );
    // The render pipeline reads SurfaceVertex through vertex attributes at the same offsets.
    let attribute_offsets: Vec<u64> = SurfaceVertex::ATTRIBUTES.iter().map(|a| a.offset).collect();
    // (Every member is an attribute.)
    let member_offsets: Vec<u64> = wgsl_layout(&module, "SurfaceVertex")
        .0
        .iter()
        .map(|(_, offset)| u64::from(*offset))
        .collect();
    assert_eq!(attribute_offsets, member_offsets);
    assert_eq!(
        SurfaceVertex::layout().array_stride,
        u64::from(wgsl_layout(&module, "SurfaceVertex").1)
    );
}

/// The value of the WGSL constant `name`.
fn wgsl_constant(module: &naga::Module, name: &str) -> f64 {
    let constant = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no constant {name}"))
        .1;
    match module.global_expressions[constant.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => f64::from(v),
        naga::Expression::Literal(naga::Literal::F32(v)) => f64::from(v),
        ref other => panic!("{name} is not a u32/f32 literal: {other:?}"),
    }
}

#[test]
fn evaluator_constants_match_their_rust_counterparts() {
    let module = parse_and_validate(
        "eval_bezier.wgsl",
        &shaders::compose(&shaders::EVAL_BEZIER_SHADER),
    );
    assert_eq!(
        wgsl_constant(&module, "MAX_DEGREE"),
        f64::from(GPU_MAX_DEGREE)
    );
    assert_eq!(
        wgsl_constant(&module, "WORKGROUP_SIZE"),
        f64::from(EVAL_WORKGROUP_SIZE)
    );
    assert_eq!(
        wgsl_constant(&module, "GRID_ROWS"),
        f64::from(knotwork::gpu::records::EVAL_GRID_ROWS)
    );
    assert_eq!(
        wgsl_constant(&module, "DEGENERATE_SIN2"),
        f64::from(DEGENERATE_SIN2 as f32)
    );
    assert_eq!(
        wgsl_constant(&module, "VERTEX_IRREGULAR"),
        f64::from(VERTEX_IRREGULAR)
    );
    assert_eq!(
        wgsl_constant(&module, "VERTEX_NO_CURVATURE"),
        f64::from(VERTEX_NO_CURVATURE)
    );
    assert_eq!(wgsl_constant(&module, "RAMP_STOPS"), RAMP_STOPS as f64);
    assert_eq!(
        wgsl_constant(&module, "PATCH_KIND_BEZIER"),
        f64::from(knotwork::gpu::records::PATCH_KIND_BEZIER)
    );
    use knotwork::kernel::displace::Pattern;
    for (name, value) in [
        (
            "DISPLACEMENT_NONE",
            knotwork::gpu::records::DISPLACEMENT_NONE,
        ),
        ("LATTICE_NONE", knotwork::gpu::records::LATTICE_NONE),
        ("DISPLACE_WAVES", pattern_code(Pattern::Waves)),
        ("DISPLACE_RIPPLES", pattern_code(Pattern::Ripples)),
        ("DISPLACE_NOISE", pattern_code(Pattern::Noise)),
        (
            "PATCH_KIND_STENCIL_QUAD",
            knotwork::gpu::records::PATCH_KIND_STENCIL_QUAD,
        ),
        (
            "PATCH_KIND_STENCIL_TRIANGLE",
            knotwork::gpu::records::PATCH_KIND_STENCIL_TRIANGLE,
        ),
        ("PATCH_KIND_ACC", knotwork::gpu::records::PATCH_KIND_ACC),
        (
            "PATCH_KIND_GREGORY",
            knotwork::gpu::records::PATCH_KIND_GREGORY,
        ),
        (
            "PATCH_KIND_PN_TRIANGLE",
            knotwork::gpu::records::PATCH_KIND_PN_TRIANGLE,
        ),
        (
            "STENCIL_NO_CURVATURE",
            knotwork::gpu::records::STENCIL_NO_CURVATURE,
        ),
        ("POINT_LIST_NONE", knotwork::gpu::records::POINT_LIST_NONE),
        (
            "VERTEX_OBJECT_MASK",
            knotwork::gpu::records::VERTEX_OBJECT_MASK,
        ),
        (
            "VERTEX_LEVEL_SHIFT",
            knotwork::gpu::records::VERTEX_LEVEL_SHIFT,
        ),
        (
            "VERTEX_FLAGS_SHIFT",
            knotwork::gpu::records::VERTEX_FLAGS_SHIFT,
        ),
        ("DISPLACE_IMAGE", pattern_code(Pattern::Image)),
        ("LATTICE_HEADER", knotwork::gpu::packing::LATTICE_HEADER),
        (
            "DISPLACEMENT_HEADER",
            knotwork::gpu::packing::DISPLACEMENT_HEADER,
        ),
        ("IMAGE_HEADER", knotwork::gpu::packing::IMAGE_HEADER),
        (
            "ARGS_DRAW",
            knotwork::gpu::adaptive_pass::ADAPTIVE_ARGS_DRAW,
        ),
        (
            "ARGS_TRIANGLES",
            knotwork::gpu::adaptive_pass::ADAPTIVE_ARGS_TRIANGLES,
        ),
        (
            "ARGS_STATS",
            knotwork::gpu::adaptive_pass::ADAPTIVE_ARGS_STATS,
        ),
        (
            "ARGS_GROUPS",
            knotwork::gpu::adaptive_pass::ADAPTIVE_ARGS_GROUPS,
        ),
        (
            "ARGS_GROUP_WORDS",
            knotwork::gpu::adaptive_pass::ADAPTIVE_ARGS_GROUP_WORDS,
        ),
        ("TRIM_PARTIAL", knotwork::gpu::trim_buffer::TRIM_PARTIAL),
        ("TRIM_CULLED", knotwork::gpu::trim_buffer::TRIM_CULLED),
        (
            "TRIM_HEADER_WORDS",
            knotwork::gpu::trim_buffer::TRIM_HEADER_WORDS,
        ),
        (
            "TRIM_CELL_WORDS",
            knotwork::gpu::trim_buffer::TRIM_CELL_WORDS,
        ),
        (
            "TRIM_PIECE_HEADER_WORDS",
            knotwork::gpu::trim_buffer::TRIM_PIECE_HEADER_WORDS,
        ),
    ] {
        assert_eq!(wgsl_constant(&module, name), f64::from(value), "{name}");
    }
    assert_eq!(
        wgsl_constant(&module, "CURVATURE_NUDGE"),
        f64::from(GPU_CURVATURE_NUDGE)
    );
    // The basis arrays hold MAX_DEGREE + 1 entries.
    assert!(shaders::EVAL_BEZIER.contains(&format!("array<f32, {}>", GPU_MAX_DEGREE + 1)));
    // A baked lattice keeps patches up to the degree the GPU evaluates.
    assert_eq!(
        knotwork::kernel::ffd::EXACT_MAX_DEGREE,
        GPU_MAX_DEGREE as usize
    );
}

#[test]
fn shading_modes_match_the_surface_shader() {
    let module = parse_and_validate("surface.wgsl", &shaders::compose(&shaders::SURFACE_SHADER));
    // SAMPLE_COUNT is an override set per pipeline; its default is the targets' default.
    let samples = module
        .overrides
        .iter()
        .find(|(_, o)| o.name.as_deref() == Some("SAMPLE_COUNT"))
        .and_then(|(_, o)| o.init)
        .map(|init| &module.global_expressions[init]);
    assert!(
        matches!(
            samples,
            Some(naga::Expression::Literal(naga::Literal::U32(n)))
                if *n == knotwork::render::SAMPLE_COUNT
        ),
        "SAMPLE_COUNT override: {samples:?}"
    );
    for mode in ShadingMode::ALL {
        let name = format!("MODE_{}", mode.name().to_uppercase());
        assert_eq!(wgsl_constant(&module, &name), mode as u32 as f64, "{name}");
        assert_eq!(ShadingMode::from_name(mode.name()), Some(mode));
    }
    assert_eq!(
        wgsl_constant(&module, "VERTEX_NO_CURVATURE"),
        f64::from(VERTEX_NO_CURVATURE)
    );
    // The draft analysis's colours, which the legend shows.
    for (name, rgb) in ["DRAFT_ENOUGH", "DRAFT_LITTLE", "DRAFT_UNDERCUT"]
        .iter()
        .zip(knotwork::render::DRAFT_COLORS)
    {
        let expected: Vec<f64> = rgb.iter().map(|&c| f64::from(c)).collect();
        assert_eq!(wgsl_vector(&module, name), expected, "{name}");
    }
}

/// The components of the WGSL vector constant `name` (a constructor of literals).
fn wgsl_vector(module: &naga::Module, name: &str) -> Vec<f64> {
    let constant = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no constant {name}"))
        .1;
    let naga::Expression::Compose { ref components, .. } = module.global_expressions[constant.init]
    else {
        panic!("{name} is not a vector constructor");
    };
    components
        .iter()
        .map(|&c| match module.global_expressions[c] {
            naga::Expression::Literal(naga::Literal::F32(v)) => f64::from(v),
            ref other => panic!("{name}: a component is not an f32 literal: {other:?}"),
        })
        .collect()
}

/// `entry` of `shader` in GLSL ES 3.00 (WebGL2), as wgpu's GL backend writes it: overrides
/// set (the plain one-sample pipeline's), then the GLSL writer.
fn glsl_es_300(
    shader: &shaders::PipelineShader,
    entry: &str,
    stage: naga::ShaderStage,
) -> Result<String, naga::back::glsl::Error> {
    let source = shaders::compose(shader);
    let module = parse_and_validate(shader.name, &source);
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .expect("validated above");
    let constants: naga::back::PipelineConstants = module
        .overrides
        .iter()
        .filter_map(|(_, o)| o.name.clone())
        .map(|name| {
            let value = if name == "SAMPLE_COUNT" { 1.0 } else { 0.0 };
            (name, value)
        })
        .collect();
    let (module, info) = naga::back::pipeline_constants::process_overrides(
        &module,
        &info,
        Some((stage, entry)),
        &constants,
    )
    .expect("overrides set");
    let options = naga::back::glsl::Options {
        version: naga::back::glsl::Version::new_gles(300),
        ..Default::default()
    };
    let pipeline = naga::back::glsl::PipelineOptions {
        shader_stage: stage,
        entry_point: entry.to_owned(),
        multiview: None,
    };
    let mut out = String::new();
    let mut writer = naga::back::glsl::Writer::new(
        &mut out,
        &module,
        &info,
        &options,
        &pipeline,
        naga::proc::BoundsCheckPolicies::default(),
    )?;
    writer.write()?;
    Ok(out)
}

#[test]
fn the_webgl2_pipelines_translate_to_glsl_es_300() {
    use naga::ShaderStage::{Fragment, Vertex};
    for (shader, entry, stage) in [
        (shaders::SURFACE_GL_SHADER, "vs_surface_gl", Vertex),
        (shaders::SURFACE_GL_SHADER, "fs_surface_gl", Fragment),
        (shaders::OVERLAY_SHADER, "vs_net", Vertex),
        (shaders::OVERLAY_SHADER, "fs_net", Fragment),
        (shaders::OVERLAY_SHADER, "vs_dot", Vertex),
        (shaders::OVERLAY_SHADER, "fs_dot", Fragment),
        (shaders::OVERLAY_SHADER, "vs_lines", Vertex),
        (shaders::OVERLAY_SHADER, "fs_lines", Fragment),
    ] {
        let glsl = glsl_es_300(&shader, entry, stage)
            .unwrap_or_else(|e| panic!("{} {entry}: {e}", shader.name));
        assert!(glsl.starts_with("#version 300 es"), "{entry}: {glsl}");
        assert!(!glsl.contains("buffer "), "{entry} uses a storage buffer");
    }
    // The check can fail: the WebGPU surface shader reads storage buffers and writes a sample
    // mask, which GLSL ES 3.00 lacks.
    for (entry, stage) in [("vs_surface", Vertex), ("fs_surface", Fragment)] {
        assert!(
            glsl_es_300(&shaders::SURFACE_SHADER, entry, stage).is_err(),
            "{entry} translated to GLSL ES 3.00"
        );
    }
}
