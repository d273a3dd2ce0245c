//! The text header OctoMap writes before a tree, shared by `.bt` and `.ot` files:
//!
//! ```text
//! # Octomap OcTree binary file          (or `# Octomap OcTree file`: the first line names the format)
//! # ...comments...
//! id OcTree                             the tree type
//! size 532566                           number of nodes, the root included
//! res 0.08                              voxel edge length (m)
//! data                                  the tree follows the end of this line
//! ```

use fuzzyvox_core::error::FormatError;

/// What the header says, and where the tree data begins.
pub(super) struct Header {
    /// The tree type (`OcTree`, `ColorOcTree`, ...).
    pub(super) id: String,
    /// Declared number of nodes.
    pub(super) size: u64,
    /// Voxel edge length (m), finite and positive.
    pub(super) resolution: f64,
    /// Offset of the first byte of tree data.
    pub(super) data_start: usize,
}

/// Parses the text header the way OctoMap does: whitespace-separated tokens, `#` comments to the
/// end of the line, keyword-value pairs, until a `data` token whose line ends the header.
/// `first_line` is the start the file's first line must have; `format` names the format in
/// the error when it does not.
pub(super) fn parse_header(
    bytes: &[u8],
    first_line: &str,
    format: &str,
) -> Result<Header, FormatError> {
    let invalid = |m: String| FormatError::Invalid(m);
    let first_end = bytes
        .iter()
        .position(|&b| b == b'\n')
        .unwrap_or(bytes.len());
    if !bytes.starts_with(first_line.as_bytes()) {
        return Err(invalid(format!(
            "not {format}: the first line must be `{first_line}`"
        )));
    }
    let mut tokens = Tokens {
        bytes,
        position: first_end,
    };
    let (mut id, mut size, mut resolution) = (None, None, None);
    loop {
        let token = tokens
            .next()
            .ok_or_else(|| invalid("the header ends without a `data` line".into()))?;
        match token {
            b"data" => {
                tokens.skip_line();
                break;
            }
            b"id" => id = Some(tokens.value("id")?),
            b"size" => size = Some(tokens.value("size")?),
            b"res" => resolution = Some(tokens.value("res")?),
            t if t.starts_with(b"#") => tokens.skip_line(),
            t if t.iter().all(u8::is_ascii_graphic) => tokens.skip_line(),
            _ => return Err(invalid("binary bytes in the header before `data`".into())),
        }
    }
    let id = id.ok_or_else(|| invalid("the header has no `id`".into()))?;
    let size = size.ok_or_else(|| invalid("the header has no `size`".into()))?;
    let size: u64 = size
        .parse()
        .map_err(|_| invalid(format!("header size `{size}` is not a node count")))?;
    let resolution = resolution.ok_or_else(|| invalid("the header has no `res`".into()))?;
    let resolution = resolution
        .parse::<f64>()
        .ok()
        .filter(|r| r.is_finite() && *r > 0.0)
        .ok_or_else(|| {
            invalid(format!(
                "header res `{resolution}` is not a positive length"
            ))
        })?;
    Ok(Header {
        id,
        size,
        resolution,
        data_start: tokens.position,
    })
}

/// Whitespace-separated tokens of the header.
struct Tokens<'a> {
    bytes: &'a [u8],
    position: usize,
}

impl<'a> Tokens<'a> {
    fn rest(&self) -> &'a [u8] {
        self.bytes.get(self.position..).unwrap_or_default()
    }

    /// The next token, or `None` at the end of the bytes.
    fn next(&mut self) -> Option<&'a [u8]> {
        let rest = self.rest();
        let start = rest.iter().position(|b| !b.is_ascii_whitespace())?;
        let len = rest
            .iter()
            .skip(start)
            .position(u8::is_ascii_whitespace)
            .unwrap_or(rest.len() - start);
        self.position += start + len;
        rest.get(start..start + len)
    }

    /// The token after a keyword, as text.
    fn value(&mut self, keyword: &str) -> Result<String, FormatError> {
        let token = self.next().unwrap_or_default();
        match std::str::from_utf8(token) {
            Ok(text) if !text.is_empty() => Ok(text.to_owned()),
            _ => Err(FormatError::Invalid(format!(
                "header keyword `{keyword}` has no readable value"
            ))),
        }
    }

    /// Moves past the next newline (or to the end).
    fn skip_line(&mut self) {
        let rest = self.rest();
        self.position += rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(rest.len(), |i| i + 1);
    }
}

/// Checks a header's declared node count against the `most` nodes `data_len` bytes of tree data
/// can hold (before decoding anything), runs `decode` with the declared count as its limit, and
/// checks that it read exactly that many nodes. Returns the node count.
pub(super) fn decode_declared(
    declared: u64,
    data_len: usize,
    most: usize,
    decode: impl FnOnce(usize) -> Result<usize, FormatError>,
) -> Result<usize, FormatError> {
    if declared > most as u64 {
        return Err(FormatError::Invalid(format!(
            "header declares {declared} nodes, but {data_len} bytes of tree data hold at most \
             {most}"
        )));
    }
    let declared = usize::try_from(declared).unwrap_or(usize::MAX);
    let read = decode(declared)?;
    if read != declared {
        return Err(FormatError::Invalid(format!(
            "header declares {declared} nodes, the tree data holds {read}"
        )));
    }
    Ok(read)
}
