//! A speed and depth recommendation: the stable cut with the highest material removal rate, and
//! the spindle speeds that put a tooth-passing harmonic on a measured chatter frequency.
//!
//! # Highest-MRR stable cut
//! At a fixed radial immersion and feed per tooth the material removal rate is
//! MRR = b a_e f_z N n, so among the speeds of the lobe diagram (limiting depth b_lim(n) from a
//! [`PreparedSolver`], FDM by default) the recommended cut maximizes b n with
//!
//! ```text
//! b = min(b_max, (1 - z_{1-P} s) b_lim(n), T / |SLE(n) per unit depth|),
//! ```
//!
//! where b_max is the machine's or tool's depth limit, P the accepted risk of chatter, s the
//! assumed relative standard deviation of the limiting depth (the nominal lobes carry no
//! uncertainty of their own: the limit is derated as if b_lim were normal about the nominal
//! boundary with that spread; bands or a posterior are the principled way: `chatter-jobs`'s
//! `recommend` takes the stable depths from them and calls [`best_cut`]), z the standard normal
//! quantile, and the last term the surface location error bound
//! when a tolerance T is given (the SLE is linear in the depth, [`chatter_dynamics::sle`]).
//!
//! # Harmonizer rule
//! A cut that chattered at speed S with chatter frequency f_c is moved to a speed where a
//! tooth-passing harmonic falls on f_c, n_k = 60 f_c / (N k) (the chatter frequency then
//! stays near the mode that chattered and the speed lands in a pocket near the top of a
//! lobe; Smith & Tlusty's rule as used by MetalMAX's Harmonizer): the harmonic k nearest to
//! S, i.e. k = 60 f_c / (N S) rounded down and up, gives the two nearest speeds.

use crate::error::{Result, StabilityError};
use crate::prepared::PreparedSolver;
use chatter_dynamics::ModalModel;
use chatter_dynamics::sle::surface_location_error;

/// What the highest-MRR search may use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecommendOptions {
    /// The deepest cut the tool or machine takes (m).
    pub max_depth_m: f64,
    /// Accepted probability of chatter P in (0, 0.5]; default 0.05.
    pub risk: f64,
    /// Assumed relative standard deviation s of the limiting depth; default 0.1.
    pub limit_relative_sd: f64,
    /// SLE tolerance T (m), when the wall's location matters.
    pub sle_tolerance_m: Option<f64>,
    /// Feed per tooth (m) of the SLE and the MRR; default 0.05 mm.
    pub feed_per_tooth_m: f64,
}

impl RecommendOptions {
    /// Options with the documented defaults and the depth limit `max_depth_m`.
    pub fn new(max_depth_m: f64) -> Self {
        Self {
            max_depth_m,
            risk: 0.05,
            limit_relative_sd: 0.1,
            sle_tolerance_m: None,
            feed_per_tooth_m: 0.05e-3,
        }
    }

    fn validate(&self) -> Result<()> {
        let check = |field: &'static str, v: f64, ok: bool, expected: &'static str| {
            if v.is_finite() && ok {
                Ok(())
            } else {
                Err(StabilityError::InvalidInput {
                    field,
                    value: v,
                    expected,
                })
            }
        };
        check(
            "max_depth_m",
            self.max_depth_m,
            self.max_depth_m > 0.0,
            "a depth > 0",
        )?;
        check(
            "risk",
            self.risk,
            self.risk > 0.0 && self.risk <= 0.5,
            "a probability of chatter in (0, 0.5]",
        )?;
        check(
            "limit_relative_sd",
            self.limit_relative_sd,
            (0.0..0.5).contains(&self.limit_relative_sd),
            "a relative standard deviation in [0, 0.5)",
        )?;
        check(
            "feed_per_tooth_m",
            self.feed_per_tooth_m,
            self.feed_per_tooth_m > 0.0,
            "a feed per tooth > 0",
        )?;
        if let Some(t) = self.sle_tolerance_m {
            check("sle_tolerance_m", t, t > 0.0, "a tolerance > 0")?;
        }
        Ok(())
    }

    /// The derating factor 1 - z_{1-P} s of the nominal limit (module docs).
    pub fn derating(&self) -> f64 {
        (1.0 - chatter_bayes::special::normal_quantile(1.0 - self.risk) * self.limit_relative_sd)
            .max(0.0)
    }
}

/// The recommended cut.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Recommendation {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Axial depth (mm).
    pub depth_mm: f64,
    /// The nominal limiting depth there (mm).
    pub limiting_depth_mm: f64,
    /// The derated limit (1 - z s) b_lim (mm).
    pub derated_depth_mm: f64,
    /// SLE at the recommended cut (um), when a tolerance was given.
    pub sle_um: Option<f64>,
    /// Material removal rate (cm^3/min) when the tool diameter is known.
    pub mrr_cm3_per_min: Option<f64>,
    /// Which limit set the depth: `"max_depth"`, `"stability"` or `"sle"`.
    pub limited_by: String,
    /// The reasons in plain words.
    pub reasons: Vec<String>,
}

/// The highest-MRR cut over `speeds_rpm` (see the module docs) with `solver` prepared for
/// `model`.
pub fn highest_mrr_cut(
    model: &ModalModel,
    solver: &dyn PreparedSolver,
    speeds_rpm: &[f64],
    options: &RecommendOptions,
) -> Result<Recommendation> {
    let candidates = derated_depths(solver, speeds_rpm, options)?;
    let mut r = best_cut(model, &candidates, &options.limits())?;
    r.reasons = reasons(
        &r,
        solver.name(),
        &options.limits(),
        derating_reason(&r, solver.name(), options),
    );
    Ok(r)
}

/// The reason of a derated limit (module docs) in plain words, for a recommendation `r` from
/// the `method` lobes under `options`.
pub fn derating_reason(r: &Recommendation, method: &str, options: &RecommendOptions) -> String {
    format!(
        "the nominal {method} limiting depth there is {:.3} mm; with no posterior or bands \
         given, it is derated to {:.3} mm (factor {:.3} = 1 - z({:.3}) x {:.0} %: the limit \
         taken as normal about the nominal lobes with a {:.0} % standard deviation, for a {:.0} \
         % risk of chatter)",
        r.limiting_depth_mm,
        r.derated_depth_mm,
        options.derating(),
        1.0 - options.risk,
        options.limit_relative_sd * 100.0,
        options.limit_relative_sd * 100.0,
        options.risk * 100.0
    )
}

/// The derated limit of every lobe point of `solver` at `speeds_rpm` (module docs), after
/// checking `options`.
pub fn derated_depths(
    solver: &dyn PreparedSolver,
    speeds_rpm: &[f64],
    options: &RecommendOptions,
) -> Result<Vec<StableDepth>> {
    options.validate()?;
    let derating = options.derating();
    Ok(solver
        .lobes(speeds_rpm, &chatter_progress::Silent)?
        .iter()
        .map(|p| StableDepth {
            speed_rpm: p.speed_rpm,
            limiting_depth_m: p.depth_m,
            stable_depth_m: derating * p.depth_m,
        })
        .collect())
}

/// The depth a speed allows before the depth limit and the SLE tolerance: the nominal (or
/// median) limiting depth and the depth accepted as stable at the chosen risk (the derated
/// limit, a quantile over posterior samples, the lower curve of a band).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct StableDepth {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// The nominal or median limiting depth (m); infinite or NaN where there is none.
    pub limiting_depth_m: f64,
    /// The depth accepted as stable (m); infinite when stable up to any depth searched, NaN
    /// where unknown (the speed is skipped).
    pub stable_depth_m: f64,
}

/// The limits every recommendation keeps: the depth limit, the SLE tolerance, the feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutLimits {
    /// The deepest cut the tool or machine takes (m).
    pub max_depth_m: f64,
    /// SLE tolerance T (m), when the wall's location matters.
    pub sle_tolerance_m: Option<f64>,
    /// Feed per tooth (m) of the SLE and the MRR.
    pub feed_per_tooth_m: f64,
}

impl RecommendOptions {
    /// The depth limit, SLE tolerance and feed of these options.
    pub fn limits(&self) -> CutLimits {
        CutLimits {
            max_depth_m: self.max_depth_m,
            sle_tolerance_m: self.sle_tolerance_m,
            feed_per_tooth_m: self.feed_per_tooth_m,
        }
    }
}

/// The highest-MRR cut among `candidates` (module docs: b = min(b_max, stable depth,
/// T / |SLE per unit depth|), maximizing b n); the speeds whose stable depth is NaN are skipped.
/// The reasons are left empty for the caller, who knows where the stable depths came from
/// ([`reasons`]). An error when no candidate has a stable depth.
pub fn best_cut(
    model: &ModalModel,
    candidates: &[StableDepth],
    limits: &CutLimits,
) -> Result<Recommendation> {
    let mut best: Option<(f64, Recommendation)> = None;
    for p in candidates.iter().filter(|p| !p.stable_depth_m.is_nan()) {
        let derated = p.stable_depth_m;
        let mut depth = limits.max_depth_m.min(derated);
        let mut limited_by = if limits.max_depth_m <= derated {
            "max_depth"
        } else {
            "stability"
        };
        let mut sle_um = None;
        if let Some(tolerance) = limits.sle_tolerance_m
            && depth > 0.0
        {
            let sle = surface_location_error(model, p.speed_rpm, depth, limits.feed_per_tooth_m)?;
            // the SLE is linear in the depth
            let per_depth = sle.sle_m / depth;
            let allowed = tolerance / per_depth.abs();
            if allowed < depth {
                depth = allowed;
                limited_by = "sle";
            }
            sle_um = Some(per_depth * depth * 1e6);
        }
        let score = depth * p.speed_rpm;
        if best.as_ref().is_none_or(|(s, _)| score > *s) {
            best = Some((
                score,
                Recommendation {
                    speed_rpm: p.speed_rpm,
                    depth_mm: depth * 1e3,
                    limiting_depth_mm: p.limiting_depth_m * 1e3,
                    derated_depth_mm: derated * 1e3,
                    sle_um,
                    mrr_cm3_per_min: mrr_cm3_per_min(model, p.speed_rpm, depth, limits),
                    limited_by: limited_by.into(),
                    reasons: Vec::new(),
                },
            ));
        }
    }
    best.map(|(_, r)| r).ok_or(StabilityError::InvalidInput {
        field: "speeds_rpm",
        value: candidates.len() as f64,
        expected: "at least one speed with a stable depth",
    })
}

/// MRR = b a_e f_z N n (cm^3/min) when the tool diameter is known.
fn mrr_cm3_per_min(
    model: &ModalModel,
    speed_rpm: f64,
    depth_m: f64,
    limits: &CutLimits,
) -> Option<f64> {
    match model.operation() {
        chatter_dynamics::Operation::Milling(m) => m.tool_diameter_m().map(|d| {
            depth_m
                * m.radial_immersion()
                * d
                * limits.feed_per_tooth_m
                * m.teeth() as f64
                * speed_rpm
                * 1e6
        }),
        chatter_dynamics::Operation::Turning(_) => None,
    }
}

/// The reasons of a recommendation in plain words: why this speed, `stability` (where its
/// stable depth came from, in the caller's words), which limit set the depth and the SLE left.
pub fn reasons(
    r: &Recommendation,
    method: &str,
    limits: &CutLimits,
    stability: String,
) -> Vec<String> {
    let mut out = vec![
        format!(
            "{:.0} rpm at {:.3} mm removes the most material per minute (depth times speed) \
             among the speeds of the {method} lobe diagram that stay inside the limits below",
            r.speed_rpm, r.depth_mm
        ),
        stability,
    ];
    out.push(match r.limited_by.as_str() {
        "max_depth" => format!(
            "the depth is the maximum depth you allowed ({:.3} mm); the cut is stable with margin",
            limits.max_depth_m * 1e3
        ),
        "sle" => format!(
            "the depth is lowered to keep the surface location error within {:.2} um",
            limits.sle_tolerance_m.unwrap_or(0.0) * 1e6
        ),
        _ => "the depth is the stability limit at the accepted risk (above)".into(),
    });
    if let Some(sle) = r.sle_um {
        out.push(format!(
            "the wall is left {:.2} um {} (surface location error, Schmitz & Mann 2006, at {:.3} \
             mm/tooth)",
            sle.abs(),
            if sle >= 0.0 { "undercut" } else { "overcut" },
            limits.feed_per_tooth_m * 1e3
        ));
    }
    out
}

/// One harmonic-matching speed of the Harmonizer rule.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HarmonicSpeed {
    /// Spindle speed (rpm) n = 60 f_c / (N k).
    pub speed_rpm: f64,
    /// The tooth-passing harmonic k that lands on the chatter frequency.
    pub harmonic: usize,
    /// Why, in plain words.
    pub reason: String,
}

/// The Harmonizer rule (module docs): the speeds nearest `chatter_speed_rpm` (one below or at,
/// one above) at which harmonic k of the tooth-passing frequency of `teeth` teeth equals
/// `chatter_hz`.
pub fn harmonic_speeds(
    teeth: usize,
    chatter_speed_rpm: f64,
    chatter_hz: f64,
) -> Result<Vec<HarmonicSpeed>> {
    for (field, v) in [
        ("chatter_speed_rpm", chatter_speed_rpm),
        ("chatter_hz", chatter_hz),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(StabilityError::InvalidInput {
                field,
                value: v,
                expected: "a value > 0",
            });
        }
    }
    let tooth_hz = chatter_speed_rpm / 60.0 * teeth as f64;
    let ratio = chatter_hz / tooth_hz;
    let mut ks = vec![ratio.ceil().max(1.0) as usize];
    if ratio.floor() >= 1.0 && ratio.floor() != ratio.ceil() {
        ks.insert(0, ratio.floor() as usize);
    }
    Ok(ks
        .into_iter()
        .map(|k| {
            let speed_rpm = 60.0 * chatter_hz / (teeth as f64 * k as f64);
            HarmonicSpeed {
                speed_rpm,
                harmonic: k,
                reason: format!(
                    "at {speed_rpm:.0} rpm harmonic {k} of the tooth-passing frequency \
                     ({teeth} teeth x {:.2} rev/s = {:.1} Hz) equals the chatter frequency \
                     {chatter_hz:.1} Hz heard at {chatter_speed_rpm:.0} rpm ({:+.1} % speed): \
                     each tooth then meets the wave the previous one left in phase, so the chip \
                     thickness hardly varies, the speed of a stability pocket",
                    speed_rpm / 60.0,
                    speed_rpm / 60.0 * teeth as f64,
                    (speed_rpm / chatter_speed_rpm - 1.0) * 100.0
                ),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 4 teeth, chatter at 1000 Hz heard at 7000 rpm (tooth passing 466.7 Hz, ratio 2.14):
    /// harmonics 2 and 3, at 7500 and 5000 rpm.
    #[test]
    fn harmonizer_speeds() {
        let s = harmonic_speeds(4, 7000.0, 1000.0).unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].harmonic, s[1].harmonic), (2, 3));
        assert!((s[0].speed_rpm - 7500.0).abs() < 1e-9);
        assert!((s[1].speed_rpm - 5000.0).abs() < 1e-9);
        assert!(harmonic_speeds(4, -1.0, 1000.0).is_err());
    }
}
