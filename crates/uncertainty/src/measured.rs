//! Type B offset boundaries (Schmitz 2023, seed 001) around zero-order lobes computed straight
//! from a measured FRF, with the offsets set by an FRF uncertainty instead of by hand.
//!
//! # FRF uncertainty
//! An ensemble of receptances stands for what the measurement does not pin down: repeated tap
//! tests, an RCSA ensemble, or draws from [`FrfUncertainty`], a gain (calibration) error g and a
//! frequency-axis error e with G'(f) = (1 + g) G(f / (1 + e)), g ~ N(0, s_g), e ~ N(0, s_f)
//! ([`perturbed_receptance`]). Under that pair the zero-order lobes map exactly: with
//! w' = (1 + e) w and tau' = tau / (1 + e) the phase w' tau' is unchanged and
//! Lambda' = (1 + g) Lambda, so every lobe point (Omega, b) moves to ((1 + e) Omega, b / (1 + g)).
//!
//! # Offsets
//! The pocket of a lobe diagram is its lowest point; for each ensemble member the pocket is the
//! lowest point over the nominal pocket's cusp-to-cusp span (the same lobe), refined by the
//! vertex of the parabola through its speed and its two neighbours. The Type B offsets are
//! o_Omega = k sd(pocket speed) and o_b = k sd(pocket depth) with coverage factor k (001's
//! offsets are the user's stated belief; here they are the ensemble's spread, k = 2 for about
//! 95 % of a normal spread), applied to the nominal lobes by [`type_b_offsets`] (001 Eq. 1-11).

use crate::error::{Result, UncertaintyError};
use crate::geometric::{OffsetBoundaries, TypeBOffsets, type_b_offsets};
use chatter_dynamics::{CuttingCoefficients, Operation, SampledReceptance};
use chatter_stability::boundary::LobePoint;
use chatter_stability::zero_order::{ZeroOrderOptions, measured_limiting_depths};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;

/// Relative standard deviations of a gain error and a frequency-axis error of a measured FRF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrfUncertainty {
    gain_sd: f64,
    frequency_sd: f64,
}

/// Largest relative standard deviation accepted: draws of 1 + g or 1 + e near zero (four
/// standard deviations at 0.25) would not be a perturbation of the measurement any more.
const MAX_RELATIVE_SD: f64 = 0.25;

impl FrfUncertainty {
    /// Relative standard deviations s_g (gain) and s_f (frequency axis), each in
    /// [0, 0.25], not both zero.
    pub fn new(gain_sd: f64, frequency_sd: f64) -> Result<Self> {
        for (field, v) in [("gain_sd", gain_sd), ("frequency_sd", frequency_sd)] {
            if !(v.is_finite() && (0.0..=MAX_RELATIVE_SD).contains(&v)) {
                return Err(UncertaintyError::InvalidInput {
                    field: if field == "gain_sd" {
                        "gain_sd"
                    } else {
                        "frequency_sd"
                    },
                    message: format!(
                        "{v}; expected a relative standard deviation in [0, {MAX_RELATIVE_SD}]"
                    ),
                });
            }
        }
        if gain_sd == 0.0 && frequency_sd == 0.0 {
            return Err(UncertaintyError::InvalidInput {
                field: "gain_sd",
                message: "both standard deviations are zero; give at least one".into(),
            });
        }
        Ok(Self {
            gain_sd,
            frequency_sd,
        })
    }

    /// `count` seeded draws (g, e), g ~ N(0, s_g), e ~ N(0, s_f), each truncated to
    /// +-4 standard deviations.
    pub fn draws(&self, count: usize, seed: u64) -> Vec<(f64, f64)> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        (0..count)
            .map(|_| {
                let mut z = || {
                    let v: f64 = StandardNormal.sample(&mut rng);
                    v.clamp(-4.0, 4.0)
                };
                (self.gain_sd * z(), self.frequency_sd * z())
            })
            .collect()
    }
}

/// G'(f) = (1 + `gain`) G(f / (1 + `frequency`)): the nominal samples moved to the frequencies
/// (1 + e) f_k and scaled by 1 + g (exact, no interpolation). Both factors must be positive.
pub fn perturbed_receptance(
    nominal: &SampledReceptance,
    gain: f64,
    frequency: f64,
) -> Result<SampledReceptance> {
    for (field, v) in [("gain", gain), ("frequency", frequency)] {
        if !(v.is_finite() && v > -1.0) {
            return Err(UncertaintyError::InvalidInput {
                field: if field == "gain" { "gain" } else { "frequency" },
                message: format!("{v}; expected a relative error > -1"),
            });
        }
    }
    let f = nominal
        .frequencies_hz()
        .iter()
        .map(|f| f * (1.0 + frequency))
        .collect();
    let g = nominal
        .matrices_m_per_n()
        .iter()
        .map(|m| m.map(|row| row.map(|v| v * (1.0 + gain))))
        .collect();
    SampledReceptance::new(f, g).map_err(|e| UncertaintyError::InvalidInput {
        field: "receptance",
        message: e.to_string(),
    })
}

/// The ensemble of [`FrfUncertainty::draws`] applied to `nominal`.
pub fn frf_ensemble(
    nominal: &SampledReceptance,
    uncertainty: FrfUncertainty,
    count: usize,
    seed: u64,
) -> Result<Vec<SampledReceptance>> {
    uncertainty
        .draws(count, seed)
        .into_iter()
        .map(|(g, e)| perturbed_receptance(nominal, g, e))
        .collect()
}

/// Type B bands from an ensemble's spread.
#[derive(Debug, Clone, PartialEq)]
pub struct EnsembleBands {
    /// The nominal lobes.
    pub lobes: Vec<LobePoint>,
    /// The nominal pocket (speed rpm, depth mm).
    pub pocket: (f64, f64),
    /// Each member's pocket on the nominal pocket's lobe (speed rpm, depth mm).
    pub member_pockets: Vec<(f64, f64)>,
    /// o_Omega = k sd(pocket speed), o_b = k sd(pocket depth).
    pub offsets: TypeBOffsets,
    /// The offset boundaries around the nominal lobes (001 Eq. 1-11).
    pub bands: OffsetBoundaries,
}

/// The index span of the lobe that holds the lowest finite point: from the local maximum (or
/// the first point) before it to the one (or the last point) after it.
fn pocket_span(lobes: &[LobePoint]) -> Result<(usize, usize)> {
    let d: Vec<f64> = lobes.iter().map(|p| p.depth_m).collect();
    let lowest = (0..d.len())
        .filter(|&i| d[i].is_finite())
        .min_by(|&a, &b| d[a].total_cmp(&d[b]))
        .ok_or_else(|| UncertaintyError::InvalidInput {
            field: "lobes",
            message: "no finite limiting depth: no pocket to offset".into(),
        })?;
    let mut lo = lowest;
    while lo > 0 && d[lo - 1] >= d[lo] {
        lo -= 1;
    }
    let mut hi = lowest;
    while hi + 1 < d.len() && d[hi + 1] >= d[hi] {
        hi += 1;
    }
    Ok((lo, hi))
}

/// The lowest point of `lobes` over `span`, refined by the parabola through it and its
/// neighbours (speed rpm, depth mm); the point itself at the span's ends.
fn pocket(lobes: &[LobePoint], (lo, hi): (usize, usize)) -> (f64, f64) {
    let i = (lo..=hi)
        .min_by(|&a, &b| lobes[a].depth_m.total_cmp(&lobes[b].depth_m))
        .unwrap_or(lo);
    let at = |k: usize| (lobes[k].speed_rpm, lobes[k].depth_mm());
    if i == 0 || i + 1 >= lobes.len() {
        return at(i);
    }
    let ((x0, y0), (x1, y1), (x2, y2)) = (at(i - 1), at(i), at(i + 1));
    // vertex of the parabola through the three points (divided differences)
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let a = (d12 - d01) / (x2 - x0);
    if !(a > 0.0 && [y0, y1, y2].iter().all(|y| y.is_finite())) {
        return at(i);
    }
    let x = 0.5 * (x0 + x1) - d01 / (2.0 * a);
    (x, y1 + d01 * (x - x1) + a * (x - x0) * (x - x1))
}

/// Sample standard deviation.
fn sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Type B offsets from the lobes of an ensemble (see the module docs): the nominal `lobes`, the
/// members' lobes at the same speeds, coverage factor `coverage` (> 0).
pub fn ensemble_offsets(
    lobes: &[LobePoint],
    members: &[Vec<LobePoint>],
    coverage: f64,
) -> Result<EnsembleBands> {
    if !(coverage.is_finite() && coverage > 0.0) {
        return Err(UncertaintyError::InvalidInput {
            field: "coverage",
            message: format!("{coverage}; expected a coverage factor > 0"),
        });
    }
    if members.len() < 2 {
        return Err(UncertaintyError::InvalidInput {
            field: "members",
            message: format!(
                "{} ensemble members; expected at least 2 for a spread",
                members.len()
            ),
        });
    }
    if let Some((i, m)) = members
        .iter()
        .enumerate()
        .find(|(_, m)| m.len() != lobes.len())
    {
        return Err(UncertaintyError::InvalidInput {
            field: "members",
            message: format!(
                "member {i} has {} lobe points, the nominal lobes {}; expected the same speeds",
                m.len(),
                lobes.len()
            ),
        });
    }
    let span = pocket_span(lobes)?;
    let member_pockets: Vec<(f64, f64)> = members.iter().map(|m| pocket(m, span)).collect();
    let speeds: Vec<f64> = member_pockets.iter().map(|p| p.0).collect();
    let depths: Vec<f64> = member_pockets.iter().map(|p| p.1).collect();
    let offsets = TypeBOffsets::new(coverage * sd(&speeds), coverage * sd(&depths))?;
    let curve: Vec<(f64, f64)> = lobes
        .iter()
        .filter(|p| p.depth_m.is_finite())
        .map(|p| (p.speed_rpm, p.depth_mm()))
        .collect();
    let bands = type_b_offsets(&curve, offsets)?;
    Ok(EnsembleBands {
        lobes: lobes.to_vec(),
        pocket: pocket(lobes, span),
        member_pockets,
        offsets,
        bands,
    })
}

/// Type B bands of a measured receptance: zero-order lobes of `nominal` and of each ensemble
/// member ([`measured_limiting_depths`], no depth ceiling; members in parallel, the result
/// independent of the thread count) at `speeds_rpm`, then [`ensemble_offsets`].
pub fn measured_type_b_bands(
    operation: &Operation,
    cutting: CuttingCoefficients,
    nominal: &SampledReceptance,
    members: &[SampledReceptance],
    speeds_rpm: &[f64],
    coverage: f64,
) -> Result<EnsembleBands> {
    let options = ZeroOrderOptions::unbounded();
    let lobes = |g: &SampledReceptance| {
        measured_limiting_depths(operation, cutting, g, speeds_rpm, &options)
    };
    let member_lobes = members
        .par_iter()
        .map(lobes)
        .collect::<std::result::Result<Vec<_>, _>>()?;
    ensemble_offsets(&lobes(nominal)?, &member_lobes, coverage)
}
