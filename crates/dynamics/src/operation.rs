//! The machining operation: turning or milling, its coordinates and its cutting-force geometry.
//!
//! Coordinates are fixed per operation and always two: milling uses `x` (feed) and `y` (normal to
//! the feed in the cutting plane), turning uses `feed` (the direction that modulates chip
//! thickness) and `cutting` (tangential), as in `shared/spec/formats.md` and 000 Eq. 3.

use crate::error::{DynamicsError, Result, positive};
use std::f64::consts::PI;

/// A coordinate in which modes move and forces act.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Coordinate {
    /// Milling feed direction.
    X,
    /// Milling direction normal to the feed in the cutting plane.
    Y,
    /// Turning feed direction (modulates the chip thickness).
    Feed,
    /// Turning cutting (tangential) direction.
    Cutting,
}

impl Coordinate {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Coordinate::X => "x",
            Coordinate::Y => "y",
            Coordinate::Feed => "feed",
            Coordinate::Cutting => "cutting",
        }
    }
}

/// Up (conventional) or down (climb) milling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MillingDirection {
    /// Up milling: the tooth enters at phi = 0 and leaves at arccos(1 - 2 a/D).
    Up,
    /// Down milling: the tooth enters at arccos(2 a/D - 1) and leaves at phi = pi.
    Down,
}

/// Milling geometry: teeth, radial immersion, direction, diameter and, for a variable-pitch
/// cutter, the pitch angles.
///
/// # Pitch
/// Tooth j sits at the angle offset_j = sum_{i < j} pitch_i ahead of tooth 0 (phi_j(t) =
/// Omega t + offset_j), so the tooth that passes an angle just before tooth j is tooth j + 1
/// (mod N) and tooth j cuts the surface it left `pitch_j` earlier: tooth j's regenerative delay
/// is tau_j = pitch_j / Omega (Altintas, Engin & Budak 1999). With even pitch (the default,
/// `pitch_deg` absent) every pitch is 2 pi / N and offset_j = 2 pi j / N exactly as before.
#[derive(Debug, Clone, PartialEq)]
pub struct Milling {
    teeth: usize,
    radial_immersion: f64,
    direction: MillingDirection,
    tool_diameter_m: Option<f64>,
    helix_rad: Option<f64>,
    /// Pitch angles (rad) as given, one per tooth, summing to 2 pi; `None`: even pitch.
    pitch_rad: Option<Vec<f64>>,
}

/// Largest difference (deg) between the sum of `pitch_deg` and 360 that is accepted (rounding
/// in a file written to a few decimals); pitches within it of 360 / N count as even pitch.
pub const PITCH_SUM_TOLERANCE_DEG: f64 = 1e-6;

impl Milling {
    /// Validated milling geometry. `radial_immersion` is a/D in (0, 1].
    pub fn new(
        teeth: usize,
        radial_immersion: f64,
        direction: MillingDirection,
        tool_diameter_m: Option<f64>,
        helix_rad: Option<f64>,
    ) -> Result<Self> {
        if teeth == 0 {
            return Err(DynamicsError::value(
                "operation.teeth",
                0.0,
                "an integer >= 1",
            ));
        }
        if !(radial_immersion.is_finite() && radial_immersion > 0.0 && radial_immersion <= 1.0) {
            return Err(DynamicsError::value(
                "operation.radial_immersion",
                radial_immersion,
                "a fraction of the diameter in (0, 1]",
            ));
        }
        if let Some(d) = tool_diameter_m {
            positive("operation.tool_diameter_mm", d)?;
        }
        if let Some(h) = helix_rad
            && !(h.is_finite() && (0.0..PI / 2.0).contains(&h))
        {
            return Err(DynamicsError::value(
                "operation.helix_deg",
                h.to_degrees(),
                "an angle in [0, 90) degrees",
            ));
        }
        Ok(Self {
            teeth,
            radial_immersion,
            direction,
            tool_diameter_m,
            helix_rad,
            pitch_rad: None,
        })
    }

    /// The same cutter with the pitch angles `pitch_deg` (degrees, one per tooth, each > 0,
    /// summing to 360 within [`PITCH_SUM_TOLERANCE_DEG`]); `None` is even pitch. Errors name
    /// `operation.pitch_deg` and echo the values.
    pub fn with_pitch_deg(self, pitch_deg: Option<&[f64]>) -> Result<Self> {
        let Some(p) = pitch_deg else {
            return Ok(Self {
                pitch_rad: None,
                ..self
            });
        };
        let written = format!(
            "[{}]",
            p.iter()
                .map(|v| crate::limits::written(*v))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if p.len() != self.teeth {
            return Err(DynamicsError::invalid(
                "operation.pitch_deg",
                format!(
                    "{written} has {} angles: expected one per tooth ({})",
                    p.len(),
                    self.teeth
                ),
            ));
        }
        if let Some((j, v)) = p
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v > 0.0))
        {
            return Err(DynamicsError::invalid(
                format!("operation.pitch_deg[{j}]"),
                format!(
                    "{} in {written}: expected an angle > 0 degrees",
                    crate::limits::written(*v)
                ),
            ));
        }
        let sum: f64 = p.iter().sum();
        if (sum - 360.0).abs() > PITCH_SUM_TOLERANCE_DEG {
            return Err(DynamicsError::invalid(
                "operation.pitch_deg",
                format!(
                    "{written} sums to {} degrees: expected the angles between neighbouring \
                     teeth around the cutter, summing to 360",
                    crate::limits::written(sum)
                ),
            ));
        }
        Ok(Self {
            pitch_rad: Some(p.iter().map(|v| v.to_radians()).collect()),
            ..self
        })
    }

    /// The pitch angles in degrees as given (`None`: even pitch, the default).
    pub fn pitch_deg(&self) -> Option<Vec<f64>> {
        self.pitch_rad
            .as_ref()
            .map(|p| p.iter().map(|v| v.to_degrees()).collect())
    }

    /// Whether the pitch is uneven: pitch angles given and one of them more than
    /// [`PITCH_SUM_TOLERANCE_DEG`] from 360 / N. An even `pitch_deg` ([90, 90, 90, 90]) is the
    /// default cutter, to the bit.
    pub fn is_variable_pitch(&self) -> bool {
        let even = 2.0 * PI / self.teeth as f64;
        self.pitch_rad.as_ref().is_some_and(|p| {
            p.iter()
                .any(|v| (v - even).abs() > PITCH_SUM_TOLERANCE_DEG.to_radians())
        })
    }

    /// The angle (rad) by which tooth j leads tooth 0: 2 pi j / N for even pitch, the sum of the
    /// pitches of teeth 0..j otherwise (struct docs). `j` is taken modulo N.
    pub fn tooth_offset_rad(&self, j: usize) -> f64 {
        let j = j % self.teeth;
        match &self.pitch_rad {
            Some(p) if self.is_variable_pitch() => p[..j].iter().sum(),
            _ => 2.0 * PI * j as f64 / self.teeth as f64,
        }
    }

    /// Tooth j's pitch (rad): the angle from it to the tooth ahead of it, which cut the surface
    /// tooth j cuts (`j` modulo N); 2 pi / N for even pitch.
    pub fn tooth_pitch_rad(&self, j: usize) -> f64 {
        let j = j % self.teeth;
        match &self.pitch_rad {
            Some(p) if self.is_variable_pitch() => p[j],
            _ => 2.0 * PI / self.teeth as f64,
        }
    }

    /// Number of teeth.
    pub fn teeth(&self) -> usize {
        self.teeth
    }
    /// Radial immersion a/D.
    pub fn radial_immersion(&self) -> f64 {
        self.radial_immersion
    }
    /// Up or down milling.
    pub fn direction(&self) -> MillingDirection {
        self.direction
    }
    /// Tool diameter in metres, when given.
    pub fn tool_diameter_m(&self) -> Option<f64> {
        self.tool_diameter_m
    }
    /// Helix angle in radians, when given.
    pub fn helix_rad(&self) -> Option<f64> {
        self.helix_rad
    }

    /// The same geometry at another radial immersion (observations may override it per cut).
    pub fn with_radial_immersion(&self, radial_immersion: f64) -> Result<Self> {
        Ok(Self {
            pitch_rad: self.pitch_rad.clone(),
            ..Self::new(
                self.teeth,
                radial_immersion,
                self.direction,
                self.tool_diameter_m,
                self.helix_rad,
            )?
        })
    }

    /// Entry and exit angles (rad) of a tooth, measured from the y axis in the direction of
    /// rotation (Insperger and Stépán convention): down milling enters at arccos(2 a/D - 1) and
    /// exits at pi; up milling enters at 0 and exits at arccos(1 - 2 a/D).
    pub fn entry_exit_rad(&self) -> (f64, f64) {
        let r = self.radial_immersion;
        match self.direction {
            MillingDirection::Down => ((2.0 * r - 1.0).clamp(-1.0, 1.0).acos(), PI),
            MillingDirection::Up => (0.0, (1.0 - 2.0 * r).clamp(-1.0, 1.0).acos()),
        }
    }
}

/// Turning geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct Turning {
    workpiece_diameter_m: Option<f64>,
}

impl Turning {
    /// Validated turning geometry.
    pub fn new(workpiece_diameter_m: Option<f64>) -> Result<Self> {
        if let Some(d) = workpiece_diameter_m {
            positive("operation.workpiece_diameter_mm", d)?;
        }
        Ok(Self {
            workpiece_diameter_m,
        })
    }
    /// Workpiece diameter in metres, when given.
    pub fn workpiece_diameter_m(&self) -> Option<f64> {
        self.workpiece_diameter_m
    }
}

/// The operation a model describes.
#[derive(Debug, Clone, PartialEq)]
pub enum Operation {
    /// Milling: time-periodic cutting forces, delay = tooth-passing period.
    Milling(Milling),
    /// Turning: constant cutting-force direction, delay = spindle period.
    Turning(Turning),
}

impl Operation {
    /// The two coordinates of this operation, in the order used by every vector and matrix.
    pub fn coordinates(&self) -> [Coordinate; 2] {
        match self {
            Operation::Milling(_) => [Coordinate::X, Coordinate::Y],
            Operation::Turning(_) => [Coordinate::Feed, Coordinate::Cutting],
        }
    }

    /// Index of a coordinate name (`"x"`, `"y"`, `"feed"`, `"cutting"`) for this operation.
    pub fn coordinate_index(&self, name: &str) -> Option<usize> {
        self.coordinates().iter().position(|c| c.name() == name)
    }

    /// Number of regenerative delays per spindle revolution (teeth for milling, 1 for turning).
    pub fn delays_per_revolution(&self) -> usize {
        match self {
            Operation::Milling(m) => m.teeth,
            Operation::Turning(_) => 1,
        }
    }

    /// The regenerative delay tau (s) at a spindle speed in rpm: the tooth period (the mean one
    /// of a variable-pitch cutter) in milling, the revolution in turning.
    pub fn delay_s(&self, speed_rpm: f64) -> f64 {
        60.0 / (speed_rpm * self.delays_per_revolution() as f64)
    }

    /// Whether this is a variable-pitch milling cutter ([`Milling::is_variable_pitch`]).
    pub fn is_variable_pitch(&self) -> bool {
        matches!(self, Operation::Milling(m) if m.is_variable_pitch())
    }

    /// The principal period (s) of the cutting force at `speed_rpm`: the delay
    /// ([`Self::delay_s`]), except for a variable-pitch cutter, whose force repeats once per
    /// spindle revolution (60 / n) and whose multipliers are over that period.
    pub fn principal_period_s(&self, speed_rpm: f64) -> f64 {
        if self.is_variable_pitch() {
            60.0 / speed_rpm
        } else {
            self.delay_s(speed_rpm)
        }
    }

    /// Diameter (m) that sets the cutting speed V = pi D n, when given.
    pub fn cutting_diameter_m(&self) -> Option<f64> {
        match self {
            Operation::Milling(m) => m.tool_diameter_m,
            Operation::Turning(t) => t.workpiece_diameter_m,
        }
    }

    /// Cutting speed V (m/s) at a spindle speed, when the diameter is known.
    pub fn cutting_speed_m_per_s(&self, speed_rpm: f64) -> Option<f64> {
        self.cutting_diameter_m().map(|d| PI * d * speed_rpm / 60.0)
    }
}
