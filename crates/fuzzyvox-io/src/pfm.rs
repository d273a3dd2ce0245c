//! Portable float maps (PFM), the format of Middlebury's disparity files: a text header
//! `Pf` (one channel) or `PF` (three), `width height`, a scale whose sign gives the byte order
//! (negative = little endian), one whitespace byte, then `f32` samples with rows stored bottom to
//! top. fuzzyvox reads and writes one-channel maps, top row first in memory.

use std::path::Path;

use fuzzyvox_core::error::{Error, FormatError, Result};
use fuzzyvox_core::file::write_atomic;

/// The largest map accepted (pixels): far above any camera, far below what a corrupt header
/// could claim, so a damaged file never triggers a huge allocation.
pub const MAX_PFM_PIXELS: u64 = 1 << 28;

/// A one-channel float image, row-major with the top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples, row-major, top row first.
    pub data: Vec<f32>,
}

/// Reads a one-channel PFM file.
pub fn read_pfm(path: &Path) -> Result<FloatImage> {
    let bytes = crate::bounded::read_regular(path)?;
    parse_pfm(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason,
    })
}

/// Parses the bytes of a one-channel PFM file.
pub fn parse_pfm(bytes: &[u8]) -> Result<FloatImage, FormatError> {
    let invalid = |m: &str| FormatError::Invalid(m.to_string());
    let mut position = 0usize;
    // Reads one whitespace-delimited header token.
    let mut token = || -> Result<&[u8], FormatError> {
        while bytes.get(position).is_some_and(u8::is_ascii_whitespace) {
            position += 1;
        }
        let start = position;
        while bytes
            .get(position)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            position += 1;
            if position - start > 32 {
                return Err(invalid("PFM header token too long"));
            }
        }
        if start == position {
            return Err(invalid("PFM header is incomplete"));
        }
        bytes
            .get(start..position)
            .ok_or_else(|| invalid("PFM header is incomplete"))
    };
    let magic = token()?;
    match magic {
        b"Pf" => {}
        b"PF" => return Err(invalid("three-channel PFM is not supported, expected `Pf`")),
        _ => return Err(FormatError::BadMagic),
    }
    let mut number = |what: &str| -> Result<String, FormatError> {
        let t = token()?;
        std::str::from_utf8(t)
            .map(str::to_string)
            .map_err(|_| invalid(&format!("PFM {what} is not text")))
    };
    let width: u32 = number("width")?
        .parse()
        .map_err(|_| invalid("PFM width is not a positive integer"))?;
    let height: u32 = number("height")?
        .parse()
        .map_err(|_| invalid("PFM height is not a positive integer"))?;
    let scale: f64 = number("scale")?
        .parse()
        .map_err(|_| invalid("PFM scale is not a number"))?;
    if width == 0 || height == 0 {
        return Err(invalid("PFM image is empty (zero width or height)"));
    }
    let pixels = u64::from(width) * u64::from(height);
    if pixels > MAX_PFM_PIXELS {
        return Err(invalid(&format!(
            "PFM size {width}×{height} exceeds the limit of {MAX_PFM_PIXELS} pixels"
        )));
    }
    if !scale.is_finite() || scale == 0.0 {
        return Err(invalid("PFM scale must be finite and non-zero"));
    }
    // Exactly one whitespace byte separates the header from the samples.
    let body_start = position + 1;
    let declared = pixels * 4;
    let actual = bytes.len().saturating_sub(body_start) as u64;
    if actual != declared || bytes.get(position).is_none_or(|b| !b.is_ascii_whitespace()) {
        return Err(FormatError::Length { declared, actual });
    }
    let little_endian = scale < 0.0;
    let (words, _) = bytes.get(body_start..).unwrap_or_default().as_chunks::<4>();
    let samples: Vec<f32> = words
        .iter()
        .map(|&b| {
            if little_endian {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            }
        })
        .collect();
    // Flip: the file stores the bottom row first.
    let w = width as usize;
    let data = samples.chunks_exact(w).rev().flatten().copied().collect();
    Ok(FloatImage {
        width,
        height,
        data,
    })
}

/// Encodes a one-channel image (top row first in `data`) as little-endian PFM bytes.
pub fn encode_pfm(width: u32, height: u32, data: &[f32]) -> Result<Vec<u8>> {
    let pixels = width as usize * height as usize;
    if pixels == 0 {
        return Err(Error::Empty("PFM image"));
    }
    if data.len() != pixels {
        return Err(Error::SizeMismatch {
            what: "PFM samples (width × height)",
            expected: pixels,
            found: data.len(),
        });
    }
    let mut bytes = format!("Pf\n{width} {height}\n-1.0\n").into_bytes();
    bytes.reserve(pixels * 4);
    for row in data.chunks_exact(width as usize).rev() {
        for v in row {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    Ok(bytes)
}

/// Writes a one-channel image as little-endian PFM, atomically.
pub fn write_pfm(path: &Path, width: u32, height: u32, data: &[f32]) -> Result<()> {
    write_atomic(path, &encode_pfm(width, height, data)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_values_and_row_order() {
        let data = vec![1.0, 2.0, f32::INFINITY, -4.5, 0.0, 6.25];
        let bytes = encode_pfm(3, 2, &data).unwrap();
        let back = parse_pfm(&bytes).unwrap();
        assert_eq!((back.width, back.height), (3, 2));
        assert_eq!(back.data, data);
        // The bottom row is stored first.
        assert_eq!(
            &bytes[bytes.len() - 12..bytes.len() - 8],
            &1.0f32.to_le_bytes()
        );
    }

    #[test]
    fn big_endian_files_read() {
        let mut bytes = b"Pf\n1 1\n1.0\n".to_vec();
        bytes.extend_from_slice(&2.5f32.to_be_bytes());
        assert_eq!(parse_pfm(&bytes).unwrap().data, vec![2.5]);
    }

    #[test]
    fn damaged_files_are_typed_errors() {
        let good = encode_pfm(2, 2, &[1.0; 4]).unwrap();
        assert!(matches!(
            parse_pfm(&good[..good.len() - 1]),
            Err(FormatError::Length { .. })
        ));
        assert!(matches!(
            parse_pfm(b"P6\n1 1\n255\n"),
            Err(FormatError::BadMagic)
        ));
        assert!(matches!(parse_pfm(b""), Err(FormatError::Invalid(_))));
        assert!(matches!(
            parse_pfm(b"Pf\nx 1\n-1\n"),
            Err(FormatError::Invalid(_))
        ));
        assert!(matches!(
            parse_pfm(b"Pf\n0 1\n-1\n"),
            Err(FormatError::Invalid(_))
        ));
        assert!(matches!(
            parse_pfm(b"Pf\n1 1\n0\n0000"),
            Err(FormatError::Invalid(_))
        ));
        assert!(matches!(
            parse_pfm(b"Pf\n4000000000 4000000000\n-1\n"),
            Err(FormatError::Invalid(_))
        ));
        assert!(matches!(
            parse_pfm(b"PF\n1 1\n-1\n"),
            Err(FormatError::Invalid(_))
        ));
        assert!(encode_pfm(2, 2, &[1.0; 3]).is_err());
    }
}
