//! Reading files without trusting them to be small: text formats have a size or line-length
//! cap, so a wrong path (a video, a device such as `/dev/zero`) is an error, not an endless
//! read.

use std::io::{BufRead, Read};
use std::path::Path;

use fuzzyvox_core::error::{Error, Result};

/// Longest line a text format may have (1 MiB; real lines are under 200 bytes).
pub(crate) const MAX_LINE_BYTES: u64 = 1 << 20;

/// Largest small text file (a calibration, a pose, intrinsics): 1 MiB.
pub(crate) const MAX_SMALL_FILE_BYTES: u64 = 1 << 20;

/// Reads a whole small text file, refusing one longer than `MAX_SMALL_FILE_BYTES`.
pub(crate) fn read_small(path: &Path) -> Result<Vec<u8>> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_SMALL_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_SMALL_FILE_BYTES {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: 0,
            message: format!(
                "longer than {MAX_SMALL_FILE_BYTES} bytes: not a calibration, pose or intrinsics file"
            ),
        });
    }
    Ok(bytes)
}

/// Reads the next line (with its `\n`) into `line`, at most [`MAX_LINE_BYTES`]; returns the
/// bytes read (0 at the end). A longer line is an error naming `line_number`.
pub(crate) fn read_line(
    reader: &mut impl BufRead,
    line: &mut Vec<u8>,
    path: &Path,
    line_number: usize,
) -> Result<usize> {
    line.clear();
    let read = reader
        .take(MAX_LINE_BYTES + 1)
        .read_until(b'\n', line)
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if read as u64 > MAX_LINE_BYTES {
        return Err(Error::Parse {
            path: path.to_path_buf(),
            line: line_number,
            message: format!("line longer than {MAX_LINE_BYTES} bytes: not a text file?"),
        });
    }
    Ok(read)
}

/// The content lines of a text file, one at a time: trimmed, with blank lines and `#` comments
/// skipped. Lines are read as bytes, not with `read_line`, so that a binary file is a parse
/// error naming its line rather than an I/O error; a line longer than [`MAX_LINE_BYTES`] or not
/// UTF-8 is such an error.
pub(crate) struct ContentLines<'p, R> {
    reader: R,
    path: &'p Path,
    bytes: Vec<u8>,
    line_number: usize,
}

impl<'p, R: BufRead> ContentLines<'p, R> {
    /// Lines of `reader`; errors name `path`.
    pub(crate) fn new(reader: R, path: &'p Path) -> Self {
        Self {
            reader,
            path,
            bytes: Vec::new(),
            line_number: 0,
        }
    }

    /// The next content line with its 1-based number, `None` at the end.
    pub(crate) fn next_line(&mut self) -> Result<Option<(usize, &str)>> {
        loop {
            let next = self.line_number + 1;
            if read_line(&mut self.reader, &mut self.bytes, self.path, next)? == 0 {
                return Ok(None);
            }
            self.line_number = next;
            let line = self.text()?.trim();
            if !(line.is_empty() || line.starts_with('#')) {
                break;
            }
        }
        // Taken again after the loop: a borrow returned from inside it would outlive the next
        // turn's read.
        Ok(Some((self.line_number, self.text()?.trim())))
    }

    /// The line just read, as text.
    fn text(&self) -> Result<&str> {
        std::str::from_utf8(&self.bytes).map_err(|_| Error::Parse {
            path: self.path.to_path_buf(),
            line: self.line_number,
            message: "not UTF-8 text (a binary file?)".into(),
        })
    }
}

/// Reads a whole binary file, which must be a regular file: its size is then known and bounds
/// the allocation, where a device such as `/dev/zero` would never end.
pub(crate) fn read_regular(path: &Path) -> Result<Vec<u8>> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let metadata = std::fs::metadata(path).map_err(io)?;
    if !metadata.is_file() && !metadata.is_dir() {
        return Err(io(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a device or a pipe?)",
        )));
    }
    std::fs::read(path).map_err(io)
}
