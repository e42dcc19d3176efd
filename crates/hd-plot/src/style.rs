//! Shared looks: text sizes, the line palette, canvas sizes.

use plotters::style::{FontDesc, FontFamily, FontStyle, RGBColor, TextStyle};

/// Figure title size [px].
pub(crate) const TITLE_PX: f64 = 26.0;
/// Panel caption size [px].
pub(crate) const CAPTION_PX: f64 = 19.0;
/// Axis description size [px].
pub(crate) const AXIS_LABEL_PX: f64 = 18.0;
/// Tick label size [px].
pub(crate) const TICK_PX: f64 = 15.0;
/// Legend text size [px].
pub(crate) const LEGEND_PX: f64 = 15.0;

/// Canvas of a one-panel figure [px].
pub(crate) const SINGLE: (u32, u32) = (1000, 650);
/// Canvas of a figure with two panels side by side [px].
pub(crate) const SIDE_BY_SIDE: (u32, u32) = (1500, 650);
/// Canvas of a figure with a main panel over a smaller one [px].
pub(crate) const STACKED: (u32, u32) = (1000, 850);

/// The embedded sans-serif font at `px` pixels.
pub(crate) fn text(px: f64) -> TextStyle<'static> {
    FontDesc::new(FontFamily::SansSerif, px, FontStyle::Normal).into()
}

/// Line colours, distinguishable with common colour-vision deficiencies
/// (the Okabe–Ito set, reordered so the first ones contrast most on white).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(230, 159, 0),   // orange
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
    RGBColor(200, 180, 0),   // darkened yellow
];

/// Colour of the `i`-th series (cycling after eight).
pub(crate) fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}
