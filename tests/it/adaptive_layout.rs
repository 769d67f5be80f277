//! The view-adaptive patch layout in WGSL (`shaders/adaptive.wgsl`) against its Rust reference
//! (`gpu::adaptive::PatchLevels`, whose own tests prove that it tiles the square without
//! T-junctions): for many segment counts, every vertex's (s, t) and edge sample and every
//! triangle agree, run on the GPU (lavapipe where there is none).

use crate::common;

use knotwork::gpu::adaptive::PatchLevels;
use knotwork::shaders;
use wgpu::util::DeviceExt;

const TEST_BODY: &str = r#"
struct Case {
    edges: vec4<u32>,
    // (nu, nv, first triangle, first vertex) in the outputs.
    inner: vec4<u32>,
}

@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> triangles: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read_write> vertices: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = cases[id.y];
    let inner = c.inner.xy;
    let k = id.x;
    if (k < adaptive_triangle_count(c.edges, inner)) {
        let t = adaptive_triangle(c.edges, inner, k);
        triangles[c.inner.z + k] = vec4<u32>(t, 1u);
    }
    if (k < adaptive_vertex_count(c.edges, inner)) {
        let v = adaptive_vertex(c.edges, inner, k);
        vertices[c.inner.w + k] = vec4<f32>(v.st, f32(v.edge), f32(v.m));
    }
}
"#;

#[test]
fn the_shader_layout_agrees_with_the_rust_reference() {
    let context = common::gpu();
    let device = &context.device;
    let mut levels = Vec::new();
    for nu in [2, 3, 5, 9] {
        for nv in [2, 4, 7] {
            for edges in [[1, 1, 1, 1], [3, 1, 8, 2], [16, 5, 1, 9], [2, 13, 4, 4]] {
                levels.push(PatchLevels::new(edges, [nu, nv]));
            }
        }
    }
    levels.push(PatchLevels::new([64, 33, 1, 40], [48, 17]));
    let mut cases: Vec<[u32; 8]> = Vec::new();
    let (mut triangles, mut vertices) = (0u32, 0u32);
    let mut widest = 0;
    for l in &levels {
        let [e0, e1, e2, e3] = l.edges;
        cases.push([e0, e1, e2, e3, l.inner[0], l.inner[1], triangles, vertices]);
        triangles += l.triangle_count();
        vertices += l.vertex_count();
        widest = widest.max(l.triangle_count()).max(l.vertex_count());
    }
    let source = shaders::compose_parts(&[shaders::ADAPTIVE], TEST_BODY);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("adaptive layout test"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let case_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&cases),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let output = |bytes: u64| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    };
    let triangle_buffer = output(u64::from(triangles) * 16);
    let vertex_buffer = output(u64::from(vertices) * 16);
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: case_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: triangle_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: vertex_buffer.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(widest.div_ceil(64), cases.len() as u32, 1);
    }
    context.queue.submit([encoder.finish()]);
    let read = |buffer: &wgpu::Buffer, bytes: u64| {
        knotwork::gpu::readback::read_buffer(device, &context.queue, buffer, bytes).unwrap()
    };
    let gpu_triangles: Vec<[u32; 4]> =
        bytemuck::pod_collect_to_vec(&read(&triangle_buffer, u64::from(triangles) * 16));
    let gpu_vertices: Vec<[f32; 4]> =
        bytemuck::pod_collect_to_vec(&read(&vertex_buffer, u64::from(vertices) * 16));
    for (l, case) in levels.iter().zip(&cases) {
        for k in 0..l.triangle_count() {
            let expected = l.triangle(k).unwrap();
            let got = gpu_triangles[(case[6] + k) as usize];
            assert_eq!(
                [got[0], got[1], got[2]],
                expected,
                "{l:?}: triangle {k} (written: {})",
                got[3]
            );
        }
        for k in 0..l.vertex_count() {
            let (st, edge) = l.vertex(k);
            let got = gpu_vertices[(case[7] + k) as usize];
            assert!(
                (f64::from(got[0]) - st.x).abs() < 1e-6 && (f64::from(got[1]) - st.y).abs() < 1e-6,
                "{l:?}: vertex {k} at {got:?}, expected {st:?}"
            );
            let (edge, m) = edge.map_or((4, 0), |(edge, m, _)| (edge as u32, m));
            assert_eq!(
                (got[2] as u32, got[3] as u32),
                (edge, m),
                "{l:?}: vertex {k}"
            );
        }
    }
}
