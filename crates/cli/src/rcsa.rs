//! `chatter rcsa`: the assembly file mapped to [`chatter_jobs::rcsa`], the tool-tip FRF written
//! as CSV and plotted.

use crate::output::emit;
use crate::plot::{Series, line_chart};
use anyhow::{Context, Result};
use chatter_jobs::rcsa::{RcsaRequest, rcsa as couple};
use plotters::style::BLUE;
use std::path::PathBuf;

/// Arguments of `chatter rcsa`.
#[derive(Debug, clap::Args)]
pub struct RcsaArgs {
    /// Assembly file (JSON: tool, holder, connection, spindle, band; see the README).
    #[arg(long)]
    assembly: PathBuf,
    /// Output CSV (`chatter frf` columns); stdout when absent.
    #[arg(long)]
    out: Option<PathBuf>,
    /// SVG plot of |h| at the tool tip.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// `chatter rcsa`: couple, write the CSV, plot.
pub fn rcsa(args: &RcsaArgs) -> Result<()> {
    crate::output::check_optional_file("--out", args.out.as_deref())?;
    crate::output::check_optional_file("--plot", args.plot.as_deref())?;
    let request = RcsaRequest::from_path(&args.assembly).context("reading the assembly")?;
    let outcome =
        couple(&request).with_context(|| format!("coupling {}", args.assembly.display()))?;
    emit(args.out.as_deref(), &outcome.to_csv())?;
    if let Some(p) = &args.plot {
        let tip = &outcome.tool_tip;
        let series = [Series {
            label: "tool tip |h| (RCSA)".into(),
            points: tip
                .frequencies_hz()
                .iter()
                .zip(tip.receptance_m_per_n())
                .map(|(f, g)| (*f, g.norm() * 1e6))
                .collect(),
            color: BLUE,
            dashed: false,
        }];
        line_chart(
            p,
            &format!("RCSA tool-tip FRF of {}", args.assembly.display()),
            "frequency (Hz)",
            "|h| (um/N)",
            &series,
            None,
        )?;
    }
    Ok(())
}
