//! The observations file of `shared/spec/formats.md`: test cuts, identified poles and signal
//! records, plus cutting-test tables as CSV (`speed_rpm,depth_mm,stable,chatter_hz[,sequence]`).

use crate::error::{DynamicsError, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A test cut and its observed result.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Cut {
    /// Spindle speed.
    pub speed_rpm: f64,
    /// Axial depth (milling) or width (turning) of cut.
    pub depth_mm: f64,
    /// Observed stable (true) or chatter (false).
    pub stable: bool,
    /// Observed chatter frequency; only where `stable` is false.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chatter_hz: Option<f64>,
    /// Order in which the cuts were made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<i64>,
    /// Overrides the model's radial immersion for this cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_immersion: Option<f64>,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// The numbers behind a verdict made by chatter detection (`chatter detect`); absent for
    /// cuts labelled by hand.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub evidence: Option<CutEvidence>,
}

/// Why chatter detection called a cut stable or chatter: the strongest line that is not a
/// harmonic of the spindle frequency and the statistics of its power (criterion and thresholds
/// in `chatter_oma::detection`).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CutEvidence {
    /// Spindle frequency the harmonics were taken from, after refinement (Hz).
    pub fundamental_hz: f64,
    /// Frequency of the strongest non-synchronous line (Hz).
    pub line_hz: f64,
    /// Coefficient of variation V of the line's share of the power over short segments: near 0
    /// for a limit cycle, about 1 for a resonance driven by random forces.
    pub line_variation: f64,
    /// Distance of V to the nearer threshold: positive for chatter.
    pub margin: f64,
    /// Line power over the forced (synchronous) power (dB).
    pub line_to_forced_db: f64,
    /// Line peak density over the median density of the non-synchronous bins (dB).
    pub line_to_floor_db: f64,
    /// Line power over everything else in the band (dB).
    pub line_to_rest_db: f64,
    /// Frequency bin width of the spectrum (Hz).
    pub resolution_hz: f64,
}

/// A dominant closed-loop pole identified from a stable cut.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PoleObservation {
    /// Spindle speed.
    pub speed_rpm: f64,
    /// Depth or width of cut.
    pub depth_mm: f64,
    /// Pole frequency (turning: physical; milling: principal frequency of the lifted multiplier).
    pub frequency_hz: f64,
    /// Pole damping ratio.
    pub damping_ratio: f64,
    /// Standard deviation of the frequency over repetitions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency_std_hz: Option<f64>,
    /// Standard deviation of the damping ratio over repetitions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping_std: Option<f64>,
    /// Number of repeated identifications.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repetitions: Option<u32>,
    /// Order of the cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<i64>,
    /// Per-entry radial immersion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_immersion: Option<f64>,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A measured vibration record.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SignalRecord {
    /// File relative to the observations file (CSV or WAV).
    pub file: PathBuf,
    /// Spindle speed.
    pub speed_rpm: f64,
    /// Depth or width of cut.
    pub depth_mm: f64,
    /// Sample rate (a WAV file's own rate wins).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_rate_hz: Option<f64>,
    /// Name of a tachometer channel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub once_per_rev_channel: Option<String>,
    /// `acceleration`, `velocity`, `displacement` or `sound`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantity: Option<String>,
    /// Order of the cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<i64>,
    /// Per-entry radial immersion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_immersion: Option<f64>,
    /// Free text.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// All observations of one campaign. Every section is optional, but not all may be empty.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Observations {
    /// Test cuts.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cuts: Vec<Cut>,
    /// Identified poles.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub poles: Vec<PoleObservation>,
    /// Vibration records; their `file` is resolved against the observations file's folder.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub signals: Vec<SignalRecord>,
}

const QUANTITIES: [&str; 4] = ["acceleration", "velocity", "displacement", "sound"];

fn check_speed_depth(section: &str, i: usize, speed_rpm: f64, depth_mm: f64) -> Result<()> {
    if !(speed_rpm.is_finite() && speed_rpm > 0.0) {
        return Err(DynamicsError::value(
            format!("{section}[{i}].speed_rpm"),
            speed_rpm,
            "a spindle speed > 0 rpm",
        ));
    }
    if !(depth_mm.is_finite() && depth_mm > 0.0) {
        return Err(DynamicsError::value(
            format!("{section}[{i}].depth_mm"),
            depth_mm,
            "a depth > 0 mm",
        ));
    }
    Ok(())
}

fn check_immersion(section: &str, i: usize, r: Option<f64>) -> Result<()> {
    match r {
        Some(r) if !(r.is_finite() && r > 0.0 && r <= 1.0) => Err(DynamicsError::value(
            format!("{section}[{i}].radial_immersion"),
            r,
            "a fraction of the diameter in (0, 1]",
        )),
        _ => Ok(()),
    }
}

impl Observations {
    /// Check every entry; an observations set with no entries at all is an error.
    pub fn validate(&self) -> Result<()> {
        if self.cuts.is_empty() && self.poles.is_empty() && self.signals.is_empty() {
            return Err(DynamicsError::invalid(
                "observations",
                "empty: expected at least one entry in `cuts`, `poles` or `signals`",
            ));
        }
        for (i, c) in self.cuts.iter().enumerate() {
            check_speed_depth("cuts", i, c.speed_rpm, c.depth_mm)?;
            check_immersion("cuts", i, c.radial_immersion)?;
            if let Some(f) = c.chatter_hz {
                if c.stable {
                    return Err(DynamicsError::invalid(
                        format!("cuts[{i}].chatter_hz"),
                        "given for a stable cut; chatter_hz is only for stable = false",
                    ));
                }
                if !(f.is_finite() && f > 0.0) {
                    return Err(DynamicsError::value(
                        format!("cuts[{i}].chatter_hz"),
                        f,
                        "a frequency > 0 Hz",
                    ));
                }
            }
        }
        for (i, p) in self.poles.iter().enumerate() {
            check_speed_depth("poles", i, p.speed_rpm, p.depth_mm)?;
            check_immersion("poles", i, p.radial_immersion)?;
            if !(p.frequency_hz.is_finite() && p.frequency_hz > 0.0) {
                return Err(DynamicsError::value(
                    format!("poles[{i}].frequency_hz"),
                    p.frequency_hz,
                    "a frequency > 0 Hz",
                ));
            }
            if !(p.damping_ratio.is_finite() && p.damping_ratio > -1.0 && p.damping_ratio < 1.0) {
                return Err(DynamicsError::value(
                    format!("poles[{i}].damping_ratio"),
                    p.damping_ratio,
                    "a damping ratio in (-1, 1)",
                ));
            }
            for (name, v) in [
                ("frequency_std_hz", p.frequency_std_hz),
                ("damping_std", p.damping_std),
            ] {
                if let Some(v) = v
                    && !(v.is_finite() && v >= 0.0)
                {
                    return Err(DynamicsError::value(
                        format!("poles[{i}].{name}"),
                        v,
                        "a standard deviation >= 0",
                    ));
                }
            }
        }
        for (i, s) in self.signals.iter().enumerate() {
            check_speed_depth("signals", i, s.speed_rpm, s.depth_mm)?;
            check_immersion("signals", i, s.radial_immersion)?;
            if let Some(fs) = s.sample_rate_hz
                && !(fs.is_finite() && fs > 0.0)
            {
                return Err(DynamicsError::value(
                    format!("signals[{i}].sample_rate_hz"),
                    fs,
                    "a sample rate > 0 Hz",
                ));
            }
            if let Some(q) = &s.quantity
                && !QUANTITIES.contains(&q.as_str())
            {
                return Err(DynamicsError::invalid(
                    format!("signals[{i}].quantity"),
                    format!("`{q}`: expected one of {QUANTITIES:?}"),
                ));
            }
        }
        Ok(())
    }

    /// Parse and validate observations from JSON text; `origin` names the source in errors and
    /// its folder resolves signal files.
    pub fn from_json_str(text: &str, origin: &Path) -> Result<Self> {
        if text.trim().is_empty() {
            return Err(DynamicsError::Parse {
                path: origin.to_path_buf(),
                message: "empty file: expected a JSON observations object".into(),
            });
        }
        let mut obs: Observations =
            serde_json::from_str(text).map_err(|e| DynamicsError::Parse {
                path: origin.to_path_buf(),
                message: e.to_string(),
            })?;
        obs.validate().map_err(|e| e.in_file(origin))?;
        let dir = origin.parent().unwrap_or(Path::new(""));
        for s in &mut obs.signals {
            if s.file.is_relative() {
                s.file = dir.join(&s.file);
            }
        }
        Ok(obs)
    }

    /// Read observations: JSON, or a cutting-test table when the name ends in `.csv`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| DynamicsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
        {
            Self::from_cuts_csv(&text, path)
        } else {
            Self::from_json_str(&text, path)
        }
    }

    /// Parse a cutting-test table `speed_rpm,depth_mm,stable,chatter_hz[,sequence]`.
    pub fn from_cuts_csv(text: &str, origin: &Path) -> Result<Self> {
        let parse_err = |message: String| DynamicsError::Parse {
            path: origin.to_path_buf(),
            message,
        };
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| parse_err(e.to_string()))?
            .iter()
            .map(str::to_string)
            .collect();
        let expected = ["speed_rpm", "depth_mm", "stable", "chatter_hz"];
        let ok = header.len() >= 4
            && header.len() <= 5
            && header[..4].iter().zip(expected).all(|(h, e)| h == e)
            && (header.len() == 4 || header[4] == "sequence");
        if !ok {
            return Err(parse_err(format!(
                "header is `{}`; expected `speed_rpm,depth_mm,stable,chatter_hz` optionally \
                 followed by `sequence`",
                header.join(",")
            )));
        }
        let mut cuts = Vec::new();
        for (row, record) in reader.records().enumerate() {
            let line = row + 2;
            let record = record.map_err(|e| parse_err(format!("line {line}: {e}")))?;
            let field = |i: usize| record.get(i).unwrap_or("");
            let number = |i: usize| -> Result<f64> {
                field(i).parse::<f64>().map_err(|_| {
                    parse_err(format!(
                        "line {line}, column `{}`: `{}` is not a number",
                        header[i],
                        field(i)
                    ))
                })
            };
            let stable = match field(2) {
                "true" | "1" => true,
                "false" | "0" => false,
                other => {
                    return Err(parse_err(format!(
                        "line {line}, column `stable`: `{other}`; expected true/false or 1/0"
                    )));
                }
            };
            let chatter_hz = if field(3).is_empty() {
                None
            } else {
                Some(number(3)?)
            };
            let sequence = if header.len() == 5 && !field(4).is_empty() {
                Some(field(4).parse::<i64>().map_err(|_| {
                    parse_err(format!(
                        "line {line}, column `sequence`: `{}` is not an integer",
                        field(4)
                    ))
                })?)
            } else {
                None
            };
            cuts.push(Cut {
                speed_rpm: number(0)?,
                depth_mm: number(1)?,
                stable,
                chatter_hz,
                sequence,
                radial_immersion: None,
                note: None,
                evidence: None,
            });
        }
        let obs = Observations {
            cuts,
            ..Default::default()
        };
        obs.validate().map_err(|e| e.in_file(origin))?;
        Ok(obs)
    }

    /// Pretty JSON in the formats-spec shape.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}
