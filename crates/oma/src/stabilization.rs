//! Stabilization diagrams: poles identified at increasing model orders, each flagged stable when
//! a pole of the previous order has nearly the same frequency and damping (000 Section 3, after
//! Eq. 19; 002 Section 2.1, after Eq. 9).
//!
//! Physical poles reappear at every order once the order suffices; spurious (noise) poles move.
//! A pole at order n is stable in frequency when the nearest pole of the same kind (structural or
//! imposed harmonic) at the previous order is within a relative frequency tolerance (1 % by
//! default), and stable in damping when, in addition, that pole's damping differs by at most
//! max(relative tolerance x |zeta|, absolute floor) (5 % and 5e-4 by default).

use crate::error::{OmaError, Result};
use crate::lsce::{Pole, lsce};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::RangeInclusive;

/// Tolerances of the stability checks between consecutive orders.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StabilityCriteria {
    /// Relative frequency tolerance (default 0.01).
    pub frequency_rel: f64,
    /// Relative damping tolerance (default 0.05).
    pub damping_rel: f64,
    /// Absolute damping tolerance, the floor for lightly damped poles (default 5e-4).
    pub damping_abs: f64,
}

impl Default for StabilityCriteria {
    fn default() -> Self {
        Self {
            frequency_rel: 0.01,
            damping_rel: 0.05,
            damping_abs: 5e-4,
        }
    }
}

impl StabilityCriteria {
    /// Check that every tolerance is finite and non-negative.
    pub fn validate(&self) -> Result<()> {
        for v in [self.frequency_rel, self.damping_rel, self.damping_abs] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(OmaError::InvalidInput {
                    field: "criteria",
                    message: format!("tolerance {v}; expected a finite value >= 0"),
                });
            }
        }
        Ok(())
    }

    /// Whether frequencies `f` and `f_ref` agree.
    pub fn same_frequency(&self, f: f64, f_ref: f64) -> bool {
        (f - f_ref).abs() <= self.frequency_rel * f_ref.abs()
    }

    /// Whether damping ratios `z` and `z_ref` agree.
    pub fn same_damping(&self, z: f64, z_ref: f64) -> bool {
        (z - z_ref).abs() <= (self.damping_rel * z_ref.abs()).max(self.damping_abs)
    }
}

/// A pole in the diagram with its stability flags.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DiagramPole {
    /// The pole.
    pub pole: Pole,
    /// Frequency agrees with the nearest pole of the previous order.
    pub stable_frequency: bool,
    /// Frequency and damping agree with the nearest pole of the previous order.
    pub stable_damping: bool,
}

impl DiagramPole {
    /// Stable in frequency and damping.
    pub fn is_stable(&self) -> bool {
        self.stable_frequency && self.stable_damping
    }
}

/// The poles of one model order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelOrder {
    /// The model order (meaning set by the method: pole pairs P for LSCE, AR order n_a for
    /// polyreference).
    pub order: usize,
    /// Its poles, by increasing frequency.
    pub poles: Vec<DiagramPole>,
}

/// A stabilization diagram.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StabilizationDiagram {
    /// The tolerances used for the flags.
    pub criteria: StabilityCriteria,
    /// Orders, increasing.
    pub orders: Vec<ModelOrder>,
}

impl StabilizationDiagram {
    /// Flag poles already identified at increasing orders (`(order, poles)` in increasing order).
    pub fn from_poles(criteria: StabilityCriteria, fitted: Vec<(usize, Vec<Pole>)>) -> Self {
        let mut orders: Vec<ModelOrder> = Vec::with_capacity(fitted.len());
        for (order, mut poles) in fitted {
            poles.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
            let previous = orders.last().map(|o| o.poles.as_slice());
            let poles = poles
                .into_iter()
                .map(|pole| {
                    let nearest = previous.and_then(|prev| {
                        prev.iter()
                            .map(|d| &d.pole)
                            .filter(|q| q.harmonic == pole.harmonic)
                            .min_by(|a, b| {
                                (a.frequency_hz - pole.frequency_hz)
                                    .abs()
                                    .total_cmp(&(b.frequency_hz - pole.frequency_hz).abs())
                            })
                    });
                    let stable_frequency = nearest.is_some_and(|q| {
                        criteria.same_frequency(pole.frequency_hz, q.frequency_hz)
                    });
                    let stable_damping = stable_frequency
                        && nearest.is_some_and(|q| {
                            criteria.same_damping(pole.damping_ratio, q.damping_ratio)
                        });
                    DiagramPole {
                        pole,
                        stable_frequency,
                        stable_damping,
                    }
                })
                .collect();
            orders.push(ModelOrder { order, poles });
        }
        Self { criteria, orders }
    }

    /// Fit every order of `orders` with `fit` (in parallel) and flag the poles.
    pub fn compute<F>(
        orders: RangeInclusive<usize>,
        criteria: StabilityCriteria,
        fit: F,
    ) -> Result<Self>
    where
        F: Fn(usize) -> Result<Vec<Pole>> + Sync,
    {
        criteria.validate()?;
        if orders.is_empty() {
            return Err(OmaError::InvalidInput {
                field: "max_order",
                message: format!("empty order range {}..={}", orders.start(), orders.end()),
            });
        }
        let fitted = orders
            .into_par_iter()
            .map(|n| fit(n).map(|poles| (n, poles)))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self::from_poles(criteria, fitted))
    }

    /// The poles of `order`, if the diagram has it.
    pub fn order(&self, order: usize) -> Option<&ModelOrder> {
        self.orders.iter().find(|o| o.order == order)
    }
}

/// Lowest LSCE model order (pole pairs P) of a diagram with `harmonics` imposed: 2, and more than
/// the harmonic count so that at least one structural pair is fitted.
pub fn lsce_min_order(harmonics: usize) -> usize {
    (harmonics + 1).max(2)
}

/// Stabilization diagram of (modified) LSCE (000 Eq. 19-25) on correlations `r[c][i]` sampled at
/// `sample_rate_hz`: model orders P = [`lsce_min_order`]..=`max_order`, each fitting the
/// characteristic polynomial of degree 2P (Eq. 19) with the `harmonics_hz` imposed.
pub fn lsce_diagram(
    r: &[Vec<f64>],
    sample_rate_hz: f64,
    max_order: usize,
    harmonics_hz: &[f64],
    criteria: StabilityCriteria,
) -> Result<StabilizationDiagram> {
    StabilizationDiagram::compute(
        lsce_min_order(harmonics_hz.len())..=max_order,
        criteria,
        |p| lsce(r, sample_rate_hz, 2 * p, harmonics_hz),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    fn pole(f: f64, z: f64) -> Pole {
        let w = 2.0 * std::f64::consts::PI * f;
        let lambda = Complex64::new(-z * w, w * (1.0 - z * z).sqrt());
        Pole::from_multiplier((lambda * 1e-4).exp(), 1e-4, false)
    }

    #[test]
    fn flags_follow_the_tolerances() {
        let c = StabilityCriteria::default();
        let d = StabilizationDiagram::from_poles(
            c,
            vec![
                (2, vec![pole(100.0, 0.02), pole(300.0, 0.001)]),
                (
                    3,
                    vec![pole(100.9, 0.0209), pole(300.0, 0.0014), pole(500.0, 0.01)],
                ),
                (4, vec![pole(102.0, 0.0209), pole(300.0, 0.0020)]),
            ],
        );
        let flags = |o: usize| -> Vec<(bool, bool)> {
            d.order(o)
                .unwrap()
                .poles
                .iter()
                .map(|p| (p.stable_frequency, p.stable_damping))
                .collect()
        };
        assert_eq!(flags(2), vec![(false, false); 2]);
        // 0.9 % and 4.5 %: stable; 0.0004 below the 5e-4 floor: stable; 500 Hz: new
        assert_eq!(flags(3), vec![(true, true), (true, true), (false, false)]);
        // 1.09 % off; damping 0.0014 -> 0.0020 exceeds max(7e-5, 5e-4)
        assert_eq!(flags(4), vec![(false, false), (true, false)]);
        assert!(d.order(5).is_none());
    }

    #[test]
    fn empty_ranges_and_bad_tolerances_are_errors() {
        let fit = |_: usize| Ok(vec![]);
        let (high, low) = (3, 2);
        let empty = high..=low;
        assert!(StabilizationDiagram::compute(empty, StabilityCriteria::default(), fit).is_err());
        let bad = StabilityCriteria {
            damping_abs: -1.0,
            ..StabilityCriteria::default()
        };
        assert!(StabilizationDiagram::compute(2..=3, bad, fit).is_err());
    }
}
