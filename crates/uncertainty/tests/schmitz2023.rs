//! Schmitz (2023, seed 001) Sec. 4: every stated result of the numerical example within its
//! tolerance ([`checks`]), and the mean boundary against an independent zero-order solution.
#![allow(clippy::unwrap_used)]

use chatter_uncertainty::geometric::OffsetBoundaries;
use chatter_uncertainty::geometric::schmitz2023::{checks, example_boundaries};

/// The paper's statements (lobe maxima near 5660 and 11 298 rpm with theta -> 90 deg and d ->
/// 100 rpm, minimum near 6960 rpm with theta -> 0 and d -> 200 um, Eq. 10-11 roots o_Omega to
/// the side of a cusp and o_b above and below the minimum) all hold. The depths at the extremes
/// are checked against an independent Altintas-Budak zero-order solution (numpy: directional
/// factors integrated over 126.87-180 deg, Kt = Ks sin 68 deg, Kn = Ks cos 68 deg, eigenvalues
/// -1 / (mu_alpha Phi) of the symmetric SDOF FRF, lobes k = 0..39 swept over 0.5-2.5 f_n and the
/// lowest taken on the same 10 rpm grid): 5.8947 mm at 5660 rpm, 11.7133 mm at 11 290 rpm and
/// 0.9745 mm at 6960 rpm; within 0.5 % (the sweep's interpolation between its 400 001
/// frequencies and the project's root finding differ far less).
#[test]
fn schmitz_2023_example_reproduces_section_4() {
    let bands = example_boundaries().unwrap();
    let rows = checks(&bands);
    for r in &rows {
        eprintln!(
            "{}: paper {}, ours {:.4}, tolerance {}",
            r.quantity, r.paper, r.ours, r.tolerance
        );
    }
    assert_eq!(rows.len(), 15);
    assert!(rows.iter().all(|r| r.within()), "{rows:#?}");
    let curve: Vec<(f64, f64)> = bands
        .points
        .iter()
        .map(|p| (p.speed_rpm, p.depth_mm))
        .collect();
    for (rpm, mm) in [(5660.0, 5.8947), (11_290.0, 11.7133), (6960.0, 0.9745)] {
        let ours = OffsetBoundaries::depth_at(&curve, rpm).unwrap();
        assert!(
            (ours / mm - 1.0).abs() < 0.005,
            "{rpm} rpm: {ours} mm against {mm} mm"
        );
    }
    // the lower offset polyline lies below the mean boundary wherever it is defined (it starts
    // o_Omega or o_b inside the grid's ends), which is nearly everywhere
    let inner = &curve[5..curve.len() - 5];
    let lower: Vec<(f64, f64, f64)> = inner
        .iter()
        .filter_map(|&(s, b)| Some((s, b, OffsetBoundaries::depth_at(&bands.lower, s)?)))
        .collect();
    assert!(
        lower.len() >= inner.len() * 98 / 100,
        "{} of {}",
        lower.len(),
        inner.len()
    );
    for (s, b, lo) in lower {
        assert!(lo < b, "lower {lo} mm not below {b} mm at {s} rpm");
    }
}
