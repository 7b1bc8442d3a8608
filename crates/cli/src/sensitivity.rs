//! `chatter sensitivity`: the options mapped to [`chatter_jobs::sensitivity`], the outcome
//! written as JSON.

use crate::output::emit;
use anyhow::Result;
use chatter_jobs::sensitivity::{Sensitivity, SensitivityRequest};
use chatter_uncertainty::sensitivity::{TABLE3_STEPS_PER_REVOLUTION, TransitionMap};
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
    #[arg(long, value_delimiter = ',')]
    parameters: Option<Vec<String>>,
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

/// Run `chatter sensitivity`.
pub fn run(args: &SensitivityArgs) -> Result<()> {
    let model = crate::inputs::model(&args.model)?;
    let request = SensitivityRequest {
        parameters: args.parameters.clone(),
        steps_per_revolution: args.steps_per_revolution,
        map: match args.map {
            MapArg::OneStep => TransitionMap::OneStep,
            MapArg::Period => TransitionMap::Period,
        },
        ..SensitivityRequest::new(args.speed_rpm, args.depth_mm)
    };
    let outcome = Sensitivity::new(&model, &request)
        .and_then(|job| job.run())
        .map_err(crate::job_error)?;
    emit(
        args.out.as_deref(),
        &(serde_json::to_string_pretty(&outcome.to_json())? + "\n"),
    )
}
