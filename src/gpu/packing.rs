//! The words the compute shaders read for an object's displacement and free-form deformation
//! lattice, packed from the kernel's types. They lie among the stencil entries of the
//! control-point buffer (see [`super::records::PatchRecord`]); `tests/shaders.rs` checks the
//! codes and offsets against the WGSL constants.

use crate::kernel::displace::{Displacement, HeightImage, Pattern};
use crate::kernel::ffd::Lattice;

/// The code the GPU reads for a pattern (`DISPLACE_*` in `shaders/eval_bezier.wgsl`); 0 is
/// none.
pub fn pattern_code(pattern: Pattern) -> u32 {
    match pattern {
        Pattern::Waves => 1,
        Pattern::Ripples => 2,
        Pattern::Noise => 3,
        Pattern::Image => 4,
    }
}

/// The four floats the GPU reads first for a displacement: pattern code (as a float),
/// amplitude, frequency, segments per cycle ([`Displacement::segments_per_cycle`]).
pub fn displacement_words(map: &Displacement) -> [f32; 4] {
    [
        pattern_code(map.pattern) as f32,
        map.amplitude as f32,
        map.frequency as f32,
        map.segments_per_cycle() as f32,
    ]
}

/// The words the GPU reads after the displacement's two for a height image (`image_height`):
/// (width, height) as bits, then the grey values four to a word.
pub fn height_image_words(image: &HeightImage) -> Vec<[f32; 4]> {
    let mut words = vec![[
        f32::from_bits(image.width() as u32),
        f32::from_bits(image.height() as u32),
        0.0,
        0.0,
    ]];
    words.extend(image.values().chunks(4).map(|c| {
        let mut word = [0.0; 4];
        word[..c.len()].copy_from_slice(c);
        word
    }));
    words
}

/// The lattice block the GPU reads (`lattice_jet`): (X₀, degrees packed l | m << 8 | n << 16
/// as the bits of w), the three rows of the inverse box A, then the points.
pub fn lattice_block(lattice: &Lattice) -> Vec<[f32; 4]> {
    let [l, m, n] = lattice.degrees();
    let packed = (l | (m << 8) | (n << 16)) as u32;
    let origin = lattice.origin();
    let a = lattice.inverse_axes().transpose();
    let mut block = vec![
        [
            origin.x as f32,
            origin.y as f32,
            origin.z as f32,
            f32::from_bits(packed),
        ],
        a.x_axis.extend(0.0).as_vec4().to_array(),
        a.y_axis.extend(0.0).as_vec4().to_array(),
        a.z_axis.extend(0.0).as_vec4().to_array(),
    ];
    block.extend(
        lattice
            .points()
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32, 0.0]),
    );
    block
}
