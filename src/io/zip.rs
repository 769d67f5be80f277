//! A ZIP archive of stored (uncompressed) entries, the container 3MF packages use (Open
//! Packaging Conventions). Layout from PKWARE's APPNOTE.TXT (sections 4.3.7, 4.3.12, 4.3.16):
//! each entry's local header and bytes, then the central directory and its end record; every
//! number little-endian, CRC-32 from `crc32fast` (the same polynomial the format names, and
//! already built for the PNG decoder). Times are the format's earliest date, 1980-01-01, so
//! that the same document gives the same bytes.

/// Why an archive could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ZipError {
    #[error("{0} bytes are more than a ZIP archive without its 64-bit extension holds")]
    TooLarge(usize),
    #[error("{0} entries are more than a ZIP archive without its 64-bit extension holds")]
    TooManyEntries(usize),
}

/// The DOS date of 1980-01-01: (year − 1980) << 9 | month << 5 | day.
const DOS_DATE: u16 = (1 << 5) | 1;
/// Version 2.0, enough for stored entries.
const VERSION: u16 = 20;

fn u32_size(n: usize) -> Result<u32, ZipError> {
    u32::try_from(n).map_err(|_| ZipError::TooLarge(n))
}

/// The archive holding `entries` (name, bytes) in order, stored without compression.
pub fn stored(entries: &[(&str, &[u8])]) -> Result<Vec<u8>, ZipError> {
    let count =
        u16::try_from(entries.len()).map_err(|_| ZipError::TooManyEntries(entries.len()))?;
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (name, bytes) in entries {
        let offset = u32_size(out.len())?;
        let size = u32_size(bytes.len())?;
        let name_len = u16::try_from(name.len()).map_err(|_| ZipError::TooLarge(name.len()))?;
        let crc = crc32fast::hash(bytes);
        // Fields shared by the local and central headers, from "version needed" on.
        let mut common = Vec::with_capacity(26);
        for half in [VERSION, 0, 0, 0, DOS_DATE] {
            common.extend_from_slice(&half.to_le_bytes());
        }
        for word in [crc, size, size] {
            common.extend_from_slice(&word.to_le_bytes());
        }
        common.extend_from_slice(&name_len.to_le_bytes());
        common.extend_from_slice(&0u16.to_le_bytes());

        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        out.extend_from_slice(&common);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(bytes);

        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&VERSION.to_le_bytes());
        central.extend_from_slice(&common);
        // Comment length, disk number, internal attributes.
        central.extend_from_slice(&[0; 6]);
        central.extend_from_slice(&0u32.to_le_bytes());
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let central_offset = u32_size(out.len())?;
    let central_size = u32_size(central.len())?;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0; 4]);
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&central_size.to_le_bytes());
    out.extend_from_slice(&central_offset.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    u32_size(out.len())?;
    Ok(out)
}
