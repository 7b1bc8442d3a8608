//! The example setup (`chatter serve --example`): the mill of seed 001 as the synthetic shop of
//! `chatter demo` builds it ([`chatter_gap::nominal_milling`]: 4 teeth, 20 % down milling,
//! K_s 750 N/mm^2, beta 68 deg, x 750 Hz and y 810 Hz on a 19.05 mm cutter), so a new user sees
//! every screen filled at once:
//!
//! - a tap test of its x direction: the model's direct receptance at 1 Hz steps from 200 to
//!   1500 Hz written as a UFF 58 file, fitted as an uploaded one is (the y mode kept);
//! - its cut log: the demo's campaign (32 cuts and 8 poles of a machine whose process damping
//!   the model leaves out, 2x the realistic gap, seed 101; [`chatter_gap::synthesize`], the truth
//!   by the semi-discretization at four times the resolution).
//!
//! Seeding is skipped when a setup of that name exists.

use crate::app::App;
use crate::db::{NewCut, StoredFile};
use crate::error::{Result, ServeError};
use crate::store::UploadKind;
use crate::work::{FitRequest, TapDirections, fit_tap_test};
use chatter_dynamics::ModelFile;
use chatter_frf::Frf;
use chatter_frf::uff::{Uff58Record, to_uff58_string};

/// The example setup's name.
pub const NAME: &str = "Example: seed 001 mill with its cut log";

fn job(e: impl std::fmt::Display) -> ServeError {
    ServeError::Job(format!("the example setup: {e}"))
}

/// Add the example setup unless it is there; its id.
pub fn seed(app: &App) -> Result<i64> {
    if let Some(s) = app.db().setups()?.into_iter().find(|s| s.name == NAME) {
        return Ok(s.id);
    }
    let nominal = chatter_gap::nominal_milling().map_err(job)?;
    let mut file = ModelFile::from_model(&nominal);
    let mut process = file.clone();
    process.modes.clear();
    process.name = None;
    file.name = Some("seed 001's mill (chatter demo's synthetic shop)".into());
    let process = serde_json::to_value(&process).map_err(job)?;
    let mut scenario = chatter_gap::Scenario::new(chatter_gap::HiddenEffect::ParameterError, 101);
    (scenario.effect, _) = chatter_gap::generator::effect_at(
        chatter_gap::EffectClass::ProcessDamping,
        2.0,
        &nominal,
        scenario.speed_range_rpm,
    )
    .map_err(job)?;
    let campaign = chatter_gap::synthesize(&nominal, &scenario).map_err(job)?;
    let frequencies: Vec<f64> = (200..=1500).map(f64::from).collect();
    let tap = Frf::from_model(&nominal, 0, 0, frequencies).map_err(job)?;
    let uff = to_uff58_string(&[Uff58Record::receptance(
        &tap,
        "seed 001 mill x tap test",
        (1, 1),
        (1, 1),
    )]);
    let staged = app.data().stage(UploadKind::Frf, "uff", uff.as_bytes())?;
    let shown = "seed001_tap_x.uff";
    let (fitted, report) = fit_tap_test(
        &staged.path,
        shown,
        &serde_json::from_value(process.clone()).map_err(job)?,
        Some(&file),
        &FitRequest {
            fmin_hz: None,
            fmax_hz: None,
            modes: None,
            directions: TapDirections::X,
        },
    )?;
    let id = app.db().add_setup(
        NAME,
        "synthetic shop of `chatter demo`",
        "19.05 mm 4-flute end mill",
        "shrink-fit holder",
        &process,
    )?;
    let model = serde_json::to_string_pretty(&file).map_err(job)?;
    app.db()
        .add_model(id, &model, "example: seed 001's mill", None, None)?;
    let stored = StoredFile {
        kind: UploadKind::Frf.name(),
        original_name: shown.into(),
        stored_name: staged.stored_name.clone(),
        bytes: uff.len(),
    };
    let kept = staged.keep()?;
    let written = app
        .db()
        .add_model(
            id,
            &fitted,
            &format!("fitted to the tap test {shown}"),
            Some(&report),
            Some(&stored),
        )
        .and_then(|_| {
            let cuts: Vec<NewCut> = campaign
                .cuts
                .iter()
                .map(|c| NewCut {
                    cut: c.clone(),
                    origin: "imported",
                    detection: None,
                })
                .collect();
            app.db().add_cuts(id, &cuts, &campaign.poles, None)
        });
    if let Err(e) = written {
        kept.forget();
        return Err(e);
    }
    Ok(id)
}
