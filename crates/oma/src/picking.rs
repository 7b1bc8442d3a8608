//! Automatic choice of the dominant structural pole from a stabilization diagram.
//!
//! 1. Candidates are the poles stable in frequency and damping
//!    ([`crate::stabilization::DiagramPole::is_stable`]) that are not harmonics: neither imposed
//!    (modified LSCE, 000 Eq. 22-24) nor within a narrow band around a known harmonic, and whose
//!    damping ratio lies in (0, `max_damping`) (negative damping is an unstable or spurious pole in
//!    a stable cut; very high damping is a noise pole).
//! 2. Candidates are clustered by frequency across orders (single linkage: sorted by frequency,
//!    a new cluster starts where the gap exceeds the diagram's relative frequency tolerance); a
//!    cluster keeps at most one pole per order, the one nearest its median frequency, and then
//!    only its longest run of consecutive orders (the earliest on ties): close poles that a low
//!    order merges into one, and poles that come and go, do not join the run that follows.
//! 3. Clusters whose run is shorter than three quarters of the longest run are dropped
//!    (a physical pole reappears at every order once the order suffices). Of the rest, the
//!    dominant is the one with the smallest mean decay rate -Re(lambda), i.e. the largest
//!    discrete pole modulus |mu| = e^{Re(lambda) T_s}: the "structural pole with the largest
//!    modulus" of 000 Section 3, and the dominant Floquet multiplier for lifted data.

use crate::error::{OmaError, Result};
use crate::lsce::Pole;
use crate::stabilization::{StabilityCriteria, StabilizationDiagram};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// Which poles may be picked.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PickingOptions {
    /// Poles with damping ratio at or above this are discarded (default 0.25).
    pub max_damping: f64,
    /// Relative half-width of the band around each known harmonic in which poles are discarded
    /// (default 0.0025).
    pub harmonic_band_rel: f64,
}

impl Default for PickingOptions {
    fn default() -> Self {
        Self {
            max_damping: 0.25,
            harmonic_band_rel: 0.0025,
        }
    }
}

impl PickingOptions {
    /// Check the options: `max_damping` in (0, 1], band finite and >= 0.
    pub fn validate(&self) -> Result<()> {
        if !(self.max_damping > 0.0 && self.max_damping <= 1.0) {
            return Err(OmaError::InvalidInput {
                field: "max_damping",
                message: format!("{}; expected a value in (0, 1]", self.max_damping),
            });
        }
        if !(self.harmonic_band_rel.is_finite() && self.harmonic_band_rel >= 0.0) {
            return Err(OmaError::InvalidInput {
                field: "harmonic_band_rel",
                message: format!("{}; expected a finite value >= 0", self.harmonic_band_rel),
            });
        }
        Ok(())
    }

    /// Whether `pole` may be the structural pole: not a harmonic (imposed or near one of
    /// `known_harmonics_hz`) and damping in (0, `max_damping`).
    pub fn admits(&self, pole: &Pole, known_harmonics_hz: &[f64]) -> bool {
        !pole.harmonic
            && pole.damping_ratio > 0.0
            && pole.damping_ratio < self.max_damping
            && !known_harmonics_hz
                .iter()
                .any(|h| (pole.frequency_hz - h).abs() <= self.harmonic_band_rel * h.abs())
    }
}

/// A pole of one model order in a cluster.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClusterMember {
    /// Model order.
    pub order: usize,
    /// The pole at that order.
    pub pole: Pole,
}

/// Stable poles of one physical pole across orders.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoleCluster {
    /// Mean frequency of the members (Hz).
    pub frequency_hz: f64,
    /// Mean damping ratio of the members.
    pub damping_ratio: f64,
    /// One member per order over consecutive orders, increasing (never empty).
    pub members: Vec<ClusterMember>,
}

impl PoleCluster {
    /// The cluster of the longest run of consecutive orders among `members` (at most one per
    /// order; not empty).
    fn new(mut members: Vec<ClusterMember>) -> Self {
        members.sort_by_key(|m| m.order);
        let (mut best, mut start) = (0..members.len().min(1), 0);
        for i in 1..=members.len() {
            if i == members.len() || members[i].order != members[i - 1].order + 1 {
                if i - start > best.len() {
                    best = start..i;
                }
                start = i;
            }
        }
        let members: Vec<ClusterMember> = members.drain(best).collect();
        let n = members.len().max(1) as f64;
        Self {
            frequency_hz: members.iter().map(|m| m.pole.frequency_hz).sum::<f64>() / n,
            damping_ratio: members.iter().map(|m| m.pole.damping_ratio).sum::<f64>() / n,
            members,
        }
    }

    /// Mean continuous-time pole lambda of the members (rad/s).
    pub fn lambda(&self) -> Complex64 {
        self.members
            .iter()
            .map(|m| m.pole.lambda)
            .sum::<Complex64>()
            / self.members.len().max(1) as f64
    }
}

/// Clusters of the admitted stable poles of `diagram`, by increasing frequency (steps 1-2 of the
/// module documentation).
pub fn stable_clusters(
    diagram: &StabilizationDiagram,
    known_harmonics_hz: &[f64],
    options: &PickingOptions,
) -> Vec<PoleCluster> {
    let mut candidates: Vec<ClusterMember> = diagram
        .orders
        .iter()
        .flat_map(|o| {
            o.poles
                .iter()
                .filter(|d| d.is_stable() && options.admits(&d.pole, known_harmonics_hz))
                .map(move |d| ClusterMember {
                    order: o.order,
                    pole: d.pole,
                })
        })
        .collect();
    candidates.sort_by(|a, b| a.pole.frequency_hz.total_cmp(&b.pole.frequency_hz));
    let mut groups: Vec<Vec<ClusterMember>> = Vec::new();
    for m in candidates {
        match groups.last_mut() {
            Some(g)
                if g.last().is_some_and(|p| {
                    linked(&diagram.criteria, p.pole.frequency_hz, m.pole.frequency_hz)
                }) =>
            {
                g.push(m)
            }
            _ => groups.push(vec![m]),
        }
    }
    groups
        .into_iter()
        .map(|g| PoleCluster::new(one_per_order(g)))
        .collect()
}

/// Single-linkage rule: consecutive frequencies within the relative frequency tolerance.
fn linked(criteria: &StabilityCriteria, lower: f64, upper: f64) -> bool {
    criteria.same_frequency(upper, lower)
}

/// Keep, for each order, the member nearest the group's median frequency.
fn one_per_order(group: Vec<ClusterMember>) -> Vec<ClusterMember> {
    let median = group[group.len() / 2].pole.frequency_hz;
    let mut kept: Vec<ClusterMember> = Vec::with_capacity(group.len());
    for m in group {
        match kept.iter_mut().find(|k| k.order == m.order) {
            Some(k) => {
                if (m.pole.frequency_hz - median).abs() < (k.pole.frequency_hz - median).abs() {
                    *k = m;
                }
            }
            None => kept.push(m),
        }
    }
    kept
}

/// Whether `cluster` runs over at least three quarters of the `longest` run (step 3 of the
/// module documentation).
pub fn persistent(cluster: &PoleCluster, longest: usize) -> bool {
    4 * cluster.members.len() >= 3 * longest
}

/// The persistent clusters of `clusters`, most dominant first (step 3 of the module
/// documentation: increasing mean decay rate -Re(lambda)).
pub fn ranked(clusters: Vec<PoleCluster>) -> Vec<PoleCluster> {
    let most = clusters.iter().map(|c| c.members.len()).max().unwrap_or(0);
    let mut kept: Vec<PoleCluster> = clusters
        .into_iter()
        .filter(|c| persistent(c, most))
        .collect();
    kept.sort_by(|a, b| (-a.lambda().re).total_cmp(&(-b.lambda().re)));
    kept
}

/// The dominant structural pole's cluster (step 3 of the module documentation).
pub fn pick_dominant(
    diagram: &StabilizationDiagram,
    known_harmonics_hz: &[f64],
    options: &PickingOptions,
) -> Result<PoleCluster> {
    options.validate()?;
    ranked(stable_clusters(diagram, known_harmonics_hz, options))
        .into_iter()
        .next()
        .ok_or_else(|| {
            OmaError::NoPole(format!(
                "no structural pole is stable over consecutive orders among {} orders with \
                 damping in (0, {}); raise the maximum order or use more data",
                diagram.orders.len(),
                options.max_damping
            ))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pole(f: f64, z: f64, harmonic: bool) -> Pole {
        let w = 2.0 * std::f64::consts::PI * f;
        let lambda = Complex64::new(-z * w, w * (1.0 - z * z).sqrt());
        Pole::from_multiplier((lambda * 1e-4).exp(), 1e-4, harmonic)
    }

    fn diagram(per_order: &[Vec<Pole>]) -> StabilizationDiagram {
        StabilizationDiagram::from_poles(
            StabilityCriteria::default(),
            per_order
                .iter()
                .enumerate()
                .map(|(i, p)| (i + 2, p.clone()))
                .collect(),
        )
    }

    #[test]
    fn persistent_cluster_with_the_slowest_decay_wins() {
        let orders: Vec<Vec<Pole>> = (0..6)
            .map(|k| {
                let e = 1.0 + 1e-4 * k as f64;
                let mut p = vec![
                    pole(500.0 * e, 0.03, false),  // every order; decay 94 1/s
                    pole(700.0, 0.0, true),        // imposed harmonic
                    pole(900.0 * e, -0.01, false), // negative damping
                    pole(1200.0, 0.6, false),      // absurd damping
                ];
                if k >= 1 {
                    p.push(pole(300.0 * e, 0.02, false)); // 4 stable orders; decay 38 1/s
                }
                if k >= 4 {
                    p.push(pole(800.0 * e, 0.002, false)); // 1 stable order: sporadic
                }
                if k >= 1 {
                    p.push(pole(1500.0, 0.001, false)); // near a known harmonic
                }
                p
            })
            .collect();
        let d = diagram(&orders);
        let clusters = stable_clusters(&d, &[1501.0], &PickingOptions::default());
        let sizes: Vec<(f64, usize)> = clusters
            .iter()
            .map(|c| (c.frequency_hz.round(), c.members.len()))
            .collect();
        assert_eq!(sizes, vec![(300.0, 4), (500.0, 5), (800.0, 1)]);
        let c = pick_dominant(&d, &[1501.0], &PickingOptions::default()).unwrap();
        assert!((c.frequency_hz - 300.0).abs() < 0.5, "{c:?}");
        assert_eq!(c.members.first().unwrap().order, 4);
        assert_eq!(c.members.last().unwrap().order, 7);
        let mean_lambda: Complex64 =
            c.members.iter().map(|m| m.pole.lambda).sum::<Complex64>() / 4.0;
        assert!((c.lambda() - mean_lambda).norm() < 1e-9);
        // the decay rate decides, not the damping ratio: 400 Hz at 1 % (25 1/s) beats
        // 2000 Hz at 0.3 % (38 1/s)
        let pair: Vec<Vec<Pole>> = (0..4)
            .map(|_| vec![pole(400.0, 0.01, false), pole(2000.0, 0.003, false)])
            .collect();
        let c = pick_dominant(&diagram(&pair), &[], &PickingOptions::default()).unwrap();
        assert!((c.frequency_hz - 400.0).abs() < 1e-6 && c.members.len() == 3);
        // nothing admissible
        let none: Vec<Vec<Pole>> = (0..3).map(|_| vec![pole(700.0, 0.0, true)]).collect();
        assert!(matches!(
            pick_dominant(&diagram(&none), &[], &PickingOptions::default()),
            Err(OmaError::NoPole(_))
        ));
    }

    #[test]
    fn duplicate_poles_of_one_order_count_once() {
        let orders: Vec<Vec<Pole>> = (0..3)
            .map(|_| vec![pole(500.0, 0.02, false), pole(502.0, 0.02, false)])
            .collect();
        let clusters = stable_clusters(&diagram(&orders), &[], &PickingOptions::default());
        assert_eq!(clusters.len(), 1);
        assert_eq!(clusters[0].members.len(), 2);
    }

    #[test]
    fn a_cluster_keeps_its_longest_run_of_orders() {
        // two close poles merged at low orders (2476 Hz, stable at orders 3-4), resolved from
        // order 8 on (2492 Hz, stable at 9-14): one cluster by frequency, the later run kept
        let orders: Vec<Vec<Pole>> = (0..13)
            .map(|k| match k {
                0..=2 => vec![pole(2476.0, 0.008, false)],
                3..=5 => vec![],
                _ => vec![pole(2492.0, 0.003, false)],
            })
            .collect();
        let clusters = stable_clusters(&diagram(&orders), &[], &PickingOptions::default());
        assert_eq!(clusters.len(), 1);
        let orders: Vec<usize> = clusters[0].members.iter().map(|m| m.order).collect();
        assert_eq!(orders, (9..=14).collect::<Vec<_>>());
        assert!((clusters[0].frequency_hz - 2492.0).abs() < 1e-9);
        assert!((clusters[0].damping_ratio - 0.003).abs() < 1e-12);
    }
}
