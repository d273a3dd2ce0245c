//! The container shared by every native map file: a fixed header, a postcard body, a CRC32.
//!
//! Layout (little endian):
//!
//! | bytes | field |
//! |---|---|
//! | 0..8 | magic `FUZZYVOX` |
//! | 8..10 | format version (5; 1 to 4 are still read) |
//! | 10 | map kind (1 fuzzy, 2 log-odds, 3 alpha-cut) |
//! | 11 | operator family code (255: none) |
//! | 12..20 | operator parameter (f64; 0 when the family has none) |
//! | 20..28 | resolution in metres (f64) |
//! | 28..36 | body length in bytes (u64) |
//! | 36..40 | CRC32 of bytes 0..36 followed by the body |
//! | 40.. | body (postcard) |

use std::io::Read;
use std::path::Path;

use serde::Serialize;

use crate::error::{Error, FormatError, Result};
use crate::map::MapKind;
use crate::ops::Family;

/// The first eight bytes of every native map file.
pub const MAGIC: &[u8; 8] = b"FUZZYVOX";
const VERSION: u16 = 5;
/// The oldest version still read. Version 2 added the evidence model's kind and free reach to
/// fuzzy maps' settings; a version 1 fuzzy map was built with the paper's model and loads as
/// such. Version 3 stores a fuzzy map's memberships as levels of its operator's generator
/// (exact accumulation, `map::Accumulator`); a version 1 or 2 fuzzy map's `f32` memberships are
/// converted to the nearest levels as it loads. Log-odds and alpha-cut bodies are the same in
/// versions 1 to 3. Version 4 stores each block's distinct values once and each cell's index
/// among them in the fewest bits (`stored_blocks::PackedStoredBlock`) instead of 512 cells.
/// Version 5 adds the evidence model's end-point share to fuzzy maps' settings (a version 4
/// fuzzy map loads with end points unweighed); other bodies are as in version 4.
const OLDEST_VERSION: u16 = 1;
const HEADER_LEN: usize = 40;
const NO_OPERATOR: u8 = 255;

/// `bytes` (a whole map file) relabelled as format version `version`, checksum fixed: how
/// tests make files of older versions.
#[cfg(test)]
pub(crate) fn with_version(mut bytes: Vec<u8>, version: u16) -> Vec<u8> {
    bytes[8..10].copy_from_slice(&version.to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes[..36]);
    crc.update(&bytes[40..]);
    let sum = crc.finalize().to_le_bytes();
    bytes[36..40].copy_from_slice(&sum);
    bytes
}

/// The kind's code in a file header.
fn code_of(kind: MapKind) -> u8 {
    match kind {
        MapKind::Fuzzy => 1,
        MapKind::LogOdds => 2,
        MapKind::AlphaCut => 3,
    }
}

/// The kind a file header's code names.
fn kind_of_code(code: u8) -> Option<MapKind> {
    match code {
        1 => Some(MapKind::Fuzzy),
        2 => Some(MapKind::LogOdds),
        3 => Some(MapKind::AlphaCut),
        _ => None,
    }
}

/// The fixed header of a map file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapHeader {
    /// Format version.
    pub version: u16,
    /// Map kind.
    pub kind: MapKind,
    /// Aggregation operator, for maps that have one.
    pub operator: Option<Family>,
    /// Voxel size in metres.
    pub resolution: f64,
    /// Body length in bytes.
    pub body_len: u64,
}

/// Reads and checks a map file's header and checksum without decoding the body.
pub fn read_header(path: &Path) -> Result<MapHeader> {
    let bytes = read_file(path)?;
    split(&bytes)
        .map(|(header, _)| header)
        .map_err(|reason| Error::Format {
            path: path.to_path_buf(),
            reason,
        })
}

/// Reads a whole map file once and checks its header, length and checksum; returns the header
/// and the file's bytes for the kind's decoder.
pub fn read_checked(path: &Path) -> Result<(MapHeader, Vec<u8>)> {
    let bytes = read_file(path)?;
    let (header, _) = split(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason,
    })?;
    Ok((header, bytes))
}

/// Serialises a whole file: header and postcard body.
pub(crate) fn encode<T: Serialize>(
    kind: MapKind,
    operator: Option<Family>,
    resolution: f64,
    body: &T,
) -> Vec<u8> {
    // Encoding plain data into a Vec cannot fail.
    let body = postcard::to_stdvec(body).unwrap_or_default();
    let (code, parameter) = operator.map_or((NO_OPERATOR, 0.0), family_code);
    let mut bytes = Vec::with_capacity(HEADER_LEN + body.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&VERSION.to_le_bytes());
    bytes.push(code_of(kind));
    bytes.push(code);
    bytes.extend_from_slice(&parameter.to_le_bytes());
    bytes.extend_from_slice(&resolution.to_le_bytes());
    bytes.extend_from_slice(&(body.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&bytes);
    crc.update(&body);
    bytes.extend_from_slice(&crc.finalize().to_le_bytes());
    bytes.extend_from_slice(&body);
    bytes
}

/// Checks magic, version, declared length and checksum; returns the header and the body.
pub(crate) fn split(bytes: &[u8]) -> Result<(MapHeader, &[u8]), FormatError> {
    if !bytes.starts_with(MAGIC) {
        return Err(FormatError::BadMagic);
    }
    let Some((header, body)) = bytes.split_first_chunk::<HEADER_LEN>() else {
        return Err(FormatError::Length {
            declared: 0,
            actual: 0,
        });
    };
    let version = u16::from_le_bytes(field(header, 8));
    if !(OLDEST_VERSION..=VERSION).contains(&version) {
        return Err(FormatError::UnsupportedVersion(version));
    }
    let body_len = u64::from_le_bytes(field(header, 28));
    let actual = body.len() as u64;
    if body_len != actual {
        return Err(FormatError::Length {
            declared: body_len,
            actual,
        });
    }
    let stored = u32::from_le_bytes(field(header, 36));
    let mut crc = crc32fast::Hasher::new();
    crc.update(header.get(..36).unwrap_or_default());
    crc.update(body);
    let computed = crc.finalize();
    if stored != computed {
        return Err(FormatError::Checksum { stored, computed });
    }
    let [kind_code, operator_code] = field(header, 10);
    let kind = kind_of_code(kind_code)
        .ok_or_else(|| FormatError::Invalid(format!("unknown map kind code {kind_code}")))?;
    let parameter = f64::from_le_bytes(field(header, 12));
    let operator = match operator_code {
        NO_OPERATOR => None,
        code => Some(family_from_code(code, parameter)?),
    };
    let resolution = f64::from_le_bytes(field(header, 20));
    Ok((
        MapHeader {
            version,
            kind,
            operator,
            resolution,
            body_len,
        },
        body,
    ))
}

/// `N` header bytes from offset `at` (the offsets used are constants inside the header).
fn field<const N: usize>(header: &[u8; HEADER_LEN], at: usize) -> [u8; N] {
    header
        .get(at..at + N)
        .and_then(|bytes| bytes.try_into().ok())
        .unwrap_or([0; N])
}

/// The file methods every map has, given its `to_bytes` and `decode`: `from_bytes`, an atomic
/// `save` and a checked `load`.
macro_rules! native_file_methods {
    ($map:ty) => {
        impl $map {
            /// Reads a map from the bytes of a native map file, checking the header, the
            /// length, the checksum and every value.
            pub fn from_bytes(bytes: &[u8]) -> crate::error::Result<Self> {
                super::mapfile::from_memory(bytes, Self::decode)
            }

            /// Saves the map atomically (temporary file, sync, rename): a crash never leaves a
            /// half-written map, and a failed save leaves the old file intact.
            pub fn save(&self, path: impl AsRef<std::path::Path>) -> crate::error::Result<()> {
                super::atomic::write_atomic(path.as_ref(), &self.to_bytes())
            }

            /// Loads a map saved by `save`. A damaged, truncated or foreign file is a typed
            /// [`Error::Format`](crate::Error::Format).
            pub fn load(path: impl AsRef<std::path::Path>) -> crate::error::Result<Self> {
                super::mapfile::load_with(path.as_ref(), Self::decode)
            }
        }
    };
}
pub(crate) use native_file_methods;

/// Reads a map file and decodes it with `decode`, naming the file in any error.
pub(crate) fn load_with<T>(
    path: &Path,
    decode: impl FnOnce(&[u8]) -> Result<T, FormatError>,
) -> Result<T> {
    let bytes = read_file(path)?;
    decode(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason,
    })
}

/// Reads a map file header first: a file without the magic, or whose size is not the header's
/// declared length, is refused before its body is read (so a wrong path to a huge file, or a
/// device such as `/dev/zero`, costs 40 bytes). At most the declared length is read even from a
/// stream, and memory grows only with the bytes that actually arrive.
fn read_file(path: &Path) -> Result<Vec<u8>> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::with_capacity(HEADER_LEN);
    (&mut file)
        .take(HEADER_LEN as u64)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    let Ok(header) = <&[u8; HEADER_LEN]>::try_from(bytes.as_slice()) else {
        // Too short: `split` names the problem.
        return Ok(bytes);
    };
    if !header.starts_with(MAGIC) {
        return Ok(bytes);
    }
    let declared = u64::from_le_bytes(field(header, 28));
    let metadata = file.metadata().map_err(io)?;
    if metadata.is_file() {
        let actual = metadata.len().saturating_sub(HEADER_LEN as u64);
        if actual != declared {
            return Err(Error::Format {
                path: path.to_path_buf(),
                reason: FormatError::Length { declared, actual },
            });
        }
    }
    // One byte more than declared, so that a longer stream is a length error, not a long read.
    file.take(declared.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    Ok(bytes)
}

/// Decodes map bytes held in memory.
pub(crate) fn from_memory<T>(
    bytes: &[u8],
    decode: impl FnOnce(&[u8]) -> Result<T, FormatError>,
) -> Result<T> {
    decode(bytes).map_err(|reason| Error::Format {
        path: "<memory>".into(),
        reason,
    })
}

/// Splits a file and checks that it holds a map of `kind`.
pub(crate) fn body_of(bytes: &[u8], kind: MapKind) -> Result<(MapHeader, &[u8]), FormatError> {
    let (header, body) = split(bytes)?;
    if header.kind != kind {
        return Err(FormatError::WrongKind {
            expected: kind.name(),
            found: header.kind.name().into(),
        });
    }
    Ok((header, body))
}

fn family_code(family: Family) -> (u8, f64) {
    let code = match family {
        Family::Minimum => 0,
        Family::Product => 1,
        Family::Lukasiewicz => 2,
        Family::Drastic => 3,
        Family::NilpotentMinimum => 4,
        Family::Hamacher { .. } => 5,
        Family::Einstein => 6,
        Family::Yager { .. } => 7,
        Family::Frank { .. } => 8,
        Family::Dombi { .. } => 9,
        Family::SchweizerSklar { .. } => 10,
        Family::AczelAlsina { .. } => 11,
    };
    (code, family.parameter().unwrap_or(0.0))
}

fn family_from_code(code: u8, p: f64) -> Result<Family, FormatError> {
    let family = match code {
        0 => Family::Minimum,
        1 => Family::Product,
        2 => Family::Lukasiewicz,
        3 => Family::Drastic,
        4 => Family::NilpotentMinimum,
        5 => Family::Hamacher { gamma: p },
        6 => Family::Einstein,
        7 => Family::Yager { p },
        8 => Family::Frank { s: p },
        9 => Family::Dombi { lambda: p },
        10 => Family::SchweizerSklar { p },
        11 => Family::AczelAlsina { p },
        _ => {
            return Err(FormatError::Invalid(format!(
                "unknown operator code {code}"
            )));
        }
    };
    family
        .validate()
        .map_err(|e| FormatError::Invalid(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_family_round_trips_through_its_code() {
        for family in Family::catalogue() {
            let (code, p) = family_code(family);
            assert_eq!(family_from_code(code, p).unwrap(), family);
        }
    }

    #[test]
    fn damage_is_detected() {
        let bytes = encode(
            MapKind::Fuzzy,
            Some(Family::Product),
            0.1,
            &vec![1u32, 2, 3],
        );
        assert!(split(&bytes).is_ok());
        assert_eq!(
            split(b"PK\x03\x04 zip file").unwrap_err(),
            FormatError::BadMagic
        );
        assert!(matches!(
            split(&bytes[..bytes.len() - 1]),
            Err(FormatError::Length { .. })
        ));
        for i in 8..bytes.len() {
            let mut flipped = bytes.clone();
            flipped[i] ^= 0x10;
            assert!(split(&flipped).is_err(), "flip at byte {i} went unnoticed");
        }
    }
}
