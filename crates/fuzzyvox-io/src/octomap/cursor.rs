//! A bounds-checked little-endian reader over a byte slice, for OctoMap's binary formats.
//!
//! Every read checks the remaining length first and reports a truncation as a
//! [`FormatError`], so damaged files can never make a reader index out of bounds.

use fuzzyvox_core::error::FormatError;

/// Reads little-endian values from a byte slice, front to back.
pub(super) struct Cursor<'a> {
    bytes: &'a [u8],
    position: usize,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `bytes`.
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, position: 0 }
    }

    /// Bytes not read yet.
    pub(super) fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.position)
    }

    /// Offset of the next byte to read.
    pub(super) fn position(&self) -> usize {
        self.position
    }

    /// The next `n` bytes; `what` names them in the truncation error.
    pub(super) fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], FormatError> {
        let rest = self.bytes.get(self.position..).unwrap_or_default();
        let (head, _) = rest.split_at_checked(n).ok_or_else(|| {
            FormatError::Invalid(format!(
                "truncated: {what} at byte {} needs {n} bytes, {} left",
                self.position,
                rest.len()
            ))
        })?;
        self.position += n;
        Ok(head)
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], FormatError> {
        let slice = self.take(N, what)?;
        // `take` returned exactly N bytes, so the conversion cannot fail; map it anyway rather
        // than unwrap.
        <[u8; N]>::try_from(slice)
            .map_err(|_| FormatError::Invalid(format!("internal: short read of {what}")))
    }

    /// A little-endian `u32`.
    pub(super) fn u32(&mut self, what: &str) -> Result<u32, FormatError> {
        self.array(what).map(u32::from_le_bytes)
    }

    /// A little-endian `i32`.
    pub(super) fn i32(&mut self, what: &str) -> Result<i32, FormatError> {
        self.array(what).map(i32::from_le_bytes)
    }

    /// A little-endian IEEE-754 `f64`.
    pub(super) fn f64(&mut self, what: &str) -> Result<f64, FormatError> {
        self.array(what).map(f64::from_le_bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_reports_truncation() {
        let bytes = [1, 0, 0, 0, 0xff, 0xff, 0xff, 0xff, 9];
        let mut c = Cursor::new(&bytes);
        assert_eq!(c.u32("a").unwrap(), 1);
        assert_eq!(c.i32("b").unwrap(), -1);
        assert_eq!(c.remaining(), 1);
        let error = c.f64("c").unwrap_err();
        assert!(
            error.to_string().contains("truncated: c at byte 8"),
            "{error}"
        );
        // A failed read consumes nothing.
        assert_eq!(c.position(), 8);
        assert!(c.take(usize::MAX, "huge").is_err());
        assert_eq!(c.take(1, "last").unwrap(), &[9]);
    }
}
