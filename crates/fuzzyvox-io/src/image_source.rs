//! Image files read from disk or from memory, their format told by content: what the grey-image
//! and depth-image readers share.

use std::io::{BufRead, Seek};
use std::path::Path;

use fuzzyvox_core::error::{Error, Result};
use image::{DynamicImage, ImageReader};

/// Where an image's bytes come from.
#[derive(Clone, Copy)]
pub(crate) enum ImageSource<'a> {
    /// A file; a missing one is [`Error::Io`].
    File(&'a Path),
    /// Bytes in memory; errors name the path `<memory>`.
    Memory(&'a [u8]),
}

impl<'a> ImageSource<'a> {
    /// The path errors name: the file's, or `<memory>`.
    pub(crate) fn path(&self) -> &'a Path {
        match *self {
            Self::File(path) => path,
            Self::Memory(_) => Path::new("<memory>"),
        }
    }

    /// Decodes the image in whatever format its content shows. A file that cannot be opened or
    /// read is [`Error::Io`]; bytes that are no readable image are [`Error::Parse`] whose message
    /// is `unreadable`, a colon and the decoder's reason.
    pub(crate) fn decode(&self, unreadable: &str) -> Result<DynamicImage> {
        match *self {
            Self::File(path) => {
                let reader = ImageReader::open(path).map_err(|source| Error::Io {
                    path: path.to_path_buf(),
                    source,
                })?;
                decode_from(reader, path, unreadable)
            }
            Self::Memory(bytes) => decode_from(
                ImageReader::new(std::io::Cursor::new(bytes)),
                self.path(),
                unreadable,
            ),
        }
    }
}

fn decode_from<R: BufRead + Seek>(
    reader: ImageReader<R>,
    path: &Path,
    unreadable: &str,
) -> Result<DynamicImage> {
    reader
        .with_guessed_format()
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?
        .decode()
        .map_err(|e| Error::Parse {
            path: path.to_path_buf(),
            line: 0,
            message: format!("{unreadable}: {e}"),
        })
}
