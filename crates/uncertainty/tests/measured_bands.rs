//! Type B bands (001) on measured-FRF lobes with the offsets from an FRF ensemble (gain sd 5 %,
//! frequency-axis sd 1 %, coverage 2): the bands of an FRF synthesized from seed 001's milling
//! model equal the bands of that modal model under the same draws (its frequencies scaled by
//! 1 + e, its receptance by 1 + g, lobes by `zoa_lobes`), each member's pocket moves to
//! ((1 + e) Omega, b / (1 + g)) as the zero-order method says it must, and the CutPro tool-tip
//! FRFs get bands with the stated process.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::{ModalModel, ModelFile, SampledReceptance, examples};
use chatter_stability::boundary::LobePoint;
use chatter_stability::zero_order::zoa_lobes;
use chatter_uncertainty::geometric::OffsetBoundaries;
use chatter_uncertainty::measured::{
    EnsembleBands, FrfUncertainty, ensemble_offsets, frf_ensemble, measured_type_b_bands,
};
use std::path::Path;

const DRAWS: usize = 40;
const SEED: u64 = 17;

/// The model with every natural frequency scaled by 1 + e and its receptance by 1 + g.
fn perturbed_model(model: &ModalModel, g: f64, e: f64) -> ModalModel {
    let mut file = ModelFile::from_model(model);
    for m in &mut file.modes {
        m.frequency_hz *= 1.0 + e;
        if let Some(k) = m.stiffness_n_per_m.as_mut() {
            *k /= 1.0 + g;
        }
        // mass-normalized shapes: G = phi phi^T / (w_n^2 - w^2 + ...), so phi (1 + e) sqrt(1 + g)
        if let Some(shape) = m.shape.as_mut() {
            for v in shape.values_mut() {
                *v *= (1.0 + e) * (1.0 + g).sqrt();
            }
        }
    }
    file.validate().unwrap()
}

/// The test's uncertainty (gain sd 5 %, frequency-axis sd 1 %) and the bands of its ensemble
/// (DRAWS members, SEED, coverage 2) for `model`'s process on the measured `nominal`.
fn ensemble_bands(
    model: &ModalModel,
    nominal: &SampledReceptance,
    speeds: &[f64],
) -> (FrfUncertainty, EnsembleBands) {
    let uncertainty = FrfUncertainty::new(0.05, 0.01).unwrap();
    let ensemble = frf_ensemble(nominal, uncertainty, DRAWS, SEED).unwrap();
    let bands = measured_type_b_bands(
        model.operation(),
        model.cutting(),
        nominal,
        &ensemble,
        speeds,
        2.0,
    )
    .unwrap();
    (uncertainty, bands)
}

/// Sample standard deviation.
fn sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Largest relative difference of two band polylines in depth over `speeds`.
fn band_gap(a: &[(f64, f64)], b: &[(f64, f64)], speeds: &[f64]) -> f64 {
    speeds
        .iter()
        .filter_map(|&s| {
            let (x, y) = (
                OffsetBoundaries::depth_at(a, s)?,
                OffsetBoundaries::depth_at(b, s)?,
            );
            Some((x / y - 1.0).abs())
        })
        .fold(0.0, f64::max)
}

/// Each member's pocket against the exact zero-order map of its draw, and the offsets against
/// k sd of those exact pockets; returns the largest relative errors (pocket, offsets).
fn check_against_exact(bands: &EnsembleBands, draws: &[(f64, f64)]) -> (f64, f64) {
    let (s0, b0) = bands.pocket;
    let exact: Vec<(f64, f64)> = draws
        .iter()
        .map(|&(g, e)| ((1.0 + e) * s0, b0 / (1.0 + g)))
        .collect();
    let pocket = bands
        .member_pockets
        .iter()
        .zip(&exact)
        .map(|(p, q)| ((p.0 / q.0 - 1.0).abs()).max((p.1 / q.1 - 1.0).abs()))
        .fold(0.0, f64::max);
    let speeds: Vec<f64> = exact.iter().map(|p| p.0).collect();
    let depths: Vec<f64> = exact.iter().map(|p| p.1).collect();
    let offsets = (bands.offsets.offset_rpm() / (2.0 * sd(&speeds)) - 1.0)
        .abs()
        .max((bands.offsets.offset_mm() / (2.0 * sd(&depths)) - 1.0).abs());
    (pocket, offsets)
}

#[test]
fn frf_bands_equal_the_modal_bands_of_the_same_draws() {
    let model = examples::schmitz_2023_milling();
    // 1 Hz to three times the mode (20 points per half-power bandwidth 2 zeta f_n = 45 Hz)
    let grid: Vec<f64> = (1..=2250).map(|k| k as f64).collect();
    let nominal: SampledReceptance = model.sampled_receptance(grid).unwrap();
    let speeds: Vec<f64> = (0..=160).map(|i| 4500.0 + 50.0 * i as f64).collect();
    let (uncertainty, frf) = ensemble_bands(&model, &nominal, &speeds);
    // the modal route: the same draws on the modal model, lobes by zoa_lobes
    let draws = uncertainty.draws(DRAWS, SEED);
    let members: Vec<Vec<LobePoint>> = draws
        .iter()
        .map(|&(g, e)| zoa_lobes(&perturbed_model(&model, g, e), &speeds).unwrap())
        .collect();
    let modal = ensemble_offsets(&zoa_lobes(&model, &speeds).unwrap(), &members, 2.0).unwrap();
    let offsets = (frf.offsets.offset_rpm() / modal.offsets.offset_rpm() - 1.0)
        .abs()
        .max((frf.offsets.offset_mm() / modal.offsets.offset_mm() - 1.0).abs());
    let upper = band_gap(&frf.bands.upper, &modal.bands.upper, &speeds);
    let lower = band_gap(&frf.bands.lower, &modal.bands.lower, &speeds);
    let (pocket, exact) = check_against_exact(&frf, &draws);
    eprintln!(
        "seed 001 milling: pocket {:.0} rpm {:.4} mm; offsets FRF {:.1} rpm {:.4} mm, modal {:.1} rpm {:.4} mm \
         (rel. diff {offsets:.2e}); bands upper {upper:.2e} lower {lower:.2e}; member pockets vs exact map \
         {pocket:.2e}, offsets vs 2 sd of the exact pockets {exact:.2e}",
        frf.pocket.0,
        frf.pocket.1,
        frf.offsets.offset_rpm(),
        frf.offsets.offset_mm(),
        modal.offsets.offset_rpm(),
        modal.offsets.offset_mm()
    );
    assert!(offsets < 0.01, "{offsets}");
    assert!(upper < 5e-3 && lower < 5e-3, "{upper} {lower}");
    assert!(pocket < 2e-3, "{pocket}");
    assert!(exact < 0.02, "{exact}");
}

#[test]
fn bad_inputs_are_refused() {
    assert!(FrfUncertainty::new(0.0, 0.0).is_err());
    assert!(FrfUncertainty::new(-0.1, 0.0).is_err());
    assert!(FrfUncertainty::new(0.3, 0.0).is_err());
    assert!(FrfUncertainty::new(f64::NAN, 0.01).is_err());
    let lobes = zoa_lobes(&examples::schmitz_2023_milling(), &[6000.0, 7000.0, 8000.0]).unwrap();
    let e = ensemble_offsets(&lobes, std::slice::from_ref(&lobes), 2.0).unwrap_err();
    assert!(e.to_string().contains("at least 2"), "{e}");
    let e = ensemble_offsets(&lobes, &[lobes.clone(), lobes[..2].to_vec()], 2.0).unwrap_err();
    assert!(e.to_string().contains("same speeds"), "{e}");
    let e = ensemble_offsets(&lobes, &[lobes.clone(), lobes.clone()], 0.0).unwrap_err();
    assert!(e.to_string().contains("coverage"), "{e}");
}

#[test]
fn real_cutpro_frf_bands() {
    let dir = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/real/cutpro_frf"
    ));
    if !dir.exists() {
        eprintln!("skipped: {} is absent", dir.display());
        return;
    }
    let model = ModalModel::from_json_str(
        r#"{"operation": {"kind": "milling", "teeth": 2, "radial_immersion": 0.5, "direction": "down", "tool_diameter_mm": 31.75},
            "cutting": {"kt_n_per_mm2": 1319.4, "kn_n_per_mm2": 788.8},
            "modes": [{"frequency_hz": 500, "damping_ratio": 0.05, "stiffness_n_per_m": 1e7, "direction": "x"}]}"#,
        Path::new("cutpro.json"),
    )
    .unwrap();
    let read = |name: &str| -> Vec<(f64, num_complex::Complex64)> {
        std::fs::read_to_string(dir.join(name))
            .unwrap()
            .lines()
            .filter_map(|l| {
                let v: Vec<f64> = l
                    .split_whitespace()
                    .take(3)
                    .filter_map(|t| t.parse().ok())
                    .collect();
                (v.len() == 3 && v[0] >= 10.0)
                    .then(|| (v[0], num_complex::Complex64::new(v[1], v[2])))
            })
            .collect()
    };
    let (x, y) = (read("General_FRFX.frf"), read("General_FRFY.frf"));
    let zero = num_complex::Complex64::new(0.0, 0.0);
    let nominal = SampledReceptance::new(
        x.iter().map(|p| p.0).collect(),
        x.iter()
            .zip(&y)
            .map(|(a, b)| [[a.1, zero], [zero, b.1]])
            .collect(),
    )
    .unwrap();
    let speeds: Vec<f64> = (0..=120).map(|i| 4500.0 + 25.0 * i as f64).collect();
    let (uncertainty, bands) = ensemble_bands(&model, &nominal, &speeds);
    let (pocket, exact) = check_against_exact(&bands, &uncertainty.draws(DRAWS, SEED));
    let s = bands.pocket.0;
    eprintln!(
        "CutPro General_FRFX/Y: pocket {:.0} rpm {:.4} mm; offsets {:.1} rpm {:.4} mm; at the pocket \
         lower {:.4} mm upper {:.4} mm; member pockets vs exact map {pocket:.2e}, offsets vs 2 sd {exact:.2e}",
        bands.pocket.0,
        bands.pocket.1,
        bands.offsets.offset_rpm(),
        bands.offsets.offset_mm(),
        OffsetBoundaries::depth_at(&bands.bands.lower, s).unwrap(),
        OffsetBoundaries::depth_at(&bands.bands.upper, s).unwrap()
    );
    assert!(pocket < 5e-3, "{pocket}");
    assert!(exact < 0.05, "{exact}");
}
