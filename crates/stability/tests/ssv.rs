//! Spindle-speed variation in the discretizations (`chatter_stability::ssv`): zero amplitude is
//! the constant-speed solver to the bit; an amplitude of 1e-9 goes through the time-varying-delay
//! program and gives the constant-speed multiplier to the power q (the modulation period holds q
//! delays) to 1e-6; FDM and SDM agree on the limiting depth within 1 % at A = 0.1; on seed
//! 000's lathe, at lobe numbers near 20 (low speed for its 2445 Hz mode), SSV raises the lowest
//! limiting depth of the band (the gain SSV is used for); bad ratios are errors by name.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_stability::StabilitySolver;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::{Discretization, steps};
use chatter_stability::ssv::{SpeedVariation, VariedSpeed};

#[test]
fn zero_amplitude_is_the_constant_speed_solver() {
    let model = examples::schmitz_2023_milling();
    for d in [Discretization::full(), Discretization::semi()] {
        let varied = VariedSpeed {
            discretization: d,
            variation: SpeedVariation::new(0.0, 0.5).unwrap(),
        };
        let a = varied.dominant_multiplier(&model, 9000.0, 1e-3).unwrap();
        let b = d.dominant_multiplier(&model, 9000.0, 1e-3).unwrap();
        assert_eq!(a.value, b.value);
        assert_eq!(a.period_s, b.period_s);
    }
}

#[test]
fn vanishing_amplitude_gives_the_power_of_the_constant_speed_multiplier() {
    // milling: 4 teeth, ratio 0.5, q = 8 tooth periods; turning: ratio 0.25, q = 4 revolutions
    for (model, rpm, depth, ratio, q) in [
        (examples::schmitz_2023_milling(), 9000.0, 1e-3, 0.5, 8),
        (examples::ahmadi_2022_turning(), 7150.0, 1.5e-3, 0.25, 4),
    ] {
        for d in [
            Discretization::full().with_steps(steps::<40>()),
            Discretization::semi().with_steps(steps::<40>()),
        ] {
            let varied = VariedSpeed {
                discretization: d,
                variation: SpeedVariation::new(1e-9, ratio).unwrap(),
            };
            let mu = varied.dominant_multiplier(&model, rpm, depth).unwrap();
            let expected = d
                .dominant_multiplier(&model, rpm, depth)
                .unwrap()
                .modulus()
                .powi(q);
            eprintln!("{:?}: {} vs {expected}", d.scheme, mu.modulus());
            assert!(
                (mu.modulus() - expected).abs() < 1e-6 * expected.max(1e-3),
                "{:?}: {} vs {expected}",
                d.scheme,
                mu.modulus()
            );
        }
    }
}

#[test]
fn fdm_and_sdm_agree_and_ssv_raises_the_low_speed_limit_of_a_lathe() {
    let model = examples::ahmadi_2022_turning();
    let options = BoundaryOptions::default();
    let variation = SpeedVariation::new(0.1, 0.2).unwrap();
    let speeds = [6800.0, 7000.0, 7200.0, 7400.0];
    let (mut constant_min, mut varied_min) = (f64::INFINITY, f64::INFINITY);
    for &rpm in &speeds {
        let constant = limiting_depth(&Discretization::full(), &model, rpm, &options)
            .unwrap()
            .depth_m;
        let depths: Vec<f64> = [Discretization::full(), Discretization::semi()]
            .into_iter()
            .map(|d| {
                let v = VariedSpeed {
                    discretization: d,
                    variation,
                };
                limiting_depth(&v, &model, rpm, &options).unwrap().depth_m
            })
            .collect();
        eprintln!(
            "{rpm} rpm: constant {:.4} mm, SSV fdm {:.4} mm, sdm {:.4} mm",
            constant * 1e3,
            depths[0] * 1e3,
            depths[1] * 1e3
        );
        assert!((depths[0] / depths[1] - 1.0).abs() < 0.01);
        constant_min = constant_min.min(constant);
        varied_min = varied_min.min(depths[0]);
    }
    eprintln!(
        "lowest limit over the band: constant {:.4} mm, SSV {:.4} mm",
        constant_min * 1e3,
        varied_min * 1e3
    );
    assert!(varied_min > constant_min);
}

#[test]
fn bad_ratios_are_errors_by_name() {
    for (a, r, field) in [
        (1.0, 0.2, "ssv_amplitude_ratio"),
        (-0.1, 0.2, "ssv_amplitude_ratio"),
        (0.1, 0.0, "ssv_frequency_ratio"),
    ] {
        let err = SpeedVariation::new(a, r).err().unwrap().to_string();
        assert!(err.contains(field), "{err}");
    }
    // 4 teeth / 0.3 is not a whole number of tooth periods
    let varied = VariedSpeed {
        discretization: Discretization::full(),
        variation: SpeedVariation::new(0.1, 0.3).unwrap(),
    };
    let err = varied
        .dominant_multiplier(&examples::schmitz_2023_milling(), 9000.0, 1e-3)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("ssv_frequency_ratio"), "{err}");
}
