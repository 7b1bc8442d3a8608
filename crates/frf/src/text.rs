//! Text FRF formats: the CSV that `chatter frf` writes (`frequency_hz,real_m_per_n,
//! imag_m_per_n`, or the mobility / accelerance columns `real_m_per_s_per_n`,
//! `real_m_per_s2_per_n` with their `imag_` partners), and whitespace-separated columns
//! frequency (Hz), real, imaginary (m/N): the CutPro `.frf` format (whose first data line also
//! carries the column header text after its numbers) and a tap-test system's `.txt` export.

use crate::error::{FrfError, Result};
use crate::frf::{Frf, Quantity};
use num_complex::Complex64;
use std::path::Path;

/// Read a text file with errors that name it.
pub(crate) fn read_text(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|source| FrfError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// A number as written in FRF files, accepting Fortran's `D` exponent.
pub(crate) fn number(token: &str) -> Option<f64> {
    let t = token.trim();
    t.parse::<f64>()
        .ok()
        .or_else(|| t.replace(['D', 'd'], "E").parse().ok())
        .filter(|v: &f64| v.is_finite())
}

/// Parse the CSV form; `path` names the source in errors.
pub fn parse_csv(text: &str, path: &Path) -> Result<Frf> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((_, header)) = lines.next() else {
        return Err(FrfError::parse(
            path,
            1,
            "empty file: expected a header `frequency_hz,real_m_per_n,imag_m_per_n`",
        ));
    };
    let names: Vec<String> = header
        .split(',')
        .map(|s| s.trim().trim_matches('"').to_ascii_lowercase())
        .collect();
    let column = |name: &str| names.iter().position(|n| n == name);
    let freq = column("frequency_hz").ok_or_else(|| {
        FrfError::parse(
            path,
            1,
            format!("no `frequency_hz` column in the header {names:?}"),
        )
    })?;
    let mut found = None;
    for (unit, quantity) in [
        ("m_per_n", Quantity::Receptance),
        ("m_per_s_per_n", Quantity::Mobility),
        ("m_per_s2_per_n", Quantity::Accelerance),
    ] {
        if let (Some(re), Some(im)) = (
            column(&format!("real_{unit}")),
            column(&format!("imag_{unit}")),
        ) {
            found = Some((re, im, quantity));
            break;
        }
    }
    let Some((re, im, quantity)) = found else {
        return Err(FrfError::parse(
            path,
            1,
            format!(
                "header {names:?}: expected the columns real_m_per_n and imag_m_per_n \
                 (receptance), real_m_per_s_per_n and imag_m_per_s_per_n (mobility) or \
                 real_m_per_s2_per_n and imag_m_per_s2_per_n (accelerance)"
            ),
        ));
    };
    let mut f = Vec::new();
    let mut v = Vec::new();
    for (k, line) in lines {
        let cells: Vec<&str> = line.split(',').collect();
        let cell = |c: usize, name: &str| {
            cells.get(c).and_then(|s| number(s)).ok_or_else(|| {
                FrfError::parse(
                    path,
                    k + 1,
                    format!(
                        "column `{name}`: `{}` is not a finite number",
                        cells.get(c).map_or("", |s| s.trim())
                    ),
                )
            })
        };
        f.push(cell(freq, "frequency_hz")?);
        v.push(Complex64::new(cell(re, &names[re])?, cell(im, &names[im])?));
    }
    Frf::from_quantity(f, v, quantity).map_err(|e| FrfError::parse(path, 0, e.to_string()))
}

/// Parse whitespace-separated columns frequency (Hz), real, imaginary (m/N). Lines before the
/// first data line that do not start with three numbers are headers; text after the three
/// numbers of a line is ignored (CutPro writes its header there).
pub fn parse_columns(text: &str, path: &Path) -> Result<Frf> {
    let mut f = Vec::new();
    let mut v = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if tokens.is_empty() {
            continue;
        }
        let numbers: Vec<f64> = tokens.iter().take(3).map_while(|t| number(t)).collect();
        if numbers.len() < 3 {
            if f.is_empty() {
                continue;
            }
            return Err(FrfError::parse(
                path,
                k + 1,
                format!(
                    "`{}`: expected three numbers, frequency (Hz), real and imaginary receptance \
                     (m/N)",
                    line.trim()
                ),
            ));
        }
        f.push(numbers[0]);
        v.push(Complex64::new(numbers[1], numbers[2]));
    }
    if f.is_empty() {
        return Err(FrfError::parse(
            path,
            0,
            "no data line: expected lines of frequency (Hz), real and imaginary receptance (m/N)",
        ));
    }
    Frf::new(f, v).map_err(|e| FrfError::parse(path, 0, e.to_string()))
}

/// The CSV form of `frf` (the columns of `chatter frf`, with the magnitude).
pub fn to_csv(frf: &Frf) -> String {
    use std::fmt::Write as _;
    let mut s = String::from("frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n\n");
    for (f, g) in frf.frequencies_hz().iter().zip(frf.receptance_m_per_n()) {
        let _ = writeln!(s, "{f},{:e},{:e},{:e}", g.re, g.im, g.norm());
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_reads_receptance_and_accelerance_and_names_bad_cells() {
        let p = Path::new("a.csv");
        let frf = parse_csv(
            "frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n\n0,1e-7,0,1e-7\n10,1e-7,-1e-8,1e-7\n",
            p,
        )
        .unwrap();
        assert_eq!(frf.len(), 2);
        let acc = parse_csv(
            "frequency_hz,real_m_per_s2_per_n,imag_m_per_s2_per_n\n0,1,0\n10,-3.9478,0\n20,-1,0\n",
            p,
        )
        .unwrap();
        assert_eq!(acc.frequencies_hz(), &[10.0, 20.0]);
        assert!((acc.receptance_m_per_n()[0].re - 1e-3).abs() < 1e-7);
        let e = parse_csv("frequency_hz,real_m_per_n,imag_m_per_n\n1,x,0\n2,0,0\n", p)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 2") && e.contains("real_m_per_n") && e.contains('x'),
            "{e}"
        );
        let e = parse_csv("frequency_hz,re,im\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("real_m_per_n"), "{e}");
    }

    #[test]
    fn columns_skip_headers_and_trailing_text() {
        let p = Path::new("a.frf");
        let frf = parse_columns(
            "  0.0\t2.0e-07\t0.0\tFreq\tHz\tReal\tm/N\n  1.0\t2.1e-07\t5.9e-11\t\n",
            p,
        )
        .unwrap();
        assert_eq!(frf.len(), 2);
        let frf = parse_columns(
            "freq real imag\n0.000000e+000 7.7e-001 0.0\n1 1D-2 -1E-3\n",
            p,
        )
        .unwrap();
        assert!((frf.receptance_m_per_n()[1].re - 1e-2).abs() < 1e-15);
        let e = parse_columns("0 1 2\n1 2\n", p).unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }
}
