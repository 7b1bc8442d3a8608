//! Chatter detection against records whose answer is known from elsewhere.
//!
//! 1. The time-domain simulator over lobe diagrams (milling: seed 001's example; turning: seed
//!    000's Table 1 model with spindle-harmonic forcing), at speeds across the lobes and depths
//!    from 0.5 to 1.5 times the limiting depth of the full-discretization method
//!    (`chatter_stability`), with 10 % measurement noise on the accelerations. Right labels are
//!    counted where |ln(b / b_lim)| > 0.1; the chatter frequency is compared with the
//!    simulator's own: the highest peak of a one-FFT periodogram of the noise-free `x` (or
//!    `feed`) channel over the record's second half, away from the spindle harmonics. Flip
//!    (period-doubling) chatter records are left out of those counts (the detector is told the
//!    spindle frequency only); in milling, every record, flip chatter included, is also labelled
//!    with the tooth count given (flip lines judged, `chatter_oma::detection` "Flip chatter").
//! 2. Records built here without the simulator: spindle harmonics, a self-excited sinusoid that
//!    grows into a limit cycle (or is absent), noise, and a mains comb (or none); the simulated
//!    records carry no mains hum, so no interference comb may be found in them.
//! 3. The real record `test255_accelY.csv` (labelled chatter by its authors), when the shared
//!    data folder is present.
#![allow(clippy::unwrap_used)]

use chatter_dynamics::ModalModel;
use chatter_dynamics::examples::{ahmadi_2022_turning, schmitz_2023_milling};
use chatter_dynamics::simulate::{SimulationSettings, simulate};
use chatter_oma::detection::{DetectionOptions, Verdict, detect};
use chatter_oma::interference::Interference;
use chatter_oma::signals::Signals;
use chatter_stability::boundary::{BoundaryOptions, limiting_depth};
use chatter_stability::monodromy::Discretization;
use chatter_stability::{MultiplierKind, StabilitySolver};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

const FS_HZ: f64 = 10_000.0;
const DURATION_S: f64 = 4.0;
const NOISE: f64 = 0.1;

struct Case {
    speed_rpm: f64,
    ratio: f64,
    verdict: Verdict,
    chatter_hz: Option<f64>,
    reference_hz: f64,
    line_to_forced_db: f64,
    line_to_rest_db: f64,
    line_to_floor_db: f64,
    resolution_hz: f64,
    variation: f64,
    peak_hz: f64,
    comb_hz: Option<f64>,
    /// Detection without the speed: the estimated fundamental and the verdict (None: no comb).
    unknown_speed: Option<(f64, Verdict, Option<f64>)>,
    /// The verdict with the tooth count given (flip chatter judged), milling only.
    with_teeth: Option<Verdict>,
}

/// Highest periodogram peak of the second half of `x`, at least 3 bins from every multiple of
/// `f0`.
fn reference_frequency(x: &[f64], fs: f64, f0: f64) -> f64 {
    let half = &x[x.len() / 2..];
    let n = half.len();
    let mut buf: Vec<Complex64> = half.iter().map(|v| Complex64::new(*v, 0.0)).collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let df = fs / n as f64;
    (3..n / 2)
        .filter(|&i| {
            let f = i as f64 * df;
            (f - (f / f0).round() * f0).abs() > 3.0 * df
        })
        .max_by(|a, b| buf[*a].norm().total_cmp(&buf[*b].norm()))
        .map_or(0.0, |i| i as f64 * df)
}

fn run_case(
    model: &ModalModel,
    speed_rpm: f64,
    b_lim: f64,
    ratio: f64,
    seed: u64,
    teeth: Option<usize>,
) -> Case {
    let mut settings = SimulationSettings::new(speed_rpm, ratio * b_lim, DURATION_S, FS_HZ, seed);
    settings.harmonic_force_n = 5.0;
    let sim = simulate(model, &settings).unwrap();
    let f0 = speed_rpm / 60.0;
    let reference_hz = reference_frequency(&sim.channels[0].data, FS_HZ, f0);
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed + 1000);
    let data: Vec<Vec<f64>> = sim.channels[..2]
        .iter()
        .map(|c| {
            let rms = (c.data.iter().map(|v| v * v).sum::<f64>() / c.data.len() as f64).sqrt();
            c.data
                .iter()
                .map(|v| {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    v + NOISE * rms * z
                })
                .collect()
        })
        .collect();
    let signals = Signals::new(vec!["a".into(), "b".into()], FS_HZ, data).unwrap();
    let d = detect(&signals, &DetectionOptions::new(f0)).unwrap();
    let with_teeth = teeth.map(|z| {
        let options = DetectionOptions {
            teeth: Some(z),
            ..DetectionOptions::new(f0)
        };
        detect(&signals, &options).unwrap().verdict
    });
    let unknown_speed = detect(&signals, &DetectionOptions::unknown_speed())
        .ok()
        .map(|u| (u.evidence.fundamental_hz, u.verdict, u.chatter_hz));
    Case {
        speed_rpm,
        ratio,
        verdict: d.verdict,
        chatter_hz: d.chatter_hz,
        reference_hz,
        line_to_forced_db: d.evidence.line_to_forced_db,
        line_to_rest_db: d.evidence.line_to_rest_db,
        line_to_floor_db: d.evidence.line_to_floor_db,
        resolution_hz: d.evidence.resolution_hz,
        variation: d.evidence.line_variation,
        peak_hz: d.evidence.peak_hz,
        comb_hz: d.evidence.interference.map(|c| c.fundamental_hz),
        unknown_speed,
        with_teeth,
    }
}

fn sweep(name: &str, model: &ModalModel, speeds_rpm: &[f64], teeth: Option<usize>) {
    let ratios = [0.5, 0.7, 0.85, 1.2, 1.35, 1.5];
    let solver = Discretization::full();
    let jobs: Vec<(f64, f64, f64, u64, bool)> = speeds_rpm
        .iter()
        .enumerate()
        .flat_map(|(i, &s)| {
            let b_lim = limiting_depth(&solver, model, s, &BoundaryOptions::default())
                .unwrap()
                .depth_m;
            ratios
                .iter()
                .enumerate()
                .map(|(j, &r)| {
                    // flip (period-doubling) chatter of an even-toothed cutter lies on spindle
                    // harmonics: out of scope of a detector told only the spindle frequency, in
                    // scope with the tooth count (labelled apart below)
                    let kind = solver
                        .dominant_multiplier(model, s, r * b_lim)
                        .unwrap()
                        .kind();
                    let flip = r > 1.0 && kind != MultiplierKind::Hopf;
                    if flip {
                        eprintln!("{name} {s} rpm {r} b_lim: {kind:?} chatter, left out");
                    }
                    (s, b_lim, r, (10 * i + j) as u64, flip)
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let all: Vec<(Case, bool)> = jobs
        .par_iter()
        .map(|&(s, b_lim, r, seed, flip)| (run_case(model, s, b_lim, r, seed, teeth), flip))
        .collect();
    if teeth.is_some() {
        // with the tooth count, every record (flip chatter included) is labelled
        let mut right = 0;
        for (c, flip) in &all {
            let expected = c.ratio > 1.0;
            let got = c.with_teeth == Some(Verdict::Chatter);
            right += usize::from(expected == got);
            eprintln!(
                "{name} {:6.0} rpm {:.2} b_lim{}, tooth count given: {:?}{}",
                c.speed_rpm,
                c.ratio,
                if *flip { " (flip)" } else { "" },
                c.with_teeth,
                if expected == got { "" } else { " WRONG" }
            );
        }
        eprintln!(
            "{name}, tooth count given: {right}/{} right, flip records included",
            all.len()
        );
        assert!(right as f64 >= 0.97 * all.len() as f64, "{name}: {right}");
    }
    let cases: Vec<Case> = all
        .into_iter()
        .filter(|(_, flip)| !flip)
        .map(|(c, _)| c)
        .collect();
    let (mut right, mut freq_ok, mut chatter_count) = (0, 0, 0);
    for c in &cases {
        let expected = if c.ratio < 1.0 {
            Verdict::Stable
        } else {
            Verdict::Chatter
        };
        let ok = c.verdict == expected;
        right += usize::from(ok);
        let f_ok = match (expected, c.chatter_hz) {
            (Verdict::Chatter, Some(f)) => {
                chatter_count += 1;
                let good =
                    (f - c.reference_hz).abs() <= (0.01 * c.reference_hz).max(c.resolution_hz);
                freq_ok += usize::from(good);
                good
            }
            _ => true,
        };
        eprintln!(
            "{name} {:6.0} rpm {:.2} b_lim: {:?}{} {:?} Hz (simulator {:.1} Hz) forced {:+.1} dB \
             rest {:+.1} dB floor {:+.1} dB cv {:.2} peak {:.1}{}",
            c.speed_rpm,
            c.ratio,
            c.verdict,
            if ok { "" } else { " WRONG" },
            c.chatter_hz.map(|f| (f * 10.0).round() / 10.0),
            c.reference_hz,
            c.line_to_forced_db,
            c.line_to_rest_db,
            c.line_to_floor_db,
            c.variation,
            c.peak_hz,
            if f_ok { "" } else { " FREQUENCY" }
        );
    }
    let accuracy = right as f64 / cases.len() as f64;
    eprintln!(
        "{name}: {right}/{} right ({:.1} %), chatter frequency right in {freq_ok}/{chatter_count}",
        cases.len(),
        100.0 * accuracy
    );
    assert!(accuracy >= 0.97, "{name}: {accuracy}");
    assert_eq!(freq_ok, chatter_count, "{name}");
    // the same records with the speed unknown: how often the fundamental estimated from the
    // harmonic comb is the spindle frequency (within 0.1 %) and the verdict the one given the
    // speed. Reported, not asserted: it fails here (14/30 turning, 18/34 milling; the milling
    // records' spindle harmonics are weak beside the tooth-passing comb, and the turning chatter
    // records' four forced harmonics do not stand out as lines), see the signals5 note
    let mut estimated = 0;
    let mut same = 0;
    for c in &cases {
        let f0 = c.speed_rpm / 60.0;
        match c.unknown_speed {
            Some((f, verdict, chatter_hz)) => {
                let right_f0 = (f / f0 - 1.0).abs() <= 1e-3;
                estimated += usize::from(right_f0);
                let agree = right_f0 && verdict == c.verdict && chatter_hz == c.chatter_hz;
                same += usize::from(agree);
                if !agree {
                    eprintln!(
                        "{name} {:6.0} rpm {:.2} b_lim, speed unknown: f0 {f:.3} Hz (true \
                         {f0:.3}), {verdict:?} at {chatter_hz:?} Hz",
                        c.speed_rpm, c.ratio
                    );
                }
            }
            None => eprintln!(
                "{name} {:6.0} rpm {:.2} b_lim, speed unknown: no comb",
                c.speed_rpm, c.ratio
            ),
        }
    }
    eprintln!(
        "{name}, speed unknown: fundamental right in {estimated}/{n}, same verdict and chatter \
         frequency in {same}/{n}",
        n = cases.len()
    );
    // the simulator adds no mains hum: any interference comb found is a false one
    let combs: Vec<(f64, f64, f64)> = cases
        .iter()
        .filter_map(|c| c.comb_hz.map(|f| (c.speed_rpm, c.ratio, f)))
        .collect();
    assert!(
        combs.is_empty(),
        "{name}: false interference combs {combs:?}"
    );
}

#[test]
fn simulated_milling_lobe_diagram() {
    sweep(
        "milling",
        &schmitz_2023_milling(),
        &[5000.0, 6000.0, 7000.0, 8000.0, 9000.0, 10_000.0],
        Some(4),
    );
}

#[test]
fn simulated_turning_lobe_diagram() {
    sweep(
        "turning",
        &ahmadi_2022_turning(),
        &[6500.0, 7000.0, 7500.0, 8000.0, 9000.0],
        None,
    );
}

/// Which multiples of an interference fundamental a built record carries.
#[derive(Debug, Clone, Copy)]
enum Comb {
    /// Multiples 1 to 40.
    All,
    /// Odd multiples 1 to 39 (the even ones are empty).
    Odd,
}

/// A record built here: harmonics of 80 Hz (forced), optionally a self-excited sinusoid at
/// `chatter_hz` growing from 1e-3 into a limit cycle of amplitude 0.5 (logistic growth, rate
/// 8 1/s), a lightly damped resonance at 1100 Hz driven by white noise (a Gaussian narrowband
/// process), optionally a mains comb (fundamental, multiples: amplitude 0.6 at the third
/// harmonic, 0.2 / sqrt(k) at the others, fixed phases), and 10 % white measurement noise; 4 s
/// at 10 kHz, two channels.
fn built_record(chatter_hz: Option<f64>, mains: Option<(f64, Comb)>, seed: u64) -> Signals {
    built(
        4.0,
        chatter_hz.map(|f| (f, 0.0, f64::INFINITY)),
        mains,
        seed,
    )
}

/// [`built_record`] over `duration_s`, its self-excited line (frequency, onset, end in s) growing
/// from its onset and cut off at its end.
fn built(
    duration_s: f64,
    line: Option<(f64, f64, f64)>,
    mains: Option<(f64, Comb)>,
    seed: u64,
) -> Signals {
    let fs = 10_000.0;
    let n = (duration_s * fs) as usize;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    // resonance: exact discretization of x'' + 2 z w x' + w^2 x = noise, by its AR(2) form
    let (w, z) = (2.0 * std::f64::consts::PI * 1100.0, 0.01);
    let r = (-z * w / fs).exp();
    let wd = w * (1.0 - z * z).sqrt() / fs;
    let (a1, a2) = (2.0 * r * wd.cos(), -r * r);
    let (mut y1, mut y2) = (0.0, 0.0);
    let mut channels = vec![Vec::with_capacity(n), Vec::with_capacity(n)];
    for k in 0..n {
        let t = k as f64 / fs;
        let e: f64 = StandardNormal.sample(&mut rng);
        let y = a1 * y1 + a2 * y2 + 0.02 * e;
        (y2, y1) = (y1, y);
        let forced: f64 = (1..=12)
            .map(|h| {
                (2.0 * std::f64::consts::PI * 80.0 * h as f64 * t + 0.3 * h as f64).cos() / h as f64
            })
            .sum();
        let selfexcited = line.map_or(0.0, |(f, on, off)| {
            if t < on || t >= off {
                return 0.0;
            }
            let amplitude = 0.5 / (1.0 + (0.5 / 1e-3 - 1.0) * (-8.0 * (t - on)).exp());
            amplitude * (2.0 * std::f64::consts::PI * f * t).sin()
        });
        let hum: f64 = mains.map_or(0.0, |(f, comb)| {
            (1..=40usize)
                .filter(|k| matches!(comb, Comb::All) || k % 2 == 1)
                .map(|k| {
                    let amplitude = if k == 3 { 0.6 } else { 0.2 / (k as f64).sqrt() };
                    let phase = 0.7 * (k * k) as f64;
                    amplitude * (2.0 * std::f64::consts::PI * f * k as f64 * t + phase).cos()
                })
                .sum()
        });
        let clean = forced + y + selfexcited + hum;
        for (c, ch) in channels.iter_mut().enumerate() {
            let noise: f64 = StandardNormal.sample(&mut rng);
            ch.push((1.0 + 0.3 * c as f64) * clean + 0.1 * noise);
        }
    }
    Signals::new(vec!["a".into(), "b".into()], fs, channels).unwrap()
}

#[test]
fn built_records_with_and_without_a_limit_cycle() {
    for seed in 0..5 {
        let options = DetectionOptions::new(80.0);
        let with = detect(&built_record(Some(1234.5), None, seed), &options).unwrap();
        assert_eq!(with.verdict, Verdict::Chatter, "{:?}", with.evidence);
        let f = with.chatter_hz.unwrap();
        assert!(
            (f - 1234.5).abs() <= (0.01 * 1234.5f64).min(with.evidence.resolution_hz),
            "{f}"
        );
        let without = detect(&built_record(None, None, seed), &options).unwrap();
        assert_eq!(without.verdict, Verdict::Stable, "{:?}", without.evidence);
        assert!(without.chatter_hz.is_none());
        assert!(with.evidence.interference.is_none() && without.evidence.interference.is_none());
        eprintln!(
            "seed {seed}: chatter at {f:.2} Hz, V {:.2}; without: V {:.2} at {:.1} Hz",
            with.evidence.line_variation, without.evidence.line_variation, without.evidence.peak_hz
        );
    }
}

/// A limit cycle far above the forced harmonics, 0.4 % below a harmonic of the nominal speed's
/// fundamental (15 x 80 Hz x 0.996 = 1195.2 Hz): within the default 0.5 % speed tolerance a
/// fundamental of 79.68 Hz puts its 15th multiple on the line, and a refinement over every
/// harmonic at once took it and read the line as synchronous (a time-domain lathe at 918 rpm
/// chattering at 730.6 Hz with 46 um RMS was called stable). Refined on the first ten
/// harmonics first, the line is chatter at its frequency (the old refinement gave 79.87 Hz and
/// `stable` on seed 0).
#[test]
fn a_line_near_a_harmonic_does_not_pull_the_fundamental() {
    for seed in 0..3 {
        let d = detect(
            &built_record(Some(1195.2), None, seed),
            &DetectionOptions::new(80.0),
        )
        .unwrap();
        assert_eq!(d.verdict, Verdict::Chatter, "{:?}", d.evidence);
        eprintln!(
            "seed {seed}: fundamental {:.3} Hz",
            d.evidence.fundamental_hz
        );
        assert!((d.chatter_hz.unwrap() - 1195.2).abs() <= d.evidence.resolution_hz);
    }
}

/// Mains hum: the built records above with a 50.02 Hz or 59.97 Hz comb whose third harmonic is
/// the strongest line besides the forced ones. A mains line has a constant amplitude, so left in
/// it would be called chatter in a stable record (checked with the search off) and would hide the
/// self-excited line in a chattering one. Searched for (the default), the comb is found within
/// 0.01 Hz, and the verdicts and the chatter frequency are those of the records without hum.
/// Controls: a chatter line 0.8 Hz from 26 x 50 Hz in a record without hum (no comb found, the
/// line is chatter) and in a record whose comb has only odd multiples (the comb is found, the line
/// near its empty 26th multiple is not a member and is chatter).
#[test]
fn mains_combs_are_found_and_left_out() {
    let options = DetectionOptions::new(80.0);
    let mut off = options.clone();
    off.interference = Interference::Off;
    let close = |f: f64, want: f64, d: &chatter_oma::detection::Detection| {
        (f - want).abs() <= (0.01 * want).min(d.evidence.resolution_hz)
    };
    for seed in 0..3 {
        for mains_hz in [50.02, 59.97] {
            let stable = built_record(None, Some((mains_hz, Comb::All)), seed);
            let d = detect(&stable, &options).unwrap();
            let comb = d.evidence.interference.clone().unwrap();
            eprintln!(
                "seed {seed}, {mains_hz} Hz hum, stable: {:?}, V {:.2} at {:.1} Hz, comb {:.4} Hz \
                 ({} lines)",
                d.verdict,
                d.evidence.line_variation,
                d.evidence.peak_hz,
                comb.fundamental_hz,
                comb.lines_hz.len()
            );
            assert!((comb.fundamental_hz - mains_hz).abs() < 0.01, "{comb:?}");
            assert_eq!(d.verdict, Verdict::Stable, "{:?}", d.evidence);
            let blind = detect(&stable, &off).unwrap();
            assert_eq!(blind.verdict, Verdict::Chatter, "{:?}", blind.evidence);
            let chatter = built_record(Some(1234.5), Some((mains_hz, Comb::All)), seed);
            let d = detect(&chatter, &options).unwrap();
            assert_eq!(d.verdict, Verdict::Chatter, "{:?}", d.evidence);
            assert!(close(d.chatter_hz.unwrap(), 1234.5, &d), "{:?}", d.evidence);
            let comb = d.evidence.interference.unwrap();
            assert!((comb.fundamental_hz - mains_hz).abs() < 0.01, "{comb:?}");
        }
        let lone = built_record(Some(1300.8), None, seed);
        let d = detect(&lone, &options).unwrap();
        assert!(d.evidence.interference.is_none(), "{:?}", d.evidence);
        assert_eq!(d.verdict, Verdict::Chatter, "{:?}", d.evidence);
        assert!(close(d.chatter_hz.unwrap(), 1300.8, &d), "{:?}", d.evidence);
        let odd = built_record(Some(1300.8), Some((50.0, Comb::Odd)), seed);
        let d = detect(&odd, &options).unwrap();
        let comb = d.evidence.interference.clone().unwrap();
        eprintln!(
            "seed {seed}, odd comb + 1300.8 Hz: {:?} at {:?} Hz, comb {:.4} Hz ({} lines)",
            d.verdict,
            d.chatter_hz,
            comb.fundamental_hz,
            comb.lines_hz.len()
        );
        assert!((comb.fundamental_hz - 50.0).abs() < 0.01, "{comb:?}");
        assert!(
            comb.lines_hz.iter().all(|f| (f - 1300.0).abs() > 5.0),
            "{comb:?}"
        );
        assert_eq!(d.verdict, Verdict::Chatter, "{:?}", d.evidence);
        assert!(close(d.chatter_hz.unwrap(), 1300.8, &d), "{:?}", d.evidence);
    }
}

/// Chatter in part of a record (window-by-window judgement): 20 s built records (as above) whose
/// self-excited line is present only from 1 to 10 s or from 12 to 20 s (grown as above from
/// its onset, cut off at its end). The whole-record criterion, which judges the second half,
/// calls the early episode stable; the windows (3.28 s) find both at their frequency, in a span
/// within a window of the episode. The same records without the line stay stable window by
/// window. (A window holding the onset or the end has V about 1 here, so an episode is found
/// when two neighbouring windows fit in its steady part: at least 2 windows long.)
#[test]
fn chatter_in_part_of_a_record_is_found_by_the_windows() {
    let options = DetectionOptions::new(80.0);
    for seed in 0..3 {
        let stable = built(20.0, None, None, seed);
        let d = detect(&stable, &options).unwrap();
        let w = d.evidence.windows.clone().unwrap();
        eprintln!(
            "seed {seed}, no episode: {:?}, windows margin {:?}, contrast {:.1} dB, {} windows \
             of {:.2} s",
            d.verdict,
            w.margin,
            w.contrast_db,
            w.windows.len(),
            w.window_s
        );
        assert_eq!(d.verdict, Verdict::Stable, "{:?}", d.evidence);
        assert!(w.chatter.is_none(), "{w:?}");
        for (on, off) in [(1.0, 10.0), (12.0, 20.0)] {
            let d = detect(&built(20.0, Some((1234.5, on, off)), None, seed), &options).unwrap();
            let w = d.evidence.windows.clone().unwrap();
            for j in &w.windows {
                eprintln!(
                    "  window {:5.2} s: line {:7.1} Hz, {:5.1} dB, {:+5.1} dB over the rest, V \
                     {:?}, margin {:?}, reference {}",
                    j.start_s,
                    j.line_hz,
                    j.line_to_floor_db,
                    j.line_to_rest_db,
                    j.line_variation,
                    j.margin,
                    j.reference
                );
            }
            let span = w.chatter.clone().unwrap();
            eprintln!(
                "seed {seed}, episode {on}-{off} s: {:?} at {:?} Hz (whole record: V {:.2}, margin {:+.2}); windows: {:.1}-{:.1} s, V {:.2}, margin {:?}",
                d.verdict,
                d.chatter_hz,
                d.evidence.line_variation,
                d.evidence.margin,
                span.start_s,
                span.end_s,
                span.line_variation,
                w.margin
            );
            assert_eq!(d.verdict, Verdict::Chatter);
            assert!((d.chatter_hz.unwrap() - 1234.5).abs() <= d.evidence.resolution_hz);
            assert!(
                span.start_s <= on + w.window_s && span.end_s >= off - w.window_s,
                "{span:?}"
            );
            assert!(span.end_s - span.start_s >= w.min_duration_s, "{span:?}");
            if off <= 10.0 {
                // the second half holds no chatter: only the windows find it
                assert!(d.evidence.margin < 0.0, "{:?}", d.evidence);
            }
        }
    }
}

/// The speed unknown (`DetectionOptions::unknown_speed`): on the built records, with and without
/// the self-excited line and a 50.02 Hz mains comb, the fundamental estimated from the harmonic
/// comb is the 80 Hz the records were built with (within 0.1 %), the mains comb is still found,
/// and the verdicts are those of the records (the same as with the speed given). A record of
/// noise has no comb: a clear error.
#[test]
fn unknown_speed_is_estimated_from_the_harmonic_comb() {
    let options = DetectionOptions::unknown_speed();
    for seed in 0..3 {
        for mains in [None, Some((50.02, Comb::All))] {
            for chatter_hz in [None, Some(1234.5)] {
                let d = detect(&built_record(chatter_hz, mains, seed), &options).unwrap();
                let e = &d.evidence;
                eprintln!(
                    "seed {seed}, mains {mains:?}, chatter {chatter_hz:?}: f0 {:.4} Hz, {:?} \
                     at {:?} Hz, comb {:?}",
                    e.fundamental_hz,
                    d.verdict,
                    d.chatter_hz,
                    e.interference.as_ref().map(|c| c.fundamental_hz)
                );
                assert!((e.fundamental_hz / 80.0 - 1.0).abs() < 1e-3, "{e:?}");
                let comb = e.interference.as_ref().map(|c| c.fundamental_hz);
                assert_eq!(comb.is_some(), mains.is_some(), "{e:?}");
                assert!(comb.is_none_or(|f| (f - 50.02).abs() < 0.01), "{e:?}");
                match chatter_hz {
                    Some(f) => {
                        assert_eq!(d.verdict, Verdict::Chatter, "{e:?}");
                        assert!((d.chatter_hz.unwrap() - f).abs() <= e.resolution_hz);
                    }
                    None => assert_eq!(d.verdict, Verdict::Stable, "{e:?}"),
                }
            }
        }
    }
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let x: Vec<f64> = (0..40_000)
        .map(|_| StandardNormal.sample(&mut rng))
        .collect();
    let s = Signals::new(vec!["a".into()], 10_000.0, vec![x]).unwrap();
    let e = detect(&s, &options).unwrap_err().to_string();
    assert!(e.contains("no harmonic comb"), "{e}");
}

/// Out of scope and bad input: pure noise is never chatter; a fundamental above the Nyquist
/// frequency, or an unknown tachometer channel, is an error naming the field.
#[test]
fn noise_is_stable_and_bad_options_are_errors() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let x: Vec<f64> = (0..40_000)
        .map(|_| StandardNormal.sample(&mut rng))
        .collect();
    let s = Signals::new(vec!["a".into()], 10_000.0, vec![x]).unwrap();
    let d = detect(&s, &DetectionOptions::new(80.0)).unwrap();
    assert_eq!(d.verdict, Verdict::Stable, "{:?}", d.evidence);
    let e = detect(&s, &DetectionOptions::new(6000.0))
        .unwrap_err()
        .to_string();
    assert!(e.contains("fundamental_hz"), "{e}");
    let mut o = DetectionOptions::new(80.0);
    o.once_per_rev_channel = Some("tach".into());
    let e = detect(&s, &o).unwrap_err().to_string();
    assert!(e.contains("once_per_rev_channel"), "{e}");
}

/// The real record of a slot cut at 5000 rpm with a four-flute cutter, labelled chatter by its
/// authors (`shared/data/real/milling_chatter_record`, MIT licence): detected as chatter, at a
/// frequency that is neither a spindle harmonic nor a mains (50 Hz) harmonic (684 Hz). Its
/// strongest non-synchronous line is 150 Hz, the third harmonic of a 50 Hz mains comb (lines at
/// most multiples from 50 to 4600 Hz), whose share of the power varies with the chatter bursts (V 0.56): with
/// the search off the verdict is stable. The default search finds the comb (fundamental within
/// 0.05 Hz of 50 Hz, independent check: its lines are the multiples of 50 Hz to within 0.5 Hz);
/// giving 50 Hz as a known fundamental gives the same verdict.
#[test]
fn real_record_test255_is_chatter() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/data/real/milling_chatter_record/test255_accelY.csv"
    );
    if !std::path::Path::new(path).exists() {
        eprintln!("skipped: {path} is absent");
        return;
    }
    let s = Signals::from_csv(std::path::Path::new(path), 10_000.0).unwrap();
    let off = |f: f64, base: f64| (f - (f / base).round() * base).abs();
    let mut options = DetectionOptions::new(5000.0 / 60.0);
    let d = detect(&s, &options).unwrap();
    let comb = d.evidence.interference.clone().unwrap();
    eprintln!(
        "test255: {:?} at {:?} Hz, V {:.2}, comb {:.4} Hz with {} lines ({} of the first 12)",
        d.verdict,
        d.chatter_hz,
        d.evidence.line_variation,
        comb.fundamental_hz,
        comb.lines_hz.len(),
        comb.low_members
    );
    assert!((comb.fundamental_hz - 50.0).abs() < 0.05, "{comb:?}");
    assert!(
        comb.lines_hz.iter().all(|f| off(*f, 50.0) < 0.5),
        "{comb:?}"
    );
    assert_eq!(d.verdict, Verdict::Chatter);
    let f = d.chatter_hz.unwrap();
    assert!(off(f, 5000.0 / 60.0) > 2.0 && off(f, 50.0) > 2.0, "{f}");
    options.interference = Interference::Known(vec![50.0]);
    let known = detect(&s, &options).unwrap();
    assert_eq!(known.verdict, Verdict::Chatter);
    assert!(known.evidence.interference.is_none());
    assert!(
        (known.chatter_hz.unwrap() - f).abs() < 0.5,
        "{:?}",
        known.chatter_hz
    );
    options.interference = Interference::Off;
    let blind = detect(&s, &options).unwrap();
    assert_eq!(blind.verdict, Verdict::Stable, "{:?}", blind.evidence);
}

/// The two MP3 sound clips of the real-data folder (44.1 kHz stereo, 63.2 s and 9.3 s; labelled
/// chatter and no chatter, cutting conditions not recorded) decode (symphonia, MP3 feature) and
/// are judged with the speed unknown, by the criterion validated above on the built and
/// simulated records, nothing tuned to them.
/// - `metalcutting_nochatter8058.mp3`: the fundamental is estimated at 91.6 Hz (5496 rpm);
///   independent check (a separate Welch spectrum, scipy): its strongest lines 91.5, 366.7,
///   732.8, 1007.4 and 1099.5 Hz are the multiples 1, 4, 8, 11, 12 of 91.6 Hz within 0.3 Hz (a
///   four-flute cutter's tooth passing at 366.7 Hz). Verdict stable, as labelled (whole record:
///   V 0.318, margin -0.018).
///   Window by window (5.94 s windows) it stays stable: its line 739.7 Hz has V 0.54 and
///   0.32 in its two windows.
/// - `combined_chatter6567.mp3`: the cut lasts from about 5 to 18 s of 63 s (short-time
///   spectra, scipy: band power 8-10 dB over the rest of the clip, whose strongest lines 2331.0,
///   869.4, 1771.1 and 215.3 Hz are the same, at the same levels, before and after the cut).
///   Judged whole it is stable (its second half, 31-63 s, is that background). Window by
///   window, before the reference stretch (module docs) was built, it was labelled chatter at
///   2329.9 Hz, a stationary background tone (V 0.09-0.17 from 17.8 s to the end) and not a
///   spindle or tooth harmonic (the cut's comb is 215.3 Hz: 2329.9 / 215.3 = 10.82). Now: the
///   windows before and after the cut are its reference stretch, not judged; the cut's windows
///   carry the 1067-1077 Hz line (V 2.35, 1.32, 0.67, 0.62, 1.92: no two neighbouring limit
///   cycles) at +2.0, +3.9 and +1.0 dB over the rest of the band from 8.9 s: chatter by
///   dominance at 1067.6 Hz from 8.9 to 20.8 s, asserted within 1062-1072 Hz (scipy's
///   short-time spectra put the line at 1076.7, 1068.6, 1065.9 and 1068.6 Hz in 3 s blocks from
///   6 to 18 s, with sidebands 215.3 Hz away; the cut's comb 215.3, 430.7, 646.0, 861.3 Hz puts
///   its 5th multiple at 1076.5 Hz, near the onset's line, so the range excludes it), and the
///   background tone is no longer chatter (every window from 18 s is reference).
#[test]
fn real_mp3_clips_with_the_speed_unknown() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/data/real/milling_chatter_record/"
    );
    for (file, seconds) in [
        ("combined_chatter6567.mp3", 63.2),
        ("metalcutting_nochatter8058.mp3", 9.3),
    ] {
        let path = std::path::PathBuf::from(dir).join(file);
        if !path.exists() {
            eprintln!("skipped: {} is absent", path.display());
            continue;
        }
        let s = Signals::from_mp3(&path).unwrap();
        assert_eq!(s.sample_rate_hz, 44_100.0);
        assert_eq!(s.data.len(), 2);
        let duration = s.data[0].len() as f64 / s.sample_rate_hz;
        assert!((duration - seconds).abs() < 0.1, "{file}: {duration} s");
        let d = detect(&s, &DetectionOptions::unknown_speed()).unwrap();
        let e = &d.evidence;
        eprintln!(
            "{file}: f0 {:.3} Hz ({:.0} rpm), {:?} at {:?} Hz, line {:.1} Hz, V {:.3}, margin \
             {:+.3}, comb {:?}",
            e.fundamental_hz,
            60.0 * e.fundamental_hz,
            d.verdict,
            d.chatter_hz,
            e.peak_hz,
            e.line_variation,
            e.margin,
            e.interference.as_ref().map(|c| c.fundamental_hz)
        );
        if let Some(w) = &e.windows {
            for j in &w.windows {
                eprintln!(
                    "  window {:5.1} s: line {:7.1} Hz, {:5.1} dB over floor, {:+5.1} dB over \
                     the rest, V {:?}, margin {:?}, reference {}, dominant {}",
                    j.start_s,
                    j.line_hz,
                    j.line_to_floor_db,
                    j.line_to_rest_db,
                    j.line_variation,
                    j.margin,
                    j.reference,
                    j.dominant
                );
            }
            eprintln!(
                "  windows of {:.2} s, at least {:.2} s, contrast {:.1} dB: margin {:?}, chatter \
                 {:?}",
                w.window_s, w.min_duration_s, w.contrast_db, w.margin, w.chatter
            );
        }
        if file.contains("combined") {
            let w = e.windows.as_ref().unwrap();
            assert!(w.reference_stretch, "{w:?}");
            assert_eq!(d.verdict, Verdict::Chatter, "{e:?}");
            let f = d.chatter_hz.unwrap();
            // the chatter of the middle of the cut, not the 5th multiple of the cut's 215.3 Hz
            // comb (1076.5 Hz), which the onset windows' line lies near
            assert!((1062.0..=1072.0).contains(&f), "chatter at {f} Hz");
            let span = w.chatter.as_ref().unwrap();
            assert!(
                span.by_dominance && span.start_s >= 0.0 && span.end_s <= 24.0,
                "{span:?}"
            );
            assert!(
                w.windows
                    .iter()
                    .filter(|j| j.start_s > 18.0)
                    .all(|j| j.reference),
                "{w:?}"
            );
        }
        if file.contains("nochatter") {
            assert!((e.fundamental_hz - 91.6).abs() < 0.1, "{e:?}");
            assert_eq!(d.verdict, Verdict::Stable, "{e:?}");
            assert!(
                e.windows
                    .as_ref()
                    .is_some_and(|w| w.chatter.is_none() && !w.reference_stretch),
                "{e:?}"
            );
        }
    }
}
