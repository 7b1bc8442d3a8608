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

/// Milling geometry: teeth, radial immersion, direction, diameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Milling {
    teeth: usize,
    radial_immersion: f64,
    direction: MillingDirection,
    tool_diameter_m: Option<f64>,
    helix_rad: Option<f64>,
}

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
        })
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
        Self::new(
            self.teeth,
            radial_immersion,
            self.direction,
            self.tool_diameter_m,
            self.helix_rad,
        )
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

    /// The regenerative delay tau (s) at a spindle speed in rpm.
    pub fn delay_s(&self, speed_rpm: f64) -> f64 {
        60.0 / (speed_rpm * self.delays_per_revolution() as f64)
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
