//! The look of tandem's figures: the one bundled font and the one palette.
//!
//! `tandem plot` (the command line) and `cargo xtask study` (the paper's Fig. 5, §III) draw
//! with plotters' pure-Rust backends. Both take their text font and their colours from here,
//! so a figure needs nothing but a Rust toolchain (no system font, fontconfig or freetype)
//! and the two programs colour the same things alike: robot 1 low-confidence blue, robot 2
//! low-confidence red, neither gray, as in the paper's example schedules.
//!
//! ```
//! use plotters::prelude::*;
//!
//! tandem_plot::register_font()?;
//! let mut svg = String::new();
//! {
//!     let root = SVGBackend::with_string(&mut svg, (200, 40)).into_drawing_area();
//!     root.fill(&WHITE)?;
//!     let [robot1, _] = tandem_plot::ROBOT_LC;
//!     root.draw(&Text::new("robot 1", (5, 5), (tandem_plot::FONT_FAMILY, 20).into_font().color(&robot1)))?;
//!     root.present()?;
//! }
//! assert!(svg.contains("robot 1") && svg.contains("#4285F4"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::sync::OnceLock;

use plotters::style::{FontStyle, RGBColor, register_font as plotters_register_font};

/// DejaVu Sans 2.37 (Debian `fonts-dejavu-core` 2.37-6, unmodified; Bitstream Vera licence,
/// see `assets/README.md`), the text font of every figure.
pub static FONT_TTF: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Family name [`register_font`] registers [`FONT_TTF`] under. SVG files name this generic
/// family, so viewers use their own sans-serif face.
pub const FONT_FAMILY: &str = "sans-serif";

/// Dark blue of mean lines and their ±1 std bands (the paper's Fig. 5 "dark blue line") and
/// of the model's mean in `tandem plot`.
pub const MEAN: RGBColor = RGBColor(16, 42, 120);

/// Low-confidence stretches of robot 1 (blue) and robot 2 (red), as in the paper's example
/// schedules (Fig. 5); index by robot (0 or 1). The first two of [`ROBOT_LC_N`].
pub const ROBOT_LC: [RGBColor; 2] = [ROBOT_LC_N[0], ROBOT_LC_N[1]];

/// Low-confidence stretches of robots 1 to 8 (then again from robot 9): robot 1 blue and robot 2 red as in
/// [`ROBOT_LC`], then orange, brown, pink, olive, cyan and gold; index by robot (0-based),
/// modulo 8 for robots 9 to 16 (`tandem_realtime` runs up to 16: the figures repeat the
/// colours and name the robots in their labels).
pub const ROBOT_LC_N: [RGBColor; 8] = [
    RGBColor(66, 133, 244),
    RGBColor(214, 39, 40),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(230, 171, 2),
];

/// Neither robot low-confidence, or a robot running high-confidence (gray in Fig. 5).
pub const NEITHER_LC: RGBColor = RGBColor(185, 185, 185);

/// Both robots low-confidence at once: what a valid schedule never has (Eq. 20, constraint
/// 3), drawn in a loud colour of its own.
pub const BOTH_LC: RGBColor = RGBColor(148, 0, 211);

/// The ground-truth line of Fig. 5 (the paper's "gray dotted line").
pub const GROUND_TRUTH: RGBColor = RGBColor(110, 110, 110);

/// The high-confidence map of `tandem plot` (green).
pub const HIGH_CONFIDENCE: RGBColor = RGBColor(44, 160, 44);

/// The operator's own quantities (the busy share of `cargo xtask capacity`): a dark teal
/// that no robot has, so a reader does not take the operator's line for robot 2's.
pub const OPERATOR: RGBColor = RGBColor(0, 121, 107);

/// What can go wrong in `tandem-plot`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// plotters could not parse the bundled font.
    #[error("the bundled font tandem-plot/assets/DejaVuSans.ttf could not be parsed")]
    Font,
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Registers [`FONT_TTF`] with plotters as [`FONT_FAMILY`] (normal style); call it before
/// drawing text. Registers once per process; later calls return the first call's outcome.
///
/// # Errors
/// [`Error::Font`] if plotters cannot parse the font.
pub fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED
        .get_or_init(|| plotters_register_font(FONT_FAMILY, FontStyle::Normal, FONT_TTF).is_ok());
    if ok { Ok(()) } else { Err(Error::Font) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_font_is_a_truetype_file_and_registers() {
        // TrueType files start with the sfnt version 0x00010000.
        assert_eq!(&FONT_TTF[..4], &[0, 1, 0, 0]);
        assert!(FONT_TTF.len() > 700_000);
        register_font().unwrap();
        register_font().unwrap();
    }

    #[test]
    fn the_palette_tells_the_robots_and_the_violation_apart() {
        assert_eq!(ROBOT_LC, [ROBOT_LC_N[0], ROBOT_LC_N[1]]);
        let mut all = vec![
            MEAN,
            NEITHER_LC,
            BOTH_LC,
            GROUND_TRUTH,
            HIGH_CONFIDENCE,
            OPERATOR,
        ];
        all.extend(ROBOT_LC_N);
        for (i, a) in all.iter().enumerate() {
            for b in &all[..i] {
                assert_ne!((a.0, a.1, a.2), (b.0, b.1, b.2));
            }
        }
    }
}
