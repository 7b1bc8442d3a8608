//! Parsing and checks of the command-line options that no job request holds: `MIN:MAX:N` grids,
//! values echoed as typed (`--depth-mm -1` is reported as `-1`, not as metres), ranges of the
//! commands not yet behind a request, options that concern outputs, and consistency between the
//! files given together (operation kind, coordinates). The ranges, the cost guard and the
//! refused combinations of the requests live with them in `chatter_jobs` (`checks`).
//!
//! Ranges of file contents live with their types (`chatter_dynamics::limits`); this module
//! reuses them for the options that carry the same quantities.

use anyhow::{Result, bail};
use chatter_dynamics::limits::{Plausible, SPEED_RPM, open_closed, written};
use chatter_dynamics::{ModalModel, Observations, Operation};
use chatter_stability::monodromy::Discretization;

/// Most speeds or depths of a `MIN:MAX:N` grid.
pub const MAX_GRID: usize = 10_000;

/// The option values as typed on the command line, by option name (`speed_rpm`).
static TYPED: std::sync::OnceLock<std::collections::HashMap<String, String>> =
    std::sync::OnceLock::new();

/// Keep the values of the subcommand's options as typed, for messages that echo them.
pub fn remember_typed(matches: &clap::ArgMatches) {
    let typed = matches
        .ids()
        .filter_map(|id| {
            let raw = matches.get_raw(id.as_str())?;
            let text: Vec<String> = raw.map(|v| v.to_string_lossy().into_owned()).collect();
            Some((id.as_str().to_string(), text.join(",")))
        })
        .collect();
    let _ = TYPED.set(typed);
}

/// The value of option `flag` as the user typed it, else `value` written plainly.
pub fn as_typed(flag: &str, value: f64) -> String {
    let id = flag.trim_start_matches('-').replace('-', "_");
    TYPED
        .get()
        .and_then(|t| t.get(&id))
        .filter(|text| text.trim().parse::<f64>() == Ok(value))
        .cloned()
        .unwrap_or_else(|| written(value))
}

/// `value` of option `flag` when `range` holds it, else an error that echoes it as typed.
pub fn option(flag: &str, value: f64, range: &Plausible) -> Result<f64> {
    if range.contains(value) {
        Ok(value)
    } else {
        bail!(
            "{flag} {}: expected {}",
            as_typed(flag, value),
            range.expected()
        )
    }
}

/// A count option within `min..=max`.
pub fn count(flag: &str, value: usize, min: usize, max: usize, what: &str) -> Result<usize> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        bail!("{flag} {value}: expected {what} from {min} to {max}")
    }
}

/// Width in depth of a cut likelihood (003's sigma, 004's s_S).
pub const SIGMA_DEPTH_MM: Plausible = open_closed(0.0, 100.0, "a likelihood width", "mm");
/// Chatter-frequency width of a cut likelihood (004's s_fc).
pub const SIGMA_CHATTER_HZ: Plausible = open_closed(0.0, 1e5, "a likelihood width", "Hz");
/// Probability of stability of a tested contour.
pub const PROBABILITY: Plausible = Plausible {
    min: 0.0,
    min_included: false,
    max: 1.0,
    max_included: false,
    what: "a probability",
    unit: "",
};

/// An option given where the chosen kind does not use it.
pub fn unused(given: bool, flag: &str, context: &str, used_by: &str) -> Result<()> {
    if given {
        bail!("{flag} is not used {context}; it is for {used_by}");
    }
    Ok(())
}

/// Parse `MIN:MAX:N` of option `flag` with MIN and MAX in `range` and 2 <= N <= [`MAX_GRID`].
pub fn grid(flag: &str, spec: &str, range: &Plausible) -> Result<Vec<f64>> {
    let parts: Vec<&str> = spec.split(':').collect();
    let [min, max, n] = parts[..] else {
        bail!("{flag} {spec}: expected MIN:MAX:N, e.g. 3000:15000:200");
    };
    let number = |part: &str, name: &str| -> Result<f64> {
        part.trim()
            .parse::<f64>()
            .map_err(|_| anyhow::anyhow!("{flag} {spec}: {name} `{part}` is not a number"))
    };
    let (lo, hi) = (number(min, "MIN")?, number(max, "MAX")?);
    let n: usize = n
        .trim()
        .parse()
        .map_err(|_| anyhow::anyhow!("{flag} {spec}: N `{n}` is not a whole number of points"))?;
    for (name, v, text) in [("MIN", lo, min), ("MAX", hi, max)] {
        if !range.contains(v) {
            bail!(
                "{flag} {spec}: {name} {}: expected {}",
                text.trim(),
                range.expected()
            );
        }
    }
    if hi <= lo {
        bail!("{flag} {spec}: expected MIN < MAX");
    }
    if !(2..=MAX_GRID).contains(&n) {
        bail!("{flag} {spec}: N {n}: expected 2 to {MAX_GRID} points");
    }
    Ok(chatter_dynamics::grid::evenly_spaced(lo, hi, n))
}

/// `--speeds MIN:MAX:N` within the plausible spindle speeds.
pub fn speeds(spec: &str) -> Result<Vec<f64>> {
    grid("--speeds", spec, &SPEED_RPM)
}

/// The cost guard of the jobs ([`chatter_jobs::checks::work_size`]) for the commands that run
/// solvers outside a job request; `flag` names where the speeds came from.
pub fn work_size(
    model: &ModalModel,
    method: Discretization,
    speeds: &[f64],
    flag: &str,
) -> Result<()> {
    chatter_jobs::checks::work_size(model, method, speeds, flag.trim_start_matches("--"))
        .map_err(crate::job_error)
}

/// [`work_size`] at the speeds of the observations' cuts and poles, for the commands that
/// evaluate the model there with the automatic full discretization.
pub fn observation_work_size(
    model: &ModalModel,
    observations: &Observations,
    path: &std::path::Path,
) -> Result<()> {
    chatter_jobs::checks::observation_work_size(model, observations, &path.display().to_string())
        .map_err(crate::job_error)
}

/// The model and the observations describe the same operation (see
/// [`Observations::check_against`]), with the file names in the message.
pub fn observations_match(
    model: &ModalModel,
    observations: &Observations,
    observations_path: &std::path::Path,
    model_path: &std::path::Path,
) -> Result<()> {
    observations.check_against(model).map_err(|e| {
        anyhow::anyhow!(
            "{}: {e} (model {})",
            observations_path.display(),
            model_path.display()
        )
    })
}

/// The operation of a model in words.
fn kind(model: &ModalModel) -> &'static str {
    match model.operation() {
        Operation::Milling(_) => "milling",
        Operation::Turning(_) => "turning",
    }
}

/// A posterior folder of `chatter update` belongs to `model`: its `updated_model.json` has the
/// same operation and number of modes (the parameters name modes by number).
pub fn posterior_matches(model: &ModalModel, dir: &std::path::Path) -> Result<()> {
    let path = dir.join("updated_model.json");
    if !path.is_file() {
        return Ok(());
    }
    let updated = ModalModel::from_path(&path)
        .map_err(|e| anyhow::anyhow!("--posterior {}: {e}", dir.display()))?;
    if kind(&updated) != kind(model) || updated.mode_count() != model.mode_count() {
        bail!(
            "--posterior {}: the posterior comes from a {} model with {} modes ({}), but \
             --model is a {} model with {} modes; give the model the posterior was updated on",
            dir.display(),
            kind(&updated),
            updated.mode_count(),
            path.display(),
            kind(model),
            model.mode_count()
        );
    }
    Ok(())
}

/// A job's error in the command line's words: a request field is reported as its option
/// (`samples` as `--samples`, the value echoed as typed), and the fields the job's messages
/// quote in backticks likewise (`` `kind` geometric `` as `--kind geometric`); the rest as it is.
pub fn job_error(e: chatter_jobs::JobError) -> anyhow::Error {
    use chatter_jobs::JobError;
    match e {
        JobError::Invalid {
            field,
            value,
            expected,
        } => {
            let flag = flag(field);
            let value = match value.parse::<f64>() {
                Ok(v) => as_typed(&flag, v),
                Err(_) => value,
            };
            anyhow::anyhow!("{flag} {value}: expected {}", flags(&expected))
        }
        JobError::Unused {
            field,
            context,
            used_by,
        } => anyhow::anyhow!(
            "{} is not used {}; it is for {}",
            flag(field),
            flags(&context),
            flags(&used_by)
        ),
        JobError::TooManySteps { ref field, .. } => {
            let text = e.to_string();
            let source = if is_field(field) {
                flag(field)
            } else {
                field.clone()
            };
            anyhow::anyhow!(
                "{source}{}",
                flags(&text[field.len()..])
                    .replace("where the job offers", "where the command offers")
            )
        }
        JobError::Refused(_) | JobError::Missing { .. } => {
            anyhow::anyhow!("{}", flags(&e.to_string()))
        }
        other => other.into(),
    }
}

/// Whether `name` is a request field (lower-case words joined by `_`).
fn is_field(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// The option of request field `field` (`offset_rpm` -> `--offset-rpm`).
fn flag(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

/// `text` with every field quoted in backticks written as its option.
fn flags(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('`') {
        let Some(close) = rest[open + 1..].find('`') else {
            break;
        };
        let inner = &rest[open + 1..open + 1 + close];
        out.push_str(&rest[..open]);
        if is_field(inner) {
            out.push_str(&flag(inner));
        } else {
            out.push_str(&rest[open..open + close + 2]);
        }
        rest = &rest[open + close + 2..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_errors_echo_the_spec() {
        let e = speeds("0.001:0.01:2").unwrap_err().to_string();
        assert!(
            e.contains("--speeds 0.001:0.01:2") && e.contains("MIN 0.001"),
            "{e}"
        );
        let e = speeds("1e9:2e9:5").unwrap_err().to_string();
        assert!(e.contains("MIN 1e9:"), "{e}");
        assert_eq!(speeds("1000:2000:3").unwrap(), vec![1000.0, 1500.0, 2000.0]);
    }

    #[test]
    fn option_echoes_the_value_as_written() {
        let e = option("--depth-mm", -1.0, &chatter_dynamics::limits::DEPTH_MM)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("--depth-mm -1: expected a depth of cut"),
            "{e}"
        );
    }
}
