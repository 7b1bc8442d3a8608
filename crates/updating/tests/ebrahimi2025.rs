//! Seed 002, numerical simulation (Section 3.1): poles "identified" at the Table 1 cutting
//! conditions of a simulated SDOF milling system (194 Hz, zeta 0.005, 2.35 N/um, Kt 650 and
//! Kn 110 MPa, two-flute slotting) are computed here from the model itself, with the Table 1
//! standard deviations as scatter; the exact-monodromy likelihood with uniform priors then brings
//! the parameter variations back to zero, as in the paper (Fig. 7).

#![allow(clippy::unwrap_used)]

use chatter_bayes::prior::{IndependentPrior, Marginal};
use chatter_dynamics::{
    CuttingCoefficients, Milling, MillingDirection, ModalModel, Mode, ModeShape, Operation,
    PoleObservation,
};
use chatter_stability::monodromy::Discretization;
use chatter_updating::classes::{Sampler, SamplerOptions, Silent, sample_posterior};
use chatter_updating::milling::MillingPoleLikelihood;
use chatter_updating::parameters::{Parameterization, parse_model_parameters};

fn simulated_setup() -> ModalModel {
    let mode = Mode::new(
        194.0,
        0.005,
        ModeShape::Directional {
            coordinate: 0,
            stiffness_n_per_m: 2.35e6,
        },
    )
    .unwrap();
    let op = Operation::Milling(
        Milling::new(2, 1.0, MillingDirection::Down, Some(12.7e-3), None).unwrap(),
    );
    ModalModel::new(
        Some("002 numerical simulation".into()),
        op,
        CuttingCoefficients::new(650e6, 110e6).unwrap(),
        vec![mode],
        None,
    )
    .unwrap()
}

#[test]
fn simulated_poles_bring_the_parameters_back_to_nominal() {
    let model = simulated_setup();
    let p = Parameterization::new(
        model,
        parse_model_parameters("theta_omega_1,theta_zeta_1,theta_k_1").unwrap(),
    )
    .unwrap();
    // Table 1 conditions and standard deviations (frequency Hz, damping)
    let table = [
        (2000.0, 0.4, 0.0182, 0.0143),
        (2000.0, 0.6, 0.0362, 0.0133),
        (2000.0, 0.8, 0.0889, 0.0047),
        (2100.0, 0.3, 0.0102, 0.0063),
        (2100.0, 0.4, 0.0041, 0.0037),
    ];
    let solver = Discretization::full();
    let mut poles: Vec<PoleObservation> = table
        .iter()
        .map(|&(speed_rpm, depth_mm, sf, sz)| PoleObservation {
            speed_rpm,
            depth_mm,
            frequency_hz: 0.0,
            damping_ratio: 0.0,
            frequency_std_hz: Some(sf),
            damping_std: Some(sz),
            repetitions: Some(10),
            sequence: None,
            radial_immersion: None,
            note: None,
        })
        .collect();
    let exact = MillingPoleLikelihood::new(p.clone(), &poles, 0.1, solver).unwrap();
    for (pole, (f, z)) in poles
        .iter_mut()
        .zip(exact.predicted_poles(&[0.0, 0.0, 0.0]).unwrap())
    {
        pole.frequency_hz = f;
        pole.damping_ratio = z;
    }
    let like = MillingPoleLikelihood::new(p, &poles, 0.1, solver).unwrap();
    let prior = IndependentPrior::new(vec![
        Marginal::Uniform {
            low: -0.3,
            high: 0.3,
        },
        Marginal::Uniform {
            low: -0.3,
            high: 0.3,
        },
        Marginal::Uniform {
            low: -0.3,
            high: 0.3,
        },
        Marginal::Uniform {
            low: 1e-10,
            high: 1.0,
        },
    ])
    .unwrap();
    let options = SamplerOptions {
        sampler: Sampler::Tmcmc,
        samples: 150,
        seed: 2,
    };
    let post = sample_posterior(&prior, &like, &options, &Silent).unwrap();
    let m = post.samples.mean();
    let c = post.samples.covariance();
    eprintln!(
        "posterior mean {:.4?}, sd {:.1e} {:.1e} {:.1e}",
        &m[..3],
        c[(0, 0)].sqrt(),
        c[(1, 1)].sqrt(),
        c[(2, 2)].sqrt()
    );
    // zero within the posterior spread; the frequency is pinned hardest (002 Fig. 7)
    for k in 0..3 {
        assert!(m[k].abs() < 2.5 * c[(k, k)].sqrt() + 1e-4, "{k}: {}", m[k]);
    }
    assert!(m[0].abs() < 0.002 && m[1].abs() < 0.1 && m[2].abs() < 0.06);
    assert!(c[(0, 0)] < 0.01 * c[(1, 1)].min(c[(2, 2)]));
}
