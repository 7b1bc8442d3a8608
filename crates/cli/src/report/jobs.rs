//! What each command puts on its report page: `update`, `bands`, `diagnose`, `plan` and the
//! demo. Each builder takes the result the command already has (and the plots it already
//! made) and returns the [`Page`]; the command writes it.

use super::model::parameter_unit;
use super::{Page, Table, number, optional};
use crate::output::Folder;
use crate::plot::Series;
use anyhow::Result;
use chatter_dynamics::{ModalModel, Observations};
use chatter_gap::{Diagnosis, EffectClass, Verdict};
use chatter_jobs::bands::BandCurves;
use chatter_jobs::diagnose::RecordedDiagnosis;
use chatter_jobs::recordings::{RecordVerdict, row_file_name};
use chatter_updating::plan::PlanOutcome;
use chatter_updating::update::UpdateResult;

/// "N cuts, M poles, K signals" of an observations file.
fn observation_counts(o: &Observations) -> String {
    format!(
        "{} cuts ({} stable, {} chatter), {} poles, {} signal records",
        o.cuts.len(),
        o.cuts.iter().filter(|c| c.stable).count(),
        o.cuts.iter().filter(|c| !c.stable).count(),
        o.poles.len(),
        o.signals.len()
    )
}

/// The inputs every job shares: the options as typed, the model and what the observations hold.
fn common(title: &str, model: &ModalModel, observations: Option<&Observations>) -> Page {
    let mut page = Page::new(title);
    page.command_line_inputs();
    if let Some(o) = observations {
        page.input("observations hold", observation_counts(o));
    }
    page.model("model (as read)", model);
    page
}

/// Posterior mean and standard deviation per parameter, with units.
fn posterior_table(caption: &str, names: &[String], mean: &[f64], sd: &[f64]) -> Table {
    let mut t = Table::new(
        caption,
        &["parameter", "mean", "standard deviation", "unit"],
    );
    for ((name, m), s) in names.iter().zip(mean).zip(sd) {
        t.row(vec![
            name.clone(),
            number(*m),
            number(*s),
            parameter_unit(name).into(),
        ]);
    }
    t
}

/// The page of `chatter update`: `figures` are the evidence and corner plots (name, SVG).
pub fn update(
    model: &ModalModel,
    observations: &Observations,
    r: &UpdateResult,
    figures: &[(&str, String)],
) -> Result<Page> {
    let mut page = common(
        "chatter update: Bayesian model updating",
        model,
        Some(observations),
    );
    page.model("updated model (posterior mean)", &r.updated_model);
    let best = r
        .classes
        .iter()
        .max_by(|a, b| a.probability.total_cmp(&b.probability));
    match (r.selected_alpha, best) {
        (Some(alpha), Some(c)) => page.verdict(format!(
            "The data select the model class alpha = {} (probability {} among the {} classes \
             tried); the updated model is that class's posterior mean (updated_model.json).",
            number(alpha),
            number(c.probability),
            r.classes.len()
        )),
        _ => page.verdict(
            "The cut results (004) update the parameters directly (no model classes); the \
             updated model is the posterior mean (updated_model.json).",
        ),
    };
    page.verdict(
        "Next: chatter bands --kind perturbation (or montecarlo) --posterior with this output \
         folder draws the updated lobes with their credibility bounds.",
    );
    for w in chatter_jobs::update::warnings(r) {
        page.warning(w);
    }
    let n = r.parameter_names.len();
    let sd: Vec<f64> = (0..n)
        .map(|i| r.posterior_covariance[(i, i)].max(0.0).sqrt())
        .collect();
    page.table(posterior_table(
        "Posterior of the selected class",
        &r.parameter_names,
        &r.posterior_mean,
        &sd,
    ));
    if r.classes.iter().any(|c| c.alpha.is_some()) {
        let mut t = Table::new(
            "Model classes (000 Eq. 32-33)",
            &[
                "alpha",
                "ln p(D | M) (nats)",
                "p(M | D)",
                "data fit (nats)",
                "information gain (nats)",
                "failed evaluations",
            ],
        );
        for c in &r.classes {
            t.row(vec![
                optional(c.alpha),
                number(c.log_evidence),
                number(c.probability),
                optional(c.data_fit),
                optional(c.information_gain),
                c.numerical_failures
                    .map_or_else(|| "none".into(), |f| f.to_string()),
            ]);
        }
        page.table(t);
    }
    if !r.pole_table.is_empty() {
        let mut t = Table::new(
            "Identified poles against the model before and after updating",
            &[
                "speed (rpm)",
                "depth (mm)",
                "identified (Hz)",
                "identified damping (%)",
                "nominal (Hz)",
                "nominal damping (%)",
                "updated (Hz)",
                "updated damping (%)",
            ],
        );
        for p in &r.pole_table {
            t.row(vec![
                number(p.speed_rpm),
                number(p.depth_mm),
                number(p.identified_hz),
                number(100.0 * p.identified_damping),
                number(p.nominal_hz),
                number(100.0 * p.nominal_damping),
                number(p.updated_hz),
                number(100.0 * p.updated_damping),
            ]);
        }
        page.table(t);
    }
    if let Some(s) = &r.surrogate {
        let mut t = Table::new(
            "GP surrogate of the milling multiplier (002 Sec. 2.2)",
            &["quantity", "value", "unit"],
        );
        let h = &s.held_out;
        for (q, v, u) in [
            ("training points", h.training_points as f64, ""),
            (
                "held-out RMS pole frequency error",
                h.rms_frequency_error_hz,
                "Hz",
            ),
            (
                "held-out max pole frequency error",
                h.max_frequency_error_hz,
                "Hz",
            ),
            ("held-out RMS damping-ratio error", h.rms_damping_error, "1"),
            ("held-out max damping-ratio error", h.max_damping_error, "1"),
            (
                "mean |ln L error| at posterior samples",
                s.mean_abs_ln_likelihood_error,
                "nats",
            ),
            (
                "max |ln L error| at posterior samples",
                s.max_abs_ln_likelihood_error,
                "nats",
            ),
        ] {
            t.row(vec![q.into(), number(v), u.into()]);
        }
        page.table(t);
    }
    for (name, svg) in figures {
        let caption = match *name {
            "evidence.svg" => {
                "Evidence per model class with its two terms, and the class probabilities (000 Fig. 4)"
            }
            "corner.svg" => {
                "Posterior (blue) over prior draws (grey); diagonal: posterior histogram with its Gaussian fit (000 Fig. 5)"
            }
            other => other,
        };
        page.figure(caption, svg)?;
    }
    Ok(page)
}

/// The lowest and the highest finite value of `ys` with its `xs`.
fn extremes(xs: &[f64], ys: &[f64]) -> Option<((f64, f64), (f64, f64))> {
    let pts: Vec<(f64, f64)> = xs
        .iter()
        .zip(ys)
        .map(|(x, y)| (*x, *y))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let low = pts.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1))?;
    let high = pts.iter().copied().max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some((low, high))
}

/// What a band (or lobe) outcome says: its verdict, a summary table and the speeds without a
/// boundary (a warning that gives `why_missing`). `c` has the boundary and may have the
/// conservative curve (called `lower_label`) and the upper one.
pub fn band_findings(
    page: &mut Page,
    what: &str,
    c: &BandCurves,
    lower_label: &str,
    why_missing: &str,
) {
    let speeds = &c.speed_rpm;
    let mut table = Table::new(
        &format!("{what}: summary"),
        &[
            "curve",
            "speeds with a boundary",
            "lowest depth (mm)",
            "at speed (rpm)",
            "deepest (mm)",
            "at speed (rpm)",
        ],
    );
    for (column, label) in [
        (Some(&c.depth_mm), "boundary"),
        (c.lower_mm.as_ref(), lower_label),
        (c.upper_mm.as_ref(), "upper curve"),
    ] {
        let Some(ys) = column else { continue };
        let finite = ys.iter().filter(|y| y.is_finite()).count();
        let (low, high) =
            extremes(speeds, ys).unwrap_or(((f64::NAN, f64::NAN), (f64::NAN, f64::NAN)));
        table.row(vec![
            label.into(),
            format!("{finite} of {}", ys.len()),
            number(low.1),
            number(low.0),
            number(high.1),
            number(high.0),
        ]);
        if finite < ys.len() {
            page.warning(format!(
                "{what}, {label}: {} of {} speeds have no boundary ({why_missing})",
                ys.len() - finite,
                ys.len()
            ));
        }
    }
    if let Some(((s_low, d_low), (s_high, d_high))) = extremes(speeds, &c.depth_mm) {
        let mut text = format!(
            "{what}: the deepest stable pocket reaches {} mm at {} rpm; the boundary's lowest \
             point is {} mm at {} rpm.",
            number(d_high),
            number(s_high),
            number(d_low),
            number(s_low)
        );
        if let Some(lower) = &c.lower_mm {
            let at_pocket = speeds
                .iter()
                .zip(lower)
                .find(|(s, _)| **s == s_high)
                .map(|(_, l)| *l);
            if let Some(l) = at_pocket.filter(|l| l.is_finite()) {
                text.push_str(&format!(
                    " With the uncertainty, the {lower_label} lies at {} mm there: a cut at \
                     {} rpm below {} mm stays stable.",
                    number(l),
                    number(s_high),
                    number(l)
                ));
            }
            if let Some(((s, l), _)) = extremes(speeds, lower) {
                text.push_str(&format!(
                    " Anywhere in this speed range, cuts below {} mm (the {lower_label} at {} \
                     rpm) are stable.",
                    number(l),
                    number(s)
                ));
            }
        }
        page.verdict(text);
    } else {
        page.verdict(format!(
            "{what}: no finite limiting depth at these speeds (every depth is stable, or no \
             lobe was found)."
        ));
    }
    page.table(table);
}

/// Title of the demo's credibility plot (and its caption in the report page).
pub const CREDIBILITY_TITLE: &str = "Turning tool of Ahmadi (2022) after updating: limit at the \
     posterior mean, bounds where the dominant multiplier's mean modulus +- 1 sd reaches 1";

/// Why a lobe diagram has no boundary at a speed.
pub const LOBES_MISSING: &str = "no lobe there: every depth is stable at that speed";
/// Why a perturbation band has no boundary at a speed.
pub const PERTURBATION_MISSING: &str =
    "the contour is not reached on the depth grid: a clipped grid; widen --depths";
/// Why a Type B offset band has no boundary at a speed.
pub const GEOMETRIC_MISSING: &str =
    "the offset boundary does not reach that speed: the ends of the speed range, or no lobe";
/// Why a Monte Carlo band has no boundary at a speed.
pub const MONTECARLO_MISSING: &str =
    "the quantile is not finite there: samples failed or had no lobe at that speed";

/// What `chatter bands` computed, for its page.
pub struct BandsResult<'a> {
    /// The band kind as typed (`geometric`, `perturbation`, `montecarlo`).
    pub kind: &'a str,
    /// The name of the conservative curve (`lower_mm`).
    pub lower_label: &'a str,
    /// Why a speed may have no boundary with this kind.
    pub why_missing: &'a str,
    /// The model.
    pub model: &'a ModalModel,
    /// The observed cuts, when given.
    pub observations: Option<&'a Observations>,
    /// The outcome's curves per speed.
    pub curves: &'a BandCurves,
    /// The CSV the command wrote (shown as a table).
    pub csv: &'a str,
    /// The plots (caption, SVG).
    pub figures: Vec<(String, String)>,
    /// Warnings the command printed (failed samples).
    pub warnings: Vec<String>,
}

/// The page of `chatter bands`.
pub fn bands(r: &BandsResult) -> Result<Page> {
    let mut page = common(
        &format!("chatter bands --kind {}: stability bands", r.kind),
        r.model,
        r.observations,
    );
    for w in &r.warnings {
        page.warning(w.clone());
    }
    band_findings(&mut page, "Bands", r.curves, r.lower_label, r.why_missing);
    page.table(Table::from_csv("Every speed (the CSV)", r.csv));
    for (caption, svg) in &r.figures {
        page.figure(caption, svg)?;
    }
    Ok(page)
}

/// An effect class in plain words.
fn effect_words(c: EffectClass) -> &'static str {
    match c {
        EffectClass::ParameterError => {
            "wrong model parameters (natural frequencies, damping or cutting coefficients)"
        }
        EffectClass::ProcessDamping => "process damping that the model leaves out",
        EffectClass::SpeedDependentDynamics => {
            "spindle dynamics that change with speed (natural frequencies falling at high speed)"
        }
        EffectClass::ExtraMode => "a structural mode that the model lacks",
        EffectClass::Drift => "cutting coefficients drifting over the campaign (tool wear)",
        EffectClass::SpeedBand => {
            "an effect confined to a band of speeds, which none of the listed effects describes"
        }
    }
}

/// A region's range with its unit (`3000 to 4317 rpm`, `runs 2 to 21`); empty without one.
fn region_range(r: &chatter_gap::regions::Region) -> String {
    use chatter_gap::regions::RegionKind;
    r.range.map_or(String::new(), |[a, b]| match r.kind {
        RegionKind::DepthBand => format!("{} to {} mm", number(a), number(b)),
        RegionKind::Sequence => format!("runs {} to {}", number(a), number(b)),
        _ => format!("{} to {} rpm", number(a), number(b)),
    })
}

/// The verdict, warnings and tables of a diagnosis (shared by `diagnose` and the demo).
pub fn diagnosis_findings(page: &mut Page, d: &Diagnosis) {
    let best = d.classes.iter().find(|c| c.name == d.best_class);
    let evidence = best.map_or_else(String::new, |c| {
        format!(
            " (ln evidence {} nats, probability {} among the classes tried)",
            number(c.log_evidence),
            number(c.probability)
        )
    });
    page.verdict(match d.verdict {
        Verdict::Consistent => "Verdict: consistent. The nominal model explains the \
             observations up to the noise: it passes its posterior predictive check and the \
             effects tried do not beat it by the required Bayes factor."
            .to_string(),
        Verdict::Class(c) => format!(
            "Verdict: {}. The gap between the model and the shop floor is explained by {}{evidence}; \
             the diagnosed machine passes the posterior predictive check (diagnosed_model.json).",
            c.name(),
            effect_words(c)
        ),
        Verdict::Unexplained => format!(
            "Verdict: unexplained. None of the tried effects explains the gap: the best, {}{evidence}, \
             still fails the posterior predictive check{}. Look for an effect outside the list.",
            effect_words(d.best_class),
            d.predictive_check
                .failing_band()
                .map_or(String::new(), |(from, to)| format!(
                    ", its misfit concentrated between {} and {} rpm",
                    number(from),
                    number(to)
                ))
        ),
    });
    if let Some(r) = d
        .regions
        .iter()
        .filter(|r| r.gap_share > 0.0)
        .max_by(|a, b| a.gap_share.total_cmp(&b.gap_share))
    {
        let range = region_range(r);
        let range = if range.is_empty() {
            range
        } else {
            format!(" ({range})")
        };
        page.verdict(format!(
            "The largest share of the gap is in the region `{}`{range}: {} % of the nominal \
             model's misfit, {} of {} observations disagreeing. Next test: a cut in that region \
             confirms the diagnosis.",
            r.name,
            number(100.0 * r.gap_share),
            r.disagreements,
            r.observations
        ));
    }
    for c in &d.classes {
        if c.solver_failures > 0 {
            page.warning(format!(
                "{}: {} of {} multiplier evaluations failed (solver failures, given a neutral \
                 likelihood term){}",
                c.name,
                c.solver_failures,
                c.evaluations,
                if c.failures_flagged {
                    "; above 1 %: this class's evidence is unreliable"
                } else {
                    ""
                }
            ));
        }
    }
    for n in &d.notes {
        page.warning(n.clone());
    }
    if !d.predictive_check.passed {
        page.warning(format!(
            "the best class ({}) fails the posterior predictive check at level {}",
            d.best_class,
            number(d.predictive_check.level)
        ));
    }
    let mut t = Table::new(
        "Model classes compared by evidence",
        &[
            "class",
            "ln evidence (nats)",
            "probability",
            "data fit (nats)",
            "information gain (nats)",
            "solver failures / evaluations",
        ],
    );
    for c in &d.classes {
        t.row(vec![
            c.name.to_string(),
            number(c.log_evidence),
            number(c.probability),
            number(c.data_fit),
            number(c.information_gain),
            format!("{} / {}", c.solver_failures, c.evaluations),
        ]);
    }
    t.row(vec![
        "nominal model".into(),
        number(d.nominal_log_evidence),
        String::new(),
        String::new(),
        String::new(),
        String::new(),
    ]);
    page.table(t);
    if let Some(c) = best {
        let names: Vec<String> = c.parameters.keys().cloned().collect();
        let mean: Vec<f64> = c.parameters.values().map(|p| p.mean).collect();
        let sd: Vec<f64> = c.parameters.values().map(|p| p.sd).collect();
        page.table(posterior_table(
            &format!("Parameters of the best class ({})", c.name),
            &names,
            &mean,
            &sd,
        ));
    }
    let mut t = Table::new(
        "Posterior predictive check: p-values",
        &[
            "model",
            "cut labels",
            "chatter frequencies",
            "pole frequencies",
            "pole damping",
            "level",
            "passed",
        ],
    );
    for (label, p) in [
        ("best class", &d.predictive_check),
        ("nominal", &d.nominal_check),
    ] {
        t.row(vec![
            label.into(),
            optional(p.cut_labels),
            optional(p.chatter_frequencies),
            optional(p.pole_frequencies),
            optional(p.pole_damping),
            number(p.level),
            if p.passed { "yes" } else { "no" }.into(),
        ]);
    }
    page.table(t);
    let mut t = Table::new(
        "Where the gap lies",
        &[
            "region",
            "range",
            "observations",
            "disagreeing cuts",
            "share of the misfit (%)",
            "RMS chatter-frequency residual (Hz)",
        ],
    );
    for r in &d.regions {
        t.row(vec![
            r.name.clone(),
            region_range(r),
            r.observations.to_string(),
            r.disagreements.to_string(),
            number(100.0 * r.gap_share),
            optional(r.rms_chatter_residual_hz),
        ]);
    }
    page.table(t);
    if let Some(s) = &d.shrink {
        let mut t = Table::new(
            "Held-out gap: nominal model (before) and the best class (after)",
            &["metric", "before", "after", "unit"],
        );
        let metrics = [
            (
                "balanced misclassification of the cuts",
                s.balanced_misclassification,
                "1",
            ),
            (
                "log predictive density per observation",
                Some(s.log_predictive_density_per_observation),
                "nats",
            ),
            (
                "RMS chatter-frequency residual",
                s.rms_chatter_residual_hz,
                "Hz",
            ),
            (
                "RMS pole-frequency residual",
                s.rms_pole_frequency_residual_hz,
                "Hz",
            ),
            (
                "RMS pole-damping residual",
                s.rms_pole_damping_residual,
                "1",
            ),
        ];
        for (name, m, unit) in metrics {
            if let Some(m) = m {
                t.row(vec![
                    name.into(),
                    number(m.before),
                    number(m.after),
                    unit.into(),
                ]);
            }
        }
        page.table(t);
    }
}

/// The page of `chatter diagnose`: `observations` as read, the diagnosis with the table of
/// the signal records it was made from; `figures` are the lobe plot and the residual map.
pub fn diagnose(
    model: &ModalModel,
    observations: &Observations,
    recorded: &RecordedDiagnosis,
    figures: &[(String, Vec<u8>)],
) -> Result<Page> {
    let mut page = common(
        "chatter diagnose: sim-to-real gap",
        model,
        Some(observations),
    );
    if !recorded.records.is_empty() {
        page.input(
            "observations diagnosed",
            observation_counts(&recorded.observations),
        );
        records_findings(&mut page, recorded);
    }
    diagnosis_findings(&mut page, &recorded.diagnosis);
    add_svgs(&mut page, figures, "")?;
    Ok(page)
}

/// What the signal records gave, in words, a warning per record without a cut or a pole for a
/// reason other than chatter, and the `records` table: detection's verdict, chatter frequency
/// and evidence, the identified pole, or the reason there is none.
fn records_findings(page: &mut Page, recorded: &RecordedDiagnosis) {
    let c = recorded.record_counts();
    page.verdict(format!(
        "The diagnosis is made from {} signal records: chatter detection judged {} stable and \
         {} chatter ({} not judged); OMA identified a pole from {} of the {} stable records. \
         See the table of signal records.",
        recorded.records.len(),
        c.stable,
        c.chatter,
        c.not_judged,
        c.poles,
        c.stable
    ));
    for r in &recorded.records {
        if r.verdict != RecordVerdict::Chatter
            && let Some(reason) = &r.reason
        {
            page.warning(format!(
                "signals[{}] ({}): {reason}",
                r.record,
                row_file_name(r)
            ));
        }
    }
    let mut t = Table::new(
        "Signal records: chatter detection and OMA",
        &[
            "record",
            "file",
            "speed (rpm)",
            "depth (mm)",
            "verdict",
            "chatter frequency (Hz)",
            "pole frequency (Hz)",
            "pole damping ratio",
            "line (Hz)",
            "line variation V",
            "margin (positive: chatter)",
            "line over floor (dB)",
            "reason (no cut or no pole)",
        ],
    );
    for r in &recorded.records {
        let e = r.evidence.as_ref();
        let p = r.pole.as_ref();
        t.row(vec![
            format!("signals[{}]", r.record),
            row_file_name(r),
            number(r.speed_rpm),
            number(r.depth_mm),
            r.verdict.name().into(),
            optional(r.chatter_hz),
            optional(p.map(|p| p.frequency_hz)),
            optional(p.map(|p| p.damping_ratio)),
            optional(e.map(|e| e.line_hz)),
            optional(e.map(|e| e.line_variation)),
            optional(e.map(|e| e.margin)),
            optional(e.map(|e| e.line_to_floor_db)),
            r.reason.clone().unwrap_or_default(),
        ]);
    }
    page.table(t);
}

/// Caption of a plot file the commands write.
fn caption_of(name: &str) -> Option<&'static str> {
    Some(match name {
        "lobes.svg" => "Lobes of the nominal and the diagnosed model over the observed cuts",
        "residuals.svg" => {
            "Cuts at their depth over the nominal limit: circles above 1 and crosses below 1 \
             disagree with the nominal model"
        }
        "turning_lobes.svg" => "Turning tool of Ahmadi (2022): FDM lobes and the test cuts",
        "turning_credibility.svg" => CREDIBILITY_TITLE,
        "milling_bands.svg" => {
            "Milling example of Schmitz (2023): zero-order lobes offset by 100 rpm and 0.2 mm"
        }
        "milling_bands-theta.svg" => {
            "Angle theta of the mean boundary against spindle speed (Schmitz 2023 Eq. 2)"
        }
        "milling_bands-distance.svg" => {
            "Offset distance d against spindle speed (Schmitz 2023 Eq. 1)"
        }
        "milling_bands-roots.svg" => {
            "The two roots of Schmitz 2023 Eq. 10-11 at every point of the mean boundary"
        }
        _ => return None,
    })
}

/// The SVG files among `files` (name, bytes) as figures, `prefix` before each name.
fn add_svgs(page: &mut Page, files: &[(String, Vec<u8>)], prefix: &str) -> Result<()> {
    for (name, bytes) in files.iter().filter(|f| f.0.ends_with(".svg")) {
        let caption = caption_of(name).map_or_else(|| format!("{prefix}{name}"), str::to_string);
        page.figure(&caption, &String::from_utf8_lossy(bytes))?;
    }
    Ok(())
}

/// The plot of `chatter plan`'s page: the cuts made so far and the proposed cut (a line from
/// zero to its depth at its speed); the reason when there is nothing to draw.
pub fn plan_plot(
    observations: &Observations,
    outcome: &PlanOutcome,
) -> std::result::Result<String, String> {
    let series: Vec<Series> = outcome
        .next_cut
        .iter()
        .map(|t| Series {
            label: format!(
                "next test: {} rpm, {} mm",
                number(t.speed_rpm),
                number(t.depth_mm)
            ),
            points: vec![(t.speed_rpm, 0.0), (t.speed_rpm, t.depth_mm)],
            color: plotters::style::GREEN,
            dashed: false,
        })
        .collect();
    crate::plot::line_chart_svg(
        "Cuts made so far and the next test",
        "spindle speed (rpm)",
        "depth (mm)",
        &series,
        crate::tables::markers(Some(observations)).as_ref(),
    )
    .map_err(|e| e.to_string())
}

/// The page of `chatter plan`: `plot` is the cuts with the proposed one (None when nothing
/// could be drawn, with the reason); `warnings` are the plan's (`chatter_jobs::plan::warnings`).
pub fn plan(
    model: &ModalModel,
    observations: &Observations,
    outcome: &PlanOutcome,
    warnings: &[String],
    plot: std::result::Result<String, String>,
) -> Result<Page> {
    let mut page = common("chatter plan: the next test cut", model, Some(observations));
    for w in warnings {
        page.warning(w.clone());
    }
    if outcome.stop {
        page.verdict(format!(
            "Stop testing: {}.",
            outcome
                .stop_reason
                .as_deref()
                .unwrap_or("the stopping rule fired")
        ));
    }
    match &outcome.next_cut {
        Some(t) => {
            let mut text = format!(
                "Next test: cut at {} rpm, {} mm deep (probability of stability {} under the \
                 sampled boundaries",
                number(t.speed_rpm),
                number(t.depth_mm),
                number(t.p_stable)
            );
            if let Some(r) = t.expected_reduction_percent {
                text.push_str(&format!(
                    "; expected to cut the parameter's standard deviation by {} %",
                    number(r)
                ));
            }
            if let Some(m) = t.mrr_cm3_per_min {
                text.push_str(&format!("; material removal rate {} cm^3/min", number(m)));
            }
            text.push_str(").");
            page.verdict(text);
        }
        None => {
            page.verdict("No candidate cut qualifies: there is no next test on this grid.");
        }
    }
    let mut t = Table::new("The proposed cut", &["quantity", "value", "unit"]);
    if let Some(n) = &outcome.next_cut {
        t.row(vec![
            "spindle speed".into(),
            number(n.speed_rpm),
            "rpm".into(),
        ]);
        t.row(vec!["depth of cut".into(), number(n.depth_mm), "mm".into()]);
        t.row(vec![
            "probability of stability".into(),
            number(n.p_stable),
            "1".into(),
        ]);
        t.row(vec![
            "expected reduction of the sd".into(),
            optional(n.expected_reduction_percent),
            "%".into(),
        ]);
        t.row(vec![
            "material removal rate".into(),
            optional(n.mrr_cm3_per_min),
            "cm^3/min".into(),
        ]);
    }
    t.row(vec![
        "cuts used".into(),
        outcome.cuts_used.to_string(),
        "".into(),
    ]);
    t.row(vec![
        "effective samples (Kish)".into(),
        number(outcome.effective_samples),
        "".into(),
    ]);
    t.row(vec![
        "best stable material removal rate".into(),
        optional(outcome.best_stable_mrr_cm3_per_min),
        "cm^3/min".into(),
    ]);
    page.table(t);
    page.table(posterior_table(
        "Posterior after the cuts (003 Eq. 5-6)",
        &outcome.parameter_names,
        &outcome.posterior_mean,
        &outcome.posterior_sd,
    ));
    match plot {
        Ok(svg) => {
            page.figure(
                "Cuts made so far (o stable, x chatter) and the proposed cut",
                &svg,
            )?;
        }
        Err(why) => {
            page.warning(format!("no plot of the cuts: {why}"));
        }
    }
    Ok(page)
}

/// A band result of the demo for its findings: what it is, its curves, the name of its
/// conservative curve and why a speed may have no boundary.
pub type DemoBands<'a> = (&'a str, BandCurves, &'a str, &'a str);

/// The page of `chatter demo`, from the files of its folder (before the commit), its band
/// results, the models it ran and the diagnosis.
pub fn demo(
    folder: &Folder,
    bands: &[DemoBands],
    models: &[(&str, &ModalModel)],
    d: &Diagnosis,
) -> Result<Page> {
    let mut page = Page::new("chatter demo: the main job on the embedded examples");
    page.command_line_inputs();
    page.input(
        "examples",
        "the turning tool of Ahmadi (2022) (its hammer-test modes, test cuts and posterior); the \
         milling example of Schmitz (2023); a synthetic shop-floor campaign with withheld \
         process damping",
    );
    for (label, m) in models {
        page.model(label, m);
    }
    let text = |name: &str| {
        folder
            .get(name)
            .map(|b| String::from_utf8_lossy(b).into_owned())
            .unwrap_or_default()
    };
    for (what, curves, lower_label, why_missing) in bands {
        band_findings(&mut page, what, curves, lower_label, why_missing);
    }
    diagnosis_findings(&mut page, d);
    for (name, caption) in [
        ("turning_lobes.csv", "Turning lobes (the CSV)"),
        (
            "turning_credibility.csv",
            "Turning credibility bounds (the CSV)",
        ),
        ("milling_bands.csv", "Milling Type B bands (the CSV)"),
    ] {
        page.table(Table::from_csv(caption, &text(name)));
    }
    for name in [
        "turning_lobes.svg",
        "turning_credibility.svg",
        "milling_bands.svg",
        "milling_bands-theta.svg",
        "milling_bands-distance.svg",
        "milling_bands-roots.svg",
        "diagnosis/lobes.svg",
        "diagnosis/residuals.svg",
    ] {
        let short = name.trim_start_matches("diagnosis/");
        let caption = caption_of(short).unwrap_or(short);
        page.figure(caption, &text(name))?;
    }
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_stability::boundary::LobePoint;

    #[test]
    fn band_findings_name_the_pocket_the_safe_depth_and_the_missing_rows() {
        let curves = BandCurves {
            speed_rpm: vec![1000.0, 2000.0, 3000.0],
            depth_mm: vec![1.0, 3.0, 2.0],
            lower_mm: Some(vec![0.5, 2.0, 1.5]),
            upper_mm: Some(vec![1.5, f64::NAN, 2.5]),
        };
        let mut page = Page::new("t");
        band_findings(&mut page, "Bands", &curves, "lower bound", "why");
        let html = page.html();
        assert!(
            html.contains("the deepest stable pocket reaches 3 mm at 2000 rpm"),
            "{html}"
        );
        assert!(html.contains("below 2 mm stays stable"), "{html}");
        assert!(
            html.contains("cuts below 0.5 mm (the lower bound at 1000 rpm)"),
            "{html}"
        );
        assert!(
            html.contains("upper curve: 1 of 3 speeds have no boundary"),
            "{html}"
        );
        assert!(!html.contains("boundary: 1 of 3"), "{html}");
    }

    #[test]
    fn lobes_without_a_finite_boundary_say_so() {
        let mut page = Page::new("t");
        let lobes = [LobePoint {
            speed_rpm: 1000.0,
            depth_m: f64::INFINITY,
            chatter_hz: f64::NAN,
        }];
        band_findings(
            &mut page,
            "Lobes",
            &BandCurves::of_lobes(&lobes),
            "",
            LOBES_MISSING,
        );
        let html = page.html();
        assert!(html.contains("no finite limiting depth"), "{html}");
        assert!(html.contains("1 of 1 speeds have no boundary"), "{html}");
    }
}
