//! The one font every figure uses, bundled in the binary: text looks the same on every machine
//! and no figure depends on the system's fonts or fontconfig.

use std::sync::OnceLock;

/// DejaVu Sans (Bitstream Vera licence, in `assets/fonts/LICENSE-DejaVu.txt`).
static DEJAVU_SANS: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// The family name figures ask for.
pub const FAMILY: &str = "sans-serif";

/// Registers the bundled font with the chart renderer, once per process. Returns whether the
/// font is usable (it always is unless the bundled file is damaged, which a test rules out).
pub fn ensure() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FAMILY, plotters::style::FontStyle::Normal, DEJAVU_SANS)
            .is_ok()
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_bundled_font_registers() {
        assert!(super::ensure());
    }
}
