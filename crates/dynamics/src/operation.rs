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
    /// Helix angles (rad) per tooth of a variable-helix cutter; `None`: every tooth has
    /// `helix_rad` (or none).
    helix_per_tooth_rad: Option<Vec<f64>>,
    /// Axial slices of the depth of cut of a helical cutter; `None`: [`DEFAULT_AXIAL_SLICES`].
    axial_slices: Option<usize>,
    /// Radial runout (m) of each tooth, `None`: none.
    runout_m: Option<Vec<f64>>,
}

/// The axial slices of a helical cutter's depth when the model gives none (`axial_slices`).
pub const DEFAULT_AXIAL_SLICES: usize = 20;

/// One cutting edge element of a milling cutter: a tooth, or for a helical cutter one axial
/// slice of a tooth (Altintas 2012, Sec. 3.6; Insperger et al. 2003; Zatarain et al. 2006).
///
/// At time t the element sits at the angle phi(t) = Omega t + `lead_rad`, cuts a chip of width
/// `weight` b (a fraction of the axial depth b) and removes the surface that the element of the
/// tooth ahead at the same height left when the spindle was `delay_rad` earlier: its
/// regenerative delay is tau = `delay_rad` / Omega.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CuttingEdge {
    /// The tooth the element belongs to.
    pub tooth: usize,
    /// Angle (rad) at t = 0: the tooth's offset minus the helix lag z tan(beta_j) / R.
    pub lead_rad: f64,
    /// Fraction of the axial depth the element cuts (1 for a straight tooth, 1 / slices).
    pub weight: f64,
    /// Angle (rad) the spindle turns between the tooth ahead's pass and this element's at the
    /// same height: pitch_j + z (tan(beta_j) - tan(beta_{j+1})) / R.
    pub delay_rad: f64,
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
        let out = Self {
            teeth,
            radial_immersion,
            direction,
            tool_diameter_m,
            helix_rad,
            pitch_rad: None,
            helix_per_tooth_rad: None,
            axial_slices: None,
            runout_m: None,
        };
        out.require_diameter_for_helix()?;
        Ok(out)
    }

    /// The same cutter with the helix angles `helix_deg` (degrees in [0, 90)): one value for
    /// every tooth or one per tooth (a variable-helix cutter); `None` keeps the helix given to
    /// [`Self::new`]. A helix other than zero needs the tool diameter (the lag of a slice at
    /// height z is z tan(beta) / R). Errors name `operation.helix_deg` and echo the values.
    pub fn with_helix_deg(self, helix_deg: Option<&[f64]>) -> Result<Self> {
        let Some(h) = helix_deg else {
            return Ok(self);
        };
        if h.len() != 1 && h.len() != self.teeth {
            return Err(DynamicsError::invalid(
                "operation.helix_deg",
                format!(
                    "{} angles: expected one value or one per tooth ({})",
                    h.len(),
                    self.teeth
                ),
            ));
        }
        for (j, v) in h.iter().enumerate() {
            if !(v.is_finite() && (0.0..90.0).contains(v)) {
                let field = if h.len() == 1 {
                    "operation.helix_deg".to_string()
                } else {
                    format!("operation.helix_deg[{j}]")
                };
                return Err(DynamicsError::value(
                    field,
                    *v,
                    "an angle in [0, 90) degrees",
                ));
            }
        }
        let first = h[0].to_radians();
        let per_tooth = (h.len() > 1 && h.iter().any(|v| *v != h[0]))
            .then(|| h.iter().map(|v| v.to_radians()).collect());
        let out = Self {
            helix_rad: Some(first),
            helix_per_tooth_rad: per_tooth,
            ..self
        };
        out.require_diameter_for_helix()?;
        Ok(out)
    }

    /// The same cutter with `axial_slices` slices of the depth for the helix (>= 1; `None`:
    /// [`DEFAULT_AXIAL_SLICES`]). Errors name `operation.axial_slices`.
    pub fn with_axial_slices(self, axial_slices: Option<usize>) -> Result<Self> {
        if axial_slices == Some(0) {
            return Err(DynamicsError::value(
                "operation.axial_slices",
                0.0,
                "a number of axial slices >= 1",
            ));
        }
        Ok(Self {
            axial_slices,
            ..self
        })
    }

    /// The same cutter with the radial runout `runout_um` (micrometres, one per tooth, none
    /// negative: how far each tooth's edge stands out beyond the nominal radius); `None` is none.
    /// Runout is a forced motion: it changes the chips and the surface (the time-domain
    /// simulator models it) but not the linear stability of the cut. Errors name
    /// `operation.runout_um`.
    pub fn with_runout_um(self, runout_um: Option<&[f64]>) -> Result<Self> {
        let Some(r) = runout_um else {
            return Ok(Self {
                runout_m: None,
                ..self
            });
        };
        if r.len() != self.teeth {
            return Err(DynamicsError::invalid(
                "operation.runout_um",
                format!(
                    "{} values: expected one radial offset per tooth ({})",
                    r.len(),
                    self.teeth
                ),
            ));
        }
        if let Some((j, v)) = r
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
        {
            return Err(DynamicsError::value(
                format!("operation.runout_um[{j}]"),
                *v,
                "a radial runout >= 0 micrometres (how far the tooth stands out)",
            ));
        }
        Ok(Self {
            runout_m: Some(r.iter().map(|v| v * 1e-6).collect()),
            ..self
        })
    }

    /// Tooth j's radial runout (m; `j` modulo N), 0 without runout.
    pub fn tooth_runout_m(&self, j: usize) -> f64 {
        self.runout_m.as_ref().map_or(0.0, |r| r[j % self.teeth])
    }

    /// The radial runout per tooth in micrometres as given (`None`: none).
    pub fn runout_um(&self) -> Option<Vec<f64>> {
        self.runout_m
            .as_ref()
            .map(|r| r.iter().map(|v| v * 1e6).collect())
    }

    /// A helical cutter needs its radius: the error names `operation.tool_diameter_mm`.
    fn require_diameter_for_helix(&self) -> Result<()> {
        if self.is_helical() && self.tool_diameter_m.is_none() {
            return Err(DynamicsError::invalid(
                "operation.tool_diameter_mm",
                "missing: a helical cutter (operation.helix_deg > 0) needs the tool diameter",
            ));
        }
        Ok(())
    }

    /// Tooth j's helix angle (rad; `j` modulo N), 0 for a straight tooth.
    pub fn tooth_helix_rad(&self, j: usize) -> f64 {
        match &self.helix_per_tooth_rad {
            Some(h) => h[j % self.teeth],
            None => self.helix_rad.unwrap_or(0.0),
        }
    }

    /// The helix angles per tooth in degrees as given for a variable-helix cutter, `None`
    /// otherwise ([`Self::helix_rad`] holds the one angle).
    pub fn helix_per_tooth_deg(&self) -> Option<Vec<f64>> {
        self.helix_per_tooth_rad
            .as_ref()
            .map(|h| h.iter().map(|v| v.to_degrees()).collect())
    }

    /// Whether some tooth has a helix angle other than zero: the cut is then spread along the
    /// axis ([`Self::cutting_edges`]). With every helix zero the cutter is the straight one, to
    /// the bit.
    pub fn is_helical(&self) -> bool {
        (0..self.teeth).any(|j| self.tooth_helix_rad(j) != 0.0)
    }

    /// Whether the teeth have different helix angles (variable helix): the delay then varies
    /// along the axis.
    pub fn is_variable_helix(&self) -> bool {
        (1..self.teeth).any(|j| self.tooth_helix_rad(j) != self.tooth_helix_rad(0))
    }

    /// The axial slices of the depth as given (`None`: [`DEFAULT_AXIAL_SLICES`] is used).
    pub fn axial_slices(&self) -> Option<usize> {
        self.axial_slices
    }

    /// The cutting edge elements at the axial depth `depth_m` (m): one per tooth for a straight
    /// cutter (weight 1, lead offset_j, delay pitch_j); for a helical one, S slices of each tooth
    /// (S = `axial_slices`), slice s at the mid-height z_s = (s + 1/2) b / S with weight 1 / S,
    /// lead offset_j - z_s tan(beta_j) / R and delay pitch_j + z_s (tan(beta_j) -
    /// tan(beta_{j+1})) / R ([`CuttingEdge`]). The sum over elements of weight times the tooth
    /// directional matrix at phi = Omega t + lead is the helical cutter's H(t) per unit depth,
    /// the midpoint rule of the integral over z (Altintas 2012, Eq. 3.74).
    pub fn cutting_edges(&self, depth_m: f64) -> Vec<CuttingEdge> {
        let radius = self.tool_diameter_m.map_or(f64::INFINITY, |d| 0.5 * d);
        if !self.is_helical() {
            return (0..self.teeth)
                .map(|j| CuttingEdge {
                    tooth: j,
                    lead_rad: self.tooth_offset_rad(j),
                    weight: 1.0,
                    delay_rad: self.tooth_pitch_rad(j),
                })
                .collect();
        }
        let slices = self.axial_slices.unwrap_or(DEFAULT_AXIAL_SLICES);
        let mut out = Vec::with_capacity(self.teeth * slices);
        for j in 0..self.teeth {
            let tan_j = self.tooth_helix_rad(j).tan();
            let tan_ahead = self.tooth_helix_rad(j + 1).tan();
            for s in 0..slices {
                let z = (s as f64 + 0.5) * depth_m / slices as f64;
                out.push(CuttingEdge {
                    tooth: j,
                    lead_rad: self.tooth_offset_rad(j) - z * tan_j / radius,
                    weight: 1.0 / slices as f64,
                    delay_rad: self.tooth_pitch_rad(j) + z * (tan_j - tan_ahead) / radius,
                });
            }
        }
        out
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
            helix_per_tooth_rad: self.helix_per_tooth_rad.clone(),
            axial_slices: self.axial_slices,
            runout_m: self.runout_m.clone(),
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

    /// Whether this is a helical milling cutter ([`Milling::is_helical`]).
    pub fn is_helical(&self) -> bool {
        matches!(self, Operation::Milling(m) if m.is_helical())
    }

    /// Whether the teeth differ (variable pitch or variable helix): the cutting force then
    /// repeats once per revolution, not once per tooth period.
    pub fn has_uneven_teeth(&self) -> bool {
        matches!(self, Operation::Milling(m) if m.is_variable_pitch() || m.is_variable_helix())
    }

    /// The principal period (s) of the cutting force at `speed_rpm`: the delay
    /// ([`Self::delay_s`]), except for a cutter with uneven teeth (variable pitch or helix,
    /// [`Self::has_uneven_teeth`]), whose force repeats once per spindle revolution (60 / n)
    /// and whose multipliers are over that period.
    pub fn principal_period_s(&self, speed_rpm: f64) -> f64 {
        if self.has_uneven_teeth() {
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
