//! The sensitivity job (`chatter sensitivity`, `chatter.sensitivity`): |d mu / d theta| of the
//! dominant pole at one cut (000 Section 6.2, Eq. 15, Table 3), on the one-step map of the full
//! discretization by default ([`chatter_uncertainty::sensitivity::pole_sensitivity`]).

use crate::error::{JobError, Result};
use chatter_dynamics::{ModalModel, Parameter};
use chatter_uncertainty::sensitivity::{
    PoleSensitivity, TABLE3_STEPS_PER_REVOLUTION, TransitionMap, pole_sensitivity,
};
use std::num::NonZeroUsize;

/// The options of a sensitivity job in user units, with their defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityRequest {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth (milling) or width (turning) of cut (mm).
    pub depth_mm: f64,
    /// Parameter names (`theta_omega_N`, `theta_zeta_N`, `theta_phi_N`, `theta_k_N`); `None`:
    /// omega, zeta and phi of every mode (the rows of 000 Table 3).
    pub parameters: Option<Vec<String>>,
    /// Full-discretization steps per revolution (per tooth period in milling); default
    /// [`TABLE3_STEPS_PER_REVOLUTION`] (200, as in 000 Table 3).
    pub steps_per_revolution: usize,
    /// The differentiated map; default the one-step map of 000 Table 3.
    pub map: TransitionMap,
}

impl SensitivityRequest {
    /// The request at one cut with the defaults of 000 Table 3.
    pub fn new(speed_rpm: f64, depth_mm: f64) -> Self {
        Self {
            speed_rpm,
            depth_mm,
            parameters: None,
            steps_per_revolution: TABLE3_STEPS_PER_REVOLUTION.get(),
            map: TransitionMap::OneStep,
        }
    }
}

/// The map named `one-step` or `period` (the CLI's `--map` values, Python's `map`).
pub fn transition_map(name: &str) -> Result<TransitionMap> {
    match name {
        "one-step" => Ok(TransitionMap::OneStep),
        "period" => Ok(TransitionMap::Period),
        _ => Err(JobError::NotOneOf {
            what: "map",
            value: name.into(),
            known: vec!["one-step".into(), "period".into()],
        }),
    }
}

/// A checked sensitivity job on one model.
#[derive(Debug, Clone)]
pub struct Sensitivity<'a> {
    model: &'a ModalModel,
    speed_rpm: f64,
    depth_mm: f64,
    parameters: Vec<Parameter>,
    steps_per_revolution: NonZeroUsize,
    map: TransitionMap,
}

/// The parameters named in `names`, each of a mode of the model (`modes` of them); `None`:
/// omega, zeta and phi of every mode.
fn parameters(names: Option<&[String]>, modes: usize) -> Result<Vec<Parameter>> {
    let Some(names) = names else {
        return ["omega", "zeta", "phi"]
            .iter()
            .flat_map(|k| (1..=modes).map(move |n| format!("theta_{k}_{n}")))
            .map(|n| n.parse::<Parameter>().map_err(JobError::from))
            .collect();
    };
    let spec = format!("`{}`", names.join(","));
    let invalid = |expected: String| JobError::Invalid {
        field: "parameters",
        value: spec.clone(),
        expected,
    };
    let parsed = names
        .iter()
        .map(|n| n.trim())
        .filter(|n| !n.is_empty())
        .map(|n| {
            n.parse::<Parameter>().map_err(|_| {
                invalid(format!(
                    "parameter names theta_omega_N, theta_zeta_N, theta_phi_N or theta_k_N \
                     with N the 1-based mode index (`{n}` is not one)"
                ))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    if parsed.is_empty() {
        return Err(invalid("at least one parameter name".into()));
    }
    if let Some(bad) = parsed.iter().find(|q| q.mode >= modes) {
        return Err(invalid(format!(
            "parameters of modes 1 to {modes} (mode {} does not exist)",
            bad.mode + 1
        )));
    }
    Ok(parsed)
}

impl<'a> Sensitivity<'a> {
    /// Check `request` against `model`: a speed and a depth > 0, at least 2 steps per
    /// revolution, parameters of existing modes.
    pub fn new(model: &'a ModalModel, request: &SensitivityRequest) -> Result<Self> {
        if !(request.speed_rpm.is_finite() && request.speed_rpm > 0.0) {
            return Err(JobError::Invalid {
                field: "speed_rpm",
                value: request.speed_rpm.to_string(),
                expected: "a speed > 0".into(),
            });
        }
        if !(request.depth_mm.is_finite() && request.depth_mm > 0.0) {
            return Err(JobError::Invalid {
                field: "depth_mm",
                value: request.depth_mm.to_string(),
                expected: "a depth > 0".into(),
            });
        }
        let steps_per_revolution = NonZeroUsize::new(request.steps_per_revolution)
            .filter(|m| m.get() >= 2)
            .ok_or_else(|| JobError::Invalid {
                field: "steps_per_revolution",
                value: request.steps_per_revolution.to_string(),
                expected: "at least 2".into(),
            })?;
        Ok(Self {
            model,
            speed_rpm: request.speed_rpm,
            depth_mm: request.depth_mm,
            parameters: parameters(request.parameters.as_deref(), model.mode_count())?,
            steps_per_revolution,
            map: request.map,
        })
    }

    /// Eq. 15 at the cut.
    pub fn run(&self) -> Result<SensitivityOutcome> {
        Ok(SensitivityOutcome {
            speed_rpm: self.speed_rpm,
            depth_mm: self.depth_mm,
            sensitivity: pole_sensitivity(
                self.model,
                &self.parameters,
                self.speed_rpm,
                self.depth_mm * 1e-3,
                self.steps_per_revolution,
                self.map,
            )?,
        })
    }
}

/// The outcome of a sensitivity job: the cut and the dominant pole's gradient.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityOutcome {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Depth or width of cut (mm).
    pub depth_mm: f64,
    /// The dominant eigenvalue of the map and d mu / d theta per parameter.
    pub sensitivity: PoleSensitivity,
}

impl SensitivityOutcome {
    /// The outcome as the JSON document of `chatter sensitivity` (and the dict of Python's
    /// `chatter.sensitivity`).
    pub fn to_json(&self) -> serde_json::Value {
        let s = &self.sensitivity;
        let entries: Vec<_> = s
            .entries
            .iter()
            .map(|e| {
                serde_json::json!({
                    "parameter": e.parameter.to_string(),
                    "modulus": e.modulus(),
                    "real": e.derivative.re,
                    "imag": e.derivative.im,
                })
            })
            .collect();
        serde_json::json!({
            "speed_rpm": self.speed_rpm,
            "depth_mm": self.depth_mm,
            "map": s.map,
            "map_description": match s.map {
                TransitionMap::OneStep => "dominant eigenvalue of the one-step map of the full \
                    discretization (000 Eq. 9-12), as in 000 Table 3",
                TransitionMap::Period => "dominant multiplier over one delay period (the \
                    monodromy whose |mu| = 1 is the stability boundary)",
            },
            "steps_per_delay": s.steps_per_delay,
            "eigenvalue": {"real": s.eigenvalue.re, "imag": s.eigenvalue.im, "modulus": s.eigenvalue.norm()},
            "period_multiplier_modulus": s.period_multiplier.norm(),
            "chatter_hz": s.chatter_hz,
            "sensitivities": entries,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lathe() -> ModalModel {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/ahmadi2022_turning_model.json"
        );
        ModalModel::from_path(std::path::Path::new(path)).unwrap()
    }

    #[test]
    fn bad_options_name_the_field_and_value() {
        let model = lathe();
        let mut r = SensitivityRequest::new(-5.0, 2.0);
        let e = Sensitivity::new(&model, &r).unwrap_err().to_string();
        assert_eq!(e, "speed_rpm -5: expected a speed > 0");
        r.speed_rpm = 7150.0;
        r.steps_per_revolution = 1;
        let e = Sensitivity::new(&model, &r).unwrap_err().to_string();
        assert_eq!(e, "steps_per_revolution 1: expected at least 2");
        r.steps_per_revolution = 200;
        r.parameters = Some(vec!["theta_omega_9".into()]);
        let e = Sensitivity::new(&model, &r).unwrap_err().to_string();
        assert!(e.starts_with("parameters `theta_omega_9`: expected parameters of modes 1 to"));
        r.parameters = Some(vec![" ".into()]);
        assert!(Sensitivity::new(&model, &r).is_err());
        assert!(transition_map("monodromy").is_err());
    }

    /// The default parameters are omega, zeta and phi of every mode, in that order, the rows
    /// of 000 Table 3 (the names parsed back independently of the job's list).
    #[test]
    fn default_parameters_are_table3_rows() {
        let model = lathe();
        let p = parameters(None, model.mode_count()).unwrap();
        let names: Vec<String> = p.iter().map(ToString::to_string).collect();
        assert_eq!(names.len(), 3 * model.mode_count());
        assert_eq!(names[0], "theta_omega_1");
        assert_eq!(names[model.mode_count()], "theta_zeta_1");
        assert_eq!(names[2 * model.mode_count()], "theta_phi_1");
    }
}
