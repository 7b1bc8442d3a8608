//! Reference models shipped with the toolkit: the seeds' cases (the JSON files in this crate's
//! `data/` folder, embedded here; the repository's `examples/` folder links to them) and the
//! classic single-DOF milling benchmark.
//! Tests, benches and `chatter demo` share them.

use crate::model::{CuttingCoefficients, ModalModel, Mode, ModeShape};
use crate::observations::Observations;
use crate::operation::{Milling, MillingDirection, Operation, Turning};
use std::path::Path;

/// Model file of the turning case of Ahmadi (2022), seed 000, Table 1.
pub const AHMADI_2022_TURNING_MODEL: &str = include_str!("../data/ahmadi2022_turning_model.json");
/// Observations of the turning case of seed 000: Table 2 poles and the Fig. 2 cuts.
pub const AHMADI_2022_TURNING_OBSERVATIONS: &str =
    include_str!("../data/ahmadi2022_turning_observations.json");
/// The posterior of seed 000's turning case (Section 6.4) over theta_omega_2, theta_zeta_2 and
/// theta_phi_2: the published mean and covariance (Eq. 34), as a covariance file
/// (`chatter bands --covariance`).
pub const AHMADI_2022_POSTERIOR: &str = include_str!("../data/ahmadi2022_posterior.json");
/// Model file of the milling example of Schmitz (2023), seed 001.
pub const SCHMITZ_2023_MILLING_MODEL: &str = include_str!("../data/schmitz2023_milling_model.json");
/// Model file of the experimental milling case of Ebrahimi-Tirtashi and Ahmadi (2025), seed 002.
pub const EBRAHIMI_2025_MILLING_MODEL: &str =
    include_str!("../data/ebrahimi2025_milling_model.json");
/// Model file of the flexure of Karandikar, Tyler and Schmitz (seed 003), stiffness and damping
/// calibrated to the paper's prior probabilities of stability.
pub const KARANDIKAR_FLEXURE_MODEL: &str = include_str!("../data/karandikar_flexure_model.json");
/// Observations of seed 003: the cuts its text reports.
pub const KARANDIKAR_FLEXURE_OBSERVATIONS: &str =
    include_str!("../data/karandikar_flexure_observations.json");
/// Model file of seed 004 (Schmitz et al. 2022): its 12.7 mm three-flute end mill at 75 %
/// radial immersion, modes at the mean of the RCSA prior, K_s 600 N/mm^2, beta 68 deg.
pub const SCHMITZ_2022_RCSA_MODEL: &str = include_str!("../data/schmitz2022_rcsa_model.json");
/// Seed 004's correlated prior over [K_s, beta, f_n1, k_1, zeta_1, f_n2, k_2, zeta_2]: the prior
/// file `chatter plan --priors` reads (written by chatter-rcsa's `prior_map` example).
pub const SCHMITZ_2022_RCSA_PRIOR: &str = include_str!("../data/schmitz2022_rcsa_prior.json");
/// Observations of seed 002: Table 2 poles and their stable cuts.
pub const EBRAHIMI_2025_MILLING_OBSERVATIONS: &str =
    include_str!("../data/ebrahimi2025_milling_observations.json");

fn embedded_model(text: &str, name: &str) -> ModalModel {
    // The embedded files are checked by this crate's tests; failure here is a build defect.
    ModalModel::from_json_str(text, Path::new(name))
        .unwrap_or_else(|e| panic!("embedded example {name} is invalid: {e}"))
}

fn embedded_observations(text: &str, name: &str) -> Observations {
    Observations::from_json_str(text, Path::new(name))
        .unwrap_or_else(|e| panic!("embedded example {name} is invalid: {e}"))
}

/// A published Gaussian posterior of named parameters: its mean and covariance.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct PublishedPosterior {
    /// Parameter names (`chatter_dynamics::Parameter` syntax).
    pub parameter_names: Vec<String>,
    /// Posterior mean, in the order of the names.
    pub mean: Vec<f64>,
    /// Posterior covariance, row by row.
    pub covariance: Vec<Vec<f64>>,
}

impl PublishedPosterior {
    /// The covariance as a matrix.
    pub fn covariance_matrix(&self) -> nalgebra::DMatrix<f64> {
        let n = self.covariance.len();
        nalgebra::DMatrix::from_fn(n, n, |i, j| self.covariance[i][j])
    }
}

/// Seed 000's posterior after updating (Section 6.4): mean (0.0067, 0.1385, 0.0549) and the
/// covariance of Eq. 34 ([`AHMADI_2022_POSTERIOR`]).
pub fn ahmadi_2022_posterior() -> PublishedPosterior {
    serde_json::from_str(AHMADI_2022_POSTERIOR)
        .unwrap_or_else(|e| panic!("embedded example ahmadi2022_posterior.json is invalid: {e}"))
}

/// Turning tool of seed 000 (Table 1; kt 635, kfc 159 N/mm^2).
pub fn ahmadi_2022_turning() -> ModalModel {
    embedded_model(AHMADI_2022_TURNING_MODEL, "ahmadi2022_turning_model.json")
}
/// Observations of seed 000 (Table 2 poles, Fig. 2 cuts).
pub fn ahmadi_2022_turning_observations() -> Observations {
    embedded_observations(
        AHMADI_2022_TURNING_OBSERVATIONS,
        "ahmadi2022_turning_observations.json",
    )
}
/// Milling example of seed 001 (4 teeth, 20 % down milling, 750 Hz, 3 %, 3e6 N/m, x and y).
pub fn schmitz_2023_milling() -> ModalModel {
    embedded_model(SCHMITZ_2023_MILLING_MODEL, "schmitz2023_milling_model.json")
}
/// Seed 004's end mill (three flutes, 75 % down milling, two modes in x and y at the RCSA
/// prior mean).
pub fn schmitz_2022_rcsa() -> ModalModel {
    embedded_model(SCHMITZ_2022_RCSA_MODEL, "schmitz2022_rcsa_model.json")
}
/// Experimental milling case of seed 002 (hammer values before milling).
pub fn ebrahimi_2025_milling() -> ModalModel {
    embedded_model(
        EBRAHIMI_2025_MILLING_MODEL,
        "ebrahimi2025_milling_model.json",
    )
}
/// Observations of seed 002 (Table 2).
pub fn ebrahimi_2025_milling_observations() -> Observations {
    embedded_observations(
        EBRAHIMI_2025_MILLING_OBSERVATIONS,
        "ebrahimi2025_milling_observations.json",
    )
}

/// The flexure of seed 003 (228 Hz, single-tooth 18.54 mm endmill, 50 % up milling, C 2.5e5 N/m).
pub fn karandikar_flexure() -> ModalModel {
    embedded_model(KARANDIKAR_FLEXURE_MODEL, "karandikar_flexure_model.json")
}
/// Observations of seed 003 (the cuts named in its text).
pub fn karandikar_flexure_observations() -> Observations {
    embedded_observations(
        KARANDIKAR_FLEXURE_OBSERVATIONS,
        "karandikar_flexure_observations.json",
    )
}

/// The classic single-DOF milling benchmark (Insperger and Stépán 2004; Ding et al. 2010):
/// fn 922 Hz, zeta 0.011, modal mass 0.03993 kg in x, kt 6e8 and kn 2e8 N/m^2, 2 teeth, down
/// milling at radial immersion a/D (1 and 0.05 in the literature).
pub fn insperger_benchmark(radial_immersion: f64) -> ModalModel {
    let fn_hz = 922.0;
    let mass_kg = 0.03993;
    let k = mass_kg * (2.0 * std::f64::consts::PI * fn_hz).powi(2);
    let build = || -> crate::Result<ModalModel> {
        let op = Operation::Milling(Milling::new(
            2,
            radial_immersion,
            MillingDirection::Down,
            None,
            None,
        )?);
        let mode = Mode::new(
            fn_hz,
            0.011,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: k,
            },
        )?;
        ModalModel::new(
            Some(format!(
                "single-DOF milling benchmark (Insperger and Stepan 2004), a/D = {radial_immersion}"
            )),
            op,
            CuttingCoefficients::new(6e8, 2e8)?,
            vec![mode],
            None,
        )
    };
    build().unwrap_or_else(|e| panic!("benchmark with a/D = {radial_immersion}: {e}"))
}

/// A flexure like the one of seed 003 (Karandikar, Tyler and Schmitz) for process damping: one
/// 228 Hz mode in x (damping ratio 0.02, stiffness 5.6e6 N/m; the text does not give the
/// flexure's stiffness and damping, so these are chosen here), a single-tooth 18.54 mm cutter in
/// 50 % up milling, kt 2111.2 and kn 1052.6 N/mm^2, and the process-damping coefficient
/// `c_n_per_m` (N/m) of F_d = -C b ydot / V.
pub fn process_damping_flexure(c_n_per_m: Option<f64>) -> ModalModel {
    let build = || -> crate::Result<ModalModel> {
        let mode = Mode::new(
            228.0,
            0.02,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: 5.6e6,
            },
        )?;
        let op = Operation::Milling(Milling::new(
            1,
            0.5,
            MillingDirection::Up,
            Some(18.54e-3),
            None,
        )?);
        ModalModel::new(
            Some("003-like flexure".into()),
            op,
            CuttingCoefficients::new(2111.2e6, 1052.6e6)?,
            vec![mode],
            c_n_per_m,
        )
    };
    build().unwrap_or_else(|e| panic!("003-like flexure with C = {c_n_per_m:?}: {e}"))
}

/// The 2-DOF mill of issue 14, on which lobes and Monte Carlo maps used to abort in the
/// eigen-solver (a Hessenberg QR that did not converge at 23 500 rpm): 3 teeth of a 12.7 mm
/// cutter in 75 % down milling, kt 700 and kn 210 N/mm^2, x and y modes at 918.8 and 889.3 Hz
/// (damping ratio 0.03, 7.82e6 and 7.52e6 N/m): a nearly symmetric tool.
pub fn issue_14_mill() -> ModalModel {
    let build = || -> crate::Result<ModalModel> {
        let mode = |frequency_hz, stiffness_n_per_m, coordinate| {
            Mode::new(
                frequency_hz,
                0.03,
                ModeShape::Directional {
                    coordinate,
                    stiffness_n_per_m,
                },
            )
        };
        ModalModel::new(
            Some("issue 14 mill".into()),
            Operation::Milling(Milling::new(
                3,
                0.75,
                MillingDirection::Down,
                Some(12.7e-3),
                None,
            )?),
            CuttingCoefficients::new(700e6, 210e6)?,
            vec![
                mode(918.817_583_621_353_3, 7_815_703.869_117_313, 0)?,
                mode(889.340_042_863_237, 7_516_307.737_741_677, 1)?,
            ],
            None,
        )
    };
    build().unwrap_or_else(|e| panic!("issue 14 mill: {e}"))
}

/// The gap proving ground's lathe: a 640 Hz feed mode (damping ratio 0.03, 2.5e7 N/m) and a
/// 700 Hz mode at 30 degrees (0.035, 3e7 N/m), a 50 mm workpiece, kt 1500 and kn 600 N/mm^2,
/// and the process-damping coefficient `c_n_per_m` (N/m). With C about 1e6 N/m and more, slow
/// surface regeneration dominates at low speed and the multipliers cluster near one modulus.
pub fn proving_ground_lathe(c_n_per_m: Option<f64>) -> ModalModel {
    let build = || -> crate::Result<ModalModel> {
        let feed = Mode::new(
            640.0,
            0.03,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: 2.5e7,
            },
        )?;
        // mass-normalized shape of a 3e7 N/m mode at 30 degrees: |phi| = omega / sqrt(k)
        let a = 2.0 * std::f64::consts::PI * 700.0 / 3e7f64.sqrt();
        let t = 30f64.to_radians();
        let oblique = Mode::new(
            700.0,
            0.035,
            ModeShape::MassNormalized([a * t.cos(), a * t.sin()]),
        )?;
        ModalModel::new(
            Some("gap proving-ground lathe".into()),
            Operation::Turning(Turning::new(Some(0.05))?),
            CuttingCoefficients::new(1500e6, 600e6)?,
            vec![feed, oblique],
            c_n_per_m,
        )
    };
    build().unwrap_or_else(|e| panic!("proving-ground lathe with C = {c_n_per_m:?}: {e}"))
}
