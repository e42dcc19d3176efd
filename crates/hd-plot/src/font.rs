//! The embedded font. Plotters' `ab_glyph` text support has no fonts of its own, so DejaVu
//! Sans (licence in `assets/DejaVu-LICENSE.txt`) is compiled into the crate and registered
//! once per process. No system font is ever read.

use std::sync::OnceLock;

use plotters::style::{FontStyle, register_font};

/// DejaVu Sans, regular.
static DEJAVU_SANS: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The family name every text style of the crate uses.
pub(crate) const FAMILY: &str = "sans-serif";

/// Outcome of the one registration attempt.
static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();

/// Register the embedded font under the generic family names (first call only) and report
/// whether that worked.
pub(crate) fn ensure_registered() -> Result<(), String> {
    REGISTERED
        .get_or_init(|| {
            for family in [FAMILY, "serif", "monospace"] {
                register_font(family, FontStyle::Normal, DEJAVU_SANS)
                    .map_err(|_| "the embedded DejaVu Sans font could not be parsed".to_string())?;
            }
            Ok(())
        })
        .clone()
}
