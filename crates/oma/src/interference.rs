//! Interference combs: narrow lines at the multiples of a fundamental that is not the spindle's,
//! such as the mains frequency (50 or 60 Hz) and its harmonics, which an accelerometer cable or a
//! microphone picks up. Such a line is stationary and deterministic, as a limit cycle is, so
//! chatter detection must leave it out like a forced line; what tells it from chatter is that it
//! belongs to a comb.
//!
//! # Criterion
//! On a density with bins df apart (the Welch spectrum of [`crate::detection`]):
//! 1. **Lines**: local maxima of the density standing at least [`LINE_RATIO`] times above the
//!    median of the bins 3 to [`NEIGHBOUR_BINS`] bins away on either side (a line is one Hann
//!    main lobe, at most 2 bins from its centre; a structural resonance of damping zeta is about
//!    2 zeta f / df bins wide and does not pass), whose frequency, refined by a parabola through
//!    the logarithms of the three densities around the maximum, is not forced
//!    (not within the synchronous band of a spindle harmonic).
//! 2. **Members**: a line is a member of the comb of fundamental f_m when it lies within
//!    [`MEMBER_TOLERANCE_BINS`] df of a multiple k f_m. Candidates f_m lie on a grid over the
//!    search range (default [`MAINS_RANGE_HZ`]) fine enough to move the [`LOW_HARMONICS`]-th
//!    multiple by a tenth of a bin; the candidate with the most members among its first
//!    [`LOW_HARMONICS`] multiples wins (ties: the smallest sum of squared offsets), then f_m is
//!    refined by least squares through the origin over all its members (f_m = sum k f_k / sum
//!    k^2), twice.
//! 3. **Comb**: found when at least [`MIN_LOW_MEMBERS`] of the first [`LOW_HARMONICS`]
//!    multiples are members, and
//!    - it is not part of a finer comb: for no j = 2 to [`MAX_FINER_DIVISOR`] are there lines
//!      at [`MIN_LOW_MEMBERS`] or more of the multiples k f_m / j, k <= 12 j, with k not a
//!      multiple of j (within the same tolerance): the evidence a comb needs, between its
//!      multiples. Mains hum has nothing between its multiples; a record with a
//!      motion periodic over several revolutions has lines at all multiples of f_0 / q, and every
//!      comb in 45-65 Hz that is a multiple of f_0 / q is a sub-comb of it (a simulated chatter
//!      cut at 7000 rpm, its lines on the multiples of f_0 / 7 = 16.7 Hz, showed a 70-line
//!      "comb" at 50 Hz = 3 f_0 / 7 before this rule);
//!    - the harmonic numbers of its members among the first 12 multiples have no common
//!      divisor j > 1 (else they are the comb of j f_m: a spindle comb at 100 Hz has members at
//!      the even multiples of 50 Hz);
//!    - the members are not all on the multiples of f_0 / q for q = 2, 3, 4 (that comb is the
//!      spindle's own: period-doubling or period-q chatter, whose in-between multiples are
//!      spindle harmonics and hence not among the lines).
//!
//! Only the members are left out of the chatter search, each over the same +-2.5 df band as a
//! forced harmonic; a line near an empty multiple of f_m stays (a chatter line that happens to
//! sit near a mains multiple is not removed unless it is within [`MEMBER_TOLERANCE_BINS`] bins of
//! it, where no spectrum of this resolution can tell them apart).
//!
//! Why not constant amplitude and phase: on the real record `test255_accelY.csv` the 50 Hz comb
//! members drift (the phase coherence |sum_s X_s| / sum_s |X_s| of most members over 18 segments is
//! 0.3-0.8, only the 150 Hz line reaches 0.999), while its intermittent chatter line has 0.94: a
//! limit cycle is at least as phase-stable as mains hum, so stationarity cannot separate them,
//! while belonging to a comb of 52 members (10 of its first 12 multiples) does.
//!
//! False combs: a multiple of a candidate f_m is hit by chance when one of the L_12 lines below
//! 12 f_m falls within 0.4 df of it, with probability p about L_12 x 0.8 df / (12 f_m) (0.02 for
//! 15 lines at df = 1.2 Hz, f_m = 50 Hz); 4 of the first 12 multiples by chance then has
//! probability about C(12, 4) p^4 = 8e-5 per independent candidate (about 20 Hz / (0.8 df / 12)
//! = 250 of them in 45-65 Hz). Validated: no comb found in any of the 64 simulated lobe-diagram
//! records of `tests/oma_detection.rs` (spindle harmonics, chatter and its sidebands, no hum).

use crate::spectrum::refine_peak_hz;
use serde::{Deserialize, Serialize};

/// Default search range of an interference fundamental (Hz): the mains frequencies 50 and 60 Hz
/// with room for the 45-65 Hz of generator-fed or off-nominal supplies.
pub const MAINS_RANGE_HZ: (f64, f64) = (45.0, 65.0);
/// A line stands this many times (10 dB) above the median of its neighbouring bins.
pub const LINE_RATIO: f64 = 10.0;
/// Neighbouring bins on each side whose median is a line's background (from bin 3 on).
pub const NEIGHBOUR_BINS: usize = 18;
/// Largest distance of a member line's refined frequency from its multiple k f_m, in bins.
pub const MEMBER_TOLERANCE_BINS: f64 = 0.4;
/// Multiples of f_m (1 to this) that must hold most of the evidence: interference combs are
/// strongest at their low harmonics.
pub const LOW_HARMONICS: usize = 12;
/// Members needed among the first [`LOW_HARMONICS`] multiples.
pub const MIN_LOW_MEMBERS: usize = 4;
/// Largest j for which a comb is checked for being part of the finer comb f_m / j.
pub const MAX_FINER_DIVISOR: usize = 8;

/// Where interference fundamentals come from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Interference {
    /// Search a comb whose fundamental lies in `min_hz` to `max_hz` (see the
    /// [module documentation](self)); only its member lines are left out.
    Search {
        /// Lowest fundamental (Hz).
        min_hz: f64,
        /// Highest fundamental (Hz).
        max_hz: f64,
    },
    /// Given fundamentals (Hz): every multiple of each is left out, line or not.
    Known(Vec<f64>),
    /// No interference.
    Off,
}

impl Default for Interference {
    /// A search over [`MAINS_RANGE_HZ`].
    fn default() -> Self {
        Self::Search {
            min_hz: MAINS_RANGE_HZ.0,
            max_hz: MAINS_RANGE_HZ.1,
        }
    }
}

/// An interference comb found in a spectrum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InterferenceComb {
    /// Fundamental f_m (Hz), refined over the members.
    pub fundamental_hz: f64,
    /// Refined frequencies of the member lines (Hz), ascending.
    pub lines_hz: Vec<f64>,
    /// Members among the first [`LOW_HARMONICS`] multiples.
    pub low_members: usize,
}

/// The lines of a density `psd` (bins `df` apart) within bins `first..=last`, as refined
/// frequencies (Hz), leaving out those for which `forced(frequency_hz)` holds.
pub fn spectral_lines(
    psd: &[f64],
    df: f64,
    first: usize,
    last: usize,
    forced: impl Fn(f64) -> bool,
) -> Vec<f64> {
    let last = last.min(psd.len().saturating_sub(2));
    let mut background = Vec::with_capacity(2 * NEIGHBOUR_BINS);
    (first.max(1)..=last)
        .filter(|&i| psd[i] > psd[i - 1] && psd[i] >= psd[i + 1])
        .filter(|&i| {
            background.clear();
            background.extend(
                (3..=NEIGHBOUR_BINS)
                    .flat_map(|m| [i.checked_sub(m), Some(i + m)])
                    .flatten()
                    .filter(|&j| j > 0 && j < psd.len())
                    .map(|j| psd[j]),
            );
            if background.is_empty() {
                return false;
            }
            let mid = background.len() / 2;
            let median = *background.select_nth_unstable_by(mid, f64::total_cmp).1;
            psd[i] >= LINE_RATIO * median
        })
        .map(|i| refine_peak_hz(psd, i, df))
        .filter(|f| !forced(*f))
        .collect()
}

/// Members of the comb of fundamental `f_m` among `lines_hz`: (harmonic number, frequency).
fn members(lines_hz: &[f64], f_m: f64, tolerance_hz: f64) -> Vec<(usize, f64)> {
    lines_hz
        .iter()
        .filter_map(|&f| {
            let k = (f / f_m).round();
            (k >= 1.0 && (f - k * f_m).abs() <= tolerance_hz).then_some((k as usize, f))
        })
        .collect()
}

/// Greatest common divisor (Euclid); gcd(0, n) = n.
fn greatest_common_divisor(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        greatest_common_divisor(b, a % b)
    }
}

/// Least-squares fundamental through the origin of harmonic numbers and frequencies.
fn least_squares_fundamental(members: &[(usize, f64)]) -> f64 {
    let (num, den) = members.iter().fold((0.0, 0.0), |(n, d), &(k, f)| {
        (n + k as f64 * f, d + (k * k) as f64)
    });
    num / den
}

/// Search `lines_hz` (refined line frequencies, from [`spectral_lines`], bins `df` apart) for an
/// interference comb with a fundamental in `min_hz..=max_hz` (see the
/// [module documentation](self#criterion)); `spindle_hz`, when known, is the fundamental whose
/// subharmonic combs (f_0 / 2, f_0 / 3, f_0 / 4) are not interference.
pub fn find_comb(
    lines_hz: &[f64],
    df: f64,
    range_hz: (f64, f64),
    spindle_hz: Option<f64>,
) -> Option<InterferenceComb> {
    let comb = best_comb(lines_hz, df, range_hz)?;
    if finer_divisor(lines_hz, df, &comb).is_some() || common_divisor(&comb) != 1 {
        return None;
    }
    let tolerance = MEMBER_TOLERANCE_BINS * df;
    let subharmonic_family = spindle_hz.is_some_and(|f0| {
        (2..=4).any(|q| {
            let base = f0 / q as f64;
            comb.lines_hz
                .iter()
                .all(|f| (f - (f / base).round() * base).abs() <= tolerance)
        })
    });
    (!subharmonic_family).then_some(comb)
}

/// The fundamental of the harmonic comb of a record whose spindle speed is unknown: the comb
/// with the most members among its first [`LOW_HARMONICS`] multiples for a fundamental in
/// `range_hz` (steps 1-2 of the [criterion](self#criterion), with no line left out beforehand),
/// then made the comb of its true fundamental by the same two rules as an interference comb:
/// multiplied by the common divisor of its members' harmonic numbers (a comb found at f_0 / 3
/// has members only at multiples of 3), then divided by the largest j <= [`MAX_FINER_DIVISOR`]
/// with lines at [`MIN_LOW_MEMBERS`] of the low multiples of f / j between its own (a milling
/// record's tooth-passing comb, with the spindle harmonics between its multiples), as long as it
/// stays in the range. Each step refines the comb by least squares over its members.
pub fn harmonic_fundamental(
    lines_hz: &[f64],
    df: f64,
    range_hz: (f64, f64),
) -> Option<InterferenceComb> {
    let best = best_comb(lines_hz, df, range_hz)?;
    let divisor = common_divisor(&best);
    let coarse = if divisor > 1 {
        refined_comb(lines_hz, df, best.fundamental_hz * divisor as f64).unwrap_or(best)
    } else {
        best
    };
    match finer_divisor(lines_hz, df, &coarse) {
        Some(j) if coarse.fundamental_hz / j as f64 >= range_hz.0 => {
            refined_comb(lines_hz, df, coarse.fundamental_hz / j as f64).or(Some(coarse))
        }
        _ => Some(coarse),
    }
}

/// The largest j in 2..=[`MAX_FINER_DIVISOR`] for which `lines_hz` holds lines at
/// [`MIN_LOW_MEMBERS`] or more of the multiples k f_m / j, k <= [`LOW_HARMONICS`] j, with k not a
/// multiple of j: the low-harmonic evidence a comb needs, between the comb's own multiples.
fn finer_divisor(lines_hz: &[f64], df: f64, comb: &InterferenceComb) -> Option<usize> {
    let tolerance = MEMBER_TOLERANCE_BINS * df;
    (2..=MAX_FINER_DIVISOR).rev().find(|&j| {
        let base = comb.fundamental_hz / j as f64;
        let between = lines_hz
            .iter()
            .filter(|&&f| {
                let k = (f / base).round();
                k >= 1.0
                    && (k as usize) <= LOW_HARMONICS * j
                    && !(k as usize).is_multiple_of(j)
                    && (f - k * base).abs() <= tolerance
            })
            .count();
        between >= MIN_LOW_MEMBERS
    })
}

/// The greatest common divisor of the harmonic numbers of a comb's members among its first
/// [`LOW_HARMONICS`] multiples (a chance member far up the band does not count).
fn common_divisor(comb: &InterferenceComb) -> usize {
    comb.lines_hz
        .iter()
        .map(|f| (f / comb.fundamental_hz).round() as usize)
        .filter(|k| *k <= LOW_HARMONICS)
        .fold(0, greatest_common_divisor)
}

/// The comb with the most members among the first [`LOW_HARMONICS`] multiples of a fundamental
/// in `range_hz`, refined, with at least [`MIN_LOW_MEMBERS`] of them.
fn best_comb(lines_hz: &[f64], df: f64, (min_hz, max_hz): (f64, f64)) -> Option<InterferenceComb> {
    if !(min_hz > 0.0 && max_hz >= min_hz && df > 0.0) {
        return None;
    }
    let tolerance = MEMBER_TOLERANCE_BINS * df;
    let low_top = |f_m: f64| (LOW_HARMONICS as f64 + 0.5) * f_m;
    let low_lines: Vec<f64> = lines_hz
        .iter()
        .copied()
        .filter(|f| *f <= low_top(max_hz))
        .collect();
    let step = 0.1 * df / LOW_HARMONICS as f64;
    let count = ((max_hz - min_hz) / step).ceil() as usize;
    let score = |f_m: f64| {
        let m = members(&low_lines, f_m, tolerance);
        let low: Vec<&(usize, f64)> = m.iter().filter(|(k, _)| *k <= LOW_HARMONICS).collect();
        let spread: f64 = low.iter().map(|(k, f)| (f - *k as f64 * f_m).powi(2)).sum();
        (low.len(), spread)
    };
    let (f_m, (best, _)) = (0..=count)
        .map(|c| (min_hz + c as f64 * step).min(max_hz))
        .map(|f| (f, score(f)))
        .max_by(|a, b| a.1.0.cmp(&b.1.0).then(b.1.1.total_cmp(&a.1.1)))?;
    if best < MIN_LOW_MEMBERS {
        return None;
    }
    refined_comb(lines_hz, df, f_m)
}

/// The comb of `lines_hz` around the fundamental `f_m`, refined by least squares over its
/// members (twice), if it keeps at least [`MIN_LOW_MEMBERS`] among its first multiples.
fn refined_comb(lines_hz: &[f64], df: f64, mut f_m: f64) -> Option<InterferenceComb> {
    let tolerance = MEMBER_TOLERANCE_BINS * df;
    for _ in 0..2 {
        let m = members(lines_hz, f_m, tolerance);
        if m.is_empty() {
            return None;
        }
        f_m = least_squares_fundamental(&m);
    }
    let m = members(lines_hz, f_m, tolerance);
    let low_members = m.iter().filter(|(k, _)| *k <= LOW_HARMONICS).count();
    if low_members < MIN_LOW_MEMBERS {
        return None;
    }
    Some(InterferenceComb {
        fundamental_hz: f_m,
        lines_hz: m.into_iter().map(|(_, f)| f).collect(),
        low_members,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat density with unit lines at the given bins.
    fn density(bins: usize, lines: &[f64], df: f64) -> Vec<f64> {
        let mut psd = vec![1.0; bins];
        for f in lines {
            // a Hann main lobe centred on f: 1, 1/4 of the peak one bin off (a sampled sinc^2
            // shape is not needed for the centre and the parabola's sign)
            let i = (f / df).round() as usize;
            psd[i] = 1000.0;
            psd[i - 1] = 250.0;
            psd[i + 1] = 250.0;
        }
        psd
    }

    #[test]
    fn finds_a_mains_comb_and_not_a_lone_line() {
        let df = 1.0;
        let comb: Vec<f64> = (1..=10).map(|k| 50.0 * k as f64).collect();
        let psd = density(2000, &comb, df);
        let lines = spectral_lines(&psd, df, 10, 1900, |_| false);
        assert_eq!(lines.len(), 10);
        let c = find_comb(&lines, df, MAINS_RANGE_HZ, Some(83.0)).unwrap();
        assert!((c.fundamental_hz - 50.0).abs() < 1e-9, "{c:?}");
        assert_eq!(c.lines_hz.len(), 10);
        // three lines are not a comb
        let psd = density(2000, &comb[..3], df);
        let lines = spectral_lines(&psd, df, 10, 1900, |_| false);
        assert!(find_comb(&lines, df, MAINS_RANGE_HZ, None).is_none());
        // the odd multiples of f0 / 2 = 50 Hz are period-doubling lines of a 100 Hz spindle
        let flip: Vec<f64> = (0..6).map(|k| 50.0 * (2 * k + 1) as f64).collect();
        let psd = density(2000, &flip, df);
        let lines = spectral_lines(&psd, df, 10, 1900, |_| false);
        assert!(find_comb(&lines, df, MAINS_RANGE_HZ, Some(100.0)).is_none());
        assert!(find_comb(&lines, df, MAINS_RANGE_HZ, Some(83.0)).is_some());
        // lines at every multiple of 50 / 3 Hz: the 50 Hz comb is part of a finer one
        let fine: Vec<f64> = (1..=40).map(|k| 50.0 / 3.0 * k as f64).collect();
        let psd = density(2000, &fine, df);
        let lines = spectral_lines(&psd, df, 10, 1900, |_| false);
        assert!(find_comb(&lines, df, MAINS_RANGE_HZ, None).is_none());
        // a 100 Hz comb has members only at the even multiples of 50 Hz
        let coarse: Vec<f64> = (1..=12).map(|k| 100.0 * k as f64).collect();
        let psd = density(2000, &coarse, df);
        let lines = spectral_lines(&psd, df, 10, 1900, |_| false);
        assert!(find_comb(&lines, df, MAINS_RANGE_HZ, None).is_none());
        // ... whose fundamental is 100 Hz, not 50 or 33.3 Hz
        let c = harmonic_fundamental(&lines, df, (10.0, 500.0)).unwrap();
        assert!((c.fundamental_hz - 100.0).abs() < 1e-9, "{c:?}");
    }
}
