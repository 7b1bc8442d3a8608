//! `chatter sensitivity`: |d mu / d theta| of the dominant pole at one cut (000 Section 6.2,
//! Table 3), on the one-step map of the full discretization by default.

use crate::output::emit;
use anyhow::{Context, Result, bail};
use chatter_dynamics::Parameter;
use chatter_uncertainty::sensitivity::{
    TABLE3_STEPS_PER_REVOLUTION, TransitionMap, pole_sensitivity,
};
use std::path::PathBuf;

/// Which map to differentiate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MapArg {
    /// One time step of the full discretization (000 Eq. 9-12), as in 000 Table 3.
    OneStep,
    /// One delay period (the monodromy of the stability lobes), m times larger near |mu| = 1.
    Period,
}

/// Arguments of `chatter sensitivity`.
#[derive(Debug, clap::Args)]
pub struct SensitivityArgs {
    /// Model file (JSON).
    #[arg(long)]
    model: PathBuf,
    /// Spindle speed (rpm).
    #[arg(long)]
    speed_rpm: f64,
    /// Depth (milling) or width (turning) of cut (mm).
    #[arg(long)]
    depth_mm: f64,
    /// Parameters, comma-separated (theta_omega_N, theta_zeta_N, theta_phi_N, theta_k_N);
    /// default omega, zeta and phi of every mode (the rows of 000 Table 3).
    #[arg(long)]
    parameters: Option<String>,
    /// Full-discretization steps per revolution (per tooth period in milling).
    #[arg(long, default_value_t = TABLE3_STEPS_PER_REVOLUTION.get())]
    steps_per_revolution: usize,
    /// The differentiated map.
    #[arg(long, value_enum, default_value = "one-step")]
    map: MapArg,
    /// Write the JSON here instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
}

fn parameters(spec: Option<&str>, modes: usize) -> Result<Vec<Parameter>> {
    match spec {
        Some(s) => s
            .split(',')
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .map(|n| {
                n.parse::<Parameter>()
                    .with_context(|| format!("--parameters `{s}`"))
            })
            .collect::<Result<Vec<_>>>()
            .and_then(|p| {
                if p.is_empty() {
                    bail!("--parameters `{s}`: no parameter named");
                }
                if let Some(bad) = p.iter().find(|q| q.mode >= modes) {
                    bail!(
                        "--parameters `{s}`: mode {} does not exist (the model has {modes})",
                        bad.mode + 1
                    );
                }
                Ok(p)
            }),
        None => Ok(["omega", "zeta", "phi"]
            .iter()
            .flat_map(|k| (1..=modes).map(move |n| format!("theta_{k}_{n}")))
            .map(|n| n.parse::<Parameter>())
            .collect::<std::result::Result<Vec<_>, _>>()?),
    }
}

/// Run `chatter sensitivity`.
pub fn run(args: &SensitivityArgs) -> Result<()> {
    let model = crate::inputs::model(&args.model)?;
    if !(args.speed_rpm.is_finite() && args.speed_rpm > 0.0) {
        bail!("--speed-rpm {}: expected a speed > 0", args.speed_rpm);
    }
    if !(args.depth_mm.is_finite() && args.depth_mm > 0.0) {
        bail!("--depth-mm {}: expected a depth > 0", args.depth_mm);
    }
    let Some(steps_per_revolution) =
        std::num::NonZeroUsize::new(args.steps_per_revolution).filter(|m| m.get() >= 2)
    else {
        bail!(
            "--steps-per-revolution {}: expected at least 2",
            args.steps_per_revolution
        );
    };
    let params = parameters(args.parameters.as_deref(), model.mode_count())?;
    let map = match args.map {
        MapArg::OneStep => TransitionMap::OneStep,
        MapArg::Period => TransitionMap::Period,
    };
    let s = pole_sensitivity(
        &model,
        &params,
        args.speed_rpm,
        args.depth_mm * 1e-3,
        steps_per_revolution,
        map,
    )?;
    let entries: Vec<_> = s
        .entries
        .iter()
        .map(|e| {
            serde_json::json!({
                "parameter": e.parameter.to_string(),
                "modulus": e.modulus(),
                "real": e.derivative.re,
                "imag": e.derivative.im,
            })
        })
        .collect();
    let json = serde_json::json!({
        "speed_rpm": args.speed_rpm,
        "depth_mm": args.depth_mm,
        "map": s.map,
        "map_description": match s.map {
            TransitionMap::OneStep => "dominant eigenvalue of the one-step map of the full \
                discretization (000 Eq. 9-12), as in 000 Table 3",
            TransitionMap::Period => "dominant multiplier over one delay period (the \
                monodromy whose |mu| = 1 is the stability boundary)",
        },
        "steps_per_delay": s.steps_per_delay,
        "eigenvalue": {"real": s.eigenvalue.re, "imag": s.eigenvalue.im, "modulus": s.eigenvalue.norm()},
        "period_multiplier_modulus": s.period_multiplier.norm(),
        "chatter_hz": s.chatter_hz,
        "sensitivities": entries,
    });
    emit(
        args.out.as_deref(),
        &(serde_json::to_string_pretty(&json)? + "\n"),
    )
}
