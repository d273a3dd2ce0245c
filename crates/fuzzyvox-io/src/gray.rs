//! Camera images as grey levels: PNG (8 or 16 bits, grey or colour, with or without alpha) and
//! JPEG, told apart by content. Colour becomes luminance (`GrayImage::from_rgb8`).

use std::path::Path;

use fuzzyvox_core::error::Result;
use fuzzyvox_core::image::GrayImage;

use crate::image_source::ImageSource;

/// Reads a PNG or JPEG image file as a [`GrayImage`]. A missing file is [`Error::Io`]; any other
/// format, or a damaged file, is [`Error::Parse`] naming the file.
///
/// [`Error::Io`]: fuzzyvox_core::error::Error::Io
/// [`Error::Parse`]: fuzzyvox_core::error::Error::Parse
pub fn read_gray_image(path: &Path) -> Result<GrayImage> {
    gray_from(ImageSource::File(path))
}

/// Decodes a PNG or JPEG image held in memory; see [`read_gray_image`]. Errors name the path
/// `<memory>`.
pub fn decode_gray_image(bytes: &[u8]) -> Result<GrayImage> {
    gray_from(ImageSource::Memory(bytes))
}

fn gray_from(source: ImageSource<'_>) -> Result<GrayImage> {
    let rgb = source
        .decode("not a readable image (PNG or JPEG)")?
        .to_rgb8();
    let (width, height) = rgb.dimensions();
    GrayImage::from_rgb8(width, height, rgb.as_raw())
}
