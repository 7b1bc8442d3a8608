//! The recommendation job (`chatter recommend`): the speed and depth with the highest material
//! removal rate MRR = b a_e f_z N n that is stable with probability >= 1 - P and, when asked,
//! keeps the surface location error within a tolerance ([`chatter_stability::recommend`]), and
//! the Harmonizer's speeds for a cut that chattered; every choice with its reasons in plain
//! words.
//!
//! Where the stable depth b_P(n) at each speed comes from ([`Evidence`]):
//! - [`Evidence::Nominal`]: the nominal FDM limit derated as if normal with an assumed relative
//!   spread, b_P = (1 - z_{1-P} s) b_lim ([`chatter_stability::recommend`]);
//! - [`Evidence::Posterior`]: the limiting depths b_lim,s(n) of the models of S posterior samples
//!   of `chatter update` (Ahmadi 2022 / 004's Monte Carlo boundaries), and b_P(n) their order
//!   statistic b_(k+1) with k = floor(P S): at every depth below it at most k of the S samples
//!   chatter, so the probability of stability is >= (S - k) / S >= 1 - P;
//! - [`Evidence::Bands`] with a Monte Carlo probability map (004, `chatter bands --kind
//!   montecarlo --map-out`): the deepest grid depth up to which P_s >= 1 - P at every grid
//!   depth;
//! - [`Evidence::Bands`] with a band table's lower curve (`chatter bands --out`): Type B offsets
//!   (001), credibility bounds (000) or the 5 % Monte Carlo quantile, whose risk is the band's
//!   own.
//!
//! The cut is then b = min(b_max, b_P(n), T / |SLE(n) per unit depth|), maximizing b n over the
//! speeds ([`chatter_stability::recommend::best_cut`]).

use crate::checks;
use crate::error::{JobError, Result};
use chatter_dynamics::limits::{DEPTH_MM, OBSERVED_FREQUENCY_HZ, SPEED_RPM, written};
use chatter_dynamics::{ModalModel, Operation};
use chatter_progress::Observer;
use chatter_stability::Method;
use chatter_stability::boundary::BoundaryOptions;
use chatter_stability::prepared::SolverOptions;
use chatter_stability::recommend::{
    CutLimits, HarmonicSpeed, RecommendOptions, Recommendation, StableDepth, best_cut,
    derated_depths, derating_reason, harmonic_speeds, reasons,
};
use chatter_uncertainty::montecarlo::{SampledBoundaries, StabilityMap, sample_boundaries};
use chatter_uncertainty::parameters::ParameterDistribution;
use std::path::Path;

/// Default accepted probability of chatter P.
pub const RISK: f64 = 0.05;
/// Default posterior samples whose boundaries are computed (every k-th of `posterior.csv`).
pub const POSTERIOR_SAMPLES: usize = 200;
/// Most posterior samples.
pub const MAX_POSTERIOR_SAMPLES: usize = 100_000;
/// Default assumed relative standard deviation of the nominal limit (%).
pub const LIMIT_SD_PERCENT: f64 = 10.0;

/// Where the stable depth at each speed comes from (module docs).
#[derive(Debug, Clone)]
pub enum Evidence {
    /// The nominal FDM lobes of the model, derated for the risk.
    Nominal,
    /// Posterior samples of `chatter update` (a folder with `summary.json` and
    /// `posterior.csv`).
    Posterior(ParameterDistribution),
    /// A table written by `chatter bands`.
    Bands(BandsTable),
}

impl Evidence {
    /// The posterior of a `chatter update` folder: `summary.json` and `posterior.csv` must both
    /// be there (the recommendation is over the samples).
    pub fn posterior(dir: &Path) -> Result<Self> {
        for name in ["summary.json", "posterior.csv"] {
            let path = dir.join(name);
            if !path.is_file() {
                return Err(JobError::File {
                    path: path.display().to_string(),
                    message: "not found: a posterior folder of `chatter update` holds \
                              summary.json and posterior.csv"
                        .into(),
                });
            }
        }
        Ok(Evidence::Posterior(
            ParameterDistribution::from_posterior_dir(dir)?,
        ))
    }
}

/// Which band a lower curve bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LowerBand {
    /// Type B offset boundaries (001): stated speed and depth offsets, no probability.
    TypeB,
    /// Second-order credibility bounds (000 Eq. 14-18) of a coverage the table does not state.
    Credibility,
    /// The 5 % quantile of Monte Carlo limits (004): stable with probability about 95 %.
    MonteCarloQ05,
}

impl LowerBand {
    fn describe(self) -> &'static str {
        match self {
            LowerBand::TypeB => {
                "the Type B lower boundary (001: the lobes offset by the stated speed and depth uncertainties; such offsets carry no probability, so no risk is stated)"
            }
            LowerBand::Credibility => {
                "the lower credibility bound (000 Eq. 14-18: second-order perturbation of the multiplier; its coverage is the one `chatter bands` was given)"
            }
            LowerBand::MonteCarloQ05 => {
                "the 5 % quantile of the Monte Carlo limiting depths (004): stable with probability about 95 %"
            }
        }
    }
}

/// A table of `chatter bands`, read back by [`BandsTable::read`].
#[derive(Debug, Clone)]
pub enum BandsTable {
    /// A probability-of-stability map `speed_rpm,depth_mm,p_stable` (`--map-out`).
    Map(StabilityMap),
    /// A band table with `speed_rpm,depth_mm,lower_mm` (`--out`).
    Lower {
        /// Which band.
        band: LowerBand,
        /// Speeds (rpm).
        speeds_rpm: Vec<f64>,
        /// The boundary (mm; NaN where empty).
        depth_mm: Vec<f64>,
        /// The lower curve (mm; NaN where empty).
        lower_mm: Vec<f64>,
    },
}

fn file_error(path: &Path, message: impl Into<String>) -> JobError {
    JobError::File {
        path: path.display().to_string(),
        message: message.into(),
    }
}

impl BandsTable {
    /// Read a CSV of `chatter bands`: a map (header with `p_stable`) or a band table (header
    /// with `lower_mm`; Type B when it has `theta_deg`, Monte Carlo when it has
    /// `chatter_hz_q05`, credibility bounds otherwise). Empty cells are NaN.
    pub fn read(path: &Path) -> Result<Self> {
        let mut reader =
            csv::Reader::from_path(path).map_err(|e| file_error(path, e.to_string()))?;
        let header = reader
            .headers()
            .map_err(|e| file_error(path, e.to_string()))?
            .clone();
        let column = |name: &str| header.iter().position(|h| h == name);
        let need = |name: &str| {
            column(name).ok_or_else(|| {
                file_error(
                    path,
                    format!(
                        "no column `{name}`: expected a table of `chatter bands` (`--out`, with \
                         speed_rpm,depth_mm,lower_mm) or its Monte Carlo map (`--map-out`, with \
                         speed_rpm,depth_mm,p_stable)"
                    ),
                )
            })
        };
        let (speed, depth) = (need("speed_rpm")?, need("depth_mm")?);
        let map = column("p_stable");
        let lower = if map.is_some() {
            None
        } else {
            Some(need("lower_mm")?)
        };
        let mut rows: Vec<[f64; 3]> = Vec::new();
        for (i, record) in reader.records().enumerate() {
            let record = record.map_err(|e| file_error(path, e.to_string()))?;
            let cell = |c: usize| -> Result<f64> {
                let text = record.get(c).unwrap_or("").trim();
                if text.is_empty() {
                    return Ok(f64::NAN);
                }
                text.parse::<f64>().map_err(|_| {
                    file_error(
                        path,
                        format!(
                            "row {}: `{text}` in column `{}` is not a number",
                            i + 2,
                            &header[c]
                        ),
                    )
                })
            };
            rows.push([
                cell(speed)?,
                cell(depth)?,
                cell(map.or(lower).unwrap_or(depth))?,
            ]);
        }
        if rows.is_empty() {
            return Err(file_error(path, "no rows"));
        }
        if map.is_some() {
            return Ok(BandsTable::Map(map_of(path, &rows)?));
        }
        let band = if column("theta_deg").is_some() {
            LowerBand::TypeB
        } else if column("chatter_hz_q05").is_some() {
            LowerBand::MonteCarloQ05
        } else {
            LowerBand::Credibility
        };
        Ok(BandsTable::Lower {
            band,
            speeds_rpm: rows.iter().map(|r| r[0]).collect(),
            depth_mm: rows.iter().map(|r| r[1]).collect(),
            lower_mm: rows.iter().map(|r| r[2]).collect(),
        })
    }
}

/// The rows `speed_rpm,depth_mm,p_stable` of a map as a [`StabilityMap`]: every speed with the
/// same depths, in the order written (speed-major, as `chatter bands` writes).
fn map_of(path: &Path, rows: &[[f64; 3]]) -> Result<StabilityMap> {
    let mut speeds_rpm: Vec<f64> = Vec::new();
    for r in rows {
        if speeds_rpm.last() != Some(&r[0]) {
            speeds_rpm.push(r[0]);
        }
    }
    let per_speed = rows.len() / speeds_rpm.len();
    let depths_mm: Vec<f64> = rows[..per_speed].iter().map(|r| r[1]).collect();
    let regular = per_speed * speeds_rpm.len() == rows.len()
        && rows
            .chunks(per_speed)
            .all(|c| c.iter().zip(&depths_mm).all(|(r, d)| r[1] == *d));
    if !regular || !depths_mm.windows(2).all(|w| w[0] < w[1]) {
        return Err(file_error(
            path,
            "a probability map needs the same increasing depths at every speed, speed by speed",
        ));
    }
    Ok(StabilityMap {
        p_stable: rows
            .chunks(per_speed)
            .map(|c| c.iter().map(|r| r[2]).collect())
            .collect(),
        samples_per_speed: vec![0; speeds_rpm.len()],
        speeds_rpm,
        depths_mm,
    })
}

/// What the recommendation was asked, in user units; `None` fields take the documented
/// defaults.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RecommendRequest {
    /// The deepest cut the tool or machine takes (mm).
    pub max_depth_mm: f64,
    /// Accepted probability of chatter P; default [`RISK`]. In (0, 0.5] for the derated nominal
    /// limit, in (0, 1) with a posterior or a map; not used with a band's lower curve (its risk
    /// is the band's), except 0.05 with the Monte Carlo 5 % quantile.
    pub risk: Option<f64>,
    /// Assumed relative standard deviation of the nominal limit (%), from 0 to 50; default
    /// [`LIMIT_SD_PERCENT`]; nominal evidence only.
    pub limit_sd_percent: Option<f64>,
    /// Largest surface location error allowed (um).
    pub sle_tolerance_um: Option<f64>,
    /// Feed per tooth (mm) of the SLE and the MRR; default [`crate::sle::FEED_PER_TOOTH_MM`].
    pub feed_per_tooth_mm: Option<f64>,
    /// Speeds (rpm) to choose from; default those of the lobes. Not with bands (their speeds
    /// are the table's).
    pub speeds_rpm: Option<Vec<f64>>,
    /// Posterior samples whose boundaries are computed; default [`POSTERIOR_SAMPLES`].
    pub samples: Option<usize>,
    /// Speed (rpm) of a cut that chattered (with `chatter_hz`).
    pub chatter_speed_rpm: Option<f64>,
    /// Its chatter frequency (Hz).
    pub chatter_hz: Option<f64>,
}

/// A checked recommendation job.
pub struct Recommend<'a> {
    model: &'a ModalModel,
    evidence: Evidence,
    teeth: usize,
    risk: f64,
    limit_sd_percent: f64,
    limits: CutLimits,
    speeds_rpm: Vec<f64>,
    samples: usize,
    chatter: Option<(f64, f64)>,
}

/// Where the stable depths came from, with what was used.
#[derive(Debug, Clone, PartialEq)]
pub enum Basis {
    /// The nominal FDM limit derated by an assumed relative standard deviation (%).
    Derated {
        /// The assumed relative standard deviation (%).
        limit_sd_percent: f64,
    },
    /// Posterior samples.
    Posterior {
        /// Samples whose boundaries were computed.
        samples: usize,
        /// Sample-speed pairs without a boundary (left out, never counted as stable).
        failures: usize,
    },
    /// A Monte Carlo probability map.
    StabilityMap,
    /// A band's lower curve.
    LowerBand(LowerBand),
}

/// The Harmonizer's speeds for a cut that chattered.
#[derive(Debug, Clone, PartialEq)]
pub struct Harmonizer {
    /// Speed (rpm) of the cut that chattered.
    pub chatter_speed_rpm: f64,
    /// Its chatter frequency (Hz).
    pub chatter_hz: f64,
    /// The harmonic-matching speeds nearest to it.
    pub speeds: Vec<HarmonicSpeed>,
}

/// What the recommendation computed.
#[derive(Debug, Clone, PartialEq)]
pub struct RecommendOutcome {
    /// Where the stable depths came from.
    pub basis: Basis,
    /// The accepted probability of chatter (None for a band whose risk is not stated).
    pub risk: Option<f64>,
    /// Feed per tooth (mm).
    pub feed_per_tooth_mm: f64,
    /// The stable depth at every speed considered.
    pub stable_depths: Vec<StableDepth>,
    /// The recommended cut with its reasons.
    pub cut: Recommendation,
    /// The probability of stability at the cut, where the evidence gives one: the share of the
    /// posterior samples whose limit is at or above the depth, or the map's P_s at the first
    /// grid depth at or above the depth (a lower bound: P_s falls with depth).
    pub probability_of_stability: Option<f64>,
    /// The Harmonizer's speeds, when a chattering cut was given.
    pub harmonizer: Option<Harmonizer>,
}

fn invalid(field: &'static str, value: f64, expected: &str) -> JobError {
    JobError::Invalid {
        field,
        value: written(value),
        expected: expected.into(),
    }
}

impl<'a> Recommend<'a> {
    /// Check `request` against `model` (milling) and `evidence`, once: ranges, the options the
    /// evidence does not use, the chattering cut given whole, the cost guard of FDM.
    pub fn new(
        model: &'a ModalModel,
        evidence: Evidence,
        request: RecommendRequest,
    ) -> Result<Self> {
        let Operation::Milling(milling) = model.operation() else {
            return Err(JobError::Refused(
                "the recommendation is for milling models (turning given)".into(),
            ));
        };
        let max_depth_mm = checks::in_range("max_depth_mm", request.max_depth_mm, &DEPTH_MM)?;
        let feed_mm = checks::in_range(
            "feed_per_tooth_mm",
            request
                .feed_per_tooth_mm
                .unwrap_or(crate::sle::FEED_PER_TOOTH_MM),
            &crate::simulate::FEED_MM,
        )?;
        if let Some(t) = request.sle_tolerance_um
            && !(t.is_finite() && t > 0.0)
        {
            return Err(invalid("sle_tolerance_um", t, "a tolerance > 0 um"));
        }
        let context = match &evidence {
            Evidence::Nominal => "without a posterior or bands",
            Evidence::Posterior(_) => "with a posterior",
            Evidence::Bands(_) => "with bands",
        };
        let nominal = matches!(evidence, Evidence::Nominal);
        checks::unused(
            request.limit_sd_percent.is_some() && !nominal,
            "limit_sd_percent",
            context,
            "the derated nominal limit (no posterior, no bands): the spread comes from them",
        )?;
        checks::unused(
            request.samples.is_some() && !matches!(evidence, Evidence::Posterior(_)),
            "samples",
            context,
            "a posterior",
        )?;
        checks::unused(
            request.speeds_rpm.is_some() && matches!(evidence, Evidence::Bands(_)),
            "speeds",
            context,
            "the lobes of the model or a posterior: a band table brings its own speeds",
        )?;
        let risk = request.risk.unwrap_or(RISK);
        let (risk_ok, risk_expected) = if nominal {
            (
                risk > 0.0 && risk <= 0.5,
                "a probability of chatter in (0, 0.5]",
            )
        } else {
            (
                risk > 0.0 && risk < 1.0,
                "a probability of chatter in (0, 1)",
            )
        };
        if !(risk.is_finite() && risk_ok) {
            return Err(invalid("risk", risk, risk_expected));
        }
        if let (Evidence::Bands(BandsTable::Lower { band, .. }), Some(p)) =
            (&evidence, request.risk)
            && !(*band == LowerBand::MonteCarloQ05 && p == RISK)
        {
            return Err(JobError::Refused(format!(
                "`risk` {}: the lower curve of a band table has its own risk ({}); for a risk of \
                 your choice give the Monte Carlo map of `chatter bands --kind montecarlo \
                 --map-out` or a posterior",
                written(p),
                band.describe()
            )));
        }
        let limit_sd_percent = request.limit_sd_percent.unwrap_or(LIMIT_SD_PERCENT);
        if !(limit_sd_percent.is_finite() && (0.0..50.0).contains(&limit_sd_percent)) {
            return Err(invalid(
                "limit_sd_percent",
                limit_sd_percent,
                "a relative standard deviation from 0 to 50 %",
            ));
        }
        let samples = crate::error::count(
            "samples",
            request.samples.unwrap_or(POSTERIOR_SAMPLES),
            2,
            MAX_POSTERIOR_SAMPLES,
            "posterior samples",
        )?;
        let chatter = match (request.chatter_speed_rpm, request.chatter_hz) {
            (Some(s), Some(f)) => Some((
                checks::in_range("chatter_speed_rpm", s, &SPEED_RPM)?,
                checks::in_range("chatter_hz", f, &OBSERVED_FREQUENCY_HZ)?,
            )),
            (None, None) => None,
            (Some(_), None) => {
                return Err(JobError::Missing {
                    what: "`chatter_hz`",
                    needed_by: "`chatter_speed_rpm`".into(),
                });
            }
            (None, Some(_)) => {
                return Err(JobError::Missing {
                    what: "`chatter_speed_rpm`",
                    needed_by: "`chatter_hz`".into(),
                });
            }
        };
        let speeds_rpm = match (&evidence, request.speeds_rpm) {
            (Evidence::Bands(BandsTable::Map(m)), _) => m.speeds_rpm.clone(),
            (Evidence::Bands(BandsTable::Lower { speeds_rpm, .. }), _) => speeds_rpm.clone(),
            (_, Some(s)) => s,
            (_, None) => chatter_stability::speed_grid::default_speeds_rpm(model),
        };
        checks::speeds("speeds", &speeds_rpm)?;
        if !matches!(evidence, Evidence::Bands(_))
            && let Some(d) = Method::Fdm.discretization()
        {
            checks::work_size(model, d, &speeds_rpm, "speeds")?;
        }
        Ok(Self {
            model,
            evidence,
            teeth: milling.teeth(),
            risk,
            limit_sd_percent,
            limits: CutLimits {
                max_depth_m: max_depth_mm * 1e-3,
                sle_tolerance_m: request.sle_tolerance_um.map(|t| t * 1e-6),
                feed_per_tooth_m: feed_mm * 1e-3,
            },
            speeds_rpm,
            samples,
            chatter,
        })
    }

    /// The speeds (rpm) the recommendation chooses from.
    pub fn speeds_rpm(&self) -> &[f64] {
        &self.speeds_rpm
    }

    /// Run: `observer` hears of the posterior samples done.
    pub fn run(&self, observer: &dyn Observer) -> Result<RecommendOutcome> {
        let (basis, risk, stable_depths, cut, probability_of_stability) = match &self.evidence {
            Evidence::Nominal => self.nominal()?,
            Evidence::Posterior(distribution) => self.posterior(distribution, observer)?,
            Evidence::Bands(BandsTable::Map(map)) => self.map(map)?,
            Evidence::Bands(BandsTable::Lower {
                band,
                speeds_rpm,
                depth_mm,
                lower_mm,
            }) => self.lower(*band, speeds_rpm, depth_mm, lower_mm)?,
        };
        let harmonizer = match self.chatter {
            Some((chatter_speed_rpm, chatter_hz)) => Some(Harmonizer {
                chatter_speed_rpm,
                chatter_hz,
                speeds: harmonic_speeds(self.teeth, chatter_speed_rpm, chatter_hz)?,
            }),
            None => None,
        };
        Ok(RecommendOutcome {
            basis,
            risk,
            feed_per_tooth_mm: self.limits.feed_per_tooth_m * 1e3,
            stable_depths,
            cut,
            probability_of_stability,
            harmonizer,
        })
    }

    fn nominal(&self) -> Result<Found> {
        let options = RecommendOptions {
            max_depth_m: self.limits.max_depth_m,
            risk: self.risk,
            limit_relative_sd: self.limit_sd_percent / 100.0,
            sle_tolerance_m: self.limits.sle_tolerance_m,
            feed_per_tooth_m: self.limits.feed_per_tooth_m,
        };
        let fdm = Method::Fdm.prepare(self.model, &BoundaryOptions::default())?;
        let depths = derated_depths(fdm.as_ref(), &self.speeds_rpm, &options)?;
        let mut cut = best_cut(self.model, &depths, &self.limits)?;
        let why = derating_reason(&cut, fdm.name(), &options);
        cut.reasons = reasons(&cut, fdm.name(), &self.limits, why);
        Ok((
            Basis::Derated {
                limit_sd_percent: self.limit_sd_percent,
            },
            Some(self.risk),
            depths,
            cut,
            None,
        ))
    }

    fn posterior(
        &self,
        distribution: &ParameterDistribution,
        observer: &dyn Observer,
    ) -> Result<Found> {
        // posterior samples are taken in order (every k-th), no randomness: the seed is unused
        let thetas = distribution.draws(self.samples, 0)?;
        let options = SolverOptions {
            method: Method::Fdm,
            boundary: BoundaryOptions::default(),
        };
        let sampled = sample_boundaries(
            &distribution.parameterization(self.model)?,
            &thetas,
            &self.speeds_rpm,
            &options,
            observer,
        )?;
        let depths: Vec<StableDepth> = (0..self.speeds_rpm.len())
            .map(|i| posterior_depth(&sampled, i, self.risk))
            .collect();
        // the SLE of the posterior mean model
        let mean_model = distribution.mean_model(self.model)?;
        let mut cut = best_cut(&mean_model, &depths, &self.limits)?;
        let i = self
            .speeds_rpm
            .iter()
            .position(|&s| s == cut.speed_rpm)
            .unwrap_or(0);
        let valid = sampled.limits_mm.iter().filter(|l| !l[i].is_nan()).count();
        let holding = sampled
            .limits_mm
            .iter()
            .filter(|l| l[i] >= cut.depth_mm)
            .count();
        let p_stable = holding as f64 / valid.max(1) as f64;
        let mut why = format!(
            "over {valid} posterior samples (every sample's FDM limiting depth at {:.0} rpm), the \
             limit is at or above {:.3} mm in {holding} of them: the cut is stable with \
             probability {:.3} >= 1 - {} (the median limit there is {:.3} mm)",
            cut.speed_rpm,
            cut.depth_mm,
            p_stable,
            written(self.risk),
            cut.limiting_depth_mm
        );
        if self.risk * (valid as f64) < 1.0 {
            why += &format!(
                "; {valid} samples cannot resolve a risk below 1/{valid}, so the smallest sampled \
                 limit is taken"
            );
        }
        cut.reasons = reasons(&cut, "fdm", &self.limits, why);
        if cut.sle_um.is_some() {
            cut.reasons
                .push("the SLE is that of the posterior mean model".into());
        }
        Ok((
            Basis::Posterior {
                samples: thetas.len(),
                failures: sampled.failures.len(),
            },
            Some(self.risk),
            depths,
            cut,
            Some(p_stable),
        ))
    }

    fn map(&self, map: &StabilityMap) -> Result<Found> {
        let depths: Vec<StableDepth> = map
            .speeds_rpm
            .iter()
            .zip(&map.p_stable)
            .map(|(&speed_rpm, row)| map_depth(speed_rpm, &map.depths_mm, row, self.risk))
            .collect();
        let mut cut = best_cut(self.model, &depths, &self.limits)?;
        let i = map
            .speeds_rpm
            .iter()
            .position(|&s| s == cut.speed_rpm)
            .unwrap_or(0);
        // P_s falls with depth: its value at the first grid depth at or above the cut bounds it
        // from below
        let j = map
            .depths_mm
            .iter()
            .position(|&d| d >= cut.depth_mm)
            .unwrap_or(map.depths_mm.len() - 1);
        let p_stable = map.p_stable[i][j];
        let why = format!(
            "the Monte Carlo map gives a probability of stability of at least {:.3} at {:.0} rpm \
             up to {:.3} mm (its grid depth {:.3} mm), >= 1 - {} (the map's median limit there \
             is {:.3} mm)",
            p_stable,
            cut.speed_rpm,
            cut.depth_mm,
            map.depths_mm[j],
            written(self.risk),
            cut.limiting_depth_mm
        );
        cut.reasons = reasons(&cut, "Monte Carlo", &self.limits, why);
        Ok((
            Basis::StabilityMap,
            Some(self.risk),
            depths,
            cut,
            Some(p_stable),
        ))
    }

    fn lower(
        &self,
        band: LowerBand,
        speeds_rpm: &[f64],
        depth_mm: &[f64],
        lower_mm: &[f64],
    ) -> Result<Found> {
        let depths: Vec<StableDepth> = speeds_rpm
            .iter()
            .zip(depth_mm.iter().zip(lower_mm))
            .map(|(&speed_rpm, (&d, &l))| StableDepth {
                speed_rpm,
                limiting_depth_m: d * 1e-3,
                stable_depth_m: l * 1e-3,
            })
            .collect();
        let mut cut = best_cut(self.model, &depths, &self.limits)?;
        let why = format!(
            "the depth stays at or below {} at {:.0} rpm, {:.3} mm (the boundary there is {:.3} \
             mm)",
            band.describe(),
            cut.speed_rpm,
            cut.derated_depth_mm,
            cut.limiting_depth_mm
        );
        cut.reasons = reasons(&cut, "band", &self.limits, why);
        let risk = (band == LowerBand::MonteCarloQ05).then_some(RISK);
        Ok((Basis::LowerBand(band), risk, depths, cut, None))
    }
}

/// What one evidence gives: basis, risk, stable depths, cut, probability of stability.
type Found = (
    Basis,
    Option<f64>,
    Vec<StableDepth>,
    Recommendation,
    Option<f64>,
);

/// The stable depth at speed index `i` over the samples with a boundary there (module docs):
/// the (k+1)-th smallest limit, k = floor(P S), so that at most k of S samples chatter below
/// it; the median limit as the limiting depth. NaN when no sample has a boundary there.
pub fn posterior_depth(sampled: &SampledBoundaries, i: usize, risk: f64) -> StableDepth {
    let mut limits: Vec<f64> = sampled
        .limits_mm
        .iter()
        .map(|l| l[i])
        .filter(|l| !l.is_nan())
        .collect();
    limits.sort_by(f64::total_cmp);
    let speed_rpm = sampled.speeds_rpm[i];
    if limits.is_empty() {
        return StableDepth {
            speed_rpm,
            limiting_depth_m: f64::NAN,
            stable_depth_m: f64::NAN,
        };
    }
    let n = limits.len();
    // the 1e-9 keeps floor(0.05 x 200) at 10 whichever way the product rounds
    let k = ((risk * n as f64 + 1e-9).floor() as usize).min(n - 1);
    StableDepth {
        speed_rpm,
        limiting_depth_m: chatter_bayes::special::quantile(limits.clone(), 0.5) * 1e-3,
        stable_depth_m: limits[k] * 1e-3,
    }
}

/// The deepest grid depth up to which P_s >= 1 - `risk` at every grid depth (0 when not even
/// the first); the first grid depth with P_s < 0.5 as the limiting depth (infinite when none).
/// NaN when the map has no value at this speed.
fn map_depth(speed_rpm: f64, depths_mm: &[f64], p_stable: &[f64], risk: f64) -> StableDepth {
    if p_stable.iter().any(|p| p.is_nan()) {
        return StableDepth {
            speed_rpm,
            limiting_depth_m: f64::NAN,
            stable_depth_m: f64::NAN,
        };
    }
    let holding = p_stable.iter().take_while(|&&p| p >= 1.0 - risk).count();
    let median = p_stable
        .iter()
        .position(|&p| p < 0.5)
        .map_or(f64::INFINITY, |j| depths_mm[j]);
    StableDepth {
        speed_rpm,
        limiting_depth_m: median * 1e-3,
        stable_depth_m: if holding == 0 {
            0.0
        } else {
            depths_mm[holding - 1] * 1e-3
        },
    }
}
