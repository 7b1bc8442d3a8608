//! Where the gap lies: per-observation residuals and the regions where they concentrate.
//!
//! A cut's residual is its signed log-depth distance d = ln(b / b_lim) to the predicted boundary;
//! it disagrees with the prediction when it is stable above (d > 0) or chatters below (d < 0)
//! the boundary, and then d bounds how far the real boundary lies above (+) or below (-) the
//! predicted one. Chatter frequencies are folded over the harmonics; poles give frequency and
//! damping residuals, split per speed into the zero-depth value and the slope with depth.
//!
//! The misfit of an observation is the log-likelihood it loses against a perfect prediction: for
//! a cut -ln p(label) + ln max(p, 1 - p) (zero when the prediction agrees), for frequencies and
//! damping half the squared standardized residual. A region's share of the gap is its share of
//! the total misfit of the nominal model.

use crate::data::Dataset;
use crate::likelihood::{NoiseModel, nearest_chatter_residual, pole_residuals, terms};
use crate::predict::Prediction;
use serde::Serialize;
use std::f64::consts::PI;

/// One cut's residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CutResidual {
    /// Index in the observations' `cuts`.
    pub index: usize,
    /// Spindle speed.
    pub speed_rpm: f64,
    /// Depth of cut.
    pub depth_mm: f64,
    /// Observed result.
    pub stable: bool,
    /// Run order, if recorded.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequence: Option<i64>,
    /// Predicted limiting depth (mm).
    pub limit_mm: f64,
    /// ln(depth / limit).
    pub log_depth_distance: f64,
    /// Whether the observed result contradicts the predicted boundary.
    pub disagrees: bool,
    /// Chatter-frequency residual folded over the harmonics (Hz).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chatter_residual_hz: Option<f64>,
    /// Misfit (see the module docs).
    pub misfit: f64,
}

/// One pole's residual.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoleResidual {
    /// Index in the observations' `poles`.
    pub index: usize,
    /// Spindle speed.
    pub speed_rpm: f64,
    /// Depth of the cut.
    pub depth_mm: f64,
    /// Run order, if recorded.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sequence: Option<i64>,
    /// Observed minus predicted frequency (Hz).
    pub frequency_residual_hz: f64,
    /// Observed minus predicted damping ratio.
    pub damping_residual: f64,
    /// Misfit (see the module docs).
    pub misfit: f64,
}

/// Residuals of every observation against one model.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Residuals {
    /// The cuts.
    pub cuts: Vec<CutResidual>,
    /// The poles.
    pub poles: Vec<PoleResidual>,
}

impl Residuals {
    /// Total misfit.
    pub fn misfit(&self) -> f64 {
        self.cuts.iter().map(|c| c.misfit).sum::<f64>()
            + self.poles.iter().map(|p| p.misfit).sum::<f64>()
    }
}

/// The residuals of `data` under `prediction`.
pub(crate) fn residuals(prediction: &Prediction, data: &Dataset, noise: &NoiseModel) -> Residuals {
    let cuts = data
        .cuts
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let predicted = prediction.cuts[i];
            let d = predicted.map_or(f64::NAN, |q| q.log_distance());
            let limit = c.depth_m / d.exp();
            let p = noise.chatter_probability(d);
            let observed = if c.stable { 1.0 - p } else { p };
            let label_misfit = -observed.ln() + p.max(1.0 - p).ln();
            let chatter_residual_hz = c.chatter_hz.and_then(|f| {
                predicted.map(|q| nearest_chatter_residual(f, &q, prediction.cut_fold_hz[i]))
            });
            let chatter_misfit =
                chatter_residual_hz.map_or(0.0, |r| 0.5 * (r / data.chatter_std_hz).powi(2));
            CutResidual {
                index: c.index,
                speed_rpm: c.speed_rpm,
                depth_mm: c.depth_m * 1e3,
                stable: c.stable,
                sequence: c.sequence,
                limit_mm: limit * 1e3,
                log_depth_distance: d,
                disagrees: (c.stable && d > 0.0) || (!c.stable && d < 0.0),
                chatter_residual_hz,
                misfit: label_misfit + chatter_misfit,
            }
        })
        .collect();
    // the poles' noise at the scale the data imply under this prediction
    let scale = terms(prediction, data, noise).pole_scale;
    let poles = data
        .poles
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let frequency_std = p.frequency_std_hz(scale);
            let (fr, zr) = prediction.poles[i].map_or((f64::NAN, f64::NAN), |q| {
                pole_residuals(
                    p.frequency_hz,
                    p.damping_ratio,
                    &q,
                    prediction.pole_fold_hz[i],
                )
            });
            let misfit = if fr.is_finite() {
                0.5 * (fr / frequency_std).powi(2) + 0.5 * (zr / p.damping_std).powi(2)
            } else {
                0.0
            };
            PoleResidual {
                index: p.index,
                speed_rpm: p.speed_rpm,
                depth_mm: p.depth_m * 1e3,
                sequence: p.sequence,
                frequency_residual_hz: fr,
                damping_residual: zr,
                misfit,
            }
        })
        .collect();
    Residuals { cuts, poles }
}

/// What a region groups by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RegionKind {
    /// A band of spindle speeds.
    SpeedBand,
    /// Speeds near lobe peaks or in the pockets of the nominal diagram.
    LobePosition,
    /// A band of depths relative to the nominal minimum limiting depth.
    DepthBand,
    /// One observable type.
    Observable,
    /// Early or late in the run order.
    Sequence,
    /// The poles at one speed.
    PoleSpeed,
}

/// A region of the observations and the gap in it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    /// What it groups by.
    pub kind: RegionKind,
    /// A short name (`low speed`, `lobe pockets`, ...).
    pub name: String,
    /// The range of the grouping variable, when it has one (rpm, mm, sequence).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range: Option<[f64; 2]>,
    /// Observations in the region.
    pub observations: usize,
    /// Cuts whose result contradicts the nominal boundary.
    pub disagreements: usize,
    /// Mean signed log-depth offset of the real boundary from the nominal one, over the
    /// disagreeing cuts (positive: the real boundary lies higher).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub boundary_offset_log_depth: Option<f64>,
    /// RMS of the folded chatter-frequency residuals (Hz).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_chatter_residual_hz: Option<f64>,
    /// Mean pole-frequency residual (Hz).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_pole_frequency_residual_hz: Option<f64>,
    /// Mean pole-damping residual.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_pole_damping_residual: Option<f64>,
    /// Pole residuals extrapolated to zero depth and their slope with depth:
    /// [frequency Hz, frequency Hz/mm, damping, damping per mm].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pole_intercept_and_slope: Option<[f64; 4]>,
    /// Share of the nominal model's total misfit.
    pub gap_share: f64,
    /// The region in words.
    pub summary: String,
}

/// Inputs of the region analysis beyond the residuals.
pub(crate) struct RegionContext {
    /// Lowest nominal limiting depth over the observed speeds (mm).
    pub min_limit_mm: f64,
    /// Diameter that sets the cutting speed (m), for surface wavelengths.
    pub cut_diameter_m: Option<f64>,
    /// Nominal chatter frequency per cut (Hz).
    pub cut_chatter_hz: Vec<f64>,
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Root mean square; None for no values.
pub(crate) fn rms(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt())
}

/// Least-squares intercept and slope of y on x (None with fewer than two distinct x).
fn line(x: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let (mx, my) = (mean(x)?, mean(y)?);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    if sxx <= 1e-12 * mx.abs().max(1.0) {
        return None;
    }
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let slope = sxy / sxx;
    Some((my - slope * mx, slope))
}

/// Builds a region from the selected cuts and poles.
struct Builder<'a> {
    r: &'a Residuals,
    total: f64,
}

impl Builder<'_> {
    fn region(
        &self,
        kind: RegionKind,
        name: String,
        range: Option<[f64; 2]>,
        cuts: &[usize],
        poles: &[usize],
        context: &str,
    ) -> Region {
        let cut = |i: &usize| &self.r.cuts[*i];
        let pole = |i: &usize| &self.r.poles[*i];
        let offsets: Vec<f64> = cuts
            .iter()
            .map(cut)
            .filter(|c| c.disagrees)
            .map(|c| c.log_depth_distance)
            .collect();
        let chatter: Vec<f64> = cuts
            .iter()
            .filter_map(|i| cut(i).chatter_residual_hz)
            .collect();
        let pf: Vec<f64> = poles
            .iter()
            .map(|i| pole(i).frequency_residual_hz)
            .filter(|v| v.is_finite())
            .collect();
        let pz: Vec<f64> = poles
            .iter()
            .map(|i| pole(i).damping_residual)
            .filter(|v| v.is_finite())
            .collect();
        let misfit: f64 = cuts.iter().map(|i| cut(i).misfit).sum::<f64>()
            + poles.iter().map(|i| pole(i).misfit).sum::<f64>();
        let gap_share = if self.total > 0.0 {
            misfit / self.total
        } else {
            0.0
        };
        let offset = mean(&offsets);
        let mut words = vec![format!("{name}{context}")];
        if !cuts.is_empty() {
            let mut w = format!(
                "{} of {} cuts disagree with the nominal boundary",
                offsets.len(),
                cuts.len()
            );
            if let Some(o) = offset {
                // a disagreeing cut bounds the real boundary from one side: "at least"
                if o > 0.0 {
                    w += &format!(
                        "; the real boundary lies at least {:.0} % above the nominal one",
                        (o.exp() - 1.0) * 100.0
                    );
                } else {
                    w += &format!(
                        "; the real boundary lies at least {:.0} % below the nominal one",
                        (1.0 - o.exp()) * 100.0
                    );
                }
            }
            words.push(w);
        }
        if let Some(c) = rms(&chatter) {
            words.push(format!("chatter frequencies off by {c:.1} Hz RMS"));
        }
        if let (Some(f), Some(z)) = (mean(&pf), mean(&pz)) {
            words.push(format!(
                "poles off by {f:+.1} Hz and {z:+.4} in damping on average"
            ));
        }
        words.push(format!("{:.0} % of the gap", gap_share * 100.0));
        Region {
            kind,
            name,
            range,
            observations: cuts.len() + poles.len(),
            disagreements: offsets.len(),
            boundary_offset_log_depth: offset,
            rms_chatter_residual_hz: rms(&chatter),
            mean_pole_frequency_residual_hz: mean(&pf),
            mean_pole_damping_residual: mean(&pz),
            pole_intercept_and_slope: None,
            gap_share,
            summary: words.join("; "),
        }
    }
}

/// The regions of the nominal model's residuals.
pub(crate) fn regions(r: &Residuals, context: &RegionContext) -> Vec<Region> {
    let b = Builder {
        r,
        total: r.misfit(),
    };
    let mut out = Vec::new();
    let all_cuts: Vec<usize> = (0..r.cuts.len()).collect();
    let all_poles: Vec<usize> = (0..r.poles.len()).collect();
    // speed bands: terciles of the distinct speeds
    let mut speeds: Vec<f64> = r
        .cuts
        .iter()
        .map(|c| c.speed_rpm)
        .chain(r.poles.iter().map(|p| p.speed_rpm))
        .collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    if speeds.len() >= 3 {
        let n = speeds.len();
        let bands = [
            ("low speed", speeds[0], speeds[n / 3 - 1]),
            ("middle speed", speeds[n / 3], speeds[2 * n / 3 - 1]),
            ("high speed", speeds[2 * n / 3], speeds[n - 1]),
        ];
        for (name, lo, hi) in bands {
            let inside = |s: f64| s >= lo && s <= hi;
            let cuts: Vec<usize> = all_cuts
                .iter()
                .copied()
                .filter(|&i| inside(r.cuts[i].speed_rpm))
                .collect();
            let poles: Vec<usize> = all_poles
                .iter()
                .copied()
                .filter(|&i| inside(r.poles[i].speed_rpm))
                .collect();
            let wavelengths: Vec<f64> = match context.cut_diameter_m {
                Some(d) => cuts
                    .iter()
                    .filter_map(|&i| {
                        let f = context.cut_chatter_hz[i];
                        (f > 0.0).then(|| PI * d * r.cuts[i].speed_rpm / 60.0 / f * 1e3)
                    })
                    .collect(),
                None => Vec::new(),
            };
            let context_words = match (
                wavelengths.iter().copied().reduce(f64::min),
                wavelengths.iter().copied().reduce(f64::max),
            ) {
                (Some(a), Some(z)) => {
                    format!(" ({lo:.0}-{hi:.0} rpm, surface wavelength V/f_c {a:.1}-{z:.1} mm)")
                }
                _ => format!(" ({lo:.0}-{hi:.0} rpm)"),
            };
            out.push(b.region(
                RegionKind::SpeedBand,
                name.into(),
                Some([lo, hi]),
                &cuts,
                &poles,
                &context_words,
            ));
        }
    }
    // lobe position: pockets (nominal limit below 1.5 times the minimum) and peaks
    let floor = context.min_limit_mm;
    if floor.is_finite() && !r.cuts.is_empty() {
        for (name, pocket) in [("lobe pockets", true), ("near lobe peaks", false)] {
            let cuts: Vec<usize> = all_cuts
                .iter()
                .copied()
                .filter(|&i| (r.cuts[i].limit_mm < 1.5 * floor) == pocket)
                .collect();
            if !cuts.is_empty() {
                let words = if pocket {
                    format!(" (nominal limit below {:.2} mm)", 1.5 * floor)
                } else {
                    format!(" (nominal limit above {:.2} mm)", 1.5 * floor)
                };
                out.push(b.region(
                    RegionKind::LobePosition,
                    name.into(),
                    None,
                    &cuts,
                    &[],
                    &words,
                ));
            }
        }
        // depth bands relative to the minimum limiting depth
        for (name, lo, hi) in [
            ("shallow cuts", 0.0, floor),
            ("middle depths", floor, 2.0 * floor),
            ("deep cuts", 2.0 * floor, f64::INFINITY),
        ] {
            let cuts: Vec<usize> = all_cuts
                .iter()
                .copied()
                .filter(|&i| r.cuts[i].depth_mm >= lo && r.cuts[i].depth_mm < hi)
                .collect();
            if !cuts.is_empty() {
                let words = if hi.is_finite() {
                    format!(" ({lo:.2}-{hi:.2} mm)")
                } else {
                    format!(" (above {lo:.2} mm)")
                };
                let range = hi.is_finite().then_some([lo, hi]);
                out.push(b.region(
                    RegionKind::DepthBand,
                    name.into(),
                    range,
                    &cuts,
                    &[],
                    &words,
                ));
            }
        }
    }
    // observable types
    if !all_cuts.is_empty() {
        out.push(b.region(
            RegionKind::Observable,
            "cut results and chatter frequencies".into(),
            None,
            &all_cuts,
            &[],
            "",
        ));
    }
    if !all_poles.is_empty() {
        out.push(b.region(
            RegionKind::Observable,
            "identified poles".into(),
            None,
            &[],
            &all_poles,
            "",
        ));
    }
    // sequence: early and late halves, with the trend of the cut residuals
    let sequenced: Vec<(i64, usize)> = r
        .cuts
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.sequence.map(|s| (s, i)))
        .collect();
    if sequenced.len() >= 4 {
        let mut seqs: Vec<i64> = sequenced.iter().map(|s| s.0).collect();
        seqs.sort_unstable();
        let median = seqs[seqs.len() / 2];
        let x: Vec<f64> = sequenced.iter().map(|s| s.0 as f64).collect();
        let y: Vec<f64> = sequenced
            .iter()
            .map(|&(_, i)| {
                let c = &r.cuts[i];
                if c.disagrees {
                    c.log_depth_distance
                } else {
                    0.0
                }
            })
            .collect();
        let trend = line(&x, &y).map(|(_, slope)| {
            slope
                * (x.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    - x.iter().copied().fold(f64::INFINITY, f64::min))
        });
        for (name, early) in [
            ("early in the run order", true),
            ("late in the run order", false),
        ] {
            let cuts: Vec<usize> = sequenced
                .iter()
                .filter(|s| (s.0 < median) == early)
                .map(|s| s.1)
                .collect();
            let poles: Vec<usize> = all_poles
                .iter()
                .copied()
                .filter(|&i| r.poles[i].sequence.is_some_and(|s| (s < median) == early))
                .collect();
            let lo = cuts
                .iter()
                .filter_map(|&i| r.cuts[i].sequence)
                .min()
                .unwrap_or(0) as f64;
            let hi = cuts
                .iter()
                .filter_map(|&i| r.cuts[i].sequence)
                .max()
                .unwrap_or(0) as f64;
            let words = match trend {
                Some(t) => format!(
                    " (sequence {lo:.0}-{hi:.0}; boundary offset trend over the campaign {t:+.3} in ln depth)"
                ),
                None => format!(" (sequence {lo:.0}-{hi:.0})"),
            };
            out.push(b.region(
                RegionKind::Sequence,
                name.into(),
                Some([lo, hi]),
                &cuts,
                &poles,
                &words,
            ));
        }
    }
    // poles per speed: zero-depth value and slope with depth
    let mut pole_speeds: Vec<f64> = r.poles.iter().map(|p| p.speed_rpm).collect();
    pole_speeds.sort_by(f64::total_cmp);
    pole_speeds.dedup();
    for s in pole_speeds {
        let idx: Vec<usize> = all_poles
            .iter()
            .copied()
            .filter(|&i| r.poles[i].speed_rpm == s)
            .collect();
        let x: Vec<f64> = idx.iter().map(|&i| r.poles[i].depth_mm).collect();
        let yf: Vec<f64> = idx
            .iter()
            .map(|&i| r.poles[i].frequency_residual_hz)
            .collect();
        let yz: Vec<f64> = idx.iter().map(|&i| r.poles[i].damping_residual).collect();
        let mut region = b.region(
            RegionKind::PoleSpeed,
            format!("poles at {s:.0} rpm"),
            Some([s, s]),
            &[],
            &idx,
            "",
        );
        if let (Some((f0, fs)), Some((z0, zs))) = (line(&x, &yf), line(&x, &yz)) {
            region.pole_intercept_and_slope = Some([f0, fs, z0, zs]);
            region.summary = format!(
                "poles at {s:.0} rpm: at zero depth {f0:+.1} Hz and {z0:+.4} in damping, slope with depth {fs:+.2} Hz/mm and {zs:+.4}/mm; {:.0} % of the gap",
                region.gap_share * 100.0
            );
        }
        out.push(region);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_fits_intercept_and_slope() {
        let (a, b) = line(&[1.0, 2.0, 3.0], &[3.0, 5.0, 7.0]).unwrap();
        assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
        assert!(line(&[2.0, 2.0], &[1.0, 3.0]).is_none());
    }

    #[test]
    fn the_nominal_model_has_no_gap_on_its_own_data() {
        use crate::generator::{HiddenEffect, Scenario, nominal_milling, synthesize};
        let model = nominal_milling().unwrap();
        let mut scenario = Scenario::new(HiddenEffect::ParameterError, 4);
        scenario.label_width_log_depth = 1e-3;
        let obs = synthesize(&model, &scenario).unwrap();
        let noise = NoiseModel::default();
        let data = Dataset::new(&model, &obs, &noise, 750.0).unwrap();
        let variant = crate::variant::Variant::new(model.clone());
        let r = residuals(&crate::predict::predict(&variant, &data), &data, &noise);
        // the truth (semi-discretization, 4x resolution) and the prediction (full
        // discretization) differ by up to ~2 % in depth: only cuts that close may disagree
        assert!(
            r.cuts
                .iter()
                .all(|c| !c.disagrees || c.log_depth_distance.abs() < 0.03),
            "{:?}",
            r.cuts
                .iter()
                .filter(|c| c.disagrees)
                .map(|c| c.log_depth_distance)
                .collect::<Vec<_>>()
        );
        let context = RegionContext {
            min_limit_mm: r
                .cuts
                .iter()
                .map(|c| c.limit_mm)
                .fold(f64::INFINITY, f64::min),
            cut_diameter_m: Some(0.01905),
            cut_chatter_hz: vec![750.0; r.cuts.len()],
        };
        let regions = regions(&r, &context);
        assert!(regions.iter().any(|g| g.kind == RegionKind::SpeedBand));
        assert!(regions.iter().any(|g| g.kind == RegionKind::PoleSpeed));
        let shares: f64 = regions
            .iter()
            .filter(|g| g.kind == RegionKind::Observable)
            .map(|g| g.gap_share)
            .sum();
        assert!((shares - 1.0).abs() < 1e-9);
    }
}
