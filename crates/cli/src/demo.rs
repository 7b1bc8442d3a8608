//! `chatter demo`: the main jobs on the embedded examples (seed 000 turning lobes and
//! credibility bounds, seed 001 Type B bands, the papers' numbers, a synthetic campaign's gap
//! diagnosis), each through its `chatter_jobs` request, results into a folder that appears
//! complete or not at all, with a report page.

use crate::output::Folder;
use crate::plot::{Series, line_chart_svg};
use crate::progress::Bar;
use crate::tables::{self, band_series, markers};
use anyhow::Result;
use chatter_jobs::bands::BandCurves;
use chatter_jobs::demo::DemoRequest;
use plotters::style::BLUE;
use std::path::Path;

pub use crate::report::jobs::CREDIBILITY_TITLE;

/// What `--out` of `chatter demo` may hold (the folder of its previous run).
pub const DEMO_FILES: [&str; 17] = [
    "papers.csv",
    "turning_lobes.csv",
    "turning_lobes.svg",
    "eq34_covariance.json",
    "turning_credibility.csv",
    "turning_credibility.svg",
    "milling_bands.csv",
    "milling_bands.svg",
    "milling_bands-theta.svg",
    "milling_bands-distance.svg",
    "milling_bands-roots.svg",
    "milling_frf.csv",
    "shopfloor_model.json",
    "shopfloor_observations.json",
    "diagnosis",
    "summary.json",
    "report.html",
];

/// `chatter demo`: the main job on the embedded examples, results into a folder that appears
/// complete or not at all.
pub fn demo(out_dir: &Path, quiet: bool) -> Result<()> {
    let mut folder = Folder::new("--out", out_dir, &DEMO_FILES)?;
    let mut summary = serde_json::Map::new();
    let stage = |k: usize, what: &str| {
        if !quiet {
            eprintln!("demo {k}/5: {what}");
        }
    };

    // 1. Turning case of seed 000: lobes (FDM and exact ZOA) over the tested speeds with the cuts.
    stage(
        1,
        "turning lobes of the Ahmadi (2022) tool and its test cuts",
    );
    let request = DemoRequest::default();
    let stage1 = job_with_bar(quiet, request.turning_speeds_rpm.len(), |bar| {
        chatter_jobs::demo::turning_lobes(&request, bar)
    })?;
    let (turning, obs, fdm) = (&stage1.model, &stage1.observations, &stage1.lobes);
    folder.add("turning_lobes.csv", tables::lobes_csv(fdm));
    folder.add(
        "turning_lobes.svg",
        line_chart_svg(
            "Turning tool of Ahmadi (2022), hammer-test modes: FDM lobes and test cuts",
            "spindle speed (rpm)",
            "width of cut (mm)",
            &[Series {
                label: "FDM limiting width".into(),
                points: fdm.iter().map(|p| (p.speed_rpm, p.depth_mm())).collect(),
                color: BLUE,
                dashed: false,
            }],
            markers(Some(obs)).as_ref(),
        )?,
    );
    let limits: Vec<_> = stage1
        .limits
        .iter()
        .map(|p| serde_json::json!({"speed_rpm": p.speed_rpm, "depth_mm": p.depth_mm(), "chatter_hz": p.chatter_hz}))
        .collect();
    summary.insert("turning_limits".into(), serde_json::json!(limits));

    // 2. Credibility bounds of the same case after updating (000 Section 6.4, Fig. 8): the
    //    model at the posterior mean of Eq. 34's distribution with its covariance (written out
    //    as a covariance file that `chatter bands --covariance` reads).
    stage(2, "credibility bounds after updating (Eq. 34)");
    folder.add(
        "eq34_covariance.json",
        chatter_dynamics::examples::AHMADI_2022_POSTERIOR,
    );
    let credibility = job_with_bar(quiet, request.credibility_speeds_rpm.len(), |bar| {
        chatter_jobs::demo::credibility(&request, turning, bar)
    })?;
    let rule = request.credibility_rule;
    let (csv, series) = tables::credibility_bands(&credibility.bounds, rule);
    folder.add("turning_credibility.csv", csv);
    folder.add(
        "turning_credibility.svg",
        line_chart_svg(
            CREDIBILITY_TITLE,
            "spindle speed (rpm)",
            "width of cut (mm)",
            &series,
            markers(Some(obs)).as_ref(),
        )?,
    );

    // 3. Milling example of seed 001: zero-order lobes with Type B offsets (100 rpm, 0.2 mm).
    stage(
        3,
        "milling lobes with speed and depth offsets (Schmitz 2023)",
    );
    let stage3 = chatter_jobs::demo::milling_bands(&request).map_err(crate::job_error)?;
    let (milling, bands) = (&stage3.model, &stage3.bands);
    let curve: Vec<(f64, f64)> = bands
        .points
        .iter()
        .map(|p| (p.speed_rpm, p.depth_mm))
        .collect();
    folder.add("milling_bands.csv", tables::geometric_csv(bands));
    folder.add(
        "milling_bands.svg",
        line_chart_svg(
            "Milling example of Schmitz (2023): zero-order lobes offset by 100 rpm and 0.2 mm",
            "spindle speed (rpm)",
            "axial depth (mm)",
            &band_series(
                curve,
                bands.lower.clone(),
                bands.upper.clone(),
                ["mean boundary", "lower offset", "upper offset"],
            ),
            None,
        )?,
    );
    for (name, svg) in crate::bands::offset_detail_svgs("milling_bands", bands)? {
        folder.add(name, svg);
    }
    folder.add("milling_frf.csv", tables::frf_csv(&stage3.frf));

    // 4. The seeds' published numbers beside ours, with tolerances.
    stage(
        4,
        "the papers' numbers beside ours (000 Table 3, 001 Sec. 4, 003 Table 2, 004)",
    );
    let rows = crate::papers::rows(bands)?;
    folder.add("papers.csv", crate::papers::csv(&rows));
    summary.insert(
        "papers".into(),
        serde_json::json!({
            "rows": rows.len(),
            "within_tolerance": rows.iter().filter(|r| r.within()).count(),
            "outside": rows.iter().filter(|r| !r.within()).map(|r| format!("{}: {}", r.source, r.quantity)).collect::<Vec<_>>(),
        }),
    );

    // 5. Sim-to-real gap: a synthetic shop-floor campaign of a milling machine whose process
    //    damping the nominal model leaves out, diagnosed from the nominal model and the data.
    stage(5, "sim-to-real gap diagnosis of a synthetic campaign");
    let (nominal, campaign) =
        chatter_jobs::demo::shopfloor_campaign(&request).map_err(crate::job_error)?;
    folder.add(
        "shopfloor_model.json",
        serde_json::to_string_pretty(&chatter_dynamics::ModelFile::from_model(&nominal))?,
    );
    folder.add("shopfloor_observations.json", campaign.to_json_string());
    let (model_path, obs_path) = (
        folder.path_of("shopfloor_model.json"),
        folder.path_of("shopfloor_observations.json"),
    );
    let (recorded, report, files) = crate::diagnose::report_of(
        &nominal,
        &campaign,
        &crate::diagnose::DiagnoseRequest {
            model: &model_path,
            observations: &obs_path,
            seed: request.diagnosis.seed,
            samples: request.diagnosis.samples,
            validation: validation_arg(request.diagnosis.validation),
            folds: request.diagnosis.folds(),
            out: Some(&folder.path_of("diagnosis")),
            report: None,
            netcdf: false,
            quiet,
        },
    )?;
    let diagnosis = recorded.diagnosis;
    folder.add("diagnosis/report.json", report);
    for (name, bytes) in files {
        folder.add(Path::new("diagnosis").join(name), bytes);
    }
    summary.insert(
        "diagnosis".into(),
        serde_json::json!({
            "hidden_effect": "process_damping (C = 6e4 N/m), withheld from the model",
            "verdict": diagnosis.verdict.name(),
        }),
    );

    let page = crate::report::jobs::demo(
        &folder,
        &[
            (
                "Turning tool of Ahmadi (2022) (FDM lobes)",
                BandCurves::of_lobes(fdm),
                "",
                crate::report::jobs::LOBES_MISSING,
            ),
            (
                "Turning tool of Ahmadi (2022) after updating (credibility bounds)",
                BandCurves::of_credibility(&credibility.bounds),
                "lower credibility bound",
                crate::report::jobs::PERTURBATION_MISSING,
            ),
            (
                "Milling example of Schmitz (2023) (offsets 100 rpm, 0.2 mm)",
                BandCurves::of_offsets(bands),
                "lower offset boundary",
                crate::report::jobs::GEOMETRIC_MISSING,
            ),
        ],
        &[
            ("turning tool of Ahmadi (2022), hammer-test modes", turning),
            ("milling example of Schmitz (2023)", milling),
            ("shop-floor machine: the nominal model diagnosed", &nominal),
        ],
        &diagnosis,
    )?;
    folder.add("report.html", page.html());
    let mut files: Vec<String> = folder
        .paths()
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    files.push(folder.path_of("summary.json").display().to_string());
    summary.insert("files".into(), serde_json::json!(files));
    folder.add("summary.json", serde_json::to_string_pretty(&summary)?);
    for p in folder.commit()? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// A demo stage run with a progress bar over `speeds` speeds.
fn job_with_bar<T>(
    quiet: bool,
    speeds: usize,
    job: impl FnOnce(&Bar) -> chatter_jobs::Result<T>,
) -> Result<T> {
    let bar = Bar::new(speeds as u64, "lobes", quiet);
    bar.announce(&format!("{speeds} speeds, fdm"));
    let out = job(&bar).map_err(crate::job_error)?;
    bar.finish();
    Ok(out)
}

/// The CLI's validation option of a diagnosis request's validation.
fn validation_arg(v: chatter_gap::Validation) -> crate::diagnose::ValidationArg {
    use crate::diagnose::ValidationArg;
    match v {
        chatter_gap::Validation::KFold { .. } => ValidationArg::Kfold,
        chatter_gap::Validation::SpeedBands { .. } => ValidationArg::SpeedBands,
        chatter_gap::Validation::Off => ValidationArg::Off,
    }
}
