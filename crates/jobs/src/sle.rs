//! The surface-location-error job (`chatter sle`, the SLE panel of `chatter lobes --sle`): the
//! steady forced response of a stable milling cut at each speed (Schmitz & Mann 2006: the
//! periodic cutting force's Fourier series through the FRF at the tooth-passing harmonics,
//! [`chatter_dynamics::sle`]), with the dominant multiplier |mu| by FDM at the same depth so
//! that unstable speeds are marked: their forced response is not what the cut leaves.

use crate::checks;
use crate::error::Result;
use chatter_dynamics::ModalModel;
use chatter_dynamics::limits::DEPTH_MM;
use chatter_dynamics::sle::surface_location_error;
use chatter_stability::Method;
use chatter_stability::boundary::BoundaryOptions;

/// Default feed per tooth (mm).
pub const FEED_PER_TOOTH_MM: f64 = 0.05;

/// What the SLE job was asked, in user units.
#[derive(Debug, Clone, PartialEq)]
pub struct SleRequest {
    /// Spindle speeds (rpm).
    pub speeds_rpm: Vec<f64>,
    /// Axial depth of cut (mm).
    pub depth_mm: f64,
    /// Feed per tooth (mm); default [`FEED_PER_TOOTH_MM`].
    pub feed_per_tooth_mm: Option<f64>,
}

/// A checked SLE job.
pub struct Sle<'a> {
    model: &'a ModalModel,
    speeds_rpm: Vec<f64>,
    depth_mm: f64,
    feed_per_tooth_mm: f64,
}

/// The SLE at one speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SleRow {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Surface location error (um): > 0 undercut, < 0 overcut.
    pub sle_um: f64,
    /// Peak-to-valley of the steady surface (um).
    pub peak_to_valley_um: f64,
    /// |mu| of the dominant multiplier by FDM at the depth.
    pub modulus: f64,
}

impl SleRow {
    /// The stability rule |mu| < 1.
    pub fn stable(&self) -> bool {
        self.modulus < 1.0
    }
}

/// What the SLE job computed.
#[derive(Debug, Clone, PartialEq)]
pub struct SleOutcome {
    /// Axial depth (mm).
    pub depth_mm: f64,
    /// Feed per tooth (mm).
    pub feed_per_tooth_mm: f64,
    /// One row per speed, in the request's order.
    pub rows: Vec<SleRow>,
}

impl<'a> Sle<'a> {
    /// Check `request` for `model`: the depth and feed in range, the speeds plausible and within
    /// the cost guard of FDM ([`checks::work_size`]); the model's kind (even-pitch straight
    /// milling without process damping) is checked by the SLE itself when run, by field name.
    pub fn new(model: &'a ModalModel, request: SleRequest) -> Result<Self> {
        let depth_mm = checks::in_range("depth_mm", request.depth_mm, &DEPTH_MM)?;
        let feed_per_tooth_mm = checks::in_range(
            "feed_per_tooth_mm",
            request.feed_per_tooth_mm.unwrap_or(FEED_PER_TOOTH_MM),
            &crate::simulate::FEED_MM,
        )?;
        checks::speeds("speeds", &request.speeds_rpm)?;
        if let Some(d) = Method::Fdm.discretization() {
            checks::work_size(model, d, &request.speeds_rpm, "speeds")?;
        }
        Ok(Self {
            model,
            speeds_rpm: request.speeds_rpm,
            depth_mm,
            feed_per_tooth_mm,
        })
    }

    /// The SLE, peak-to-valley and |mu| at every speed.
    pub fn run(&self) -> Result<SleOutcome> {
        let fdm = Method::Fdm.prepare(self.model, &BoundaryOptions::default())?;
        let (depth_m, feed_m) = (self.depth_mm * 1e-3, self.feed_per_tooth_mm * 1e-3);
        let rows = self
            .speeds_rpm
            .iter()
            .map(|&speed_rpm| {
                let s = surface_location_error(self.model, speed_rpm, depth_m, feed_m)?;
                let modulus = fdm.dominant_multiplier(speed_rpm, depth_m)?.modulus();
                Ok(SleRow {
                    speed_rpm,
                    sle_um: s.sle_m * 1e6,
                    peak_to_valley_um: s.peak_to_valley_m * 1e6,
                    modulus,
                })
            })
            .collect::<Result<_>>()?;
        Ok(SleOutcome {
            depth_mm: self.depth_mm,
            feed_per_tooth_mm: self.feed_per_tooth_mm,
            rows,
        })
    }
}
