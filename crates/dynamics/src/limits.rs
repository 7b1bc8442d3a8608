//! Physical plausibility ranges of the file formats, in the units the files use.
//!
//! Every number a user writes in a model or observations file is checked against a range that
//! holds every machine tool this toolkit is for, with a margin of orders of magnitude, so that a
//! typo (a missing exponent, a sign, degrees for radians) is an error that names the field and
//! echoes the value as written, instead of a NaN lobe or an allocation of terabytes downstream.
//! The ranges are deliberately wide: they catch nonsense, not unusual machines.
//!
//! The bounds are judgement, not a table: orders of magnitude around what machine tools do
//! (spindles up to some 2e5 rpm, structural modes of tool, holder, spindle and workpiece from
//! about 1 Hz to tens of kHz, specific cutting forces of metals of hundreds to thousands of
//! N/mm^2, milling cutters with 1 to about 100 teeth), widened so that no real machine is
//! refused.
//!
//! ```
//! use chatter_dynamics::limits::{FREQUENCY_HZ, written};
//! assert!(FREQUENCY_HZ.check("modes[0].frequency_hz", 750.0).is_ok());
//! let e = FREQUENCY_HZ.check("modes[0].frequency_hz", 1e300).unwrap_err();
//! assert!(e.to_string().contains("1e300"));
//! assert_eq!(written(-750.0), "-750");
//! ```

use crate::error::{DynamicsError, Result};

/// A closed or half-open interval of plausible values of one quantity, with its unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plausible {
    /// Lower bound.
    pub min: f64,
    /// Whether the lower bound itself is allowed.
    pub min_included: bool,
    /// Upper bound.
    pub max: f64,
    /// Whether the upper bound itself is allowed.
    pub max_included: bool,
    /// What the quantity is, in words ("a natural frequency").
    pub what: &'static str,
    /// Unit as written in the file ("Hz"), empty when dimensionless.
    pub unit: &'static str,
}

impl Plausible {
    /// Whether `value` is finite and inside the range.
    pub fn contains(&self, value: f64) -> bool {
        value.is_finite()
            && (value > self.min || (self.min_included && value == self.min))
            && (value < self.max || (self.max_included && value == self.max))
    }

    /// What was expected, e.g. `a natural frequency in [0.1, 100000] Hz`.
    pub fn expected(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!(
            "{} in {}{}, {}{}{unit}",
            self.what,
            if self.min_included { "[" } else { "(" },
            written(self.min),
            written(self.max),
            if self.max_included { "]" } else { ")" },
        )
    }

    /// `value` when plausible, else an [`DynamicsError::InvalidValue`] naming `field`.
    pub fn check(&self, field: impl Into<String>, value: f64) -> Result<f64> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(DynamicsError::value(field, value, self.expected()))
        }
    }

    /// [`Plausible::check`] of an optional value.
    pub fn check_optional(&self, field: impl Into<String>, value: Option<f64>) -> Result<()> {
        value.map_or(Ok(()), |v| self.check(field, v).map(|_| ()))
    }
}

/// The interval (min, max] of `what` in `unit`.
pub const fn open_closed(min: f64, max: f64, what: &'static str, unit: &'static str) -> Plausible {
    Plausible {
        min,
        min_included: false,
        max,
        max_included: true,
        what,
        unit,
    }
}

/// The interval [min, max] of `what` in `unit`.
pub const fn closed(min: f64, max: f64, what: &'static str, unit: &'static str) -> Plausible {
    Plausible {
        min,
        min_included: true,
        max,
        max_included: true,
        what,
        unit,
    }
}

/// Natural frequency of a structural mode.
pub const FREQUENCY_HZ: Plausible = closed(0.1, 1e5, "a natural frequency", "Hz");
/// Damping ratio of a structural mode (underdamped; zero damping is a valid limit case).
pub const DAMPING_RATIO: Plausible = Plausible {
    min: 0.0,
    min_included: true,
    max: 1.0,
    max_included: false,
    what: "an underdamped damping ratio",
    unit: "",
};
/// Modal stiffness, given or implied by a mass-normalized shape (omega^2 / phi^2). Very stiff
/// modes (1e12 N/m) are valid and give deep limits.
pub const STIFFNESS_N_PER_M: Plausible = closed(1e2, 1e13, "a modal stiffness", "N/m");
/// Tangential (cutting) or resultant specific cutting-force coefficient.
pub const CUTTING_COEFFICIENT_N_PER_MM2: Plausible =
    open_closed(0.0, 1e5, "a specific cutting-force coefficient", "N/mm^2");
/// Normal (milling) or feed (turning) coefficient; may be negative (small rake angles).
pub const NORMAL_COEFFICIENT_N_PER_MM2: Plausible = closed(
    -1e5,
    1e5,
    "a normal or feed cutting-force coefficient",
    "N/mm^2",
);
/// Angle of the resultant cutting force from the normal, so that kt = ks sin(beta) > 0.
pub const BETA_DEG: Plausible = Plausible {
    min: 0.0,
    min_included: false,
    max: 180.0,
    max_included: false,
    what: "a force angle",
    unit: "deg",
};
/// Most teeth of a milling cutter.
pub const MAX_TEETH: i64 = 1000;
/// Tool diameter.
pub const TOOL_DIAMETER_MM: Plausible = open_closed(0.0, 2000.0, "a tool diameter", "mm");
/// Workpiece diameter (turning).
pub const WORKPIECE_DIAMETER_MM: Plausible =
    open_closed(0.0, 10_000.0, "a workpiece diameter", "mm");
/// Most axial slices of a helical cutter's depth (each slice is one delayed input per tooth).
pub const MAX_AXIAL_SLICES: i64 = 1000;
/// Helix angle of a milling cutter.
pub const HELIX_DEG: Plausible = Plausible {
    min: 0.0,
    min_included: true,
    max: 90.0,
    max_included: false,
    what: "a helix angle",
    unit: "deg",
};
/// Process-damping coefficient C of F_d = -C b ydot / V.
pub const PROCESS_DAMPING_N_PER_M: Plausible =
    closed(0.0, 1e10, "a process-damping coefficient", "N/m");
/// Spindle speed of a cut.
pub const SPEED_RPM: Plausible = closed(1.0, 1e6, "a spindle speed", "rpm");
/// Axial depth (milling) or width (turning) of a cut.
pub const DEPTH_MM: Plausible = open_closed(0.0, 1000.0, "a depth of cut", "mm");
/// An observed chatter or pole frequency.
pub const OBSERVED_FREQUENCY_HZ: Plausible = open_closed(0.0, 1e6, "a frequency", "Hz");
/// Damping ratio of a pole identified from a stable cut (a stable cut's poles are damped).
pub const POLE_DAMPING_RATIO: Plausible = Plausible {
    min: 0.0,
    min_included: true,
    max: 1.0,
    max_included: false,
    what: "the damping ratio of a pole from a stable cut",
    unit: "",
};
/// A standard deviation over repetitions (it scales a likelihood, so zero is not allowed).
pub const STANDARD_DEVIATION: Plausible = Plausible {
    min: 0.0,
    min_included: false,
    max: f64::MAX,
    max_included: true,
    what: "a standard deviation > 0",
    unit: "",
};
/// Sample rate of a signal record.
pub const SAMPLE_RATE_HZ: Plausible = open_closed(0.0, 1e8, "a sample rate", "Hz");
/// Radial immersion a/D.
pub const RADIAL_IMMERSION: Plausible = open_closed(0.0, 1.0, "a fraction of the diameter", "");

/// A number as a user would write it: integers without a decimal point, other values in the
/// shortest form that reads back to the same number (`1e300`, `0.05`, `-750`).
pub fn written(value: f64) -> String {
    if value == f64::MAX {
        return "inf".into();
    }
    if !(value.is_finite() && value.fract() == 0.0 && value.abs() < 1e16) {
        return format!("{value:?}");
    }
    let plain = format!("{value:.0}");
    let scientific = format!("{value:e}");
    if value.abs() >= 1e6 && scientific.len() < plain.len() {
        scientific
    } else {
        plain
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_reads_back_and_drops_the_trailing_point() {
        for (v, s) in [
            (-750.0, "-750"),
            (1e300, "1e300"),
            (0.05, "0.05"),
            (1e-6, "1e-6"),
            (0.0, "0"),
            (1e13, "1e13"),
            (1234567.0, "1234567"),
            (f64::NAN, "NaN"),
        ] {
            assert_eq!(written(v), s);
        }
    }

    #[test]
    fn bounds_are_honoured() {
        assert!(DAMPING_RATIO.contains(0.0));
        assert!(!DAMPING_RATIO.contains(1.0));
        assert!(RADIAL_IMMERSION.contains(1.0));
        assert!(!RADIAL_IMMERSION.contains(0.0));
        assert!(!FREQUENCY_HZ.contains(f64::INFINITY));
        assert_eq!(
            FREQUENCY_HZ.expected(),
            "a natural frequency in [0.1, 100000] Hz"
        );
    }
}
