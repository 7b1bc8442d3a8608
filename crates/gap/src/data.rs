//! Observations prepared for the likelihood: SI units, one boundary request per distinct
//! (speed, cut geometry), campaign position u in [0, 1] from `sequence`, pole standard deviations.

use crate::error::{GapError, Result};
use crate::likelihood::NoiseModel;
use crate::predict::milling_multiplier;
use crate::variant::Variant;
use chatter_dynamics::{ModalModel, Observations, Operation};
use rayon::prelude::*;

/// A test cut.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CutPoint {
    /// Index in the observations' `cuts`.
    pub index: usize,
    pub speed_rpm: f64,
    pub depth_m: f64,
    pub stable: bool,
    pub chatter_hz: Option<f64>,
    pub sequence: Option<i64>,
    /// Campaign position in [0, 1] (0 without `sequence`).
    pub u: f64,
    /// Cut geometry (index into the immersions).
    pub geometry: usize,
    /// Index of the boundary request (speed, geometry).
    pub request: usize,
}

/// An identified pole.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PolePoint {
    /// Index in the observations' `poles`.
    pub index: usize,
    pub speed_rpm: f64,
    pub depth_m: f64,
    pub frequency_hz: f64,
    pub damping_ratio: f64,
    /// The reported standard deviation of the frequency (Hz; 0 when none): the floor of the
    /// noise model's ([`PolePoint::frequency_std_hz`]).
    pub frequency_floor_hz: f64,
    /// The frequency the noise scale s multiplies: the pole's own for a physical (turning)
    /// pole, the dominant natural frequency for a lifted (milling) one, whose principal
    /// frequency carries the absolute error of the physical pole it folds.
    pub frequency_unit_hz: f64,
    pub damping_std: f64,
    pub sequence: Option<i64>,
    pub u: f64,
    pub geometry: usize,
}

/// Prepared observations.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Dataset {
    pub cuts: Vec<CutPoint>,
    pub poles: Vec<PolePoint>,
    /// Distinct (speed, geometry) pairs of the cuts.
    pub requests: Vec<(f64, usize)>,
    /// Radial immersion of each geometry (`None`: the model's own).
    pub immersions: Vec<Option<f64>>,
    /// Whether every cut and pole carries `sequence` and they span more than one value.
    pub has_sequence: bool,
    /// Standard deviation of chatter frequencies (Hz).
    pub chatter_std_hz: f64,
    /// The grid of relative pole-frequency noise scales s the likelihood integrates over
    /// ([`NoiseModel::pole_scales`]).
    pub pole_scales: Vec<f64>,
    /// Milling: the nominal model's start vector of each cut's and each pole's operator
    /// ([`crate::predict::milling_multiplier`]), where its solver succeeded; empty for turning.
    pub cut_starts: Vec<Option<Vec<f64>>>,
    /// As `cut_starts`, for the poles.
    pub pole_starts: Vec<Option<Vec<f64>>>,
}

impl PolePoint {
    /// Standard deviation of the pole frequency at relative noise scale `scale`: the larger of
    /// s times [`PolePoint::frequency_unit_hz`] and the reported one (an identification's
    /// scatter over overlapping segments leaves out its bias, so it is a floor, not the noise).
    pub fn frequency_std_hz(&self, scale: f64) -> f64 {
        self.frequency_floor_hz.max(scale * self.frequency_unit_hz)
    }
}

impl Dataset {
    /// Prepare `observations` for `model`; `reference_hz` scales the default noise.
    pub fn new(
        model: &ModalModel,
        observations: &Observations,
        noise: &NoiseModel,
        reference_hz: f64,
    ) -> Result<Self> {
        observations.validate()?;
        if observations.cuts.is_empty() && observations.poles.is_empty() {
            return Err(GapError::Observations(
                "no cuts and no poles: a diagnosis needs test cuts or identified poles \
                 (signals alone are not used; identify their poles first)"
                    .into(),
            ));
        }
        let milling = matches!(model.operation(), Operation::Milling(_));
        let mut immersions: Vec<Option<f64>> = vec![None];
        let mut geometry_of = |r: Option<f64>| -> usize {
            match r {
                Some(r) if milling => {
                    if let Some(i) = immersions.iter().position(|x| *x == Some(r)) {
                        i
                    } else {
                        immersions.push(Some(r));
                        immersions.len() - 1
                    }
                }
                _ => 0,
            }
        };
        let cut_geometry: Vec<usize> = observations
            .cuts
            .iter()
            .map(|c| geometry_of(c.radial_immersion))
            .collect();
        let pole_geometry: Vec<usize> = observations
            .poles
            .iter()
            .map(|p| geometry_of(p.radial_immersion))
            .collect();
        let sequences: Vec<Option<i64>> = observations
            .cuts
            .iter()
            .map(|c| c.sequence)
            .chain(observations.poles.iter().map(|p| p.sequence))
            .collect();
        let known: Vec<i64> = sequences.iter().flatten().copied().collect();
        let (lo, hi) = (
            known.iter().copied().min().unwrap_or(0),
            known.iter().copied().max().unwrap_or(0),
        );
        let has_sequence = known.len() == sequences.len() && hi > lo;
        let position = |s: Option<i64>| match s {
            Some(s) if has_sequence => (s - lo) as f64 / (hi - lo) as f64,
            _ => 0.0,
        };
        let cuts = observations
            .cuts
            .iter()
            .zip(&cut_geometry)
            .enumerate()
            .map(|(index, (c, &geometry))| CutPoint {
                index,
                speed_rpm: c.speed_rpm,
                depth_m: c.depth_mm * 1e-3,
                stable: c.stable,
                chatter_hz: c.chatter_hz,
                sequence: c.sequence,
                u: position(c.sequence),
                geometry,
                request: 0,
            })
            .collect();
        let poles = observations
            .poles
            .iter()
            .zip(&pole_geometry)
            .enumerate()
            .map(|(index, (p, &geometry))| PolePoint {
                index,
                speed_rpm: p.speed_rpm,
                depth_m: p.depth_mm * 1e-3,
                frequency_hz: p.frequency_hz,
                damping_ratio: p.damping_ratio,
                frequency_floor_hz: p.frequency_std_hz.unwrap_or(0.0),
                frequency_unit_hz: if milling {
                    reference_hz
                } else {
                    p.frequency_hz.abs()
                },
                damping_std: p.damping_std.unwrap_or(0.0).max(
                    noise.pole_damping_std_relative * p.damping_ratio.abs()
                        + noise.pole_damping_std_floor,
                ),
                sequence: p.sequence,
                u: position(p.sequence),
                geometry,
            })
            .collect();
        let mut data = Self {
            cuts,
            poles,
            requests: Vec::new(),
            immersions,
            has_sequence,
            chatter_std_hz: noise.chatter_std_fraction * reference_hz,
            pole_scales: noise.pole_scales(),
            cut_starts: Vec::new(),
            pole_starts: Vec::new(),
        };
        data.index_requests();
        if milling {
            data.nominal_starts(model);
        }
        Ok(data)
    }

    /// The nominal model's start vectors (in parallel over the observations).
    fn nominal_starts(&mut self, model: &ModalModel) {
        let nominal = Variant::new(model.clone());
        let start = |speed_rpm: f64, depth_m: f64, geometry: usize, u: f64| {
            let m = nominal
                .at(
                    self.immersions.get(geometry).copied().flatten(),
                    speed_rpm,
                    u,
                )
                .ok()?;
            milling_multiplier(&m, speed_rpm, depth_m, None).map(|(_, v)| v)
        };
        self.cut_starts = self
            .cuts
            .par_iter()
            .map(|c| start(c.speed_rpm, c.depth_m, c.geometry, c.u))
            .collect();
        self.pole_starts = self
            .poles
            .par_iter()
            .map(|p| start(p.speed_rpm, p.depth_m, p.geometry, p.u))
            .collect();
    }

    /// The start vector of cut `k` (milling), if any.
    pub fn cut_start(&self, k: usize) -> Option<&[f64]> {
        self.cut_starts.get(k).and_then(Option::as_deref)
    }

    /// The start vector of pole `k` (milling), if any.
    pub fn pole_start(&self, k: usize) -> Option<&[f64]> {
        self.pole_starts.get(k).and_then(Option::as_deref)
    }

    fn index_requests(&mut self) {
        self.requests.clear();
        for c in &mut self.cuts {
            let key = (c.speed_rpm, c.geometry);
            c.request = match self.requests.iter().position(|r| *r == key) {
                Some(i) => i,
                None => {
                    self.requests.push(key);
                    self.requests.len() - 1
                }
            };
        }
    }

    /// The cuts and poles at the given positions (into `cuts` and `poles`), sharing geometries.
    pub fn subset(&self, cuts: &[usize], poles: &[usize]) -> Self {
        let pick = |starts: &[Option<Vec<f64>>], at: &[usize]| -> Vec<Option<Vec<f64>>> {
            if starts.is_empty() {
                return Vec::new();
            }
            at.iter()
                .map(|&i| starts.get(i).cloned().flatten())
                .collect()
        };
        let mut data = Self {
            cuts: cuts
                .iter()
                .filter_map(|&i| self.cuts.get(i).cloned())
                .collect(),
            poles: poles
                .iter()
                .filter_map(|&i| self.poles.get(i).cloned())
                .collect(),
            requests: Vec::new(),
            immersions: self.immersions.clone(),
            has_sequence: self.has_sequence,
            chatter_std_hz: self.chatter_std_hz,
            pole_scales: self.pole_scales.clone(),
            cut_starts: pick(&self.cut_starts, cuts),
            pole_starts: pick(&self.pole_starts, poles),
        };
        data.index_requests();
        data
    }

    /// Number of cuts plus poles.
    pub fn len(&self) -> usize {
        self.cuts.len() + self.poles.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::{Cut, PoleObservation};

    fn cut(speed_rpm: f64, sequence: Option<i64>, radial_immersion: Option<f64>) -> Cut {
        Cut {
            speed_rpm,
            depth_mm: 1.0,
            stable: true,
            chatter_hz: None,
            sequence,
            radial_immersion,
            note: None,
            evidence: None,
        }
    }

    #[test]
    fn sequence_positions_geometries_and_requests() {
        let model = crate::generator::nominal_milling().unwrap();
        let obs = Observations {
            cuts: vec![
                cut(5000.0, Some(3), None),
                cut(5000.0, Some(7), Some(0.5)),
                cut(6000.0, Some(11), None),
                cut(5000.0, Some(5), None),
            ],
            poles: vec![PoleObservation {
                speed_rpm: 6000.0,
                depth_mm: 0.5,
                frequency_hz: 80.0,
                damping_ratio: 0.2,
                frequency_std_hz: None,
                damping_std: Some(0.05),
                repetitions: None,
                sequence: Some(9),
                radial_immersion: None,
                note: None,
            }],
            signals: Vec::new(),
        };
        let data = Dataset::new(&model, &obs, &NoiseModel::default(), 750.0).unwrap();
        assert!(data.has_sequence);
        assert_eq!(data.cuts[0].u, 0.0);
        assert_eq!(data.cuts[2].u, 1.0);
        assert!((data.poles[0].u - 0.75).abs() < 1e-12);
        assert_eq!(data.immersions, vec![None, Some(0.5)]);
        assert_eq!(data.cuts[1].geometry, 1);
        // (5000, 0), (5000, 1), (6000, 0)
        assert_eq!(data.requests.len(), 3);
        assert_eq!(data.cuts[3].request, data.cuts[0].request);
        // a lifted (milling) pole's noise scales with the reference frequency
        assert!((data.poles[0].frequency_std_hz(0.01) - 0.01 * 750.0).abs() < 1e-12);
        // a reported standard deviation above the noise model's floor (0.15 * 0.2 + 0.002) is kept
        assert_eq!(data.poles[0].damping_std, 0.05);
        let sub = data.subset(&[2, 3], &[]);
        assert_eq!(sub.requests.len(), 2);
        assert_eq!(sub.cuts[1].request, 1);
        // one entry without sequence: no campaign positions
        let mut partial = obs.clone();
        partial.cuts[0].sequence = None;
        let data = Dataset::new(&model, &partial, &NoiseModel::default(), 750.0).unwrap();
        assert!(!data.has_sequence);
        assert!(data.cuts.iter().all(|c| c.u == 0.0));
    }
}
