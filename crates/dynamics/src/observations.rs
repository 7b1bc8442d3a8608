//! The observations file of `shared/spec/formats.md`: test cuts, identified poles and signal
//! records, plus cutting-test tables as CSV (`speed_rpm,depth_mm,stable,chatter_hz[,sequence]`).

use crate::error::{DynamicsError, Result};
use crate::limits;
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

impl Cut {
    /// A cut labelled stable or chatter by hand, with none of the optional fields (no chatter
    /// frequency, order, immersion override, note or detection evidence).
    pub fn labelled(speed_rpm: f64, depth_mm: f64, stable: bool) -> Self {
        Self {
            speed_rpm,
            depth_mm,
            stable,
            chatter_hz: None,
            sequence: None,
            radial_immersion: None,
            note: None,
            evidence: None,
        }
    }
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
    limits::SPEED_RPM.check(format!("{section}[{i}].speed_rpm"), speed_rpm)?;
    limits::DEPTH_MM.check(format!("{section}[{i}].depth_mm"), depth_mm)?;
    Ok(())
}

fn check_immersion(section: &str, i: usize, r: Option<f64>) -> Result<()> {
    limits::RADIAL_IMMERSION.check_optional(format!("{section}[{i}].radial_immersion"), r)
}

impl PoleObservation {
    /// Ranges of entry `i` ([`crate::limits`]): a pole from a stable cut is damped
    /// (0 <= zeta < 1) and its standard deviations, which scale the likelihood, are > 0.
    fn validate(&self, i: usize) -> Result<()> {
        let field = |f: &str| format!("poles[{i}].{f}");
        check_speed_depth("poles", i, self.speed_rpm, self.depth_mm)?;
        check_immersion("poles", i, self.radial_immersion)?;
        limits::OBSERVED_FREQUENCY_HZ.check(field("frequency_hz"), self.frequency_hz)?;
        limits::POLE_DAMPING_RATIO.check(field("damping_ratio"), self.damping_ratio)?;
        limits::STANDARD_DEVIATION
            .check_optional(field("frequency_std_hz"), self.frequency_std_hz)?;
        limits::STANDARD_DEVIATION.check_optional(field("damping_std"), self.damping_std)?;
        if self.repetitions == Some(0) {
            return Err(DynamicsError::value(
                field("repetitions"),
                0.0,
                "at least 1 identification",
            ));
        }
        Ok(())
    }

    /// Whether two entries describe the same identification (same cut, same pole).
    fn same_as(&self, other: &Self) -> bool {
        self.speed_rpm == other.speed_rpm
            && self.depth_mm == other.depth_mm
            && self.frequency_hz == other.frequency_hz
            && self.damping_ratio == other.damping_ratio
            && self.radial_immersion == other.radial_immersion
    }
}

/// A validation error of a cuts table with the CSV line (header on line 1) before the entry:
/// `line 3, cuts[1].depth_mm`.
fn csv_line(error: DynamicsError) -> DynamicsError {
    let line = |field: &str| {
        field
            .strip_prefix("cuts[")
            .and_then(|rest| rest.split(']').next())
            .and_then(|i| i.parse::<usize>().ok())
            .map_or_else(|| field.to_string(), |i| format!("line {}, {field}", i + 2))
    };
    match error {
        DynamicsError::InvalidValue {
            field,
            value,
            expected,
        } => DynamicsError::InvalidValue {
            field: line(&field),
            value,
            expected,
        },
        DynamicsError::Invalid { field, message } => DynamicsError::Invalid {
            field: line(&field),
            message,
        },
        other => other,
    }
}

impl Observations {
    /// The spindle speeds (rpm) of the cuts, then of the poles, in file order.
    pub fn speeds_rpm(&self) -> Vec<f64> {
        self.cuts
            .iter()
            .map(|c| c.speed_rpm)
            .chain(self.poles.iter().map(|p| p.speed_rpm))
            .collect()
    }

    /// Check every entry; an observations set with no entries at all is an error, and so is a
    /// pole given twice (it would count twice in the likelihood).
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
                limits::OBSERVED_FREQUENCY_HZ.check(format!("cuts[{i}].chatter_hz"), f)?;
            }
        }
        for (i, p) in self.poles.iter().enumerate() {
            p.validate(i)?;
            if let Some(j) = self.poles[..i].iter().position(|q| q.same_as(p)) {
                return Err(DynamicsError::invalid(
                    format!("poles[{i}]"),
                    format!(
                        "repeats poles[{j}] (same speed, depth, frequency and damping): a pole \
                         given twice counts twice; give repeated identifications as one entry \
                         with `frequency_std_hz`, `damping_std` and `repetitions`"
                    ),
                ));
            }
        }
        for (i, s) in self.signals.iter().enumerate() {
            check_speed_depth("signals", i, s.speed_rpm, s.depth_mm)?;
            check_immersion("signals", i, s.radial_immersion)?;
            limits::SAMPLE_RATE_HZ
                .check_optional(format!("signals[{i}].sample_rate_hz"), s.sample_rate_hz)?;
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

    /// Whether these observations can come from the operation of `model`: a turning model
    /// takes no `radial_immersion` (a milling quantity), and a milling pole's `frequency_hz` is
    /// the principal frequency of the multiplier lifted at the tooth period, so it lies in
    /// [0, f_tp / 2] with f_tp the tooth-passing frequency (002 Section 2.1); a larger value is a
    /// physical frequency, as turning observations give.
    pub fn check_against(&self, model: &crate::ModalModel) -> Result<()> {
        let immersions = self
            .cuts
            .iter()
            .map(|c| ("cuts", c.radial_immersion))
            .chain(self.poles.iter().map(|p| ("poles", p.radial_immersion)))
            .chain(self.signals.iter().map(|s| ("signals", s.radial_immersion)));
        match model.operation() {
            crate::Operation::Turning(_) => {
                let mut index = std::collections::BTreeMap::<&str, usize>::new();
                for (section, r) in immersions {
                    let i = index.entry(section).or_default();
                    if r.is_some() {
                        return Err(DynamicsError::invalid(
                            format!("{section}[{i}].radial_immersion"),
                            "a milling quantity, but the model is turning: are these milling \
                             observations?",
                        ));
                    }
                    *i += 1;
                }
            }
            crate::Operation::Milling(m) => {
                for (i, p) in self.poles.iter().enumerate() {
                    let half_tooth_passing_hz = p.speed_rpm / 60.0 * m.teeth() as f64 / 2.0;
                    // 10 % slack: a principal frequency near the edge plus identification
                    // scatter; a physical frequency is many times above it
                    if p.frequency_hz > 1.1 * half_tooth_passing_hz {
                        return Err(DynamicsError::value(
                            format!("poles[{i}].frequency_hz"),
                            p.frequency_hz,
                            format!(
                                "for the {}-tooth milling model a principal frequency of the \
                                 lifted multiplier, at most half the tooth-passing frequency \
                                 ({} Hz at {} rpm); a physical frequency like this one comes \
                                 from turning observations or an OMA without the milling model",
                                m.teeth(),
                                crate::limits::written(
                                    (half_tooth_passing_hz * 100.0).round() / 100.0
                                ),
                                crate::limits::written(p.speed_rpm)
                            ),
                        ));
                    }
                }
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
        if let Some(kind) = crate::model_file::non_object(text) {
            return Err(DynamicsError::Parse {
                path: origin.to_path_buf(),
                message: format!(
                    "the file holds {kind}; expected a JSON observations object {{\"cuts\": \
                     [...], \"poles\": [...], \"signals\": [...]}}"
                ),
            });
        }
        let mut obs: Observations = crate::model_file::from_json(text, origin)?;
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
        obs.validate().map_err(|e| csv_line(e).in_file(origin))?;
        Ok(obs)
    }

    /// Pretty JSON in the formats-spec shape.
    pub fn to_json_string(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

#[cfg(test)]
mod tests {
    use crate::examples;

    #[test]
    fn observations_are_checked_against_the_operation_of_the_model() {
        let turning = examples::ahmadi_2022_turning_observations();
        let milling = examples::ebrahimi_2025_milling_observations();
        assert!(
            turning
                .check_against(&examples::ahmadi_2022_turning())
                .is_ok()
        );
        assert!(
            milling
                .check_against(&examples::ebrahimi_2025_milling())
                .is_ok()
        );
        // 2473 Hz at 7150 rpm is far above half the tooth-passing frequency of 4 teeth (238 Hz)
        let e = turning
            .check_against(&examples::schmitz_2023_milling())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("poles[0].frequency_hz") && e.contains("2473"),
            "{e}"
        );
        let mut with_immersion = milling.clone();
        with_immersion.cuts[0].radial_immersion = Some(0.5);
        let e = with_immersion
            .check_against(&examples::ahmadi_2022_turning())
            .unwrap_err()
            .to_string();
        assert!(e.contains("cuts[0].radial_immersion"), "{e}");
    }
}
