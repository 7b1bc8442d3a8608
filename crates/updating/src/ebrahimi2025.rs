//! Seed 002's numerical simulation (Ebrahimi-Tirtashi and Ahmadi 2025, Section 3.1): the
//! simulated milling system and the dominant closed-loop poles of its Table 1, beside the poles
//! of the exact monodromy operator at the same cutting conditions.
//!
//! The stated system: one mode at 194 Hz, damping ratio 0.005, stiffness 2.35 N/um, Kt 650 and
//! Kn 110 N/mm^2, two-flute 12.7 mm cutter, full-immersion (slotting) down milling. Table 1
//! matches neither one model fully (a documented deviation, [`crate::milling`]): at the stated
//! 194 Hz its damping ratios are reproduced (7 of 7 within 0.016) but its lifted frequencies
//! sit a near-constant 1.22-1.31 Hz below the model's poles; at 195.3 Hz (002's experimental
//! hammer-test frequency) the frequencies are reproduced (7 of 7 within 0.1 Hz) but the damping
//! ratios at 2000 rpm come out 0.030-0.038 higher. [`reproduction`] shows both.

use crate::error::Result;
use crate::milling::multiplier_frequency_damping;
use crate::schmitz2022::Reproduced;
use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation,
};
use chatter_stability::StabilitySolver;
use chatter_stability::monodromy::Discretization;

/// The simulation's natural frequency as the paper states it (Hz).
pub const STATED_FREQUENCY_HZ: f64 = 194.0;
/// The natural frequency that reproduces Table 1's pole frequencies (Hz; 002's experimental
/// hammer-test value).
pub const TABLE_1_FREQUENCY_HZ: f64 = 195.3;
/// Tolerance on a pole frequency (Hz): 0.1 Hz, the largest standard deviation of Table 1's
/// identified frequencies (0.0889 Hz) rounded up.
pub const FREQUENCY_TOLERANCE_HZ: f64 = 0.1;
/// Tolerance on a pole damping ratio: 0.016, the largest standard deviation of Table 1's
/// identified damping ratios (0.0157) rounded up.
pub const DAMPING_TOLERANCE: f64 = 0.016;

/// One row of Table 1: the mean and standard deviation of the dominant pole identified by TDPR
/// over 10 repetitions at one cutting condition.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentifiedPole {
    /// Spindle speed (rpm).
    pub speed_rpm: f64,
    /// Axial depth (mm).
    pub depth_mm: f64,
    /// Mean lifted pole frequency (Hz).
    pub frequency_hz: f64,
    /// Its standard deviation (Hz).
    pub frequency_sd_hz: f64,
    /// Mean damping ratio.
    pub damping_ratio: f64,
    /// Its standard deviation.
    pub damping_sd: f64,
}

const fn pole(s: f64, b: f64, f: f64, sf: f64, z: f64, sz: f64) -> IdentifiedPole {
    IdentifiedPole {
        speed_rpm: s,
        depth_mm: b,
        frequency_hz: f,
        frequency_sd_hz: sf,
        damping_ratio: z,
        damping_sd: sz,
    }
}

/// Table 1 of 002 (numerical simulation), P1-P7.
pub const TABLE_1: [IdentifiedPole; 7] = [
    pole(2000.0, 0.4, 4.69, 0.0182, 0.088, 0.0143),
    pole(2000.0, 0.5, 4.6, 0.0222, 0.0722, 0.0157),
    pole(2000.0, 0.6, 4.56, 0.0362, 0.0501, 0.0133),
    pole(2000.0, 0.7, 4.53, 0.0233, 0.0303, 0.0066),
    pole(2000.0, 0.8, 4.45, 0.0889, 0.01, 0.0047),
    pole(2100.0, 0.3, 14.14, 0.0102, 0.03, 0.0063),
    pole(2100.0, 0.4, 14.05, 0.0041, 0.0129, 0.0037),
];

/// The simulated system of Section 3.1 with natural frequency `frequency_hz`
/// ([`STATED_FREQUENCY_HZ`] as stated).
pub fn simulated_model(frequency_hz: f64) -> Result<ModalModel> {
    let mode = Mode::new(
        frequency_hz,
        0.005,
        ModeShape::Directional {
            coordinate: 0,
            stiffness_n_per_m: 2.35e6,
        },
    )?;
    let operation = Operation::Milling(Milling::new(
        2,
        1.0,
        MillingDirection::Down,
        Some(12.7e-3),
        None,
    )?);
    Ok(ModalModel::new(
        Some(format!("002 numerical simulation, {frequency_hz} Hz")),
        operation,
        CuttingCoefficients::new(650e6, 110e6)?,
        vec![mode],
        None,
    )?)
}

/// (frequency Hz, damping ratio) of the dominant multiplier of `model` at each Table 1
/// condition (full discretization, automatic resolution).
pub fn table_1_poles(model: &ModalModel) -> Result<Vec<(f64, f64)>> {
    TABLE_1
        .iter()
        .map(|p| {
            let mu = Discretization::full().dominant_multiplier(
                model,
                p.speed_rpm,
                p.depth_mm * 1e-3,
            )?;
            Ok(multiplier_frequency_damping(&mu))
        })
        .collect()
}

/// Table 1 against the exact poles of the simulated system at the stated 194 Hz and at
/// 195.3 Hz: frequency within [`FREQUENCY_TOLERANCE_HZ`], damping ratio within
/// [`DAMPING_TOLERANCE`] (14 rows each; at 194 Hz the frequencies and at 195.3 Hz five damping
/// ratios fall outside, the documented deviation of the module docs).
pub fn reproduction() -> Result<Vec<Reproduced>> {
    let mut rows = Vec::new();
    for frequency_hz in [STATED_FREQUENCY_HZ, TABLE_1_FREQUENCY_HZ] {
        let poles = table_1_poles(&simulated_model(frequency_hz)?)?;
        for (i, (p, (f, z))) in TABLE_1.iter().zip(poles).enumerate() {
            let at = format!(
                "P{} ({} rpm, {} mm), model at {frequency_hz} Hz",
                i + 1,
                p.speed_rpm,
                p.depth_mm
            );
            rows.push(Reproduced {
                quantity: format!("Table 1 pole frequency at {at} (Hz)"),
                paper: p.frequency_hz,
                ours: f,
                tolerance: FREQUENCY_TOLERANCE_HZ,
            });
            rows.push(Reproduced {
                quantity: format!("Table 1 pole damping ratio at {at}"),
                paper: p.damping_ratio,
                ours: z,
                tolerance: DAMPING_TOLERANCE,
            });
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The documented deviation, as the demo's papers table shows it: at the stated 194 Hz the
    /// damping ratios are reproduced and the frequencies lie 1.15-1.35 Hz above the table; at
    /// 195.3 Hz the frequencies are reproduced.
    #[test]
    fn table_1_damping_at_194_hz_frequencies_at_195_3_hz() {
        let rows = reproduction().unwrap();
        assert_eq!(rows.len(), 28);
        let (stated, fitted) = rows.split_at(14);
        for pair in stated.chunks(2) {
            let offset = pair[0].ours - pair[0].paper;
            assert!((1.15..1.35).contains(&offset), "{:?}", pair[0]);
            assert!(pair[1].within(), "{:?}", pair[1]);
        }
        for pair in fitted.chunks(2) {
            assert!(pair[0].within(), "{:?}", pair[0]);
        }
    }
}
