//! Seed 003's Table 2 on the calibrated flexure (`examples/karandikar_flexure_model.json`):
//! prior probability of stability and expected percent reduction of sigma_C at the candidate
//! tests, against the paper within 0.1 and 5 points (issue 18). D's expected reduction is not
//! reproduced (ours ~1.5 % against 24.9 %: a documented deviation, see the
//! `chatter_updating::karandikar` module docs and `examples/karandikar_point_d.py`), so only
//! D's P_s is held, and its reduction is held below 5 % (what the deviation says).
//! 300 paths (the example uses 2000): a few seconds.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::examples;
use chatter_progress::Silent;
use chatter_updating::karandikar;

#[test]
fn table_2_candidates_match_the_paper() {
    let model = examples::karandikar_flexure();
    let speeds = [400.0, 1000.0, 1500.0, 2000.0];
    let prior = karandikar::prior_paths(&model, 300, &speeds, 3, &Silent).unwrap();
    for r in karandikar::table_2(&prior).unwrap() {
        let t = r.test;
        eprintln!(
            "{}: P_s {:.3} (paper {}), reduction {:.1} % (paper {})",
            t.label, r.p_stable, t.paper_p_stable, r.reduction_percent, t.paper_reduction_percent
        );
        assert!((r.p_stable - t.paper_p_stable).abs() <= 0.1, "{t:?}: {r:?}");
        if t.label == "D" {
            assert!(r.reduction_percent < 5.0, "{t:?}: {r:?}");
        } else {
            assert!(
                (r.reduction_percent - t.paper_reduction_percent).abs() <= 5.0,
                "{t:?}: {r:?}"
            );
        }
    }
    // the text's prior P_s at 400 rpm (Fig. 7): 1 at 1 mm, 0.7 at 4 mm
    let p = |s: f64, d: f64| prior.probability_of_stability(s, d * 1e-3).unwrap();
    assert!(p(400.0, 1.0) >= 0.9);
    assert!((p(400.0, 4.0) - 0.7).abs() <= 0.1);
}

/// RSS identification of C (003, Tyler and Schmitz 2012) recovers the C of the machine that
/// made the cuts: cuts bracketing the limit of the flexure with C = 2.5e5 N/m at three speeds
/// (limits from a 4x finer full discretization than the fit's), fitted within 10 %.
#[test]
fn rss_recovers_the_process_damping_coefficient() {
    use chatter_dynamics::Cut;
    use chatter_stability::boundary;
    use chatter_stability::monodromy::{Discretization, steps_at_least};
    use std::num::NonZeroUsize;
    let model = examples::karandikar_flexure();
    let mut cuts = Vec::new();
    for speed in [500.0, 700.0, 900.0] {
        let steps = steps_at_least(
            (4.0 * 228.0 * 0.5 * 60.0 / speed * 24.0) as usize,
            NonZeroUsize::MIN,
        );
        let limit = boundary::limiting_depth(
            &Discretization::full().with_steps(steps),
            &model,
            speed,
            &boundary::BoundaryOptions::default(),
        )
        .unwrap()
        .depth_m
            * 1e3;
        for (depth_mm, stable) in [(limit - 0.05, true), (limit + 0.05, false)] {
            cuts.push(Cut::labelled(speed, depth_mm, stable));
        }
    }
    let fit = karandikar::rss_process_damping(&model, &cuts, 0.5e5, 10e5).unwrap();
    eprintln!(
        "RSS C = {:.4e}, rss {:.2e} mm^2",
        fit.c_n_per_m, fit.rss_mm2
    );
    assert_eq!(fit.limits.len(), 3);
    assert!((fit.c_n_per_m / 2.5e5 - 1.0).abs() < 0.1, "{fit:?}");
}
