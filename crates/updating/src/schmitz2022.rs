//! Seed 004's case (Schmitz, Cornelius, Karandikar, Tyler and Smith 2022, RCSA and
//! chatter-frequency-informed machine learning for milling stability): the published numbers
//! beside ours.
//!
//! The machine is `examples/schmitz2022_rcsa_model.json` (12.7 mm three-flute end mill, 65 mm
//! stick-out, shrink-fit holder, 75 % radial immersion down milling, feed 0.1 mm/tooth; modes at
//! the mean of the RCSA prior, K_s 600 N/mm^2, beta 68 deg) and its correlated prior
//! `examples/schmitz2022_rcsa_prior.json` over u = [K_s, beta, f_n1, k_1, zeta_1, f_n2, k_2,
//! zeta_2] (`cargo run --release -p chatter-rcsa --example prior_map FILE` writes it from
//! `examples/schmitz2022_rcsa_assembly.json`, whose holder and material are assumed: 004 gives
//! neither, see that crate). The paper's cut results (Fig. 6) are not printed in its text, so
//! the experiment cannot be replayed; what it states in numbers is compared:
//!
//! - the material removal rates of Sec. 6 (MRR = b a_e f_z N n, a_e = 0.75 x 12.7 mm), to the
//!   paper's rounding (1 cm^3/min, 1 percentage point);
//! - the force-model prior K_s ~ N(600, 60) N/mm^2, beta ~ N(68, 13.6) deg (Sec. 2) as the paths
//!   of `plan` draw it from the prior file (three standard errors of the draws' moments);
//! - the chatter frequency of the unstable test 3, 1550 Hz near 11 000 rpm, against the mean
//!   model's zero-order chatter frequency at 10 985 rpm (within 004's s_fc = 50 Hz; our tool is
//!   an assumed geometry);
//! - the test selection of Sec. 3: the proposed cut lies on the P_test contour (P_s within 0.05
//!   of P_test = 0.25, 0.5, 0.75, Fig. 3).

use crate::error::{Result, UpdatingError};
use crate::joint_prior::JointNormal;
use crate::plan::{PlanSettings, Strategy, plan_next_cut};
use chatter_dynamics::{ModalModel, Observations, examples};
use chatter_progress::Observer;
use chatter_stability::prepared::Method;

/// Feed per tooth of 004's tests (m).
pub const FEED_PER_TOOTH_M: f64 = 0.1e-3;
/// 004's chatter frequency of the unstable test 3 of the P_test = 50 % sequence (Hz).
pub const PAPER_CHATTER_HZ: f64 = 1550.0;

/// One published number and ours.
#[derive(Debug, Clone, PartialEq)]
pub struct Reproduced {
    /// What is compared, with its unit and where in the paper.
    pub quantity: String,
    /// The paper's value.
    pub paper: f64,
    /// Ours.
    pub ours: f64,
    /// Allowed |ours - paper|, in the quantity's unit.
    pub tolerance: f64,
}

impl Reproduced {
    /// Within the tolerance.
    pub fn within(&self) -> bool {
        (self.ours - self.paper).abs() <= self.tolerance
    }
}

/// The example model (modes at the prior mean).
pub fn model() -> ModalModel {
    examples::schmitz_2022_rcsa()
}

/// The correlated prior of the example (the embedded prior file).
pub fn prior() -> Result<JointNormal> {
    serde_json::from_str(examples::SCHMITZ_2022_RCSA_PRIOR).map_err(|e| {
        UpdatingError::InvalidInput {
            field: "priors",
            message: format!("schmitz2022_rcsa_prior.json: {e}"),
        }
    })
}

/// The plan settings of 004 before the first cut: the correlated prior, `paths` paths, the
/// zero-order boundaries 004 uses (reference 10 of the paper), 41 speeds over 8000-16 000 rpm (the
/// lobes around the paper's tests) and 60 depths up to 6 mm.
pub fn first_cut_settings(p_test: f64, paths: usize, seed: u64) -> Result<PlanSettings> {
    Ok(PlanSettings {
        strategy: Strategy::MaterialRemovalRate,
        p_test,
        joint_prior: Some(prior()?),
        paths,
        speeds_rpm: Some((0..41).map(|i| 8000.0 + 200.0 * i as f64).collect()),
        depths_m: Some((1..=60).map(|i| 0.1e-3 * i as f64).collect()),
        feed_per_tooth_m: FEED_PER_TOOTH_M,
        seed,
        method: Some(Method::Zoa),
        ..PlanSettings::default()
    })
}

/// The rows of the module docs, with `paths` sampled boundaries per plan.
pub fn reproduction(paths: usize, seed: u64, observer: &dyn Observer) -> Result<Vec<Reproduced>> {
    let model = model();
    let mrr = |rpm: f64, mm: f64| {
        crate::ensemble::material_removal_rate_cm3_per_min(&model, rpm, mm * 1e-3, FEED_PER_TOOTH_M)
            .unwrap_or(f64::NAN)
    };
    let mut rows = vec![
        Reproduced {
            quantity: "Sec. 6 MRR of the best P_test = 50 % cut, 10 985 rpm x 3.4 mm (cm^3/min)"
                .into(),
            paper: 107.0,
            ours: mrr(10985.0, 3.4),
            tolerance: 0.5,
        },
        Reproduced {
            quantity: "Sec. 6 MRR gain of the next proposal, 10 955 rpm x 3.7 mm (%)".into(),
            paper: 9.0,
            ours: 100.0 * (mrr(10955.0, 3.7) / mrr(10985.0, 3.4) - 1.0),
            tolerance: 0.5,
        },
        Reproduced {
            quantity: "Sec. 6 MRR of the best manual cut, 11 000 rpm x 3 mm (cm^3/min)".into(),
            paper: 94.0,
            ours: mrr(11000.0, 3.0),
            tolerance: 0.5,
        },
    ];
    let chatter = chatter_stability::zero_order::zoa_lobes(&model, &[10985.0])?;
    rows.push(Reproduced {
        quantity: "Sec. 6 chatter frequency of test 3 near 11 000 rpm (Hz; ours: mean model)"
            .into(),
        paper: PAPER_CHATTER_HZ,
        ours: chatter[0].chatter_hz,
        tolerance: 50.0,
    });
    for (i, p_test) in [0.25, 0.5, 0.75].into_iter().enumerate() {
        let settings = first_cut_settings(p_test, paths, seed + i as u64)?;
        let outcome = plan_next_cut(&model, &Observations::default(), &settings, observer)?;
        if i == 1 {
            let se = |sd: f64| 3.0 * sd / (paths as f64).sqrt();
            let named = |name: &str| outcome.parameter_names.iter().position(|n| n == name);
            for (name, mean, sd) in [("ks_n_per_mm2", 600.0, 60.0), ("beta_deg", 68.0, 13.6)] {
                let k = named(name).ok_or_else(|| UpdatingError::InvalidInput {
                    field: "priors",
                    message: format!("the prior file has no `{name}`"),
                })?;
                rows.push(Reproduced {
                    quantity: format!("Sec. 2 prior mean of {name}, paths drawn by plan"),
                    paper: mean,
                    ours: outcome.posterior_mean[k],
                    tolerance: se(sd),
                });
                rows.push(Reproduced {
                    quantity: format!("Sec. 2 prior sd of {name}, paths drawn by plan"),
                    paper: sd,
                    ours: outcome.posterior_sd[k],
                    // the sd of a sample sd is about sd / sqrt(2 n)
                    tolerance: se(sd) / 2f64.sqrt(),
                });
            }
        }
        rows.push(Reproduced {
            quantity: format!("Sec. 3 P_s of the first proposed cut at P_test = {p_test}"),
            paper: p_test,
            ours: outcome.next_cut.map_or(f64::NAN, |c| c.p_stable),
            tolerance: 0.05,
        });
    }
    Ok(rows)
}

/// The rows as an aligned text table (`paper | ours | tolerance | ok`).
pub fn table(rows: &[Reproduced]) -> String {
    let mut out = format!(
        "{:<78} {:>10} {:>10} {:>9}  ok\n",
        "quantity", "paper", "ours", "tolerance"
    );
    for r in rows {
        out += &format!(
            "{:<78} {:>10.4} {:>10.4} {:>9.4}  {}\n",
            r.quantity,
            r.paper,
            r.ours,
            r.tolerance,
            if r.within() { "yes" } else { "NO" }
        );
    }
    out
}
