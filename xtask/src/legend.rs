//! The legend and mesh pieces every figure of the xtask shares (capacity, the continuous study,
//! Fig. 5): macros, since plotters' chart and element types differ per backend and coordinate
//! system.

/// A dashed line's legend mark in `colour` (a closure for `SeriesAnno::legend`).
macro_rules! dashed_mark {
    ($colour:expr) => {{
        let colour: RGBColor = $colour;
        move |(x, y)| {
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (8, 0)], colour.stroke_width(3))
                + PathElement::new(vec![(14, 0), (22, 0)], colour.stroke_width(3))
        }
    }};
}

/// Draws `chart`'s series labels at `position` in the figures' legend box (white, framed,
/// `font_px` labels), mapping a drawing error with `err`.
macro_rules! draw_legend {
    ($chart:expr, $position:expr, $font_px:expr, $err:expr) => {
        $chart
            .configure_series_labels()
            .position($position)
            .margin(12)
            .legend_area_size(30)
            .label_font((FONT_FAMILY, $font_px))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.5))
            .draw()
            .map_err($err)
    };
}

/// The figures' mesh style on a `configure_mesh()` chain: 18 px labels, 20 px axis
/// descriptions, no light grid lines, faint bold ones.
macro_rules! mesh_style {
    ($mesh:expr) => {
        $mesh
            .label_style((FONT_FAMILY, 18))
            .axis_desc_style((FONT_FAMILY, 20))
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.12))
    };
}

/// A share axis's label (percent, 0–100): blank above 100, where the axis leaves room for
/// the legend.
pub(crate) fn percent_label(v: &f64) -> String {
    if *v <= 100.0 {
        format!("{v:.0}")
    } else {
        String::new()
    }
}
