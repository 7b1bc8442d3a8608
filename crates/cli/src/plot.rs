//! SVG plots with plotters' SVG backend (no system fonts needed).

use anyhow::{Result, anyhow};
use plotters::prelude::*;
use std::path::Path;

/// A named polyline; a point with a non-finite coordinate breaks the line (nothing is drawn
/// across it).
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBColor,
    /// Dashed style (drawn as points when true).
    pub dashed: bool,
}

/// Scatter markers for observed cuts.
pub struct Markers {
    /// Stable cuts (drawn as circles).
    pub stable: Vec<(f64, f64)>,
    /// Unstable cuts (drawn as crosses).
    pub unstable: Vec<(f64, f64)>,
}

fn finite_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo < hi).then_some((lo, hi))
}

/// Line chart of several series plus optional cut markers, written atomically to `path`.
pub fn line_chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    markers: Option<&Markers>,
) -> Result<()> {
    let svg = line_chart_svg(title, x_label, y_label, series, markers)?;
    crate::output::write_atomic(path, svg.as_bytes())
}

/// The SVG text of [`line_chart`].
pub fn line_chart_svg(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    markers: Option<&Markers>,
) -> Result<String> {
    stacked_line_charts_svg(&[Panel {
        title,
        x_label,
        y_label,
        series,
        markers,
    }])
}

/// One chart of [`stacked_line_charts_svg`].
pub struct Panel<'a> {
    /// Caption.
    pub title: &'a str,
    /// X axis label.
    pub x_label: &'a str,
    /// Y axis label.
    pub y_label: &'a str,
    /// The lines.
    pub series: &'a [Series],
    /// Cut markers.
    pub markers: Option<&'a Markers>,
}

/// Line charts stacked vertically (900 x 560 pixels each) on one x range, that of all panels'
/// points; each y axis from min(0, 1.1 y_min) to 1.1 y_max of its panel.
pub fn stacked_line_charts_svg(panels: &[Panel]) -> Result<String> {
    let points = |p: &Panel| -> Vec<(f64, f64)> {
        p.series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .chain(
                p.markers
                    .into_iter()
                    .flat_map(|m| m.stable.iter().chain(&m.unstable).copied()),
            )
            .collect()
    };
    let (x0, x1) = finite_range(panels.iter().flat_map(&points).map(|p| p.0))
        .ok_or_else(|| anyhow!("nothing to plot"))?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560 * panels.len().max(1) as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        for (area, panel) in root.split_evenly((panels.len(), 1)).iter().zip(panels) {
            let pts = points(panel);
            let (y0, y1) = finite_range(pts.iter().map(|p| p.1)).unwrap_or((0.0, 1.0));
            draw_panel(area, panel, (x0, x1), ((1.1 * y0).min(0.0), y1 * 1.1))?;
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

/// One line chart on `area` with the axis ranges `x` and `y`.
fn draw_panel(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    panel: &Panel,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(|e| anyhow!("{e}"))?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label)
        .y_desc(panel.y_label)
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    for s in panel.series {
        let color = s.color;
        let finite = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(finite).collect();
        if s.dashed {
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 1, color.filled())))
                .map_err(|e| anyhow!("{e}"))?
                .label(s.label.clone())
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, color.filled()));
        } else {
            let pieces = s.points.split(|p| !finite(p)).filter(|r| !r.is_empty());
            chart
                .draw_series(pieces.map(|r| PathElement::new(r.to_vec(), color.stroke_width(2))))
                .map_err(|e| anyhow!("{e}"))?
                .label(s.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
    }
    if let Some(m) = panel.markers {
        chart
            .draw_series(
                m.stable
                    .iter()
                    .map(|&p| Circle::new(p, 5, BLACK.stroke_width(2))),
            )
            .map_err(|e| anyhow!("{e}"))?
            .label("stable cut")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLACK.stroke_width(2)));
        chart
            .draw_series(
                m.unstable
                    .iter()
                    .map(|&p| Cross::new(p, 6, RED.stroke_width(2))),
            )
            .map_err(|e| anyhow!("{e}"))?
            .label("chatter")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, RED.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| anyhow!("{e}"))?;
    Ok(())
}

/// A panel of [`error_bar_panels`]: y label and points (x, mean, standard deviation).
pub struct ErrorBarPanel {
    /// Y axis label.
    pub y_label: String,
    /// (x, mean, standard deviation) per point.
    pub points: Vec<(f64, f64, f64)>,
}

/// Panels stacked vertically, each a line through the means with mean +- one standard
/// deviation as error bars, sharing the x axis; written atomically to `path`.
pub fn error_bar_panels(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[ErrorBarPanel],
) -> Result<()> {
    let xs = panels.iter().flat_map(|p| p.points.iter().map(|q| q.0));
    let (x0, x1) = finite_range(xs).ok_or_else(|| anyhow!("nothing to plot"))?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 300 * panels.len().max(1) as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let root = root
            .titled(title, ("sans-serif", 20))
            .map_err(|e| anyhow!("{e}"))?;
        for (area, panel) in root.split_evenly((panels.len(), 1)).iter().zip(panels) {
            let pts: Vec<(f64, f64, f64)> = panel
                .points
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
                .collect();
            let (y0, y1) = finite_range(pts.iter().flat_map(|p| [p.1 - p.2, p.1 + p.2])).map_or(
                (0.0, 1.0),
                |(a, b)| {
                    let pad = 0.05 * (b - a);
                    (a - pad, b + pad)
                },
            );
            let mut chart = ChartBuilder::on(area)
                .margin(15)
                .x_label_area_size(40)
                .y_label_area_size(80)
                .build_cartesian_2d(x0 - 0.5..x1 + 0.5, y0..y1)
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(panel.y_label.as_str())
                .draw()
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.0, p.1)),
                    BLUE.stroke_width(2),
                ))
                .map_err(|e| anyhow!("{e}"))?;
            // a bar from m - s to m + s with a dot at the mean
            chart
                .draw_series(
                    pts.iter()
                        .map(|&(x, m, s)| PathElement::new(vec![(x, m - s), (x, m + s)], BLACK)),
                )
                .map_err(|e| anyhow!("{e}"))?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|&(x, m, _)| Circle::new((x, m), 3, BLACK.filled())),
                )
                .map_err(|e| anyhow!("{e}"))?;
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    crate::output::write_atomic(path, svg.as_bytes())
}
