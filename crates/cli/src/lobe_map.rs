//! The SVG heat map of `chatter lobes --map-plot`: the dominant multiplier's modulus |mu| over
//! speed x depth (`chatter_jobs::lobes::LobeMap`) with the |mu| = 1 boundary, the quantity the
//! lobes are the unit contour of.

use anyhow::{Result, anyhow, bail};
use chatter_jobs::lobes::LobeMap;
use chatter_stability::boundary::LobePoint;
use plotters::prelude::*;

/// Colour of |mu|: white at 1, shading to blue (stable) down to 0.1 and to red (chatter) up
/// to 10 (log scale, clipped).
fn colour(modulus: f64) -> RGBColor {
    let t = modulus.log10().clamp(-1.0, 1.0);
    let fade = |x: f64| (255.0 * (1.0 - x.abs())) as u8;
    if t < 0.0 {
        RGBColor(fade(t), fade(t), 255)
    } else {
        RGBColor(255, fade(t), fade(t))
    }
}

/// SVG heat map of |mu| (speed across, depth up) with the limiting depths of `lobes` as a
/// black line: blue is stable (|mu| < 1), red chatter, white the boundary.
pub fn heat_map_svg(title: &str, map: &LobeMap, lobes: &[LobePoint]) -> Result<String> {
    let (speeds_rpm, depths_m, grid) = (&map.speeds_rpm[..], &map.depths_m[..], &map.grid);
    let (Some(&s0), Some(&s1)) = (speeds_rpm.first(), speeds_rpm.last()) else {
        bail!("an empty map");
    };
    let d1 = depths_m.last().copied().unwrap_or(1e-3) * 1e3;
    // cell edges halfway between grid points
    let edges = |v: &[f64], i: usize| -> (f64, f64) {
        let lo = if i == 0 {
            v[0]
        } else {
            0.5 * (v[i - 1] + v[i])
        };
        let hi = if i + 1 == v.len() {
            v[i]
        } else {
            0.5 * (v[i] + v[i + 1])
        };
        (lo, hi)
    };
    let depths_mm: Vec<f64> = depths_m.iter().map(|b| b * 1e3).collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(s0..s1, 0.0..d1)
            .map_err(|e| anyhow!("{e}"))?;
        chart
            .configure_mesh()
            .x_desc("spindle speed (rpm)")
            .y_desc("depth of cut (mm)")
            .draw()
            .map_err(|e| anyhow!("{e}"))?;
        let cells = (0..speeds_rpm.len()).flat_map(|i| {
            let (x0, x1) = edges(speeds_rpm, i);
            let depths_mm = &depths_mm;
            (0..depths_mm.len()).map(move |j| {
                let (y0, y1) = edges(depths_mm, j);
                let y0 = if j == 0 { 0.0 } else { y0 };
                Rectangle::new([(x0, y0), (x1, y1)], colour(grid[i][j]).filled())
            })
        });
        chart.draw_series(cells).map_err(|e| anyhow!("{e}"))?;
        let boundary: Vec<(f64, f64)> = lobes.iter().map(|p| (p.speed_rpm, p.depth_mm())).collect();
        for piece in boundary
            .split(|p| !p.1.is_finite())
            .filter(|r| !r.is_empty())
        {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    piece.to_vec(),
                    BLACK.stroke_width(2),
                )))
                .map_err(|e| anyhow!("{e}"))?;
        }
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_run_blue_white_red() {
        assert_eq!(colour(1.0), RGBColor(255, 255, 255));
        assert_eq!(colour(0.01), RGBColor(0, 0, 255));
        assert_eq!(colour(100.0), RGBColor(255, 0, 0));
    }
}
