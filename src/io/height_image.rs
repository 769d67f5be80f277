//! Height images for displacement: a PNG (grey, grey with alpha, RGB or RGBA; 1 to 16 bits;
//! palettes expanded) decoded into grey values in [0, 1] ([`HeightImage`]); colours become their
//! luminance (Rec. 709 weights), alpha is ignored. The project file keeps the PNG itself, as
//! base64.

use base64::Engine;

use crate::kernel::displace::{HeightImage, MAX_IMAGE_SIDE};

/// Whether `name` is a file knotwork reads as a height image (by its extension, in
/// [`super::formats::FORMATS`]).
pub fn is_height_image(name: &str) -> bool {
    super::formats::format_of(name, &[]).reader == super::formats::Reader::HeightImage
}

/// Refuses a palette chunk whose length is not a whole number of RGB entries, at most 256
/// (PNG specification, 11.2.3 PLTE). The png crate (0.18) panics expanding an image whose
/// palette ends in a partial entry, so it is checked here, before decoding: chunks are walked
/// by their declared lengths up to the first IDAT (after which no PLTE may come).
fn check_palette(bytes: &[u8]) -> Result<(), String> {
    const SIGNATURE: usize = 8;
    let mut at = SIGNATURE;
    while let Some(header) = bytes.get(at..at + 8) {
        let length = u32::from_be_bytes([header[0], header[1], header[2], header[3]]) as usize;
        let kind = &header[4..8];
        if kind == b"PLTE" && (!length.is_multiple_of(3) || length == 0 || length > 3 * 256) {
            return Err(format!(
                "the PNG's palette is {length} bytes: a palette is 1 to 256 entries of 3 bytes"
            ));
        }
        if kind == b"IDAT" || kind == b"IEND" {
            break;
        }
        at = at.saturating_add(12).saturating_add(length);
    }
    Ok(())
}

/// Decodes a PNG into a height image, refusing images larger than [`MAX_IMAGE_SIDE`] a side
/// before decoding their pixels.
pub fn decode_png(bytes: &[u8]) -> Result<HeightImage, String> {
    check_palette(bytes)?;
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("not a readable PNG: {e}"))?;
    let (width, height) = {
        let info = reader.info();
        (info.width as usize, info.height as usize)
    };
    if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(format!(
            "{width} × {height} pixels: a height image may have at most {MAX_IMAGE_SIDE} a side"
        ));
    }
    let size = reader
        .output_buffer_size()
        .ok_or("the PNG's size overflows")?;
    let mut buffer = vec![0; size];
    let frame = reader
        .next_frame(&mut buffer)
        .map_err(|e| format!("the PNG's pixels could not be read: {e}"))?;
    let (colour, depth) = (frame.color_type, frame.bit_depth);
    let channels = match colour {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err("an indexed PNG was not expanded".into()),
    };
    let sample = |k: usize| -> f32 {
        match depth {
            png::BitDepth::Sixteen => {
                f32::from(u16::from_be_bytes([buffer[2 * k], buffer[2 * k + 1]])) / 65535.0
            }
            _ => f32::from(buffer[k]) / 255.0,
        }
    };
    let values = (0..width * height)
        .map(|p| {
            let k = p * channels;
            if channels >= 3 {
                (0.2126 * sample(k) + 0.7152 * sample(k + 1) + 0.0722 * sample(k + 2))
                    .clamp(0.0, 1.0)
            } else {
                sample(k)
            }
        })
        .collect();
    HeightImage::new(width, height, values, bytes.to_vec()).map_err(|e| e.to_string())
}

/// The image's PNG as base64 (the project file's form).
pub fn to_base64(image: &HeightImage) -> String {
    base64::engine::general_purpose::STANDARD.encode(image.source())
}

/// A height image from its base64 PNG.
pub fn from_base64(text: &str) -> Result<HeightImage, String> {
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(text)
        .map_err(|e| format!("not base64: {e}"))?;
    decode_png(&bytes)
}

/// A grey PNG of `width` × `height` 8-bit pixels `grey` (row-major from the top): for tests
/// and the sample images.
pub fn encode_grey_png(width: u32, height: u32, grey: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(grey).map_err(|e| e.to_string())?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_palette_ending_in_a_partial_entry_is_refused_and_a_whole_one_decodes() {
        // A 5 × 4 indexed PNG with valid checksums whose 13-byte palette ends in one byte of a
        // fifth entry (the png crate panics expanding it).
        let partial = include_bytes!("../../fuzz/regressions/png/partial-palette-valid-crc");
        let e = decode_png(partial).unwrap_err();
        assert!(e.contains("palette is 13 bytes"), "{e}");
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, 2, 2);
            encoder.set_color(png::ColorType::Indexed);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_palette(vec![0, 0, 0, 255, 255, 255]);
            let mut writer = encoder.write_header().unwrap();
            writer.write_image_data(&[0, 1, 1, 0]).unwrap();
        }
        let image = decode_png(&out).unwrap();
        assert_eq!(image.values(), [0.0, 1.0, 1.0, 0.0]);
    }

    #[test]
    fn a_grey_png_round_trips_and_bad_ones_are_refused() {
        let grey: Vec<u8> = (0..12).map(|k| (k * 20) as u8).collect();
        let png = encode_grey_png(4, 3, &grey).unwrap();
        let image = decode_png(&png).unwrap();
        assert_eq!((image.width(), image.height()), (4, 3));
        for (v, g) in image.values().iter().zip(&grey) {
            assert!((v - f32::from(*g) / 255.0).abs() < 1e-7);
        }
        let again = from_base64(&to_base64(&image)).unwrap();
        assert_eq!(again, image);
        assert!(decode_png(b"not a png").is_err());
        assert!(decode_png(&png[..png.len() / 2]).is_err());
        assert!(from_base64("%%%").is_err());
        let one_row = encode_grey_png(3, 1, &[0, 1, 2]).unwrap();
        assert!(
            decode_png(&one_row).is_err(),
            "a side of one pixel is refused"
        );
    }
}
