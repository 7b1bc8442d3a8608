//! Report pages rendered in a real browser: headless Chromium (the Debian package `chromium`)
//! loads a copy of the page with a small script appended that writes, after layout, the size of
//! every figure's SVG and the page's rendered text (`innerText`, which leaves out what is not
//! displayed) into the DOM; `--dump-dom` prints that DOM. Without a browser the checks are
//! skipped with a message (`CHATTER_CHROMIUM` names another binary).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What the browser rendered.
pub struct Rendered {
    /// The page's rendered text.
    pub text: String,
    /// Width and height (CSS pixels) of every figure's SVG, in page order.
    pub figure_sizes: Vec<(f64, f64)>,
}

/// The browser binary, if one is installed.
fn browser() -> Option<PathBuf> {
    match std::env::var_os("CHATTER_CHROMIUM") {
        Some(named) => Some(PathBuf::from(named)).filter(|p| p.exists()),
        None => ["/usr/bin/chromium", "/usr/bin/chromium-browser"]
            .iter()
            .map(PathBuf::from)
            .find(|p| p.exists()),
    }
}

/// Appended before `</body>` of the copy the browser loads (the page itself has no script).
const MEASURE: &str = "<script>\
for (const s of document.querySelectorAll('figure > svg')) {\
  const r = s.getBoundingClientRect();\
  s.setAttribute('data-rendered-size', r.width + 'x' + r.height);\
}\
const p = document.createElement('pre');\
p.id = 'rendered-text';\
p.textContent = document.body.innerText;\
document.body.appendChild(p);\
</script>";

fn unescape(text: &str) -> String {
    text.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&nbsp;", "\u{a0}")
        .replace("&amp;", "&")
}

/// Render `page` in headless Chromium; None (after printing why) when no browser is installed.
pub fn render(page: &Path) -> Option<Rendered> {
    let Some(chromium) = browser() else {
        eprintln!(
            "skipping the browser check of {}: no chromium installed (apt-get install chromium, \
             or set CHATTER_CHROMIUM)",
            page.display()
        );
        return None;
    };
    let html = std::fs::read_to_string(page).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("page.html");
    let at = html.rfind("</body>").expect("the page has a </body>");
    std::fs::write(&copy, format!("{}{MEASURE}{}", &html[..at], &html[at..])).unwrap();
    let dump = dir.path().join("dom.html");
    let profile = dir.path().join("profile");
    let mut child = Command::new(&chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1280,1024",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("--dump-dom")
        .arg(format!("file://{}", copy.display()))
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&dump).unwrap())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("starting {}: {e}", chromium.display()));
    let deadline = Instant::now() + Duration::from_secs(120);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{} did not finish rendering in 120 s", chromium.display());
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success(), "{} failed: {status}", chromium.display());
    let dom = std::fs::read_to_string(&dump).unwrap();
    let text = dom
        .split_once("<pre id=\"rendered-text\">")
        .and_then(|(_, rest)| rest.split_once("</pre>"))
        .map(|(t, _)| unescape(t))
        .unwrap_or_else(|| panic!("the measuring script did not run: {dom:.2000}"));
    let figure_sizes = dom
        .split("data-rendered-size=\"")
        .skip(1)
        .map(|rest| {
            let value = rest.split('"').next().unwrap();
            let (w, h) = value.split_once('x').unwrap();
            (w.parse().unwrap(), h.parse().unwrap())
        })
        .collect();
    Some(Rendered { text, figure_sizes })
}

/// Render `page` and check that every figure it holds was drawn with a non-zero size and that
/// the rendered text holds every one of `words`; returns the rendering (None when skipped).
pub fn check(page: &Path, words: &[&str]) -> Option<Rendered> {
    let figures = std::fs::read_to_string(page)
        .unwrap()
        .matches("<figure>")
        .count();
    let rendered = render(page)?;
    assert!(figures > 0, "{} has no figure", page.display());
    assert_eq!(
        rendered.figure_sizes.len(),
        figures,
        "figures measured in {}",
        page.display()
    );
    for (k, (w, h)) in rendered.figure_sizes.iter().enumerate() {
        assert!(
            *w > 100.0 && *h > 50.0,
            "figure {k} of {} rendered {w} x {h}",
            page.display()
        );
    }
    for word in words {
        assert!(
            rendered.text.contains(word),
            "`{word}` not rendered in {}:\n{}",
            page.display(),
            rendered.text
        );
    }
    Some(rendered)
}
