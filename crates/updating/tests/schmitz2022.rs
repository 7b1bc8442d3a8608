//! Seed 004 reproduced (`chatter_updating::schmitz2022`): the paper's numbers beside ours with
//! their tolerances, and `plan --strategy mrr` with the correlated RCSA prior: the proposed cut
//! lies on the P_test contour, checked against P_s recomputed here from the exported sampled
//! boundaries; the cap on tests stops a campaign with its reason.
//!
//! `cargo test --release -p chatter-updating --test schmitz2022 -- --nocapture` prints the table.

#![allow(clippy::unwrap_used)]

use chatter_dynamics::{Cut, Observations};
use chatter_progress::Silent;
use chatter_updating::plan::plan_next_cut;
use chatter_updating::schmitz2022::{first_cut_settings, model, reproduction, table};

#[test]
fn paper_numbers_beside_ours() {
    let rows = reproduction(200, 4, &Silent).unwrap();
    println!("{}", table(&rows));
    for r in &rows {
        assert!(
            r.within(),
            "{}: paper {} ours {} (tolerance {})",
            r.quantity,
            r.paper,
            r.ours,
            r.tolerance
        );
    }
    assert_eq!(rows.len(), 4 + 4 + 3);
}

#[test]
fn proposed_cut_is_on_the_contour_of_the_exported_boundaries_and_the_cap_stops() {
    let model = model();
    let settings = first_cut_settings(0.5, 120, 11).unwrap();
    let out = plan_next_cut(&model, &Observations::default(), &settings, &Silent).unwrap();
    assert_eq!(
        out.parameter_names,
        [
            "ks_n_per_mm2",
            "beta_deg",
            "fn1_hz",
            "k1_n_per_m",
            "zeta1",
            "fn2_hz",
            "k2_n_per_m",
            "zeta2"
        ]
    );
    let cut = out.next_cut.unwrap();
    // P_s written out from the exported boundaries: the share of path probability whose limit
    // at the cut's speed lies above the cut's depth
    let b = &out.boundaries;
    let k = b
        .speeds_rpm
        .iter()
        .position(|s| *s == cut.speed_rpm)
        .unwrap();
    let p: f64 = b
        .probabilities
        .iter()
        .zip(&b.limits_mm)
        .filter(|(_, d)| d[k] > cut.depth_mm)
        .map(|(w, _)| w)
        .sum();
    assert!((p - cut.p_stable).abs() < 1e-12, "{p} {}", cut.p_stable);
    assert!((cut.p_stable - 0.5).abs() <= 0.05, "{cut:?}");
    assert_eq!(cut.on_contour, Some(true));
    // a deeper grid point at that speed would fall below P_test: the cut is the contour's
    let deeper = cut.depth_mm + 0.1;
    let p_deeper: f64 = b
        .probabilities
        .iter()
        .zip(&b.limits_mm)
        .filter(|(_, d)| d[k] > deeper)
        .map(|(w, _)| w)
        .sum();
    assert!(p_deeper < 0.5, "{p_deeper}");
    // the cap: two cuts made with max_tests 2 stop the campaign and say why
    let cuts = Observations {
        cuts: [cut.depth_mm, 0.5 * cut.depth_mm]
            .iter()
            .map(|&depth_mm| Cut {
                speed_rpm: cut.speed_rpm,
                depth_mm,
                stable: true,
                chatter_hz: None,
                sequence: None,
                radial_immersion: None,
                note: None,
                evidence: None,
            })
            .collect(),
        ..Observations::default()
    };
    let capped = chatter_updating::plan::PlanSettings {
        max_tests: 2,
        paths: 60,
        ..settings
    };
    let out = plan_next_cut(&model, &cuts, &capped, &Silent).unwrap();
    assert!(out.stop);
    assert!(out.stop_reason.unwrap().contains("cap of 2"));
}
