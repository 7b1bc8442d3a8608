//! The checks every request applies once, in the units the user wrote, before any work starts:
//! ranges of the options (reusing the ranges of file contents, `chatter_dynamics::limits`), the
//! cost guard on the discretizations ([`MAX_STEPS_PER_DELAY`]) and options that the chosen kind
//! would ignore. A request type runs them in its checked constructor (the checked-parameters
//! pattern of linfa's `ParamGuard`): what a job receives has passed them, whichever front end
//! built it.
//!
//! Errors name the request field (`speed_rpm`, `offset_mm`: the Python keyword; the CLI reports
//! it as its option `--speed-rpm`) and the value as written.

use crate::error::{JobError, Result};
use chatter_dynamics::limits::{Plausible, SPEED_RPM, closed, written};
use chatter_dynamics::{ModalModel, Observations};
use chatter_stability::monodromy::Discretization;

/// Most cutting steps per delay a discretization may use. The cost of one multiplier grows as
/// the square of the steps (measured on the seed-000 turning model, debug build: 1 400 steps
/// 0.5 s, 5 000 steps 2.9 s, 10 000 steps 11 s), and a lobe diagram needs thousands of
/// multipliers, so beyond this a run is a hang in all but name.
pub const MAX_STEPS_PER_DELAY: usize = 10_000;

/// Depths of a depth grid given by the user (zero allowed as its first value).
pub const DEPTH_GRID_MM: Plausible = closed(0.0, 1000.0, "a depth of cut", "mm");

/// `value` of `field` when `range` holds it, else [`JobError::Invalid`] with the value written
/// as a user would write it.
pub fn in_range(field: &'static str, value: f64, range: &Plausible) -> Result<f64> {
    if range.contains(value) {
        Ok(value)
    } else {
        Err(JobError::Invalid {
            field,
            value: written(value),
            expected: range.expected(),
        })
    }
}

/// A non-empty list of values of `field`, each within `range`.
pub fn all_in_range(field: &'static str, values: &[f64], range: &Plausible) -> Result<()> {
    if values.is_empty() {
        return Err(JobError::Invalid {
            field,
            value: "[]".into(),
            expected: format!("at least one value: {}", range.expected()),
        });
    }
    for &v in values {
        in_range(field, v, range)?;
    }
    Ok(())
}

/// Spindle speeds (rpm) of `field`: non-empty and each plausible.
pub fn speeds(field: &'static str, speeds_rpm: &[f64]) -> Result<()> {
    all_in_range(field, speeds_rpm, &SPEED_RPM)
}

/// An option given where the chosen kind does not use it ([`JobError::Unused`]).
pub fn unused(given: bool, field: &'static str, context: &str, used_by: &str) -> Result<()> {
    if given {
        return Err(JobError::Unused {
            field,
            context: context.into(),
            used_by: used_by.into(),
        });
    }
    Ok(())
}

/// Refuse speeds at which `method` would need more than [`MAX_STEPS_PER_DELAY`] steps per delay
/// (the step count grows as 1 / speed); `field` names where the speeds came from.
pub fn work_size(
    model: &ModalModel,
    method: Discretization,
    speeds_rpm: &[f64],
    field: &str,
) -> Result<()> {
    let Some(&slowest) = speeds_rpm.iter().min_by(|a, b| a.total_cmp(b)) else {
        return Ok(());
    };
    let steps = method.steps_at(model, slowest).get();
    if steps > MAX_STEPS_PER_DELAY {
        // steps per delay scale as 1 / speed
        let lowest = slowest * steps as f64 / MAX_STEPS_PER_DELAY as f64;
        return Err(JobError::TooManySteps {
            field: field.into(),
            speed_rpm: written(slowest),
            steps,
            lowest_rpm: written(lowest.ceil()),
        });
    }
    Ok(())
}

/// [`work_size`] at the speeds of the observations' cuts and poles, for the jobs that evaluate
/// the model there with the automatic full discretization; `source` names the observations.
pub fn observation_work_size(
    model: &ModalModel,
    observations: &Observations,
    source: &str,
) -> Result<()> {
    work_size(
        model,
        Discretization::full(),
        &observations.speeds_rpm(),
        "observations",
    )
    .map_err(|e| match e {
        JobError::TooManySteps {
            speed_rpm,
            steps,
            lowest_rpm,
            ..
        } => JobError::TooManySteps {
            field: format!("{source} (observed speeds)"),
            speed_rpm,
            steps,
            lowest_rpm,
        },
        other => other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::examples;

    /// The guard's step count is the discretization's own at the slowest speed: an independent
    /// count from the definition (steps per delay grow as 1 / speed, so halving the speed from
    /// the last accepted one must be refused once it doubles the steps beyond the limit).
    #[test]
    fn the_guard_refuses_the_slow_speeds_only() {
        let model = examples::ahmadi_2022_turning();
        let d = Discretization::full();
        assert!(work_size(&model, d, &[6000.0], "speeds").is_ok());
        let e = work_size(&model, d, &[100.0, 6000.0], "speeds").unwrap_err();
        let text = e.to_string();
        assert!(
            text.starts_with("speeds: at 100 rpm one delay needs"),
            "{text}"
        );
        let JobError::TooManySteps {
            steps, lowest_rpm, ..
        } = e
        else {
            panic!("not a step refusal")
        };
        assert_eq!(steps, d.steps_at(&model, 100.0).get());
        let lowest: f64 = lowest_rpm.parse().unwrap();
        assert!(d.steps_at(&model, lowest).get() <= MAX_STEPS_PER_DELAY);
    }

    #[test]
    fn ranges_name_the_field_and_the_value() {
        let e = in_range("depth_mm", -1.0, &chatter_dynamics::limits::DEPTH_MM)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("depth_mm -1: expected a depth of cut"), "{e}");
        assert!(speeds("speeds_rpm", &[]).is_err());
    }
}
