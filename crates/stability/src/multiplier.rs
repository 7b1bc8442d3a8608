//! The dominant Floquet multiplier (eigenvalue of the monodromy / transition matrix over one
//! delay) and what it says about the cut.

use num_complex::Complex64;
use std::f64::consts::PI;

/// How stability is lost when the dominant multiplier leaves the unit circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MultiplierKind {
    /// Complex-conjugate pair: secondary Hopf (quasi-periodic chatter).
    Hopf,
    /// Real and negative: period doubling (flip) bifurcation.
    Flip,
    /// Real and positive (fold); rare in machining.
    Fold,
}

/// The dominant multiplier mu over one delay period tau.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DominantMultiplier {
    /// mu itself (upper half-plane representative of a conjugate pair).
    pub value: Complex64,
    /// The delay period tau (s): tooth period in milling, spindle period in turning.
    pub period_s: f64,
}

impl DominantMultiplier {
    /// A multiplier over a period; the conjugate with non-negative imaginary part is kept.
    pub fn new(value: Complex64, period_s: f64) -> Self {
        let value = if value.im < 0.0 { value.conj() } else { value };
        Self { value, period_s }
    }

    /// |mu|: the cut is stable when < 1.
    pub fn modulus(&self) -> f64 {
        self.value.norm()
    }

    /// Hopf, flip or fold, with `tol` the relative imaginary part below which mu counts as real.
    pub fn kind(&self) -> MultiplierKind {
        let tol = 1e-9 * self.modulus().max(1e-300);
        if self.value.im.abs() > tol {
            MultiplierKind::Hopf
        } else if self.value.re < 0.0 {
            MultiplierKind::Flip
        } else {
            MultiplierKind::Fold
        }
    }

    /// Principal frequency f_mu = arg(mu) / (2 pi tau) in [0, 1/(2 tau)] (Hz): the frequency seen
    /// in data sampled once per delay (lifted), as in the tables of 002.
    pub fn principal_frequency_hz(&self) -> f64 {
        self.value.arg().abs() / (2.0 * PI * self.period_s)
    }

    /// Equivalent continuous-time exponent lambda = ln(mu) / tau (principal branch).
    pub fn exponent(&self) -> Complex64 {
        chatter_dynamics::pole::multiplier_pole(self.value, self.period_s)
    }

    /// The family of frequencies f_mu + k / tau, k in `harmonics`, folded to non-negative values:
    /// the chatter frequencies this multiplier can show in a continuous signal.
    pub fn frequency_family_hz(&self, harmonics: std::ops::RangeInclusive<i32>) -> Vec<f64> {
        let f0 = self.principal_frequency_hz();
        let ft = 1.0 / self.period_s;
        let mut out: Vec<f64> = harmonics
            .flat_map(|k| [(f0 + k as f64 * ft).abs(), (-f0 + k as f64 * ft).abs()])
            .collect();
        out.sort_by(f64::total_cmp);
        out.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        out
    }

    /// The member of [`Self::frequency_family_hz`] closest to `reference_hz` (e.g. the dominant
    /// natural frequency): the physically expected chatter frequency.
    pub fn chatter_frequency_near_hz(&self, reference_hz: f64) -> f64 {
        let ft = 1.0 / self.period_s;
        let k = (reference_hz / ft).floor() as i32;
        self.frequency_family_hz((k - 1)..=(k + 2))
            .into_iter()
            .min_by(|a, b| {
                (a - reference_hz)
                    .abs()
                    .total_cmp(&(b - reference_hz).abs())
            })
            .unwrap_or(self.principal_frequency_hz())
    }
}
