//! `chatter batch`: the options mapped to [`chatter_jobs::campaign`] (every machine-tool
//! campaign of a fleet manifest diagnosed and planned in parallel), the table written atomically.

use crate::output::{check_file, write_atomic};
use crate::progress::Bar;
use anyhow::Result;
use chatter_jobs::campaign::{CampaignOptions, read_manifest, run_batch};
use std::path::PathBuf;

/// Arguments of `chatter batch`.
#[derive(Debug, clap::Args)]
pub struct BatchArgs {
    /// Manifest CSV `name,model,observations,seed`, paths relative to the manifest.
    #[arg(long)]
    manifest: PathBuf,
    /// Table CSV `name,verdict,boundary_shift_percent,next_speed_rpm,next_depth_mm,
    /// next_p_stable,stop,error`, one row per campaign in manifest order.
    #[arg(long)]
    out: PathBuf,
    /// iTMCMC samples per effect class of each diagnosis.
    #[arg(long, default_value_t = chatter_jobs::diagnose::DEFAULT_SAMPLES)]
    samples: usize,
    /// Sampled boundaries of each next-test plan.
    #[arg(long, default_value_t = 300)]
    paths: usize,
}

/// Run `chatter batch`.
pub fn run(args: &BatchArgs, quiet: bool) -> Result<()> {
    check_file("--out", &args.out)?;
    let campaigns = read_manifest(&args.manifest).map_err(crate::job_error)?;
    let options = CampaignOptions::new(args.samples, args.paths).map_err(crate::job_error)?;
    let bar = Bar::new(campaigns.len() as u64, "campaigns", quiet);
    let outcome = run_batch(&campaigns, &options, &bar).map_err(crate::job_error)?;
    bar.finish();
    let failed = outcome.failed();
    if failed > 0 {
        eprintln!(
            "warning: {failed} of {} campaigns failed; their rows carry the error",
            campaigns.len()
        );
    }
    write_atomic(&args.out, outcome.table().as_bytes())
}
