//! The zero-order method for a variable-pitch cutter (Altintas, Engin & Budak 1999): tooth j
//! cuts with its own delay tau_j = pitch_j / Omega, and each tooth's directional matrix averaged
//! over the revolution is the same, A_0 / N (every tooth sweeps the same arc), so the
//! characteristic equation det(I + b sum_j (1 - e^{-i w tau_j}) (A_0 / N) G(i w)) = 0 reads, for
//! an eigenvalue Lambda of A_0 G(i w),
//!
//! 1 + b c(w) Lambda(w) / N = 0,  c(w) = sum_j (1 - e^{-i w tau_j}),
//!
//! the pitch-averaged regeneration c(w) taking the place of N (1 - e^{-i w tau}). The depth
//! b = -N / (c Lambda) is real and positive where Im(c Lambda) = 0 and Re(c Lambda) < 0. Unlike
//! the even-pitch case the phase of c does not fix w tau, so at each speed the chatter frequency
//! is searched: the eigenvalue branches are followed on a logarithmic frequency grid, each sign
//! change of Im(c Lambda) refined by bisection, and the limit is the smallest depth found. With
//! even pitch c = N (1 - e^{-i w tau}) and the equation is the even-pitch one (the tests compare
//! this search with the lobe table).

use super::Lobe;
use super::system::{AddedDamping, EigenPair, OrientedSystem};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Frequencies of the search grid per decade: a step of 0.06 % of the frequency, a tenth of the
/// half-power width of a mode with 0.3 % damping.
const GRID_PER_DECADE: f64 = 4000.0;
/// The search spans [LOW f_min, HIGH f_max] of the system's natural frequencies.
const LOW: f64 = 0.3;
/// See [`LOW`].
const HIGH: f64 = 3.0;

/// The pitch-averaged regeneration c(w) = sum_j (1 - e^{-i w tau_j}).
fn regeneration(omega_rad_s: f64, delays_s: &[f64]) -> Complex64 {
    delays_s
        .iter()
        .map(|tau| Complex64::new(1.0, 0.0) - Complex64::from_polar(1.0, -omega_rad_s * tau))
        .sum()
}

/// The lowest zero-order lobe (depth in m, chatter frequency in Hz) of `system` at
/// `speed_rpm` for a cutter with `pitches_rad` (one per tooth, summing to 2 pi), or `None`
/// where no frequency of the search span gives a positive depth (module docs).
pub fn variable_pitch_lobe(
    system: &OrientedSystem,
    pitches_rad: &[f64],
    speed_rpm: f64,
) -> Option<Lobe> {
    let omega_spindle = 2.0 * PI * speed_rpm / 60.0;
    let delays: Vec<f64> = pitches_rad.iter().map(|p| p / omega_spindle).collect();
    let teeth = pitches_rad.len() as f64;
    let (f_lo, f_hi) = system.frequency_span_hz();
    let (w_lo, w_hi) = (2.0 * PI * LOW * f_lo, 2.0 * PI * HIGH * f_hi);
    let points = ((w_hi / w_lo).log10() * GRID_PER_DECADE).ceil() as usize;
    let ratio = (w_hi / w_lo).powf(1.0 / points as f64);
    let value = |w: f64, pair: &EigenPair, branch: usize| regeneration(w, &delays) * pair.0[branch];
    let mut best: Option<Lobe> = None;
    let mut previous: Option<(f64, EigenPair)> = None;
    let mut w = w_lo;
    for _ in 0..=points {
        let Some(pair) = system.eigenvalues(w, AddedDamping::NONE) else {
            previous = None;
            w *= ratio;
            continue;
        };
        let pair = match &previous {
            Some((_, p)) => pair.matched(p),
            None => pair,
        };
        if let Some((w0, p0)) = &previous {
            for branch in 0..2 {
                let (a, b) = (value(*w0, p0, branch), value(w, &pair, branch));
                if a.im.signum() == b.im.signum() || (a.re >= 0.0 && b.re >= 0.0) {
                    continue;
                }
                // bisection on Im(c Lambda), the branch followed by the nearest eigenvalue
                let (mut lo, mut hi, mut at_lo, mut reference) = (*w0, w, a, p0.0[branch]);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let Some(m) = system.eigenvalues(mid, AddedDamping::NONE) else {
                        break;
                    };
                    let lambda = m.0[m.closest(reference)];
                    let v = regeneration(mid, &delays) * lambda;
                    if v.im.signum() == at_lo.im.signum() {
                        (lo, at_lo, reference) = (mid, v, lambda);
                    } else {
                        hi = mid;
                    }
                }
                let root = 0.5 * (lo + hi);
                let Some(m) = system.eigenvalues(root, AddedDamping::NONE) else {
                    continue;
                };
                let v = regeneration(root, &delays) * m.0[m.closest(reference)];
                if v.re < 0.0 {
                    let depth_m = -teeth / v.re;
                    if best.is_none_or(|l| depth_m < l.depth_m) {
                        best = Some(Lobe {
                            depth_m,
                            chatter_hz: root / (2.0 * PI),
                            index: 0,
                        });
                    }
                }
            }
        }
        previous = Some((w, pair));
        w *= ratio;
    }
    best
}
