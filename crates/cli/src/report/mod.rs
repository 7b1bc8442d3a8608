//! One report page per job (`--report FILE.html`): a single self-contained HTML file with the
//! verdict or the next test in plain words, the warnings, the inputs (files, options and the
//! model's key parameters with units), the numbers with units as tables and the job's plots as
//! inline SVG. No script, no external style sheet, image or font: the page opens offline and
//! can be mailed as one file.
//!
//! [`Page`] is the builder; every text it is given is HTML-escaped ([`escape`]), and a figure
//! must be an SVG document as plotters writes it ([`Page::figure`]), whose text plotters has
//! already escaped. The job pages (what each command puts on its page) are in [`jobs`].

pub mod jobs;
mod model;

use anyhow::{Result, bail};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::OnceLock;

pub use model::model_table;

/// Escape `text` for HTML element content and double-quoted attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            other => out.push(other),
        }
    }
    out
}

/// A number for a table: four significant digits in plain or scientific notation, `none` when
/// not finite (a row without a boundary, a failed evaluation).
pub fn number(value: f64) -> String {
    if !value.is_finite() {
        return "none".into();
    }
    if value == 0.0 {
        return "0".into();
    }
    let magnitude = value.abs().log10().floor();
    if (-3.0..6.0).contains(&magnitude) {
        let decimals = (3.0 - magnitude).max(0.0) as usize;
        let text = format!("{value:.decimals$}");
        // 4 significant digits without trailing zeros after the point
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        format!("{value:.3e}")
    }
}

/// [`number`] of an optional value.
pub fn optional(value: Option<f64>) -> String {
    value.map_or_else(|| "none".into(), number)
}

/// A table of numbers; the column headers carry the units.
#[derive(Debug, Clone)]
pub struct Table {
    caption: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    collapsed: bool,
}

impl Table {
    /// An empty table with a caption and column headers (units in the headers, e.g.
    /// `speed (rpm)`).
    pub fn new(caption: &str, header: &[&str]) -> Self {
        Self {
            caption: caption.into(),
            header: header.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
            collapsed: false,
        }
    }

    /// A table of a CSV text as the command writes it (first line the header, whose names carry
    /// the units: `speed_rpm`, `depth_mm`), folded away by default: the full rows behind a
    /// summary.
    pub fn from_csv(caption: &str, csv: &str) -> Self {
        let mut lines = csv.lines();
        let header = lines
            .next()
            .map(|h| h.split(',').map(str::to_string).collect())
            .unwrap_or_default();
        Self {
            caption: caption.into(),
            header,
            rows: lines
                .map(|l| l.split(',').map(str::to_string).collect())
                .collect(),
            collapsed: true,
        }
    }

    /// Add a row (one cell per header).
    pub fn row(&mut self, cells: Vec<String>) -> &mut Self {
        self.rows.push(cells);
        self
    }

    fn html(&self, out: &mut String) {
        if self.collapsed {
            let _ = write!(
                out,
                "<details><summary>{} ({} rows)</summary>",
                escape(&self.caption),
                self.rows.len()
            );
        }
        let _ = write!(
            out,
            "<table><caption>{}</caption><thead><tr>",
            escape(&self.caption)
        );
        for h in &self.header {
            let _ = write!(out, "<th>{}</th>", escape(h));
        }
        out.push_str("</tr></thead><tbody>");
        for row in &self.rows {
            out.push_str("<tr>");
            for cell in row {
                let _ = write!(out, "<td>{}</td>", escape(cell));
            }
            out.push_str("</tr>");
        }
        out.push_str("</tbody></table>");
        if self.collapsed {
            out.push_str("</details>");
        }
        out.push('\n');
    }
}

/// A plot: caption and the SVG document.
#[derive(Debug, Clone)]
struct Figure {
    caption: String,
    svg: String,
}

/// The sections of a page, in order, with their headings.
pub const SECTIONS: [&str; 6] = [
    "Verdict", "Warnings", "Inputs", "Model", "Results", "Figures",
];

/// A report page under construction.
#[derive(Debug, Clone)]
pub struct Page {
    title: String,
    verdict: Vec<String>,
    warnings: Vec<String>,
    inputs: Vec<(String, String)>,
    models: Vec<Table>,
    tables: Vec<Table>,
    figures: Vec<Figure>,
}

impl Page {
    /// An empty page titled `title` (e.g. `chatter update`).
    pub fn new(title: &str) -> Self {
        Self {
            title: title.into(),
            verdict: Vec::new(),
            warnings: Vec::new(),
            inputs: Vec::new(),
            models: Vec::new(),
            tables: Vec::new(),
            figures: Vec::new(),
        }
    }

    /// A paragraph of the verdict (or the next test), in plain words.
    pub fn verdict(&mut self, text: impl Into<String>) -> &mut Self {
        self.verdict.push(text.into());
        self
    }

    /// A warning: a prior bound hit, solver failures, a clipped grid, rows without a boundary.
    pub fn warning(&mut self, text: impl Into<String>) -> &mut Self {
        self.warnings.push(text.into());
        self
    }

    /// An input: a file or an option and its value.
    pub fn input(&mut self, name: impl Into<String>, value: impl Into<String>) -> &mut Self {
        self.inputs.push((name.into(), value.into()));
        self
    }

    /// The options of this run as given on the command line (and their defaults).
    pub fn command_line_inputs(&mut self) -> &mut Self {
        for (flag, value) in invocation() {
            self.input(flag, value);
        }
        self
    }

    /// The key parameters of a model, with units ([`model_table`]).
    pub fn model(&mut self, label: &str, m: &chatter_dynamics::ModalModel) -> &mut Self {
        self.models.push(model_table(label, m));
        self
    }

    /// A table of results.
    pub fn table(&mut self, table: Table) -> &mut Self {
        self.tables.push(table);
        self
    }

    /// A plot: `svg` must be one SVG document (`<svg ...>...</svg>`, as plotters writes it; an
    /// XML declaration before it is dropped). It is inlined as it is, so it must not come from
    /// user text.
    pub fn figure(&mut self, caption: &str, svg: &str) -> Result<&mut Self> {
        let body = svg.trim();
        let body = match body.find("<svg") {
            Some(start) if body[..start].trim().is_empty() || body.starts_with("<?xml") => {
                &body[start..]
            }
            _ => bail!("report: the figure `{caption}` is not an SVG document"),
        };
        if !body.ends_with("</svg>") || body.contains("<script") || body.contains("href") {
            bail!("report: the figure `{caption}` is not a self-contained SVG document");
        }
        self.figures.push(Figure {
            caption: caption.into(),
            svg: body.into(),
        });
        Ok(self)
    }

    /// The page as one HTML document.
    pub fn html(&self) -> String {
        let mut out = String::new();
        let _ = write!(
            out,
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
             <title>{}</title><style>{STYLE}</style></head><body>\n<h1>{}</h1>\n\
             <p class=\"generated\">written by chatter {}</p>\n",
            escape(&self.title),
            escape(&self.title),
            env!("CARGO_PKG_VERSION")
        );
        let section = |out: &mut String, k: usize| {
            let _ = writeln!(
                out,
                "<section id=\"{}\"><h2>{}</h2>",
                SECTIONS[k].to_lowercase(),
                SECTIONS[k]
            );
        };
        let none = |out: &mut String, what: &str| {
            let _ = writeln!(out, "<p class=\"none\">{what}</p>");
        };
        section(&mut out, 0);
        if self.verdict.is_empty() {
            none(&mut out, "No verdict.");
        }
        for p in &self.verdict {
            let _ = writeln!(out, "<p class=\"verdict\">{}</p>", escape(p));
        }
        out.push_str("</section>\n");
        section(&mut out, 1);
        if self.warnings.is_empty() {
            none(&mut out, "None.");
        } else {
            out.push_str("<ul class=\"warnings\">");
            for w in &self.warnings {
                let _ = write!(out, "<li>{}</li>", escape(w));
            }
            out.push_str("</ul>\n");
        }
        out.push_str("</section>\n");
        section(&mut out, 2);
        if self.inputs.is_empty() {
            none(&mut out, "None.");
        } else {
            out.push_str("<table class=\"inputs\"><tbody>");
            for (name, value) in &self.inputs {
                let _ = write!(
                    out,
                    "<tr><th>{}</th><td>{}</td></tr>",
                    escape(name),
                    escape(value)
                );
            }
            out.push_str("</tbody></table>\n");
        }
        out.push_str("</section>\n");
        section(&mut out, 3);
        if self.models.is_empty() {
            none(&mut out, "None.");
        }
        for t in &self.models {
            t.html(&mut out);
        }
        out.push_str("</section>\n");
        section(&mut out, 4);
        if self.tables.is_empty() {
            none(&mut out, "None.");
        }
        for t in &self.tables {
            t.html(&mut out);
        }
        out.push_str("</section>\n");
        section(&mut out, 5);
        if self.figures.is_empty() {
            none(&mut out, "None.");
        }
        for f in &self.figures {
            let _ = writeln!(
                out,
                "<figure>{}<figcaption>{}</figcaption></figure>",
                f.svg,
                escape(&f.caption)
            );
        }
        out.push_str("</section>\n</body></html>\n");
        out
    }

    /// Write the page to `path` atomically (checked with `output::check_file` before the work).
    pub fn write(&self, path: &Path) -> Result<()> {
        crate::output::write_atomic(path, self.html().as_bytes())
    }
}

/// The page's look: readable on screen and on paper, figures scaled to the page width.
const STYLE: &str = "body{font-family:sans-serif;max-width:62rem;margin:1rem auto;padding:0 1rem;\
color:#111}h1{font-size:1.6rem}h2{border-bottom:1px solid #999;margin-top:2rem}\
.generated{color:#555;font-size:.85rem}.verdict{font-size:1.1rem;background:#eef5ee;\
padding:.5rem;border-left:4px solid #2a7a2a}.warnings li{background:#fff3e0;margin:.2rem 0;\
padding:.3rem;border-left:4px solid #d07000}table{border-collapse:collapse;margin:.8rem 0}\
caption{text-align:left;font-weight:bold;padding:.2rem 0}th,td{border:1px solid #bbb;\
padding:.15rem .5rem;text-align:left}td{font-variant-numeric:tabular-nums}\
figure{margin:1rem 0}figure svg{display:block;max-width:100%;height:auto}\
figcaption{color:#333;font-size:.9rem}";

/// Options of this run, remembered by [`remember_invocation`].
static INVOCATION: OnceLock<Vec<(String, String)>> = OnceLock::new();

/// Remember the options of the subcommand `command` (as typed, and the defaults it used) for
/// the report page's inputs. Called once by `main`.
pub fn remember_invocation(command: &clap::Command, matches: &clap::ArgMatches) {
    let _ = INVOCATION.set(options_of(command, matches));
}

/// The options of a parsed subcommand: `command chatter NAME`, then `--flag value` for every
/// option given or defaulted (`value (default)`), in the order clap holds them.
fn options_of(command: &clap::Command, matches: &clap::ArgMatches) -> Vec<(String, String)> {
    let mut options = vec![(
        "command".to_string(),
        format!("chatter {}", command.get_name()),
    )];
    for id in matches.ids() {
        let id = id.as_str();
        // argument groups (one per flattened struct) are not options
        if id == "quiet" || !command.get_arguments().any(|a| a.get_id() == id) {
            continue;
        }
        let Ok(Some(values)) = matches.try_get_raw(id) else {
            continue;
        };
        let values: Vec<String> = values.map(|v| v.to_string_lossy().into_owned()).collect();
        let source = match matches.value_source(id) {
            Some(clap::parser::ValueSource::DefaultValue) => " (default)",
            _ => "",
        };
        options.push((
            format!("--{}", id.replace('_', "-")),
            format!("{}{source}", values.join(" ")),
        ));
    }
    options
}

/// The remembered options (empty when none were).
fn invocation() -> Vec<(String, String)> {
    INVOCATION.get().cloned().unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SVG: &str = "<svg width=\"10\" height=\"5\" viewBox=\"0 0 10 5\" \
                       xmlns=\"http://www.w3.org/2000/svg\"><rect x=\"0\" y=\"0\" width=\"10\" \
                       height=\"5\"/></svg>";

    #[test]
    fn user_text_is_escaped_everywhere() {
        let evil = "<script>alert('x')</script> & \"q\"";
        let mut page = Page::new(evil);
        page.verdict(evil).warning(evil).input(evil, evil);
        let mut t = Table::new(evil, &[evil]);
        t.row(vec![evil.into()]);
        page.table(t);
        page.table(Table::from_csv(evil, &format!("a_mm\n{evil}\n")));
        page.figure(evil, SVG).unwrap();
        let html = page.html();
        assert!(!html.contains("<script"), "{html}");
        assert!(!html.contains("'x'"), "{html}");
        assert!(
            html.contains("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;q&quot;")
        );
    }

    #[test]
    fn every_section_is_present_even_when_empty() {
        for page in [Page::new("empty"), {
            let mut p = Page::new("full");
            p.verdict("stable below 2 mm")
                .warning("w")
                .input("--model", "m.json")
                .model(
                    "nominal",
                    &chatter_dynamics::examples::schmitz_2023_milling(),
                );
            p.table(Table::new("t", &["speed (rpm)"]));
            p.figure("f", SVG).unwrap();
            p
        }] {
            let html = page.html();
            let mut at = 0;
            for s in SECTIONS {
                let heading = format!("<h2>{s}</h2>");
                let k = html[at..]
                    .find(&heading)
                    .unwrap_or_else(|| panic!("{s} missing or out of order"));
                at += k;
            }
            assert!(html.starts_with("<!DOCTYPE html>") && html.ends_with("</html>\n"));
        }
    }

    #[test]
    fn the_page_needs_no_network_and_no_script() {
        let mut page = Page::new("p");
        page.figure("f", &format!("<?xml version=\"1.0\"?>\n{SVG}"))
            .unwrap();
        let html = page.html();
        for forbidden in ["<script", "<link", "src=", "href=", "url(", "@import"] {
            assert!(!html.contains(forbidden), "{forbidden}");
        }
        assert!(html.contains("<figure><svg width=\"10\""));
    }

    #[test]
    fn figures_must_be_self_contained_svg() {
        let mut page = Page::new("p");
        assert!(page.figure("f", "<p>not svg</p>").is_err());
        assert!(page.figure("f", "<b></b><svg></svg>").is_err());
        assert!(
            page.figure("f", "<svg><image href=\"http://x/y.png\"/></svg>")
                .is_err()
        );
        assert!(page.figure("f", "<svg><script>1</script></svg>").is_err());
    }

    #[test]
    fn the_inputs_are_the_options_as_typed_with_their_defaults() {
        let matches = crate::command()
            .try_get_matches_from([
                "chatter",
                "--quiet",
                "plan",
                "--model",
                "m <1>.json",
                "--observations",
                "o.json",
                "--strategy",
                "mrr",
                "--report",
                "r.html",
            ])
            .unwrap();
        let (name, sub) = matches.subcommand().unwrap();
        let command = crate::command().find_subcommand(name).unwrap().clone();
        let options = options_of(&command, sub);
        let get = |flag: &str| {
            options
                .iter()
                .find(|o| o.0 == flag)
                .map(|o| o.1.as_str())
                .unwrap_or_else(|| panic!("{flag} missing: {options:?}"))
        };
        assert_eq!(get("command"), "chatter plan");
        assert_eq!(get("--model"), "m <1>.json");
        assert_eq!(get("--report"), "r.html");
        assert_eq!(get("--paths"), "300 (default)");
        assert_eq!(get("--feed-per-tooth-mm"), "0.1 (default)");
        // neither --quiet nor clap's argument group of the flattened PlanArgs
        assert!(
            options
                .iter()
                .all(|o| o.0 != "--quiet" && o.0 != "--PlanArgs")
        );
        assert!(
            !options.iter().any(|o| o.0 == "--p-test"),
            "not given, no default"
        );
    }

    #[test]
    fn numbers_keep_four_significant_digits() {
        assert_eq!(number(1234.5678), "1235");
        assert_eq!(number(2.5), "2.5");
        assert_eq!(number(0.0123456), "0.01235");
        assert_eq!(number(-0.5), "-0.5");
        assert_eq!(number(1.0e7), "1.000e7");
        assert_eq!(number(2.5e-6), "2.500e-6");
        assert_eq!(number(f64::NAN), "none");
        assert_eq!(number(0.0), "0");
        assert_eq!(optional(None), "none");
    }

    #[test]
    fn csv_tables_keep_their_header_and_rows() {
        let t = Table::from_csv("bands", "speed_rpm,depth_mm\n1000,2\n1100,\n");
        assert_eq!(t.rows.len(), 2);
        let mut html = String::new();
        t.html(&mut html);
        assert!(html.contains("<th>speed_rpm</th><th>depth_mm</th>"));
        assert!(html.contains("<details><summary>bands (2 rows)</summary>"));
    }
}
