//! Universal file format dataset 58, "function at nodal DOF", in its ASCII form and the binary
//! form 58b that tap-test systems export (the I-DEAS universal file specification, records
//! 1-11 then the data; 58b adds byte order, floating-point format, the number of ASCII header
//! lines and of data bytes to its first line).
//!
//! Record 6 names the function type (4 = frequency response function), the response and
//! reference nodes and directions; record 7 the ordinate data type (2/4 real single/double,
//! 5/6 complex single/double), the number of points and the abscissa spacing (1 even with
//! minimum and increment, 0 uneven with the abscissa beside each value); record 9 the
//! numerator's specific data type (8 displacement, 11 velocity, 12 acceleration), so a
//! receptance, mobility or accelerance. Values are taken in SI units (m, N, s), the usual
//! export setting; a units dataset 164 is not read.

use crate::error::{FrfError, Result};
use crate::frf::{Frf, Quantity};
use crate::text::number;
use num_complex::Complex64;
use std::fmt::Write as _;
use std::path::Path;

/// One dataset 58 record.
#[derive(Debug, Clone, PartialEq)]
pub struct Uff58Record {
    /// ID lines 1-5 (free text; line 1 is usually the function's description).
    pub id_lines: [String; 5],
    /// Function type (4 = frequency response function, 1 = time response, ...).
    pub function_type: i64,
    /// Response node.
    pub response_node: i64,
    /// Response direction (1..3 = +X..+Z, negative for minus).
    pub response_direction: i64,
    /// Reference (force) node.
    pub reference_node: i64,
    /// Reference direction.
    pub reference_direction: i64,
    /// Numerator specific data type (8 displacement, 11 velocity, 12 acceleration).
    pub ordinate_type: i64,
    /// Abscissa values (Hz for an FRF).
    pub abscissa: Vec<f64>,
    /// Ordinate values (imaginary part zero for real data).
    pub values: Vec<Complex64>,
}

impl Uff58Record {
    /// A frequency response record of a receptance (`ordinate_type` 8 over force).
    pub fn receptance(
        frf: &Frf,
        description: &str,
        response: (i64, i64),
        reference: (i64, i64),
    ) -> Self {
        Self {
            id_lines: [
                description.to_string(),
                "NONE".into(),
                "NONE".into(),
                "NONE".into(),
                "NONE".into(),
            ],
            function_type: 4,
            response_node: response.0,
            response_direction: response.1,
            reference_node: reference.0,
            reference_direction: reference.1,
            ordinate_type: 8,
            abscissa: frf.frequencies_hz().to_vec(),
            values: frf.receptance_m_per_n().to_vec(),
        }
    }

    /// The receptance of this record: displacement, velocity or acceleration over force.
    pub fn to_frf(&self, path: &Path) -> Result<Frf> {
        let quantity = match self.ordinate_type {
            8 | 0 => Quantity::Receptance,
            11 => Quantity::Mobility,
            12 => Quantity::Accelerance,
            other => {
                return Err(FrfError::parse(
                    path,
                    0,
                    format!(
                        "dataset 58 ordinate specific data type {other}: expected 8 \
                         (displacement), 11 (velocity) or 12 (acceleration) over force"
                    ),
                ));
            }
        };
        Frf::from_quantity(self.abscissa.clone(), self.values.clone(), quantity)
            .map_err(|e| FrfError::parse(path, 0, e.to_string()))
    }
}

/// A line-oriented cursor over the file's bytes (58b mixes text lines and raw bytes).
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Cursor<'a> {
    fn next_line(&mut self) -> Option<&'a str> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        self.line += 1;
        let line = &rest[..end];
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        Some(std::str::from_utf8(line).unwrap_or(""))
    }

    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let out = self.bytes.get(self.pos..self.pos + n)?;
        self.pos += n;
        Some(out)
    }
}

/// Columns `from..to` of a fixed-format line, blank where the line is shorter.
fn columns(line: &str, from: usize, to: usize) -> &str {
    let from = from.min(line.len());
    let to = to.min(line.len());
    line.get(from..to).unwrap_or("")
}

fn int_field(
    line: &str,
    from: usize,
    to: usize,
    path: &Path,
    at: usize,
    name: &str,
) -> Result<i64> {
    let s = columns(line, from, to).trim();
    if s.is_empty() {
        return Ok(0);
    }
    s.parse()
        .map_err(|_| FrfError::parse(path, at, format!("{name}: `{s}` is not an integer")))
}

/// The header records 1-11 after the dataset number.
struct Header {
    id_lines: [String; 5],
    function_type: i64,
    nodes: [i64; 4],
    ordinate_data_type: i64,
    points: usize,
    even: bool,
    abscissa_min: f64,
    abscissa_increment: f64,
    ordinate_type: i64,
}

fn header(c: &mut Cursor, path: &Path) -> Result<Header> {
    let mut lines = Vec::with_capacity(11);
    for _ in 0..11 {
        let line = c.next_line().ok_or_else(|| {
            FrfError::parse(path, c.line, "dataset 58 ends inside its 11 header records")
        })?;
        lines.push((c.line, line));
    }
    let id_lines = std::array::from_fn(|k| lines[k].1.trim_end().to_string());
    let (at6, r6) = lines[5];
    let function_type = int_field(r6, 0, 5, path, at6, "record 6 function type")?;
    let nodes = [
        int_field(r6, 41, 51, path, at6, "record 6 response node")?,
        int_field(r6, 51, 55, path, at6, "record 6 response direction")?,
        int_field(r6, 66, 76, path, at6, "record 6 reference node")?,
        int_field(r6, 76, 80, path, at6, "record 6 reference direction")?,
    ];
    let (at7, r7) = lines[6];
    let t: Vec<&str> = r7.split_whitespace().collect();
    let bad7 = || {
        FrfError::parse(
            path,
            at7,
            format!(
                "record 7 `{}`: expected ordinate data type, number of points, abscissa spacing, \
                 minimum, increment, z value",
                r7.trim()
            ),
        )
    };
    if t.len() < 5 {
        return Err(bad7());
    }
    let ordinate_data_type: i64 = t[0].parse().map_err(|_| bad7())?;
    let points: usize = t[1].parse().map_err(|_| bad7())?;
    let spacing: i64 = t[2].parse().map_err(|_| bad7())?;
    let abscissa_min = number(t[3]).ok_or_else(bad7)?;
    let abscissa_increment = number(t[4]).ok_or_else(bad7)?;
    if ![2, 4, 5, 6].contains(&ordinate_data_type) {
        return Err(FrfError::parse(
            path,
            at7,
            format!(
                "record 7 ordinate data type {ordinate_data_type}: expected 2 or 4 (real single/double) \
                 or 5 or 6 (complex single/double)"
            ),
        ));
    }
    let (at9, r9) = lines[8];
    let ordinate_type = int_field(r9, 0, 10, path, at9, "record 9 specific data type")?;
    Ok(Header {
        id_lines,
        function_type,
        nodes,
        ordinate_data_type,
        points,
        even: spacing == 1,
        abscissa_min,
        abscissa_increment,
        ordinate_type,
    })
}

/// The record from its header and the flat list of data values in file order.
fn record(h: Header, values: &[f64], path: &Path, at: usize) -> Result<Uff58Record> {
    let complex = h.ordinate_data_type >= 5;
    let per_point = usize::from(complex) + 1 + usize::from(!h.even);
    if values.len() != per_point * h.points {
        return Err(FrfError::parse(
            path,
            at,
            format!(
                "dataset 58 holds {} values: record 7 announces {} points of {} values each",
                values.len(),
                h.points,
                per_point
            ),
        ));
    }
    let mut abscissa = Vec::with_capacity(h.points);
    let mut data = Vec::with_capacity(h.points);
    for (k, chunk) in values.chunks(per_point).enumerate() {
        let (x, rest) = if h.even {
            (h.abscissa_min + h.abscissa_increment * k as f64, chunk)
        } else {
            (chunk[0], &chunk[1..])
        };
        abscissa.push(x);
        data.push(Complex64::new(rest[0], if complex { rest[1] } else { 0.0 }));
    }
    Ok(Uff58Record {
        id_lines: h.id_lines,
        function_type: h.function_type,
        response_node: h.nodes[0],
        response_direction: h.nodes[1],
        reference_node: h.nodes[2],
        reference_direction: h.nodes[3],
        ordinate_type: h.ordinate_type,
        abscissa,
        values: data,
    })
}

/// Every dataset 58 / 58b record of a universal file's bytes, in file order; other datasets
/// are skipped.
pub fn parse_uff58(bytes: &[u8], path: &Path) -> Result<Vec<Uff58Record>> {
    let mut c = Cursor {
        bytes,
        pos: 0,
        line: 0,
    };
    let mut out = Vec::new();
    while let Some(line) = c.next_line() {
        if line.trim() != "-1" {
            continue;
        }
        let Some(kind) = c.next_line() else { break };
        let tokens: Vec<&str> = kind.split_whitespace().collect();
        match tokens.first().copied() {
            Some("58") => {
                let at = c.line;
                let h = header(&mut c, path)?;
                let mut values = Vec::new();
                loop {
                    let Some(l) = c.next_line() else {
                        return Err(FrfError::parse(path, at, "dataset 58 has no closing -1"));
                    };
                    if l.trim() == "-1" {
                        break;
                    }
                    for t in l.split_whitespace() {
                        values.push(number(t).ok_or_else(|| {
                            FrfError::parse(path, c.line, format!("`{t}` is not a finite number"))
                        })?);
                    }
                }
                out.push(record(h, &values, path, at)?);
            }
            Some("58b") => {
                let at = c.line;
                let field = |k: usize| tokens.get(k).and_then(|t| t.parse::<i64>().ok());
                let (Some(order), Some(fp), Some(ascii), Some(n_bytes)) =
                    (field(1), field(2), field(3), field(4))
                else {
                    return Err(FrfError::parse(
                        path,
                        at,
                        format!(
                            "`{}`: expected 58b, byte ordering, floating-point format, ASCII \
                             lines, data bytes",
                            kind.trim()
                        ),
                    ));
                };
                if fp != 2 {
                    return Err(FrfError::parse(
                        path,
                        at,
                        format!("58b floating-point format {fp}: only 2 (IEEE 754) is read"),
                    ));
                }
                if ascii != 11 {
                    return Err(FrfError::parse(
                        path,
                        at,
                        format!("58b with {ascii} ASCII lines: expected 11"),
                    ));
                }
                let h = header(&mut c, path)?;
                let n = usize::try_from(n_bytes).unwrap_or(usize::MAX);
                let raw = c.take(n).ok_or_else(|| {
                    FrfError::parse(
                        path,
                        at,
                        format!("58b announces {n_bytes} data bytes past the end of the file"),
                    )
                })?;
                // 2 and 5 are single precision, 4 and 6 double
                let width = if matches!(h.ordinate_data_type, 2 | 5) {
                    4
                } else {
                    8
                };
                let little = order == 1;
                let values: Vec<f64> = raw
                    .chunks_exact(width)
                    .map(|b| match (width, little) {
                        (4, true) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                        (4, false) => f64::from(f32::from_be_bytes([b[0], b[1], b[2], b[3]])),
                        (_, true) => {
                            f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
                        }
                        (_, false) => {
                            f64::from_be_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
                        }
                    })
                    .collect();
                out.push(record(h, &values, path, at)?);
            }
            _ => {
                // another dataset: skip to its closing -1
                while let Some(l) = c.next_line() {
                    if l.trim() == "-1" {
                        break;
                    }
                }
            }
        }
    }
    Ok(out)
}

/// Read every dataset 58 record of a universal file.
pub fn read_uff58(path: &Path) -> Result<Vec<Uff58Record>> {
    let bytes = std::fs::read(path).map_err(|source| FrfError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_uff58(&bytes, path)
}

/// Fortran `Ew.d`: `d` digits after the point, a signed two- or three-digit exponent,
/// right-aligned in `w` columns.
fn fortran_e(x: f64, w: usize, d: usize) -> String {
    let s = format!("{x:.d$E}");
    let (mantissa, exp) = s.split_once('E').unwrap_or((&s, "0"));
    let e: i32 = exp.parse().unwrap_or(0);
    let sign = if e < 0 { '-' } else { '+' };
    format!("{:>w$}", format!("{mantissa}E{sign}{:02}", e.abs()))
}

/// The ASCII dataset 58 text of `records` (complex double ordinates; even abscissa when the
/// spacing is uniform to 1e-9, else uneven with the abscissa beside each value written as
/// E20.12 for full precision).
pub fn to_uff58_string(records: &[Uff58Record]) -> String {
    let mut s = String::new();
    for r in records {
        let n = r.abscissa.len();
        let (min, inc) = match (r.abscissa.first(), r.abscissa.get(1)) {
            (Some(&a), Some(&b)) => (a, b - a),
            (Some(&a), None) => (a, 0.0),
            _ => (0.0, 0.0),
        };
        let even = n >= 2
            && r.abscissa
                .iter()
                .enumerate()
                .all(|(k, &x)| (x - (min + inc * k as f64)).abs() <= 1e-9 * inc.abs().max(x.abs()))
            && fortran_e(min, 13, 5).trim().parse::<f64>().ok() == Some(min)
            && fortran_e(inc, 13, 5).trim().parse::<f64>().ok() == Some(inc);
        let _ = writeln!(s, "{:>6}\n{:>6}", -1, 58);
        for id in &r.id_lines {
            let _ = writeln!(s, "{:<80}", id.chars().take(80).collect::<String>());
        }
        let _ = writeln!(
            s,
            "{:>5}{:>10}{:>5}{:>10} {:<10}{:>10}{:>4} {:<10}{:>10}{:>4}",
            r.function_type,
            1,
            0,
            0,
            "NONE",
            r.response_node,
            r.response_direction,
            "NONE",
            r.reference_node,
            r.reference_direction
        );
        let _ = writeln!(
            s,
            "{:>10}{:>10}{:>10}{}{}{}",
            6,
            n,
            u8::from(even),
            fortran_e(if even { min } else { 0.0 }, 13, 5),
            fortran_e(if even { inc } else { 0.0 }, 13, 5),
            fortran_e(0.0, 13, 5)
        );
        let _ = writeln!(
            s,
            "{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}",
            18, 0, 0, 0, "Frequency", "Hz"
        );
        let (label, len_exp) = match r.ordinate_type {
            11 => ("Velocity", 1),
            12 => ("Acceleration", 1),
            _ => ("Displacement", 1),
        };
        let _ = writeln!(
            s,
            "{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}",
            r.ordinate_type, len_exp, 0, 0, label, "m"
        );
        let _ = writeln!(
            s,
            "{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}",
            13, 0, 1, 0, "Force", "N"
        );
        let _ = writeln!(
            s,
            "{:>10}{:>5}{:>5}{:>5} {:<20} {:<20}",
            0, 0, 0, 0, "NONE", "NONE"
        );
        if even {
            for pair in r.values.chunks(2) {
                for v in pair {
                    s.push_str(&fortran_e(v.re, 20, 12));
                    s.push_str(&fortran_e(v.im, 20, 12));
                }
                s.push('\n');
            }
        } else {
            for (x, v) in r.abscissa.iter().zip(&r.values) {
                let _ = writeln!(
                    s,
                    "{}{}{}",
                    fortran_e(*x, 20, 12),
                    fortran_e(v.re, 20, 12),
                    fortran_e(v.im, 20, 12)
                );
            }
        }
        let _ = writeln!(s, "{:>6}", -1);
    }
    s
}

/// Write `records` as an ASCII universal file.
pub fn write_uff58(path: &Path, records: &[Uff58Record]) -> Result<()> {
    std::fs::write(path, to_uff58_string(records)).map_err(|source| FrfError::Io {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Frf {
        let f: Vec<f64> = (0..7).map(|k| 100.0 + 0.5 * k as f64).collect();
        let g = f
            .iter()
            .map(|&f| Complex64::new(1.0 / (1e7 - f * f), -1e-9 * f))
            .collect();
        Frf::new(f, g).unwrap()
    }

    #[test]
    fn ascii_round_trip_even_and_uneven() {
        let frf = sample();
        let p = Path::new("t.uff");
        let r = Uff58Record::receptance(&frf, "tip xx", (1, 1), (1, 1));
        let text = to_uff58_string(std::slice::from_ref(&r));
        let back = parse_uff58(text.as_bytes(), p).unwrap();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].response_node, 1);
        assert_eq!(back[0].reference_direction, 1);
        let g = back[0].to_frf(p).unwrap();
        assert_eq!(g.frequencies_hz(), frf.frequencies_hz());
        for (a, b) in g.receptance_m_per_n().iter().zip(frf.receptance_m_per_n()) {
            assert!((a - b).norm() <= 1e-12 * b.norm());
        }
        let mut uneven = r.clone();
        uneven.abscissa[3] += 0.1;
        let back = parse_uff58(to_uff58_string(&[uneven.clone()]).as_bytes(), p).unwrap();
        assert_eq!(back[0].abscissa, uneven.abscissa);
    }

    #[test]
    fn binary_58b_is_read() {
        // little-endian IEEE double complex, even spacing, accelerance
        let frf = sample();
        let r = Uff58Record::receptance(&frf, "b", (1, 2), (1, 2));
        let text = to_uff58_string(&[r]);
        let lines: Vec<&str> = text.lines().collect();
        let mut raw = Vec::new();
        for v in frf.receptance_m_per_n() {
            raw.extend_from_slice(&v.re.to_le_bytes());
            raw.extend_from_slice(&v.im.to_le_bytes());
        }
        let mut bytes = format!(
            "    -1\n    58b     1     2    11 {:>12}     0     0           0           0\n",
            raw.len()
        )
        .into_bytes();
        for l in &lines[2..13] {
            bytes.extend_from_slice(l.as_bytes());
            bytes.push(b'\n');
        }
        bytes.extend_from_slice(&raw);
        bytes.extend_from_slice(b"\n    -1\n");
        let back = parse_uff58(&bytes, Path::new("b.uff")).unwrap();
        assert_eq!(back[0].values, frf.receptance_m_per_n());
        assert_eq!(back[0].abscissa, frf.frequencies_hz());
    }

    #[test]
    fn wrong_counts_and_types_are_named() {
        let r = Uff58Record::receptance(&sample(), "x", (1, 1), (1, 1));
        let text = to_uff58_string(&[r]);
        let mut short = text.lines().collect::<Vec<_>>();
        short.remove(14);
        let e = parse_uff58(short.join("\n").as_bytes(), Path::new("s.uff"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("s.uff") && e.contains("announces 7 points"),
            "{e}"
        );
        let bad = text.replacen("         6         7", "         9         7", 1);
        let e = parse_uff58(bad.as_bytes(), Path::new("s.uff"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("ordinate data type 9"), "{e}");
    }
}
