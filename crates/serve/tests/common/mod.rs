//! A minimal HTTP/1.1 client over a TCP socket (what a browser sends, without a browser) and
//! the test files: a tap test written from a known model, and recordings whose truth is known
//! by construction. Shared by this crate's tests and the CLI's `serve` tests.
#![allow(dead_code, clippy::unwrap_used)]

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

/// A response: status and body.
pub struct Reply {
    pub status: u16,
    pub body: String,
}

impl Reply {
    /// The body as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(&self.body).unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.body))
    }

    /// The `error` message of a refused request.
    pub fn error(&self) -> String {
        self.json()["error"]
            .as_str()
            .unwrap_or_default()
            .to_string()
    }
}

/// Send one request with `headers` (Host is added) and read the whole response.
pub fn send(
    addr: SocketAddr,
    method: &str,
    path: &str,
    headers: &[(&str, &str)],
    body: &[u8],
) -> Reply {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(600))).unwrap();
    let mut head = format!(
        "{method} {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n",
        body.len()
    );
    if !headers.iter().any(|(k, _)| k.eq_ignore_ascii_case("host")) {
        head += &format!("Host: {addr}\r\n");
    }
    for (k, v) in headers {
        head += &format!("{k}: {v}\r\n");
    }
    head += "\r\n";
    s.write_all(head.as_bytes()).unwrap();
    // a refused upload may be answered before the whole body is read
    let _ = s.write_all(body);
    let mut raw = Vec::new();
    let _ = s.read_to_end(&mut raw);
    let text = String::from_utf8_lossy(&raw).into_owned();
    let (head, rest) = text
        .split_once("\r\n\r\n")
        .unwrap_or_else(|| panic!("no HTTP response: {text:.300}"));
    let status = head.split(' ').nth(1).and_then(|c| c.parse().ok()).unwrap();
    let chunked = head
        .to_ascii_lowercase()
        .contains("transfer-encoding: chunked");
    let body = if chunked { dechunk(rest) } else { rest.into() };
    Reply { status, body }
}

fn dechunk(mut rest: &str) -> String {
    let mut out = String::new();
    while let Some((size, after)) = rest.split_once("\r\n") {
        let n = usize::from_str_radix(size.trim(), 16).unwrap_or(0);
        if n == 0 {
            break;
        }
        out += &after[..n];
        rest = &after[n + 2..];
    }
    out
}

/// GET.
pub fn get(addr: SocketAddr, path: &str) -> Reply {
    send(addr, "GET", path, &[], &[])
}

/// POST JSON.
pub fn post_json(addr: SocketAddr, path: &str, value: &serde_json::Value) -> Reply {
    send(
        addr,
        "POST",
        path,
        &[("Content-Type", "application/json")],
        value.to_string().as_bytes(),
    )
}

/// POST a multipart form with text fields and one file.
pub fn post_form(
    addr: SocketAddr,
    path: &str,
    fields: &[(&str, &str)],
    file: Option<(&str, &[u8])>,
) -> Reply {
    let boundary = "----chatter-test-boundary-7d41";
    let mut body = Vec::new();
    for (k, v) in fields {
        body.extend_from_slice(
            format!("--{boundary}\r\nContent-Disposition: form-data; name=\"{k}\"\r\n\r\n{v}\r\n")
                .as_bytes(),
        );
    }
    if let Some((name, bytes)) = file {
        body.extend_from_slice(
            format!(
                "--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; \
                 filename=\"{}\"\r\nContent-Type: application/octet-stream\r\n\r\n",
                name.replace('\\', "\\\\").replace('"', "\\\"")
            )
            .as_bytes(),
        );
        body.extend_from_slice(bytes);
        body.extend_from_slice(b"\r\n");
    }
    body.extend_from_slice(format!("--{boundary}--\r\n").as_bytes());
    let content_type = format!("multipart/form-data; boundary={boundary}");
    send(
        addr,
        "POST",
        path,
        &[("Content-Type", &content_type)],
        &body,
    )
}

/// The setup form of seed 001's process (4 teeth, 20 % down milling, K_s 750, beta 68).
pub fn setup_form(name: &str) -> serde_json::Value {
    serde_json::json!({
        "name": name, "machine": "test mill", "tool": "19.05 mm end mill", "holder": "HSK",
        "teeth": 4, "radial_immersion": 0.2, "direction": "down", "tool_diameter_mm": 19.05,
        "ks_n_per_mm2": 750.0, "beta_deg": 68.0,
    })
}

/// The true mode of the tap test: 720 Hz, 2.5 %, 2.8e6 N/m (x).
pub const TAP_MODE: (f64, f64, f64) = (720.0, 0.025, 2.8e6);

/// The receptance of [`TAP_MODE`], 1 / (k (1 - r^2 + 2 i zeta r)) with r = f / f_n, at 1 Hz
/// steps from 300 to 1300 Hz, from the formula (not by the model code the server fits with).
pub fn tap_receptance() -> Vec<(f64, num_complex::Complex64)> {
    let (fn_hz, zeta, k) = TAP_MODE;
    (300..=1300)
        .map(|f| {
            let r = f as f64 / fn_hz;
            let g = 1.0 / (k * num_complex::Complex64::new(1.0 - r * r, 2.0 * zeta * r));
            (f as f64, g)
        })
        .collect()
}

/// [`tap_receptance`] as the CSV of `chatter frf`.
pub fn tap_test_csv() -> String {
    let mut out = String::from("frequency_hz,real_m_per_n,imag_m_per_n,magnitude_m_per_n\n");
    for (f, g) in tap_receptance() {
        out += &format!("{f},{:e},{:e},{:e}\n", g.re, g.im, g.norm());
    }
    out
}

/// [`tap_receptance`] as a UFF 58 file (the format's writer of `chatter-frf`).
pub fn tap_test_uff() -> String {
    let (f, g): (Vec<f64>, Vec<_>) = tap_receptance().into_iter().unzip();
    let frf = chatter_frf::Frf::new(f, g).unwrap();
    chatter_frf::uff::to_uff58_string(&[chatter_frf::uff::Uff58Record::receptance(
        &frf,
        "tap test x",
        (1, 1),
        (1, 1),
    )])
}

/// A mono 16-bit WAV of 4 s at 10 kHz: spindle harmonics of `speed_rpm` (4 teeth: the tooth
/// passing frequency's harmonics strongest) and white noise, plus, for chatter, a sine of
/// constant amplitude at `chatter_hz` (a limit cycle) twice as strong as the harmonics.
pub fn recording_wav(speed_rpm: f64, chatter_hz: Option<f64>) -> Vec<u8> {
    let fs = 10_000.0;
    let n = 40_000;
    let f0 = speed_rpm / 60.0;
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut noise = || {
        // xorshift, then the sum of 4 uniforms: a bell-shaped noise of unit-ish variance
        let mut s = 0.0;
        for _ in 0..4 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            s += (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        }
        s
    };
    let mut samples = Vec::with_capacity(n);
    for i in 0..n {
        let t = i as f64 / fs;
        let mut x = 0.0;
        for h in 1..=12 {
            let a = if h % 4 == 0 { 1.0 } else { 0.25 };
            x += a * (2.0 * std::f64::consts::PI * h as f64 * f0 * t).sin();
        }
        if let Some(fc) = chatter_hz {
            x += 2.0 * (2.0 * std::f64::consts::PI * fc * t).sin();
        }
        x += 0.3 * noise();
        samples.push(x);
    }
    let peak = samples.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut out = Vec::new();
    let data_bytes = (n * 2) as u32;
    out.extend_from_slice(b"RIFF");
    out.extend_from_slice(&(36 + data_bytes).to_le_bytes());
    out.extend_from_slice(b"WAVEfmt ");
    out.extend_from_slice(&16u32.to_le_bytes());
    out.extend_from_slice(&1u16.to_le_bytes());
    out.extend_from_slice(&1u16.to_le_bytes());
    out.extend_from_slice(&(fs as u32).to_le_bytes());
    out.extend_from_slice(&(fs as u32 * 2).to_le_bytes());
    out.extend_from_slice(&2u16.to_le_bytes());
    out.extend_from_slice(&16u16.to_le_bytes());
    out.extend_from_slice(b"data");
    out.extend_from_slice(&data_bytes.to_le_bytes());
    for v in samples {
        out.extend_from_slice(&((v / peak * 30000.0) as i16).to_le_bytes());
    }
    out
}
