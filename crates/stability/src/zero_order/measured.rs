//! Zero-order (Altintas and Budak 1995) lobes straight from a measured receptance, with no modal
//! fit: the eigenvalues Lambda(w_k) of A_0 G(i w_k) at the measured frequencies w_k, with A_0
//! the delay-averaged directional matrix ([`chatter_dynamics::cutting::average_directional_matrix`];
//! K_c for turning, where the one non-zero eigenvalue is the oriented FRF). Where
//! Re(Lambda) < 0 the phase of Lambda fixes eps = (2 arg(Lambda) - pi) mod 4 pi in (0, 2 pi) and
//! the depth b = -1 / (2 Re Lambda) (module [`super`]); lobe k crosses the delay tau where
//! w tau - eps(w) - 2 pi k = 0, so the chatter frequency comes from the FRF phase.
//!
//! Between two measured frequencies the receptance is taken linear in its real and imaginary
//! parts ([`SampledReceptance::interpolate`]) and each crossing is bisected on that
//! interpolant. Lobes exist only for chatter frequencies inside the measured band: a speed whose
//! lobes all fall outside it counts as stable (infinite depth).

use super::system::{EigenPair, principal_sqrt};
use super::{ZeroOrderOptions, multipliers_unsupported};
use crate::boundary::LobePoint;
use crate::error::{Result, check_condition};
use crate::multiplier::DominantMultiplier;
use crate::prepared::PreparedSolver;
use chatter_dynamics::cutting::average_directional_matrix;
use chatter_dynamics::{CuttingCoefficients, Operation, ReceptanceMatrix, SampledReceptance};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Bisection steps on one crossing (the bracket shrinks to 2^-48 of a frequency step).
const BISECTION_STEPS: usize = 48;

/// The oriented measured FRF: the eigenvalue branches of A_0 G(i w) at the measured
/// frequencies, prepared once per model; [`Self::shallowest_crossing`] then costs one pass over the
/// frequencies per speed.
#[derive(Debug, Clone)]
pub struct MeasuredLobeTable {
    receptance: SampledReceptance,
    directional_n_per_m2: [[f64; 2]; 2],
    pairs: Vec<EigenPair>,
}

/// The eigenvalues of A_0 G for a general (not necessarily symmetric) measured G.
fn oriented_eigenpair(a: &[[f64; 2]; 2], g: &ReceptanceMatrix) -> EigenPair {
    let m = |r: usize, c: usize| g[0][c] * a[r][0] + g[1][c] * a[r][1];
    let (m00, m01, m10, m11) = (m(0, 0), m(0, 1), m(1, 0), m(1, 1));
    let half_trace = 0.5 * (m00 + m11);
    let disc = principal_sqrt(half_trace * half_trace - (m00 * m11 - m01 * m10));
    EigenPair([half_trace + disc, half_trace - disc])
}

impl MeasuredLobeTable {
    /// The table of `receptance` under the averaged cutting forces of `operation` and `cutting`.
    pub fn new(
        operation: &Operation,
        cutting: CuttingCoefficients,
        receptance: SampledReceptance,
    ) -> Self {
        let a0 = average_directional_matrix(operation, cutting);
        let a = [[a0[(0, 0)], a0[(0, 1)]], [a0[(1, 0)], a0[(1, 1)]]];
        let mut previous: Option<EigenPair> = None;
        let pairs = receptance
            .matrices_m_per_n()
            .iter()
            .map(|g| {
                let mut pair = oriented_eigenpair(&a, g);
                if let Some(p) = &previous {
                    pair = pair.matched(p);
                }
                previous = Some(pair);
                pair
            })
            .collect();
        Self {
            receptance,
            directional_n_per_m2: a,
            pairs,
        }
    }

    /// The measured receptance.
    pub fn receptance(&self) -> &SampledReceptance {
        &self.receptance
    }

    /// The eigenvalue of `branch` at fraction `t` of the step from frequency `k` to `k + 1`, on
    /// the interpolated receptance, continued from the endpoints' eigenvalues.
    fn branch_at(&self, k: usize, t: f64, branch: usize) -> (f64, Option<(f64, f64)>) {
        let f = self.receptance.frequencies_hz();
        let hz = f[k] + t * (f[k + 1] - f[k]);
        let (ga, gb) = (
            &self.receptance.matrices_m_per_n()[k],
            &self.receptance.matrices_m_per_n()[k + 1],
        );
        let g: ReceptanceMatrix =
            std::array::from_fn(|i| std::array::from_fn(|j| ga[i][j] + (gb[i][j] - ga[i][j]) * t));
        let pair = oriented_eigenpair(&self.directional_n_per_m2, &g);
        let expected: Complex64 =
            self.pairs[k].0[branch] + (self.pairs[k + 1].0[branch] - self.pairs[k].0[branch]) * t;
        let b = pair.closest(expected);
        (hz, pair.lobe(b).map(|l| (l.eps, l.depth_m)))
    }

    /// Every lobe crossing at delay `tau_s` as (depth m, chatter Hz), in no particular order.
    pub fn crossings(&self, tau_s: f64) -> Vec<(f64, f64)> {
        let f = self.receptance.frequencies_hz();
        let mut out = Vec::new();
        // (w tau - eps) / 2 pi: lobe k crosses where it equals k
        let p = |hz: f64, eps: f64| (2.0 * PI * hz * tau_s - eps) / (2.0 * PI);
        let hz = |k: usize, t: f64| f[k] + t * (f[k + 1] - f[k]);
        // the phase where a lobe begins or ends (Re Lambda = 0): the end of (0, 2 pi) nearer
        let edge = |eps: f64| if eps > PI { 2.0 * PI } else { 0.0 };
        for branch in 0..2 {
            for k in 0..f.len() - 1 {
                let (span, boundary_at_start) =
                    match (self.pairs[k].lobe(branch), self.pairs[k + 1].lobe(branch)) {
                        (Some(l0), Some(l1)) if (l1.eps - l0.eps).abs() <= PI => {
                            ((0.0, l0.eps, 1.0, l1.eps), None)
                        }
                        (None, Some(l1)) => {
                            let tb = self.boundary(k, branch, false);
                            ((tb, edge(l1.eps), 1.0, l1.eps), Some(true))
                        }
                        (Some(l0), None) => {
                            let tb = self.boundary(k, branch, true);
                            ((0.0, l0.eps, tb, edge(l0.eps)), Some(false))
                        }
                        _ => continue,
                    };
                let (t0, e0, t1, e1) = span;
                let (p0, p1) = (p(hz(k, t0), e0), p(hz(k, t1), e1));
                let (lo, hi) = (p0.min(p1), p0.max(p1));
                let mut m = lo.ceil().max(0.0);
                while m <= hi {
                    // a crossing exactly at a sample is counted on the step that starts there
                    if !(m == p1 && t1 == 1.0 && k + 2 < f.len())
                        && let Some(c) =
                            self.bisect(k, branch, m, (t0, t1), (p0 < p1, boundary_at_start), &p)
                    {
                        out.push(c);
                    }
                    m += 1.0;
                }
            }
        }
        out
    }

    /// Where on step `k` eigenvalue `branch` stops (`lobe_at_start`) or starts being a lobe.
    fn boundary(&self, k: usize, branch: usize, lobe_at_start: bool) -> f64 {
        let (mut a, mut b) = (0.0, 1.0);
        for _ in 0..BISECTION_STEPS {
            let t = 0.5 * (a + b);
            let is_lobe = self.branch_at(k, t, branch).1.is_some();
            if is_lobe == lobe_at_start {
                a = t;
            } else {
                b = t;
            }
        }
        if lobe_at_start { a } else { b }
    }

    /// The crossing of integer `m` by p(t) on `span` of step `k`; `direction` holds whether p
    /// increases and, for a span that ends at a lobe boundary, whether that is its start.
    fn bisect(
        &self,
        k: usize,
        branch: usize,
        m: f64,
        span: (f64, f64),
        direction: (bool, Option<bool>),
        p: &impl Fn(f64, f64) -> f64,
    ) -> Option<(f64, f64)> {
        let (increasing, boundary_at_start) = direction;
        let (mut a, mut b) = span;
        let mut last = None;
        for _ in 0..BISECTION_STEPS {
            let t = 0.5 * (a + b);
            let (hz, lobe) = self.branch_at(k, t, branch);
            let Some((eps, depth)) = lobe else {
                // only next to a lobe boundary: step away from it
                match boundary_at_start {
                    Some(true) => a = t,
                    Some(false) => b = t,
                    None => return None,
                }
                continue;
            };
            last = Some((depth, hz));
            if (p(hz, eps) < m) == increasing {
                a = t;
            } else {
                b = t;
            }
        }
        last
    }

    /// The shallowest crossing at delay `tau_s` as (depth m, chatter Hz), or None when no lobe
    /// crosses inside the measured band.
    pub fn shallowest_crossing(&self, tau_s: f64) -> Option<(f64, f64)> {
        self.crossings(tau_s)
            .into_iter()
            .min_by(|x, y| x.0.total_cmp(&y.0))
    }
}

/// The zero-order method prepared for a measured receptance (no modal model, no process
/// damping): its [`MeasuredLobeTable`] under one operation, queried at any speed. Like
/// [`super::PreparedZeroOrder`] it gives limiting depths only.
#[derive(Debug, Clone)]
pub struct PreparedMeasured {
    operation: Operation,
    table: MeasuredLobeTable,
    options: ZeroOrderOptions,
}

impl PreparedMeasured {
    /// Tabulate `receptance` under the averaged cutting forces of `operation` and `cutting`.
    pub fn new(
        operation: &Operation,
        cutting: CuttingCoefficients,
        receptance: &SampledReceptance,
        options: &ZeroOrderOptions,
    ) -> Result<Self> {
        options.validate()?;
        Ok(Self {
            operation: operation.clone(),
            table: MeasuredLobeTable::new(operation, cutting, receptance.clone()),
            options: *options,
        })
    }
}

impl PreparedSolver for PreparedMeasured {
    fn name(&self) -> &'static str {
        "zoa-measured"
    }

    fn dominant_multiplier(&self, _speed_rpm: f64, _depth_m: f64) -> Result<DominantMultiplier> {
        Err(multipliers_unsupported(self.name()))
    }

    fn chatter_frequency_hz(
        &self,
        _speed_rpm: f64,
        _depth_m: f64,
    ) -> Result<(DominantMultiplier, f64)> {
        Err(multipliers_unsupported(self.name()))
    }

    /// The shallowest crossing at `speed_rpm`; infinite where no lobe crosses inside the
    /// measured band below the options' depth ceiling.
    fn limiting_depth(&self, speed_rpm: f64) -> Result<LobePoint> {
        check_condition(speed_rpm, 0.0)?;
        Ok(LobePoint::below_ceiling(
            speed_rpm,
            self.table
                .shallowest_crossing(self.operation.delay_s(speed_rpm)),
            self.options.max_depth_m,
        ))
    }
}

/// Zero-order limiting depths at `speeds_rpm` from a measured receptance (no process damping):
/// `depth_m` is infinite where no lobe crosses inside the measured band below
/// `options.max_depth_m` ([`PreparedMeasured`]).
pub fn measured_limiting_depths(
    operation: &Operation,
    cutting: CuttingCoefficients,
    receptance: &SampledReceptance,
    speeds_rpm: &[f64],
    options: &ZeroOrderOptions,
) -> Result<Vec<LobePoint>> {
    options.validate()?;
    for &s in speeds_rpm {
        check_condition(s, 0.0)?;
    }
    PreparedMeasured::new(operation, cutting, receptance, options)?.limiting_depths(speeds_rpm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::zero_order::zoa_lobes;
    use chatter_dynamics::{ModalModel, examples};

    fn compare(model: &ModalModel, step_hz: f64, f_max_hz: f64, speeds: &[f64]) -> f64 {
        let n = (f_max_hz / step_hz) as usize;
        let f: Vec<f64> = (0..=n).map(|k| k as f64 * step_hz).collect();
        let g = model.sampled_receptance(f).unwrap();
        let measured = measured_limiting_depths(
            model.operation(),
            model.cutting(),
            &g,
            speeds,
            &ZeroOrderOptions::unbounded(),
        )
        .unwrap();
        let modal = zoa_lobes(model, speeds).unwrap();
        measured
            .iter()
            .zip(&modal)
            .map(|(a, b)| {
                assert!(
                    (a.chatter_hz - b.chatter_hz).abs() < 2.0 * step_hz,
                    "{} rpm: {} vs {} Hz",
                    a.speed_rpm,
                    a.chatter_hz,
                    b.chatter_hz
                );
                (a.depth_m / b.depth_m - 1.0).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn sampled_modal_frf_gives_the_modal_lobes() {
        let speeds: Vec<f64> = (0..150).map(|i| 3000.0 + 80.0 * i as f64).collect();
        let e = compare(&examples::schmitz_2023_milling(), 1.0, 3000.0, &speeds);
        assert!(e < 5e-3, "milling: worst relative depth error {e}");
        let speeds: Vec<f64> = (0..150).map(|i| 2000.0 + 40.0 * i as f64).collect();
        let e = compare(&examples::ahmadi_2022_turning(), 1.0, 6000.0, &speeds);
        assert!(e < 5e-3, "turning: worst relative depth error {e}");
    }
}
