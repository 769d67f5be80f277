//! The blocks the compute shaders read for an object's displacement and free-form deformation
//! lattice, packed from the kernel's types. They lie among the stencil entries of the
//! control-point buffer (see [`super::records::PatchRecord`]). Their headers' sizes are the
//! WGSL constants of the same names in `shaders/common.wgsl`, and `tests/it/shaders.rs` checks the
//! codes and sizes against them.

use crate::kernel::displace::{Displacement, HeightImage, Pattern};
use crate::kernel::ffd::Lattice;

/// vec4s before a lattice block's points: the origin with the packed degrees, and the three
/// rows of the inverse box. WGSL: `LATTICE_HEADER`.
pub const LATTICE_HEADER: u32 = 4;
/// vec4s of a displacement block before its image's block: the parameters
/// ([`displacement_words`]) and the object's (u0, u1, v0, v1). WGSL: `DISPLACEMENT_HEADER`.
pub const DISPLACEMENT_HEADER: u32 = 2;
/// vec4s of an image block before its grey values: (width, height) as bits. WGSL:
/// `IMAGE_HEADER`.
pub const IMAGE_HEADER: u32 = 1;

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

/// The block of a displacement over the object's (u0, u1, v0, v1) `domain`: its
/// [`DISPLACEMENT_HEADER`] vec4s, then its image's block ([`height_image_words`]) if it has
/// one.
pub fn displacement_block(map: &Displacement, domain: [f64; 4]) -> Vec<[f32; 4]> {
    let mut block = vec![displacement_words(map), domain.map(|x| x as f32)];
    if let Some(image) = &map.image {
        block.extend(height_image_words(image));
    }
    block
}

/// The block the GPU reads for a height image (`image_height`): [`IMAGE_HEADER`] vec4 of
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

/// The lattice block the GPU reads (`lattice_jet`): [`LATTICE_HEADER`] vec4s of (X₀, degrees
/// packed l | m << 8 | n << 16 as the bits of w) and the three rows of the inverse box A, then
/// the points.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::displace::{HeightImage, Pattern};
    use glam::DVec3;

    #[test]
    fn blocks_have_their_headers_then_their_payloads() {
        let lattice = Lattice::around(DVec3::ZERO, DVec3::ONE, [2, 1, 3]).unwrap();
        let block = lattice_block(&lattice);
        assert_eq!(block.len(), LATTICE_HEADER as usize + 3 * 2 * 4);
        let packed = block[0][3].to_bits();
        assert_eq!(
            [packed & 0xff, (packed >> 8) & 0xff, packed >> 16],
            [2, 1, 3]
        );
        let first = lattice.points()[0].as_vec3().to_array();
        assert_eq!(block[LATTICE_HEADER as usize][..3], first);

        let values: Vec<f32> = (0..15).map(|k| k as f32 / 14.0).collect();
        let image = HeightImage::new(5, 3, values, Vec::new()).unwrap();
        let words = height_image_words(&image);
        assert_eq!(words.len(), IMAGE_HEADER as usize + 4);
        assert_eq!([words[0][0].to_bits(), words[0][1].to_bits()], [5, 3]);
        assert_eq!(words[IMAGE_HEADER as usize + 3][2], 14.0 / 14.0);

        let waves = Displacement::new(Pattern::Waves, 0.1, 3.0).unwrap();
        let block = displacement_block(&waves, [0.0, 2.0, -1.0, 1.0]);
        assert_eq!(block.len(), DISPLACEMENT_HEADER as usize);
        assert_eq!(block[1], [0.0, 2.0, -1.0, 1.0]);
        let imaged = Displacement::with_image(std::sync::Arc::new(image), 0.1, 3.0).unwrap();
        let block = displacement_block(&imaged, [0.0, 1.0, 0.0, 1.0]);
        assert_eq!(
            block.len(),
            (DISPLACEMENT_HEADER + IMAGE_HEADER) as usize + 4
        );
        assert_eq!(block[0][0], pattern_code(Pattern::Image) as f32);
    }
}
