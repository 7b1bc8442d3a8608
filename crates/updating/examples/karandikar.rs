//! Seed 003 (Karandikar, Tyler and Schmitz): Table 2's value of information at the candidate
//! tests A-D, the prior probabilities of stability quoted in the text, and the RSS and Bayesian
//! identification of the process-damping coefficient C, each beside the paper's number with the
//! tolerance it is held to.
//!
//! ```sh
//! cargo run --release -p chatter-updating --example karandikar            # 2000 paths, ~1 min
//! cargo run --release -p chatter-updating --example karandikar -- --paths 500 \
//!     --stiffness-n-per-m 1.9e6 --damping-ratio 0.045                     # a calibration trial
//! ```
//!
//! The RSS and posterior of C use cuts from the calibrated flexure with C = 2.5e5 N/m (the
//! paper's Fig. 4 data are not in the text): a 6 x 8 grid at 300-1300 rpm, 0.5-4 mm, each
//! stable below the converged full-discretization limit (60 steps per vibration cycle), where
//! the paths and the RSS use the automatic resolution (no inverse crime).

use chatter_dynamics::{Cut, ModeShape, examples};
use chatter_progress::Silent;
use chatter_stability::boundary;
use chatter_stability::monodromy::{Discretization, steps, steps_at_least};
use chatter_updating::cuts::CutKernel;
use chatter_updating::karandikar::{self, PAPER_PRIOR_P_STABLE, PAPER_PRIOR_SD_C};

/// Tolerances of the issue: P_s within 0.1, expected reductions within 5 points.
const P_TOLERANCE: f64 = 0.1;
const REDUCTION_TOLERANCE: f64 = 5.0;

fn arg(name: &str) -> Option<f64> {
    let args: Vec<String> = std::env::args().collect();
    let i = args.iter().position(|a| a == name)?;
    let value = args.get(i + 1)?;
    Some(
        value
            .parse()
            .unwrap_or_else(|_| panic!("{name} {value}: expected a number")),
    )
}

fn mark(ok: bool) -> &'static str {
    if ok { "ok" } else { "OUT" }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let paths = arg("--paths").map_or(2000, |p| p as usize);
    let seed = arg("--seed").map_or(3, |s| s as u64);
    let mut model = examples::karandikar_flexure();
    let mode = model.modes()[0];
    let (k0, z0) = match mode.shape() {
        ModeShape::Directional {
            stiffness_n_per_m, ..
        } => (stiffness_n_per_m, mode.damping_ratio()),
        ModeShape::MassNormalized(_) => return Err("the 003 flexure is directional".into()),
    };
    let (k, zeta) = (
        arg("--stiffness-n-per-m").unwrap_or(k0),
        arg("--damping-ratio").unwrap_or(z0),
    );
    if (k, zeta) != (k0, z0) {
        let m = chatter_dynamics::Mode::new(
            mode.frequency_hz(),
            zeta,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: k,
            },
        )?;
        model = model.with_modes(vec![m])?;
    }
    println!(
        "seed 003 flexure: 228 Hz, k {k:.4e} N/m, zeta {zeta}; {paths} prior paths, seed {seed}"
    );

    let speeds = [400.0, 1000.0, 1500.0, 2000.0];
    let prior = karandikar::prior_paths(&model, paths, &speeds, seed, &Silent)?;
    let (_, sd0) = prior.moments(2)?;
    println!(
        "prior sigma_C: ours {sd0:.3e} N/m, paper {PAPER_PRIOR_SD_C:.3e} (U(0.5e5, 10e5): 2.742e5)"
    );
    println!("\nprior P_s in the text (Figs. 7-8), tolerance {P_TOLERANCE}:");
    for (speed, depth, paper) in PAPER_PRIOR_P_STABLE {
        let ours = prior.probability_of_stability(speed, depth * 1e-3)?;
        let ok = (ours - paper).abs() <= P_TOLERANCE;
        println!(
            "  {speed:5.0} rpm {depth:4.2} mm: paper {paper:4.2}  ours {ours:5.3}  {}",
            mark(ok)
        );
    }
    println!(
        "\nTable 2 (expected % reduction of sigma_C), tolerances {P_TOLERANCE} and {REDUCTION_TOLERANCE} points:"
    );
    println!("  test  rpm    mm    P_s paper/ours     reduction paper/ours");
    for r in karandikar::table_2(&prior)? {
        let t = r.test;
        let ok = (r.p_stable - t.paper_p_stable).abs() <= P_TOLERANCE
            && (r.reduction_percent - t.paper_reduction_percent).abs() <= REDUCTION_TOLERANCE;
        println!(
            "  {}  {:6.0} {:5.2}    {:4.2} / {:5.3}      {:5.1} / {:5.1}   {}",
            t.label,
            t.speed_rpm,
            t.depth_mm,
            t.paper_p_stable,
            r.p_stable,
            t.paper_reduction_percent,
            r.reduction_percent,
            mark(ok)
        );
    }
    println!(
        "  D's reduction is a documented deviation: the paper's 24.9 % needs the 2000 rpm limit to\n  \
         span ~3 mm over the C prior, which Eq. 1's C b / V does not give with its B and Fig. 8\n  \
         (chatter_updating::karandikar docs; python3 crates/updating/examples/karandikar_point_d.py)"
    );
    // why D's reduction is small here: how much C moves the limit at each candidate speed
    println!(
        "\nlimiting depth (mm) at the nominal kt, kn against C (0.5e5, 2.5e5, 5e5, 7.5e5, 10e5 N/m):"
    );
    let options = chatter_stability::prepared::SolverOptions::default()
        .with_max_depth_m(karandikar::MAX_DEPTH_M);
    for speed in speeds {
        let limits = [0.5e5, 2.5e5, 5e5, 7.5e5, 10e5]
            .iter()
            .map(|&c| {
                let m = model.with_process_damping(Some(c))?;
                let p = options.prepare_on_grid_of(&m, &m)?.limiting_depth(speed)?;
                Ok(format!(
                    "{:5.2}",
                    p.depth_m.min(karandikar::MAX_DEPTH_M) * 1e3
                ))
            })
            .collect::<Result<Vec<_>, chatter_updating::UpdatingError>>()?;
        println!("  {speed:5.0} rpm: {}", limits.join(" "));
    }
    if std::env::args().any(|a| a == "--table-only") {
        return Ok(());
    }

    // cuts from the machine with the true C, by a finer computation than the paths'
    let truth = model.with_process_damping(Some(2.5e5))?;
    let mut cuts = Vec::new();
    for speed in [300.0, 500.0, 700.0, 900.0, 1100.0, 1300.0] {
        // 50 % immersion, one tooth: the cut lasts half the revolution
        let cycles: f64 = 228.0 * 0.5 * 60.0 / speed;
        let steps = steps_at_least((60.0 * cycles).ceil() as usize, steps::<400>());
        let options = boundary::BoundaryOptions {
            relative_tolerance: 1e-5,
            max_depth_m: 0.1,
            ..Default::default()
        };
        let limit = boundary::limiting_depth(
            &Discretization::full().with_steps(steps),
            &truth,
            speed,
            &options,
        )?;
        for i in 1..=8 {
            let depth_mm = 0.5 * i as f64;
            cuts.push(Cut::labelled(
                speed,
                depth_mm,
                depth_mm * 1e-3 < limit.depth_m,
            ));
        }
    }
    let rss = karandikar::rss_process_damping(&model, &cuts, 0.5e5, 10e5)?;
    println!(
        "\nRSS identification of C from {} cuts ({} speeds with a limit): {:.3e} N/m (paper, its 48 cuts: 2.5e5; true here 2.5e5)",
        cuts.len(),
        rss.limits.len(),
        rss.c_n_per_m
    );
    let mut posterior = prior.clone();
    posterior.add_speeds(&[300.0, 500.0, 700.0, 900.0, 1100.0, 1300.0], &Silent)?;
    for cut in &cuts {
        posterior.update(cut, &CutKernel::karandikar())?;
    }
    let (mean, sd) = posterior.moments(2)?;
    println!(
        "Bayesian (003 Eq. 5-6) after the same {} cuts: C {mean:.3e} +- {sd:.3e} N/m (paper after its 48 cuts: 2.49e5 +- 0.30e5)",
        cuts.len()
    );
    Ok(())
}
