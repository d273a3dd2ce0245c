//! Camera images as grey levels: PNG (8 or 16 bits, grey or colour, with or without alpha) and
//! JPEG, told apart by content. Colour becomes luminance (`GrayImage::from_rgb8`).

use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use fuzzyvox_core::image::GrayImage;

/// Reads a PNG or JPEG image file as a [`GrayImage`]. A missing file is [`Error::Io`]; any other
/// format, or a damaged file, is [`Error::Parse`] naming the file.
pub fn read_gray_image(path: &Path) -> Result<GrayImage> {
    let reader = image::ImageReader::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    gray_from(reader, path)
}

/// Decodes a PNG or JPEG image held in memory; see [`read_gray_image`]. Errors name the path
/// `<memory>`.
pub fn decode_gray_image(bytes: &[u8]) -> Result<GrayImage> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes));
    gray_from(reader, Path::new("<memory>"))
}

fn gray_from<R: std::io::BufRead + std::io::Seek>(
    reader: image::ImageReader<R>,
    path: &Path,
) -> Result<GrayImage> {
    let decoded = reader
        .with_guessed_format()
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?
        .decode()
        .map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: 0,
            message: format!("not a readable image (PNG or JPEG): {e}"),
        })?;
    let rgb = decoded.to_rgb8();
    let (width, height) = rgb.dimensions();
    GrayImage::from_rgb8(width, height, rgb.as_raw())
}
