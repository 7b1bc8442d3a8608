//! Modal fitting of one measured receptance: poles by the least-squares complex frequency-domain
//! method (LSCF; Guillaume et al. 2003, the common-denominator estimator behind PolyMAX) over a
//! range of model orders, physical modes picked from a stabilization diagram, then residues by
//! linear least squares with residual terms for the modes outside the band.
//!
//! # Model
//! H(i w) = sum_r [ A_r / (i w - s_r) + conj(A_r) / (i w - conj(s_r)) ] + U - L / w^2,
//! with poles s_r = -zeta_r w_r + i w_r sqrt(1 - zeta_r^2), complex residues A_r (m/(N s);
//! complex = non-proportional damping), the upper residual U (m/N, modes above the band) and the
//! lower residual L (m s^2/N... as 1/mass, modes below it). A real (proportionally damped) mode
//! has a purely imaginary residue A_r = -i phi_r^2 / (2 w_dr), so phi_r^2 = -2 w_dr Im(A_r) and
//! its stiffness at the measured point is k_r = w_r^2 / phi_r^2 (000 Eq. 1).
//!
//! # LSCF
//! With z = exp(i w dt), dt = 1 / (2 f_max), the FRF is the ratio of real-coefficient
//! polynomials B(z) / A(z) of order n; minimizing sum_k |B(z_k) - H_k A(z_k)|^2 over the
//! numerator leaves the reduced normal equations (T - S^T R^-1 S) alpha = 0 with alpha_n = 1,
//! whose matrices are Toeplitz in the lag (computed once for every order). The roots of A give
//! the poles s = ln(z) / dt.
//!
//! # Stabilization
//! A pole of order n is stable when order n - 2 has one within `frequency_tolerance` in
//! frequency and `damping_tolerance` in damping ratio. Stable poles are clustered by frequency;
//! a cluster seen in at least `min_share` of the orders is a physical mode (or the `modes` most
//! frequent clusters when the count is given), represented by its median frequency and damping.
//!
//! # Modes beyond the diagram
//! Without a given count, less frequent clusters, then trial modes at the largest smoothed
//! residual, are added one at a time; a trial is kept when, after the nonlinear refinement,
//! it cuts the misfit by at least 5 % and every mode is still a resonance inside the band
//! (damping ratio at most 0.15). A place whose trial fails is not tried again, so a failed trial
//! (for example a mode just outside the band that wants to move out of it) does not end the
//! search. A mode close outside the band is fitted best by widening the band to include it:
//! residual terms stand for modes far from the band only.

use crate::error::{FrfError, Result};
use crate::frf::Frf;
use chatter_dynamics::pole::{pole_frequency_damping, pole_from_frequency_damping};
use chatter_dynamics::{ModalPole, Mode, ModeShape};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::PI;

/// A candidate mode: frequency (Hz), damping ratio, share of the orders it was stable in.
type Candidate = (f64, f64, f64);

/// Clusters seen in fewer orders than this share are never added as modes.
const MIN_SPARE_SHARE: f64 = 0.1;
/// Most trial modes placed where the fit misses most.
const MAX_RESIDUAL_MODES: usize = 8;
/// Largest damping ratio of a mode added beyond the stabilization diagram's: a wider "mode" is
/// the refinement fitting a smooth trend, not a resonance.
const MAX_ADDED_DAMPING: f64 = 0.15;
/// Share of the real modes' misfit by which the complex modes must fit better for the data to
/// need them ([`ModalFit::needs_complex_modes`]): the same 5 % that an added mode must gain.
pub const COMPLEX_MODE_GAIN: f64 = 0.05;
/// Most clusters tried beyond those that pass `min_share`.
const MAX_SPARE_TRIALS: usize = 12;

/// Options of [`fit_modes`], with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Highest LSCF order (number of poles); default 40.
    pub max_order: usize,
    /// Number of modes; None picks it from the stabilization diagram (default).
    pub modes: Option<usize>,
    /// Relative frequency change of a stable pole between orders; default 0.02.
    pub frequency_tolerance: f64,
    /// Relative damping change of a stable pole between orders; default 0.3 (LSCF damping
    /// scatters with noise; the chosen poles are refined by nonlinear least squares after).
    pub damping_tolerance: f64,
    /// Share of the orders in which a cluster of stable poles must appear to count as a mode;
    /// default 0.3.
    pub min_share: f64,
    /// Residual terms for out-of-band modes; default [`Residuals::UpperAndLower`].
    pub residuals: Residuals,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            max_order: 40,
            modes: None,
            frequency_tolerance: 0.02,
            damping_tolerance: 0.3,
            min_share: 0.3,
            residuals: Residuals::UpperAndLower,
        }
    }
}

/// Residual terms of the fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Residuals {
    /// Modes only.
    None,
    /// An upper residual U (constant) and, when the band does not start at 0 Hz, a lower
    /// residual -L / w^2.
    UpperAndLower,
}

/// One fitted mode: the fit's report of it. [`Self::complex_mode`] and [`Self::real_mode`] give
/// it as the model's [`Mode`], which holds the pole-residue conversion (one place).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FittedMode {
    /// Natural frequency (Hz) and damping ratio: the modal pole every mode type holds (written
    /// as the two fields `frequency_hz`, `damping_ratio`).
    #[serde(flatten)]
    pub pole: ModalPole,
    /// Complex residue A_r of the complex-mode fit (m/(N s)), real and imaginary parts.
    pub residue_m_per_n_s: [f64; 2],
    /// Stiffness (N/m) of the real-mode fit at the measured point; None where that fit gives
    /// the mode a negative modal mass (it cannot be a real mode there).
    pub stiffness_n_per_m: Option<f64>,
    /// Share of the LSCF orders in which the mode was stable.
    pub stability_share: f64,
}

/// One order of the stabilization diagram.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct StabilizationOrder {
    /// Model order n (number of poles).
    pub order: usize,
    /// Physical poles in the band: (frequency Hz, damping ratio, stable).
    pub poles: Vec<(f64, f64, bool)>,
}

/// The result of [`fit_modes`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModalFit {
    /// The band fitted (Hz).
    pub band_hz: (f64, f64),
    /// The modes, ascending in frequency.
    pub modes: Vec<FittedMode>,
    /// Upper residual U (m/N) of the complex-mode fit.
    pub upper_residual_m_per_n: f64,
    /// Lower residual L (1/kg) of the complex-mode fit: the term -L / w^2.
    pub lower_residual_per_kg: f64,
    /// Relative L2 misfit of the complex-mode fit with residual terms over the band.
    pub relative_misfit: f64,
    /// Relative L2 misfit of the real modes alone (what a model file of real modes keeps).
    pub real_mode_relative_misfit: f64,
    /// Relative L2 misfit of the complex modes alone, without residual terms (what a model
    /// file of non-proportional modes keeps).
    pub complex_mode_relative_misfit: f64,
    /// The stabilization diagram.
    pub stabilization: Vec<StabilizationOrder>,
}

impl FittedMode {
    /// The complex residue A_r (m/(N s)).
    pub fn residue(&self) -> Complex64 {
        Complex64::new(self.residue_m_per_n_s[0], self.residue_m_per_n_s[1])
    }

    /// The mode as a model's non-proportional mode at `coordinate` (its complex residue kept,
    /// [`Mode::from_residue`]).
    pub fn complex_mode(&self, coordinate: usize) -> Result<Mode> {
        Ok(Mode::from_residue(
            self.pole.frequency_hz,
            self.pole.damping_ratio,
            coordinate,
            self.residue(),
        )?)
    }

    /// The mode as a real (proportional) mode at `coordinate` with the real-mode refit's
    /// stiffness; None where that refit gives a negative modal mass.
    pub fn real_mode(&self, coordinate: usize) -> Option<Mode> {
        let shape = ModeShape::Directional {
            coordinate,
            stiffness_n_per_m: self.stiffness_n_per_m?,
        };
        Mode::new(self.pole.frequency_hz, self.pole.damping_ratio, shape).ok()
    }
}

impl ModalFit {
    /// The fit's residual terms as a model holds them (`chatter_dynamics::ResidualTerms`,
    /// `residuals` in model files): U - L / w^2 on the fitted coordinate's direct receptance.
    pub fn residual_terms(&self) -> chatter_dynamics::ResidualTerms {
        chatter_dynamics::ResidualTerms {
            upper_m_per_n: self.upper_residual_m_per_n,
            lower_per_kg: self.lower_residual_per_kg,
        }
    }

    /// The complex-mode fit with its residual terms at `frequency_hz`.
    pub fn receptance(&self, frequency_hz: f64) -> Complex64 {
        let w = 2.0 * PI * frequency_hz;
        let iw = Complex64::new(0.0, w);
        let mut h = Complex64::new(self.upper_residual_m_per_n, 0.0);
        if w > 0.0 {
            h -= self.lower_residual_per_kg / (w * w);
        }
        for m in &self.modes {
            let s = m.pole.pole();
            let a = m.residue();
            h += a / (iw - s) + a.conj() / (iw - s.conj());
        }
        h
    }

    /// The real modes alone at `frequency_hz`: sum k_r^-1 w_r^2 / (w_r^2 - w^2 + 2 i zeta_r w_r w).
    pub fn real_mode_receptance(&self, frequency_hz: f64) -> Complex64 {
        self.modes
            .iter()
            .filter_map(|m| m.real_mode(0))
            .map(|m| m.receptance(frequency_hz, 0, 0))
            .sum()
    }

    /// The complex modes alone, without residual terms, at `frequency_hz`: what a model file
    /// with non-proportional modes keeps.
    pub fn complex_mode_receptance(&self, frequency_hz: f64) -> Complex64 {
        self.modes
            .iter()
            .filter_map(|m| m.complex_mode(0).ok())
            .map(|m| m.receptance(frequency_hz, 0, 0))
            .sum()
    }

    /// Whether the data need non-proportional modes: the complex modes alone fit the band
    /// better than the real modes by more than [`COMPLEX_MODE_GAIN`] of the real modes' misfit.
    pub fn needs_complex_modes(&self) -> bool {
        self.complex_mode_relative_misfit
            < (1.0 - COMPLEX_MODE_GAIN) * self.real_mode_relative_misfit
    }
}

/// Toeplitz lag sums of the LSCF normal equations: r and t for lags 0..=n (real weights, so
/// negative lags are conjugates), s for lags -n..=n at index n + lag.
struct Lags {
    r: Vec<Complex64>,
    s: Vec<Complex64>,
    t: Vec<Complex64>,
    n: usize,
}

fn lags(x: &[f64], h: &[Complex64], dt: f64, n: usize) -> Lags {
    let mut l = Lags {
        r: vec![Complex64::new(0.0, 0.0); n + 1],
        s: vec![Complex64::new(0.0, 0.0); 2 * n + 1],
        t: vec![Complex64::new(0.0, 0.0); n + 1],
        n,
    };
    for (&f, &hk) in x.iter().zip(h) {
        let step = Complex64::from_polar(1.0, 2.0 * PI * f * dt);
        let mut z = Complex64::new(1.0, 0.0);
        for d in 0..=n {
            l.r[d] += z;
            l.s[n + d] += hk * z;
            l.s[n - d] += hk * z.conj();
            l.t[d] += hk.norm_sqr() * z;
            z *= step;
        }
    }
    l
}

/// Real part of the lag sum at lag `d` (negative lags are conjugates).
fn lag(v: &[Complex64], d: i64) -> Complex64 {
    if d >= 0 {
        v[d as usize]
    } else {
        v[(-d) as usize].conj()
    }
}

/// The poles (rad/s) of the LSCF model of order `n`.
fn lscf_poles(l: &Lags, n: usize, dt: f64) -> Option<Vec<Complex64>> {
    let m = n + 1;
    let idx = |j: usize, k: usize| k as i64 - j as i64;
    let r = DMatrix::from_fn(m, m, |j, k| lag(&l.r, idx(j, k)).re);
    let s = DMatrix::from_fn(m, m, |j, k| -l.s[(l.n as i64 + idx(j, k)) as usize].re);
    let t = DMatrix::from_fn(m, m, |j, k| lag(&l.t, idx(j, k)).re);
    let rs = r.lu().solve(&s)?;
    let mm = t - s.transpose() * rs;
    let a = mm.view((0, 0), (n, n)).into_owned();
    let b = -mm.view((0, n), (n, 1)).into_owned();
    let alpha = a.lu().solve(&b)?;
    let mut companion = DMatrix::<f64>::zeros(n, n);
    for i in 0..n - 1 {
        companion[(i, i + 1)] = 1.0;
    }
    for j in 0..n {
        companion[(n - 1, j)] = -alpha[j];
    }
    let schur = nalgebra::linalg::Schur::try_new(companion, 1e-14, 10_000)?;
    Some(
        schur
            .complex_eigenvalues()
            .iter()
            .filter(|z| z.norm() > 0.0)
            .map(|z| chatter_dynamics::pole::multiplier_pole(*z, dt))
            .collect(),
    )
}

/// Linear least squares for the residues of `poles` (and the residual terms): the fitted
/// coefficients [per mode (Re A, Im A) or Im A only, then U, then L].
fn residues(
    x: &[f64],
    h: &[Complex64],
    poles: &[Complex64],
    complex: bool,
    residual_columns: usize,
) -> Option<Vec<f64>> {
    let per_mode = if complex { 2 } else { 1 };
    let cols = per_mode * poles.len() + residual_columns;
    let rows = 2 * x.len();
    let mut a = DMatrix::<f64>::zeros(rows, cols);
    let mut b = DVector::<f64>::zeros(rows);
    for (k, (&f, &hk)) in x.iter().zip(h).enumerate() {
        let w = 2.0 * PI * f;
        let iw = Complex64::new(0.0, w);
        let mut c = 0;
        let mut put = |c: usize, v: Complex64| {
            a[(2 * k, c)] = v.re;
            a[(2 * k + 1, c)] = v.im;
        };
        for &s in poles {
            let (p, q) = ((iw - s).inv(), (iw - s.conj()).inv());
            if complex {
                put(c, p + q);
                c += 1;
            }
            put(c, Complex64::new(0.0, 1.0) * (p - q));
            c += 1;
        }
        if residual_columns >= 1 {
            put(c, Complex64::new(1.0, 0.0));
            c += 1;
        }
        if residual_columns >= 2 {
            put(c, Complex64::new(-1.0 / (w * w), 0.0));
        }
        b[2 * k] = hk.re;
        b[2 * k + 1] = hk.im;
    }
    // unit columns for conditioning
    let norms: Vec<f64> = (0..cols)
        .map(|c| a.column(c).norm().max(f64::MIN_POSITIVE))
        .collect();
    for (c, n) in norms.iter().enumerate() {
        a.column_mut(c).unscale_mut(*n);
    }
    let sol = a.svd(true, true).solve(&b, 1e-12).ok()?;
    Some(sol.iter().zip(&norms).map(|(v, n)| v / n).collect())
}

/// The residual vector (fit minus data, real and imaginary parts) of the best residues for
/// `poles`.
fn misfit_vector(
    x: &[f64],
    h: &[Complex64],
    poles: &[Complex64],
    residual_columns: usize,
) -> Option<DVector<f64>> {
    let c = residues(x, h, poles, true, residual_columns)?;
    let mut r = DVector::<f64>::zeros(2 * x.len());
    for (k, (&f, &hk)) in x.iter().zip(h).enumerate() {
        let w = 2.0 * PI * f;
        let iw = Complex64::new(0.0, w);
        let mut g = Complex64::new(0.0, 0.0);
        for (n, &s) in poles.iter().enumerate() {
            let a = Complex64::new(c[2 * n], c[2 * n + 1]);
            g += a / (iw - s) + a.conj() / (iw - s.conj());
        }
        let base = 2 * poles.len();
        if residual_columns >= 1 {
            g += c[base];
        }
        if residual_columns >= 2 {
            g -= c[base + 1] / (w * w);
        }
        r[2 * k] = g.re - hk.re;
        r[2 * k + 1] = g.im - hk.im;
    }
    Some(r)
}

/// Poles from (ln f, ln zeta) per mode.
fn poles_of(theta: &[f64]) -> Vec<Complex64> {
    theta
        .chunks(2)
        .map(|c| pole_from_frequency_damping(c[0].exp(), c[1].exp().min(0.99)))
        .collect()
}

/// Levenberg-Marquardt on the frequencies and damping ratios (log scale) with the residues
/// and residual terms eliminated by linear least squares (variable projection), from the
/// stabilization-diagram estimates.
fn refine(
    x: &[f64],
    h: &[Complex64],
    modes: &[(f64, f64)],
    residual_columns: usize,
) -> Vec<(f64, f64)> {
    let mut theta: Vec<f64> = modes.iter().flat_map(|&(f, z)| [f.ln(), z.ln()]).collect();
    let cost =
        |t: &[f64]| misfit_vector(x, h, &poles_of(t), residual_columns).map(|r| r.norm_squared());
    let Some(mut current) = cost(&theta) else {
        return modes.to_vec();
    };
    let mut lambda = 1e-3;
    for _ in 0..25 {
        let Some(r0) = misfit_vector(x, h, &poles_of(&theta), residual_columns) else {
            break;
        };
        let p = theta.len();
        let mut jac = DMatrix::<f64>::zeros(r0.len(), p);
        for j in 0..p {
            let step = if j % 2 == 0 { 1e-7 } else { 1e-5 };
            let mut t = theta.clone();
            t[j] += step;
            let Some(r) = misfit_vector(x, h, &poles_of(&t), residual_columns) else {
                return modes.to_vec();
            };
            jac.set_column(j, &((r - &r0) / step));
        }
        let jtj = jac.transpose() * &jac;
        let jtr = jac.transpose() * &r0;
        let mut improved = false;
        for _ in 0..10 {
            let mut a = jtj.clone();
            for j in 0..p {
                a[(j, j)] += lambda * jtj[(j, j)].max(1e-30);
            }
            let Some(delta) = a.lu().solve(&(-&jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = theta.iter().zip(delta.iter()).map(|(t, d)| t + d).collect();
            match cost(&trial) {
                Some(c) if c < current => {
                    let gain = (current - c) / current;
                    theta = trial;
                    current = c;
                    lambda = (lambda * 0.3).max(1e-9);
                    improved = gain > 1e-10;
                    break;
                }
                _ => lambda *= 10.0,
            }
        }
        if !improved {
            break;
        }
    }
    theta.chunks(2).map(|c| (c[0].exp(), c[1].exp())).collect()
}

/// Fit modes to `frf` over [`fmin_hz`, `fmax_hz`].
pub fn fit_modes(frf: &Frf, fmin_hz: f64, fmax_hz: f64, options: &FitOptions) -> Result<ModalFit> {
    if !(options.max_order >= 2 && options.max_order <= 200) {
        return Err(FrfError::value(
            "max_order",
            options.max_order as f64,
            "an LSCF order in 2..=200",
        ));
    }
    if let Some(m) = options.modes
        && (m == 0 || 2 * m > options.max_order)
    {
        return Err(FrfError::value(
            "modes",
            m as f64,
            format!("1 to max_order / 2 = {} modes", options.max_order / 2),
        ));
    }
    for (name, v) in [
        ("frequency_tolerance", options.frequency_tolerance),
        ("damping_tolerance", options.damping_tolerance),
        ("min_share", options.min_share),
    ] {
        if !(v > 0.0 && v <= 1.0) {
            return Err(FrfError::value(name, v, "in (0, 1]"));
        }
    }
    let band = frf.band(fmin_hz, fmax_hz)?;
    let x = band.frequencies_hz();
    let raw = band.receptance_m_per_n();
    if x.len() < 4 * options.max_order.max(2) / 2 {
        return Err(FrfError::Fit(format!(
            "{} frequencies in {fmin_hz} to {fmax_hz} Hz: too few for order {}",
            x.len(),
            options.max_order
        )));
    }
    let scale = (raw.iter().map(|h| h.norm_sqr()).sum::<f64>() / raw.len() as f64).sqrt();
    if scale == 0.0 {
        return Err(FrfError::Fit("the FRF is zero over the band".into()));
    }
    let h: Vec<Complex64> = raw.iter().map(|v| v / scale).collect();
    let f_hi = x[x.len() - 1];
    let dt = 1.0 / (2.0 * f_hi * 1.05);
    let max_order = options.max_order - options.max_order % 2;
    let l = lags(x, &h, dt, max_order);
    // poles per order, physical and in band
    let mut orders: Vec<(usize, Vec<(f64, f64)>)> = Vec::new();
    for n in (2..=max_order).step_by(2) {
        let Some(poles) = lscf_poles(&l, n, dt) else {
            continue;
        };
        let mut phys: Vec<(f64, f64)> = poles
            .iter()
            .filter(|s| s.im > 0.0 && s.re < 0.0)
            .map(|&s| pole_frequency_damping(s))
            .filter(|&(f, z)| f >= x[0] && f <= f_hi && z > 0.0 && z < 0.5)
            .collect();
        phys.sort_by(|a, b| a.0.total_cmp(&b.0));
        orders.push((n, phys));
    }
    let mut stabilization = Vec::with_capacity(orders.len());
    let mut stable: Vec<(f64, f64, usize)> = Vec::new();
    for (k, (n, poles)) in orders.iter().enumerate() {
        let previous = k.checked_sub(1).map(|p| &orders[p].1);
        let row: Vec<(f64, f64, bool)> = poles
            .iter()
            .map(|&(f, z)| {
                let ok = previous.is_some_and(|prev| {
                    prev.iter().any(|&(fp, zp)| {
                        (f - fp).abs() <= options.frequency_tolerance * f
                            && (z - zp).abs() <= options.damping_tolerance * z
                    })
                });
                (f, z, ok)
            })
            .collect();
        stable.extend(row.iter().filter(|p| p.2).map(|p| (p.0, p.1, *n)));
        stabilization.push(StabilizationOrder {
            order: *n,
            poles: row,
        });
    }
    // clusters of stable poles by frequency
    stable.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut clusters: Vec<Vec<(f64, f64, usize)>> = Vec::new();
    for p in stable {
        match clusters.last_mut() {
            Some(c) if (p.0 - c[c.len() - 1].0).abs() <= options.frequency_tolerance * p.0 => {
                c.push(p)
            }
            _ => clusters.push(vec![p]),
        }
    }
    let total = orders.len().max(1) as f64;
    let mut candidates: Vec<Candidate> = clusters
        .iter()
        .map(|c| {
            let mut ords: Vec<usize> = c.iter().map(|p| p.2).collect();
            ords.sort_unstable();
            ords.dedup();
            let share = ords.len() as f64 / total;
            let median = |mut v: Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            (
                median(c.iter().map(|p| p.0).collect()),
                median(c.iter().map(|p| p.1).collect()),
                share,
            )
        })
        .collect();
    candidates.sort_by(|a, b| b.2.total_cmp(&a.2));
    let (chosen, spare): (Vec<Candidate>, Vec<Candidate>) = match options.modes {
        Some(m) => (candidates.into_iter().take(m).collect(), Vec::new()),
        None => candidates
            .into_iter()
            .partition(|c| c.2 >= options.min_share),
    };
    if chosen.is_empty() {
        return Err(FrfError::Fit(format!(
            "no pole stable in at least {:.0} % of the orders 2..{max_order} between {fmin_hz} and \
             {fmax_hz} Hz",
            100.0 * options.min_share
        )));
    }
    let residual_columns = match options.residuals {
        Residuals::None => 0,
        Residuals::UpperAndLower if x[0] > 0.0 => 2,
        Residuals::UpperAndLower => 1,
    };
    let refined = |chosen: &[Candidate]| -> Vec<Candidate> {
        let start: Vec<(f64, f64)> = chosen.iter().map(|c| (c.0, c.1)).collect();
        refine(x, &h, &start, residual_columns)
            .into_iter()
            .zip(chosen)
            .map(|((f, z), c)| (f, z, c.2))
            .collect()
    };
    let fit = |chosen: &[Candidate]| -> Result<(Vec<f64>, Vec<Complex64>)> {
        let poles: Vec<Complex64> = chosen
            .iter()
            .map(|&(f, z, _)| pole_from_frequency_damping(f, z))
            .collect();
        let c = residues(x, &h, &poles, true, residual_columns)
            .ok_or_else(|| FrfError::Fit("the residue least squares failed".into()))?;
        Ok((c, poles))
    };
    let mut chosen = refined(&chosen);
    if options.modes.is_none() {
        // add less frequent clusters while each cuts the misfit by at least 5 %
        let misfit = |c: &[Candidate]| {
            let poles: Vec<Complex64> = c
                .iter()
                .map(|m| poles_of(&[m.0.ln(), m.1.ln()])[0])
                .collect();
            misfit_vector(x, &h, &poles, residual_columns).map_or(f64::INFINITY, |r| r.norm())
        };
        // an added mode must stay a resonance inside the band after refinement
        let physical = |c: &[Candidate]| {
            c.iter()
                .all(|m| m.0 >= x[0] && m.0 <= f_hi && m.1 > 0.0 && m.1 <= MAX_ADDED_DAMPING)
        };
        let mut current = misfit(&chosen);
        for cand in spare
            .iter()
            .filter(|c| c.2 >= MIN_SPARE_SHARE)
            .take(MAX_SPARE_TRIALS)
        {
            if chosen
                .iter()
                .any(|c| (c.0 - cand.0).abs() <= options.frequency_tolerance * c.0)
            {
                continue;
            }
            let mut trial = chosen.clone();
            trial.push(*cand);
            let trial = refined(&trial);
            let m = misfit(&trial);
            if physical(&trial) && m < 0.95 * current {
                chosen = trial;
                current = m;
            }
        }
        // then modes where the fit misses most (a mode the diagram did not stabilize); a place
        // whose trial fails is not tried again
        let mut tried: Vec<f64> = Vec::new();
        for _ in 0..MAX_RESIDUAL_MODES {
            let poles: Vec<Complex64> = chosen
                .iter()
                .map(|m| poles_of(&[m.0.ln(), m.1.ln()])[0])
                .collect();
            let Some(r) = misfit_vector(x, &h, &poles, residual_columns) else {
                break;
            };
            // residual power smoothed over +-1 % in frequency
            let power: Vec<f64> = (0..x.len())
                .map(|k| r[2 * k].powi(2) + r[2 * k + 1].powi(2))
                .collect();
            let mut best = (0.0, x[0]);
            let mut lo = 0;
            let mut hi = 0;
            let mut sum = 0.0;
            for &f in x {
                while hi < x.len() && x[hi] <= 1.01 * f {
                    sum += power[hi];
                    hi += 1;
                }
                while x[lo] < 0.99 * f {
                    sum -= power[lo];
                    lo += 1;
                }
                let fresh = tried.iter().all(|&t| (f - t).abs() > 0.02 * t);
                if fresh && sum > best.0 {
                    best = (sum, f);
                }
            }
            let mut trial = chosen.clone();
            trial.push((best.1, 0.03, 0.0));
            let trial = refined(&trial);
            let m = misfit(&trial);
            if physical(&trial) && m < 0.95 * current {
                chosen = trial;
                current = m;
            } else {
                tried.push(best.1);
            }
        }
    }
    let (mut coeffs, mut poles) = fit(&chosen)?;
    if options.modes.is_none() && chosen.len() > 1 {
        // drop modes that contribute under 2 % of the peak receptance, refit once
        let peak = h.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let keep: Vec<Candidate> = chosen
            .iter()
            .zip(&poles)
            .enumerate()
            .filter(|(r, (_, s))| {
                let a = Complex64::new(coeffs[2 * r], coeffs[2 * r + 1]);
                a.norm() / s.re.abs() >= 0.02 * peak
            })
            .map(|(_, (c, _))| *c)
            .collect();
        if !keep.is_empty() && keep.len() < chosen.len() {
            chosen = refined(&keep);
            (coeffs, poles) = fit(&chosen)?;
        }
    }
    let real = residues(x, &h, &poles, false, residual_columns)
        .ok_or_else(|| FrfError::Fit("the real-mode least squares failed".into()))?;
    let nm = chosen.len();
    let mut modes: Vec<FittedMode> = chosen
        .iter()
        .zip(&poles)
        .enumerate()
        .map(|(r, (&(f, z, share), s))| {
            let wd = s.im;
            let phi2 = -2.0 * wd * real[r] * scale;
            let wn = 2.0 * PI * f;
            FittedMode {
                pole: ModalPole::new(f, z),
                residue_m_per_n_s: [coeffs[2 * r] * scale, coeffs[2 * r + 1] * scale],
                stiffness_n_per_m: (phi2 > 0.0).then(|| wn * wn / phi2),
                stability_share: share,
            }
        })
        .collect();
    let upper = coeffs.get(2 * nm).copied().unwrap_or(0.0) * scale;
    let lower = if residual_columns == 2 {
        coeffs[2 * nm + 1] * scale
    } else {
        0.0
    };
    modes.sort_by(|a, b| a.pole.frequency_hz.total_cmp(&b.pole.frequency_hz));
    let mut out = ModalFit {
        band_hz: (fmin_hz, fmax_hz),
        modes,
        upper_residual_m_per_n: upper,
        lower_residual_per_kg: lower,
        relative_misfit: f64::NAN,
        real_mode_relative_misfit: f64::NAN,
        complex_mode_relative_misfit: f64::NAN,
        stabilization,
    };
    out.relative_misfit = band
        .relative_misfit(|f| Some(out.receptance(f)), fmin_hz, fmax_hz)
        .unwrap_or(f64::NAN);
    out.real_mode_relative_misfit = band
        .relative_misfit(|f| Some(out.real_mode_receptance(f)), fmin_hz, fmax_hz)
        .unwrap_or(f64::NAN);
    out.complex_mode_relative_misfit = band
        .relative_misfit(|f| Some(out.complex_mode_receptance(f)), fmin_hz, fmax_hz)
        .unwrap_or(f64::NAN);
    Ok(out)
}
