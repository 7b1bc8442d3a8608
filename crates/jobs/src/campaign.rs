//! Fleet runs: a manifest of machine-tool campaigns (one model and one observations file per
//! line), each campaign reduced to one row (verdict, shift of the boundary, next test), and the
//! batch over a manifest in parallel with deterministic results.
//!
//! # Manifest
//! CSV with the header `name,model,observations,seed`, one campaign per line; paths are relative
//! to the manifest's folder, `seed` seeds that campaign's samplers (so a row does not depend on
//! the order of the lines, the thread count or the machine it ran on):
//!
//! ```text
//! name,model,observations,seed
//! lathe-7/insert-A,lathe7.json,lathe7_2026-11-24.json,1
//! ```
//!
//! # One campaign
//! [`run_campaign`]: the gap diagnosis of the observations against the model
//! ([`crate::diagnose`]); the boundary shift is the median over the cut speeds of the diagnosed
//! machine's limiting depth over the nominal one, minus one, in percent; the next test is the
//! maximum material-removal-rate cut on the P_s = 0.5 contour of the diagnosed machine given the
//! cuts so far ([`crate::plan`], 004), or `stop` when testing should stop.

use crate::diagnose::{DiagnoseRequest, diagnose};
use crate::error::{JobError, Result};
use crate::plan::{PlanRequest, plan};
use chatter_dynamics::{ModalModel, Observations};
use chatter_gap::Validation;
use chatter_progress::Observer;
use chatter_updating::plan::Strategy;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One line of a manifest.
#[derive(Debug, Clone, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct Campaign {
    /// Name of the machine-tool combination (the table's key).
    pub name: String,
    /// Model file.
    pub model: PathBuf,
    /// Observations file.
    pub observations: PathBuf,
    /// Seed of the campaign's samplers.
    pub seed: u64,
}

/// Read a manifest; paths become relative to the current folder.
pub fn read_manifest(path: &Path) -> Result<Vec<Campaign>> {
    let file_error = |message: String| JobError::File {
        path: path.display().to_string(),
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| file_error(format!("cannot read the manifest: {e}")))?;
    let header = reader
        .headers()
        .map_err(|e| file_error(e.to_string()))?
        .clone();
    if header.iter().collect::<Vec<_>>() != ["name", "model", "observations", "seed"] {
        return Err(file_error(format!(
            "header `{}`: expected `name,model,observations,seed`",
            header.iter().collect::<Vec<_>>().join(",")
        )));
    }
    let base = path.parent().unwrap_or(Path::new(""));
    let mut campaigns: Vec<Campaign> = Vec::new();
    for (i, row) in reader.deserialize::<Campaign>().enumerate() {
        let mut c = row.map_err(|e| file_error(format!("line {}: {e}", i + 2)))?;
        if campaigns.iter().any(|o| o.name == c.name) {
            return Err(file_error(format!(
                "line {}: name `{}` is given twice; expected one line per campaign",
                i + 2,
                c.name
            )));
        }
        c.model = base.join(&c.model);
        c.observations = base.join(&c.observations);
        campaigns.push(c);
    }
    if campaigns.is_empty() {
        return Err(file_error(
            "no campaigns; expected one line per campaign".into(),
        ));
    }
    Ok(campaigns)
}

/// How much work a campaign gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CampaignOptions {
    /// iTMCMC samples per effect class of the diagnosis.
    pub samples: usize,
    /// Held-out validation of the diagnosis (the row does not use it: off by default).
    pub validation: Validation,
    /// Sampled boundaries of the next-test plan.
    pub paths: usize,
}

impl Default for CampaignOptions {
    /// The diagnosis's 120 samples per class without validation, 300 planning paths.
    fn default() -> Self {
        Self {
            samples: crate::diagnose::DEFAULT_SAMPLES,
            validation: Validation::Off,
            paths: PlanRequest::new(Strategy::MaterialRemovalRate).paths,
        }
    }
}

/// Fewest and most iTMCMC samples per class of a campaign's diagnosis.
pub const SAMPLES: (usize, usize) = (40, 100_000);
/// Fewest and most sampled boundaries of a campaign's next-test plan.
pub const PATHS: (usize, usize) = (10, 100_000);

impl CampaignOptions {
    /// The options with `samples` per class and `paths` planning paths, checked once
    /// ([`SAMPLES`], [`PATHS`]); validation off (the row does not use it).
    pub fn new(samples: usize, paths: usize) -> Result<Self> {
        crate::error::count(
            "samples",
            samples,
            SAMPLES.0,
            SAMPLES.1,
            "samples per class",
        )?;
        crate::error::count("paths", paths, PATHS.0, PATHS.1, "sampled boundaries")?;
        Ok(Self {
            samples,
            paths,
            ..Self::default()
        })
    }
}

/// What a campaign concluded.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CampaignRow {
    /// The campaign's name.
    pub name: String,
    /// `consistent`, the effect class that explains the gap, or `unexplained`.
    pub verdict: String,
    /// Median over the cut speeds of diagnosed / nominal limiting depth - 1 (%).
    pub boundary_shift_percent: f64,
    /// Next test cut's speed (rpm), when one is proposed.
    pub next_speed_rpm: Option<f64>,
    /// Next test cut's depth (mm).
    pub next_depth_mm: Option<f64>,
    /// Probability that the next cut is stable.
    pub next_p_stable: Option<f64>,
    /// Testing should stop.
    pub stop: bool,
}

/// Header of the batch table.
pub const TABLE_HEADER: &str =
    "name,verdict,boundary_shift_percent,next_speed_rpm,next_depth_mm,next_p_stable,stop,error";

impl CampaignRow {
    /// The row as a line of the batch table (without the newline; numbers in Rust's shortest
    /// round-trip form, so equal tables mean bit-equal numbers).
    pub fn csv_line(&self) -> String {
        let cell = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
        format!(
            "{},{},{},{},{},{},{},",
            quote(&self.name),
            self.verdict,
            self.boundary_shift_percent,
            cell(self.next_speed_rpm),
            cell(self.next_depth_mm),
            cell(self.next_p_stable),
            self.stop
        )
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn quote(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The line of a campaign that failed: its name and the error, other cells empty.
pub fn error_line(name: &str, error: &str) -> String {
    format!("{},,,,,,,{}", quote(name), quote(error))
}

/// Diagnose one campaign already read and plan its next test; `observer` may cancel both.
pub fn campaign_row(
    name: &str,
    model: &ModalModel,
    observations: &Observations,
    seed: u64,
    options: &CampaignOptions,
    observer: &dyn Observer,
) -> Result<CampaignRow> {
    let request = DiagnoseRequest {
        seed,
        samples: options.samples,
        validation: options.validation,
        pointwise: false,
    };
    let diagnosis = diagnose(model, observations, &request, observer)?;
    let mut speeds = observations.speeds_rpm();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    let mut ratios: Vec<f64> = diagnosis
        .lobes(&speeds)
        .iter()
        .map(|l| l.diagnosed_mm / l.nominal_mm - 1.0)
        .filter(|r| r.is_finite())
        .collect();
    ratios.sort_by(f64::total_cmp);
    let shift = match ratios.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => ratios[n / 2],
        n => 0.5 * (ratios[n / 2 - 1] + ratios[n / 2]),
    };
    let mut plan_request = PlanRequest::new(Strategy::MaterialRemovalRate);
    plan_request.paths = options.paths;
    plan_request.seed = seed;
    let outcome = plan(
        diagnosis.diagnosed_model(),
        observations,
        &plan_request,
        observer,
    )?;
    let next = outcome.next_cut.filter(|_| !outcome.stop);
    Ok(CampaignRow {
        name: name.to_string(),
        verdict: diagnosis.verdict.name().to_string(),
        boundary_shift_percent: 100.0 * shift,
        next_speed_rpm: next.map(|t| t.speed_rpm),
        next_depth_mm: next.map(|t| t.depth_mm),
        next_p_stable: next.map(|t| t.p_stable),
        stop: outcome.stop,
    })
}

/// Read a campaign's files and reduce it to a row; `observer` may cancel it.
pub fn run_campaign(
    campaign: &Campaign,
    options: &CampaignOptions,
    observer: &dyn Observer,
) -> Result<CampaignRow> {
    let model = ModalModel::from_path(&campaign.model)?;
    let observations = Observations::from_path(&campaign.observations)?;
    campaign_row(
        &campaign.name,
        &model,
        &observations,
        campaign.seed,
        options,
        observer,
    )
}

/// A campaign's entry in the batch: its row, or the error that stopped it (a failed campaign
/// does not stop the batch).
#[derive(Debug, Clone, PartialEq)]
pub enum CampaignResult {
    /// The campaign concluded.
    Row(CampaignRow),
    /// The campaign failed.
    Failed {
        /// The campaign's name.
        name: String,
        /// The error in words.
        error: String,
    },
}

impl CampaignResult {
    /// The line of the batch table.
    pub fn csv_line(&self) -> String {
        match self {
            Self::Row(row) => row.csv_line(),
            Self::Failed { name, error } => error_line(name, error),
        }
    }
}

/// A campaign's row, or its error; `observer` may cancel it.
pub fn campaign_result(
    campaign: &Campaign,
    options: &CampaignOptions,
    observer: &dyn Observer,
) -> CampaignResult {
    match run_campaign(campaign, options, observer) {
        Ok(row) => CampaignResult::Row(row),
        Err(e) => CampaignResult::Failed {
            name: campaign.name.clone(),
            error: e.to_string(),
        },
    }
}

/// The outcome of a batch: one entry per campaign in manifest order.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchOutcome {
    /// The campaigns' entries in manifest order.
    pub campaigns: Vec<CampaignResult>,
}

impl BatchOutcome {
    /// The batch table: the header, then one line per campaign.
    pub fn table(&self) -> String {
        let lines: Vec<String> = self
            .campaigns
            .iter()
            .map(CampaignResult::csv_line)
            .collect();
        table(&lines)
    }

    /// How many campaigns failed.
    pub fn failed(&self) -> usize {
        self.campaigns
            .iter()
            .filter(|c| matches!(c, CampaignResult::Failed { .. }))
            .count()
    }
}

/// Every campaign in parallel (rayon), in manifest order. Each campaign is seeded by its own
/// line, so the outcome does not depend on the number of threads; `observer` hears of each
/// finished campaign. A cancel (the observer's) stops the campaigns under way and skips the
/// others: the batch is then [`JobError::Cancelled`], not a table of failed lines.
pub fn run_batch(
    campaigns: &[Campaign],
    options: &CampaignOptions,
    observer: &dyn Observer,
) -> Result<BatchOutcome> {
    let finished = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Option<CampaignResult>> = campaigns
        .par_iter()
        .map(|c| {
            if observer.cancelled() {
                return None;
            }
            let result = campaign_result(c, options, observer);
            let k = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            observer.steps_done(k, campaigns.len());
            Some(result)
        })
        .collect();
    chatter_progress::check(observer)?;
    Ok(BatchOutcome {
        campaigns: results.into_iter().flatten().collect(),
    })
}

/// The batch table of lines in order.
pub fn table(lines: &[String]) -> String {
    let mut text = String::from(TABLE_HEADER);
    text.push('\n');
    for line in lines {
        let _ = writeln!(text, "{line}");
    }
    text
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn manifest_paths_are_relative_to_its_folder_and_names_unique() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fleet.csv");
        std::fs::write(&path, "name,model,observations,seed\na,m.json,o.json,3\n").unwrap();
        let c = read_manifest(&path).unwrap();
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].model, dir.path().join("m.json"));
        assert_eq!(c[0].seed, 3);
        std::fs::write(&path, "name,model,observations,seed\na,m,o,1\na,m,o,2\n").unwrap();
        let e = read_manifest(&path).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("twice"), "{e}");
        std::fs::write(&path, "model,observations\nm,o\n").unwrap();
        let e = read_manifest(&path).unwrap_err().to_string();
        assert!(e.contains("expected `name,model,observations,seed`"), "{e}");
        std::fs::write(&path, "name,model,observations,seed\na,m,o,-1\n").unwrap();
        let e = read_manifest(&path).unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }

    #[test]
    fn a_failed_campaign_is_a_row_with_its_error() {
        let c = Campaign {
            name: "x,1".into(),
            model: "/nonexistent/m.json".into(),
            observations: "/nonexistent/o.json".into(),
            seed: 0,
        };
        let result = campaign_result(&c, &CampaignOptions::default(), &chatter_progress::Silent);
        let line = result.csv_line();
        assert!(line.starts_with("\"x,1\",,,,,,,"), "{line}");
        assert!(line.contains("m.json"), "{line}");
        let batch = BatchOutcome {
            campaigns: vec![result],
        };
        assert_eq!(batch.failed(), 1);
        let t = batch.table();
        assert_eq!(t.lines().next(), Some(TABLE_HEADER));
        assert_eq!(t.lines().count(), 2);
    }

    #[test]
    fn options_name_the_field_and_value() {
        let e = CampaignOptions::new(3, 300).unwrap_err().to_string();
        assert_eq!(e, "samples 3: expected samples per class from 40 to 100000");
        let e = CampaignOptions::new(120, 5).unwrap_err().to_string();
        assert_eq!(e, "paths 5: expected sampled boundaries from 10 to 100000");
        let o = CampaignOptions::new(120, 300).unwrap();
        assert_eq!(o, CampaignOptions::default());
    }

    #[test]
    fn a_cancelled_campaign_and_batch_stop() {
        let nominal = chatter_gap::nominal_milling().unwrap();
        let scenario = chatter_gap::Scenario::new(chatter_gap::HiddenEffect::ParameterError, 1);
        let observations = chatter_gap::synthesize(&nominal, &scenario).unwrap();
        let options = CampaignOptions::default();
        let cancelled = &chatter_progress::AlreadyCancelled;
        let row = campaign_row("a", &nominal, &observations, 1, &options, cancelled);
        assert!(
            matches!(
                row,
                Err(JobError::Gap(chatter_gap::GapError::Cancelled(_)) | JobError::Cancelled(_))
            ),
            "{row:?}"
        );
        let dir = tempfile::tempdir().unwrap();
        let (model, obs) = (dir.path().join("m.json"), dir.path().join("o.json"));
        let model_json = serde_json::to_string(&chatter_dynamics::ModelFile::from_model(&nominal));
        std::fs::write(&model, model_json.unwrap()).unwrap();
        std::fs::write(&obs, observations.to_json_string()).unwrap();
        let campaigns: Vec<Campaign> = (0..50)
            .map(|seed| Campaign {
                name: format!("c{seed}"),
                model: model.clone(),
                observations: obs.clone(),
                seed,
            })
            .collect();
        let batch = run_batch(&campaigns, &options, cancelled);
        assert!(matches!(batch, Err(JobError::Cancelled(_))), "{batch:?}");
    }
}
