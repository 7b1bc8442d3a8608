//! Gaussian-process regression with a Matérn kernel (Rasmussen and Williams 2006, Ch. 2, 4.2 and
//! 5.4), the surrogate of Ebrahimi-Tirtashi and Ahmadi 2025 (seed 002, Section 3.3: a Matérn GPR
//! of the dominant closed-loop frequency and damping as functions of theta, trained on samples
//! that cover the prior).
//!
//! Model: y_i = f(x_i) + e_i, f ~ GP(m, k), e_i ~ N(0, sigma_n^2), with the Matérn kernel of
//! scaled distance r = sqrt(sum_q (x_q - x'_q)^2 / l_q^2) (one length scale l_q per input):
//!
//! - nu = 3/2: k(r) = sigma_f^2 (1 + sqrt(3) r) exp(-sqrt(3) r);
//! - nu = 5/2: k(r) = sigma_f^2 (1 + sqrt(5) r + 5 r^2 / 3) exp(-sqrt(5) r).
//!
//! The mean m is zero or a constant estimated by generalized least squares,
//! m = 1' K^-1 y / 1' K^-1 1 with K = k(X, X) + sigma_n^2 I. Prediction at x* (R&W Eq. 2.25-2.26,
//! plus the GLS mean term of Eq. 2.42):
//!
//! - mean m + k*' K^-1 (y - m 1);
//! - variance of f(x*): sigma_f^2 - k*' K^-1 k* (+ (1 - 1' K^-1 k*)^2 / 1' K^-1 1 for the
//!   constant mean), without the noise sigma_n^2.
//!
//! Hyperparameters (l_q, sigma_f^2, sigma_n^2) maximize the log marginal likelihood (R&W Eq. 2.30)
//! ln p(y | X) = -1/2 r' K^-1 r - sum_i ln L_ii - n/2 ln 2 pi (r = y - m 1, K = L L'), with its
//! analytic gradient d/d theta_k = 1/2 tr((a a' - K^-1) dK/d theta_k), a = K^-1 r (Eq. 5.9; by the
//! envelope theorem the profiled mean adds nothing). The optimizer is L-BFGS over logarithms of the
//! hyperparameters, each mapped into a box by a logistic function, from several deterministic
//! starting points evaluated in parallel; the best optimum wins (ties to the first start), so the
//! fit does not depend on the number of threads.
//!
//! Outputs are centered (constant mean) and scaled to unit spread before fitting; the box is
//! l_q in [1e-3, 1e3] times the range of input q, sigma_f^2 in [1e-4, 1e4] and sigma_n^2 in
//! [`GpOptions::min_noise_ratio`, 1] times the output variance.
//!
//! Linear algebra is nalgebra's dense Cholesky: the crate already speaks nalgebra (sample
//! covariances, proposals), and training sets of surrogates are small (hundreds to a few thousand
//! points), where faer's faster blocked and parallel factorizations would not pay for a second
//! matrix type in the public interface. Fitting costs O(n^3) per optimizer iteration; prediction
//! O(n d) for the mean and O(n^2) for the variance.

use crate::error::{BayesError, Result};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::collections::VecDeque;
use std::f64::consts::PI;

/// The Matérn smoothness nu.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kernel {
    /// nu = 3/2: once mean-square differentiable.
    Matern32,
    /// nu = 5/2: twice mean-square differentiable (the usual choice for smooth responses).
    Matern52,
}

impl Kernel {
    /// k(r) / sigma_f^2 and the factor g with dk/d ln l_q = sigma_f^2 g (x_q - x'_q)^2 / l_q^2.
    fn value_and_length_factor(self, r: f64) -> (f64, f64) {
        match self {
            Kernel::Matern32 => {
                let a = 3f64.sqrt() * r;
                let e = (-a).exp();
                ((1.0 + a) * e, 3.0 * e)
            }
            Kernel::Matern52 => {
                let a = 5f64.sqrt() * r;
                let e = (-a).exp();
                ((1.0 + a + a * a / 3.0) * e, 5.0 / 3.0 * (1.0 + a) * e)
            }
        }
    }
}

/// The prior mean of the process.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeanFunction {
    /// m = 0.
    Zero,
    /// A constant m estimated by generalized least squares.
    Constant,
}

/// How the noise variance sigma_n^2 is set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoiseVariance {
    /// Fitted with the other hyperparameters.
    Fitted,
    /// Fixed at this variance (output units squared), raised to the numerical floor
    /// [`GpOptions::min_noise_ratio`] times the output variance if below it.
    Fixed(f64),
}

/// Options of [`GaussianProcess::fit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpOptions {
    /// Kernel (default Matérn 5/2).
    pub kernel: Kernel,
    /// Mean function (default constant).
    pub mean: MeanFunction,
    /// Noise variance (default fitted).
    pub noise: NoiseVariance,
    /// Floor of sigma_n^2 relative to the output variance, which keeps K well conditioned
    /// (default 1e-8: interpolation to about 1e-4 output standard deviations).
    pub min_noise_ratio: f64,
    /// Optimizer starting points: length scales from 0.1 to 3 times the input ranges (default 4).
    pub starts: usize,
    /// L-BFGS iterations per start (default 200).
    pub max_iterations: usize,
}

impl Default for GpOptions {
    fn default() -> Self {
        Self {
            kernel: Kernel::Matern52,
            mean: MeanFunction::Constant,
            noise: NoiseVariance::Fitted,
            min_noise_ratio: 1e-8,
            starts: 4,
            max_iterations: 200,
        }
    }
}

impl GpOptions {
    /// The options if the noise floor is in (0, 1), a fixed noise is finite and >= 0, and there is
    /// at least one start and one iteration.
    pub fn validated(self) -> Result<Self> {
        let fixed_ok = match self.noise {
            NoiseVariance::Fitted => true,
            NoiseVariance::Fixed(v) => v.is_finite() && v >= 0.0,
        };
        let ratio_ok = self.min_noise_ratio > 0.0 && self.min_noise_ratio < 1.0;
        if !(ratio_ok && fixed_ok) || self.starts == 0 || self.max_iterations == 0 {
            return Err(BayesError::InvalidInput {
                field: "options",
                message: format!(
                    "{self:?}: need 0 < min_noise_ratio < 1, a finite fixed noise >= 0, \
                     starts >= 1 and max_iterations >= 1"
                ),
            });
        }
        Ok(self)
    }
}

/// Kernel hyperparameters in the units of the data.
#[derive(Debug, Clone, PartialEq)]
pub struct Hyperparameters {
    /// Length scale l_q of each input.
    pub length_scales: Vec<f64>,
    /// Signal variance sigma_f^2.
    pub signal_variance: f64,
    /// Noise variance sigma_n^2.
    pub noise_variance: f64,
}

/// Predictive distribution of f(x*).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Predictive mean.
    pub mean: f64,
    /// Predictive variance of the latent f (add the noise variance for a new observation).
    pub variance: f64,
}

/// Training data with outputs centered and scaled; hyperparameters in log space
/// p = [ln l_1..ln l_d, ln sigma_f^2, ln sigma_n^2] in the scaled output units.
struct Problem<'a> {
    inputs: &'a [Vec<f64>],
    outputs: DVector<f64>,
    kernel: Kernel,
    mean: MeanFunction,
}

/// K factorized at given hyperparameters.
struct Factorized {
    lower: DMatrix<f64>,
    cholesky: nalgebra::Cholesky<f64, nalgebra::Dyn>,
    alpha: DVector<f64>,
    mean: f64,
    /// K^-1 1 and 1' K^-1 1 for the constant mean.
    gls: Option<(DVector<f64>, f64)>,
    neg_log_likelihood: f64,
}

fn scaled_distance(a: &[f64], b: &[f64], inv_lengths: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(inv_lengths)
        .map(|((x, y), il)| ((x - y) * il).powi(2))
        .sum::<f64>()
        .sqrt()
}

impl Problem<'_> {
    fn dimension(&self) -> usize {
        self.inputs[0].len()
    }

    fn factorize(&self, p: &[f64]) -> Option<Factorized> {
        let (n, d) = (self.inputs.len(), self.dimension());
        let inv_lengths: Vec<f64> = p[..d].iter().map(|l| (-l).exp()).collect();
        let (signal, noise) = (p[d].exp(), p[d + 1].exp());
        let k = DMatrix::from_fn(n, n, |i, j| {
            let r = scaled_distance(&self.inputs[i], &self.inputs[j], &inv_lengths);
            signal * self.kernel.value_and_length_factor(r).0 + if i == j { noise } else { 0.0 }
        });
        let cholesky = k.cholesky()?;
        let (mean, gls) = match self.mean {
            MeanFunction::Zero => (0.0, None),
            MeanFunction::Constant => {
                let kinv_ones = cholesky.solve(&DVector::from_element(n, 1.0));
                let total = kinv_ones.sum();
                (
                    kinv_ones.dot(&self.outputs) / total,
                    Some((kinv_ones, total)),
                )
            }
        };
        let residual = self.outputs.add_scalar(-mean);
        let alpha = cholesky.solve(&residual);
        let lower = cholesky.l();
        let log_det_half: f64 = lower.diagonal().iter().map(|v| v.ln()).sum();
        let neg_log_likelihood =
            0.5 * residual.dot(&alpha) + log_det_half + 0.5 * n as f64 * (2.0 * PI).ln();
        neg_log_likelihood.is_finite().then_some(Factorized {
            lower,
            cholesky,
            alpha,
            mean,
            gls,
            neg_log_likelihood,
        })
    }

    /// -ln p(y | X) and its gradient with respect to p (the noise entry last).
    fn objective(&self, p: &[f64]) -> Option<(f64, Vec<f64>)> {
        let f = self.factorize(p)?;
        let (n, d) = (self.inputs.len(), self.dimension());
        let inv_lengths: Vec<f64> = p[..d].iter().map(|l| (-l).exp()).collect();
        let (signal, noise) = (p[d].exp(), p[d + 1].exp());
        let kinv = f.cholesky.inverse();
        let mut gradient = vec![0.0; d + 2];
        for i in 0..n {
            let w = kinv[(i, i)] - f.alpha[i] * f.alpha[i];
            gradient[d] += 0.5 * w * signal;
            gradient[d + 1] += 0.5 * w * noise;
            for j in 0..i {
                // off-diagonal pairs count twice
                let w = kinv[(i, j)] - f.alpha[i] * f.alpha[j];
                let (a, b) = (&self.inputs[i], &self.inputs[j]);
                let r = scaled_distance(a, b, &inv_lengths);
                let (value, factor) = self.kernel.value_and_length_factor(r);
                gradient[d] += w * signal * value;
                for q in 0..d {
                    gradient[q] += w * signal * factor * ((a[q] - b[q]) * inv_lengths[q]).powi(2);
                }
            }
        }
        Some((f.neg_log_likelihood, gradient))
    }
}

/// A box for one log hyperparameter, mapped from an unbounded variable by a logistic function.
#[derive(Debug, Clone, Copy)]
struct LogBox {
    low: f64,
    high: f64,
}

impl LogBox {
    fn value(self, u: f64) -> f64 {
        self.low + (self.high - self.low) / (1.0 + (-u).exp())
    }
    fn derivative(self, u: f64) -> f64 {
        let s = 1.0 / (1.0 + (-u).exp());
        (self.high - self.low) * s * (1.0 - s)
    }
    fn unbounded(self, p: f64) -> f64 {
        let s = ((p - self.low) / (self.high - self.low)).clamp(1e-9, 1.0 - 1e-9);
        (s / (1.0 - s)).ln()
    }
}

/// Minimize f by L-BFGS (memory 8) with an Armijo backtracking line search (quadratic
/// interpolation); None if f fails at u0.
fn lbfgs(
    f: impl Fn(&[f64]) -> Option<(f64, Vec<f64>)>,
    u0: Vec<f64>,
    max_iterations: usize,
) -> Option<(Vec<f64>, f64)> {
    const MEMORY: usize = 8;
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut u = u0;
    let (mut fu, mut g) = f(&u)?;
    let mut history: VecDeque<(Vec<f64>, Vec<f64>, f64)> = VecDeque::new();
    for _ in 0..max_iterations {
        // two-loop recursion for -H g
        let mut q = g.clone();
        let mut alphas = Vec::with_capacity(history.len());
        for (s, y, rho) in history.iter().rev() {
            let a = rho * dot(s, &q);
            q.iter_mut().zip(y).for_each(|(qi, yi)| *qi -= a * yi);
            alphas.push(a);
        }
        let gamma = history.back().map_or(
            1.0 / g.iter().fold(1.0, |m, v| f64::max(m, v.abs())),
            |(s, y, _)| dot(s, y) / dot(y, y),
        );
        q.iter_mut().for_each(|v| *v *= gamma);
        for ((s, y, rho), a) in history.iter().zip(alphas.iter().rev()) {
            let b = rho * dot(y, &q);
            q.iter_mut().zip(s).for_each(|(qi, si)| *qi += (a - b) * si);
        }
        let mut direction: Vec<f64> = q.iter().map(|v| -v).collect();
        let mut slope = dot(&direction, &g);
        if slope >= 0.0 {
            history.clear();
            direction = g.iter().map(|v| -v).collect();
            slope = -dot(&g, &g);
        }
        let mut step = 1.0;
        let mut next = None;
        for _ in 0..40 {
            let trial: Vec<f64> = u
                .iter()
                .zip(&direction)
                .map(|(a, b)| a + step * b)
                .collect();
            match f(&trial) {
                Some((ft, gt)) if ft <= fu + 1e-4 * step * slope => {
                    next = Some((trial, ft, gt));
                    break;
                }
                // minimum of the quadratic through f(0), f'(0) and f(step), kept in [0.1, 0.5] step
                Some((ft, _)) if ft.is_finite() => {
                    let curvature = ft - fu - slope * step;
                    step *= (-0.5 * slope * step / curvature).clamp(0.1, 0.5);
                }
                _ => step *= 0.5,
            }
        }
        let Some((un, fnew, gn)) = next else { break };
        let s: Vec<f64> = un.iter().zip(&u).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = gn.iter().zip(&g).map(|(a, b)| a - b).collect();
        let sy = dot(&s, &y);
        if sy > 1e-12 * dot(&y, &y).sqrt() * dot(&s, &s).sqrt() {
            if history.len() == MEMORY {
                history.pop_front();
            }
            history.push_back((s, y, 1.0 / sy));
        }
        let converged =
            (fu - fnew).abs() <= 1e-10 * (1.0 + fu.abs()) || gn.iter().all(|v| v.abs() < 1e-7);
        (u, fu, g) = (un, fnew, gn);
        if converged {
            break;
        }
    }
    Some((u, fu))
}

/// A fitted Gaussian-process regression model.
#[derive(Debug, Clone)]
pub struct GaussianProcess {
    inputs: Vec<Vec<f64>>,
    kernel: Kernel,
    /// Inverse length scales.
    inv_lengths: Vec<f64>,
    /// sigma_f^2 in scaled units.
    signal: f64,
    lower: DMatrix<f64>,
    alpha: DVector<f64>,
    /// GLS mean in scaled units.
    mean: f64,
    gls: Option<(DVector<f64>, f64)>,
    /// Output centre and scale: y = centre + scale * y_scaled.
    centre: f64,
    scale: f64,
    hyperparameters: Hyperparameters,
    log_marginal_likelihood: f64,
}

fn check_data(inputs: &[Vec<f64>], outputs: &[f64]) -> Result<usize> {
    let d = inputs.first().map_or(0, Vec::len);
    let bad = |m: String| {
        Err(BayesError::InvalidInput {
            field: "training data",
            message: m,
        })
    };
    if inputs.len() < 2 || d == 0 {
        return bad(format!(
            "{} inputs of dimension {d}: need at least 2 points of dimension >= 1",
            inputs.len()
        ));
    }
    if outputs.len() != inputs.len() {
        return bad(format!(
            "{} inputs but {} outputs",
            inputs.len(),
            outputs.len()
        ));
    }
    if let Some(i) = inputs
        .iter()
        .position(|x| x.len() != d || x.iter().any(|v| !v.is_finite()))
    {
        return bad(format!(
            "input {i} ({:?}) is not {d} finite numbers",
            inputs[i]
        ));
    }
    if let Some(i) = outputs.iter().position(|v| !v.is_finite()) {
        return bad(format!("output {i} is {}", outputs[i]));
    }
    Ok(d)
}

impl GaussianProcess {
    /// Fit the hyperparameters by maximizing the log marginal likelihood and condition on the data.
    /// `inputs[i]` is x_i (all of one dimension), `outputs[i]` is y_i.
    pub fn fit(inputs: &[Vec<f64>], outputs: &[f64], options: &GpOptions) -> Result<Self> {
        let options = options.validated()?;
        let d = check_data(inputs, outputs)?;
        let (centre, scale) = output_scaling(outputs, options.mean);
        let ranges: Vec<f64> = (0..d)
            .map(|q| {
                let (lo, hi) = inputs
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |m, x| {
                        (m.0.min(x[q]), m.1.max(x[q]))
                    });
                if hi > lo { hi - lo } else { 1.0 }
            })
            .collect();
        let mut boxes: Vec<LogBox> = ranges
            .iter()
            .map(|r| LogBox {
                low: (1e-3 * r).ln(),
                high: (1e3 * r).ln(),
            })
            .collect();
        boxes.push(LogBox {
            low: 1e-4f64.ln(),
            high: 1e4f64.ln(),
        });
        let noise_floor = options.min_noise_ratio.ln();
        let fixed_noise = match options.noise {
            NoiseVariance::Fitted => {
                boxes.push(LogBox {
                    low: noise_floor,
                    high: 0.0,
                });
                None
            }
            NoiseVariance::Fixed(v) => Some((v / (scale * scale)).ln().max(noise_floor)),
        };
        let problem = Problem {
            inputs,
            outputs: DVector::from_iterator(
                outputs.len(),
                outputs.iter().map(|y| (y - centre) / scale),
            ),
            kernel: options.kernel,
            mean: options.mean,
        };
        let to_p = |u: &[f64]| -> Vec<f64> {
            let mut p: Vec<f64> = u.iter().zip(&boxes).map(|(v, b)| b.value(*v)).collect();
            p.extend(fixed_noise);
            p
        };
        let objective = |u: &[f64]| -> Option<(f64, Vec<f64>)> {
            let (value, gradient) = problem.objective(&to_p(u))?;
            let chained = u
                .iter()
                .zip(&boxes)
                .zip(&gradient)
                .map(|((v, b), g)| g * b.derivative(*v))
                .collect();
            Some((value, chained))
        };
        let best = (0..options.starts)
            .into_par_iter()
            .filter_map(|s| {
                let fraction = if options.starts > 1 {
                    s as f64 / (options.starts - 1) as f64
                } else {
                    0.5
                };
                let length_factor = 0.1 * 30f64.powf(fraction);
                let mut p0: Vec<f64> = ranges.iter().map(|r| (length_factor * r).ln()).collect();
                p0.push(0.0);
                if fixed_noise.is_none() {
                    p0.push((1e-3f64).ln().max(noise_floor));
                }
                let u0 = p0
                    .iter()
                    .zip(&boxes)
                    .map(|(p, b)| b.unbounded(*p))
                    .collect();
                lbfgs(objective, u0, options.max_iterations)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .ok_or_else(|| {
                BayesError::Degenerate(
                    "the kernel matrix is not positive definite at any starting point".into(),
                )
            })?;
        let p = to_p(&best.0);
        Self::condition(problem, &p, centre, scale)
    }

    /// Condition on the data with given hyperparameters (no fitting).
    pub fn with_hyperparameters(
        inputs: &[Vec<f64>],
        outputs: &[f64],
        kernel: Kernel,
        mean: MeanFunction,
        hyperparameters: &Hyperparameters,
    ) -> Result<Self> {
        let d = check_data(inputs, outputs)?;
        let h = hyperparameters;
        if h.length_scales.len() != d
            || h.length_scales.iter().any(|l| !(*l > 0.0 && l.is_finite()))
            || !(h.signal_variance > 0.0 && h.signal_variance.is_finite())
            || !(h.noise_variance >= 0.0 && h.noise_variance.is_finite())
        {
            return Err(BayesError::InvalidInput {
                field: "hyperparameters",
                message: format!(
                    "{h:?}: need {d} positive length scales, signal variance > 0, noise >= 0"
                ),
            });
        }
        let (centre, scale) = output_scaling(outputs, mean);
        let mut p: Vec<f64> = h.length_scales.iter().map(|l| l.ln()).collect();
        p.push((h.signal_variance / (scale * scale)).ln());
        p.push((h.noise_variance / (scale * scale)).ln());
        let problem = Problem {
            inputs,
            outputs: DVector::from_iterator(
                outputs.len(),
                outputs.iter().map(|y| (y - centre) / scale),
            ),
            kernel,
            mean,
        };
        Self::condition(problem, &p, centre, scale)
    }

    fn condition(problem: Problem<'_>, p: &[f64], centre: f64, scale: f64) -> Result<Self> {
        let d = problem.dimension();
        let f = problem.factorize(p).ok_or_else(|| {
            BayesError::Degenerate(
                "the kernel matrix is not positive definite; raise the noise variance".into(),
            )
        })?;
        let n = problem.inputs.len() as f64;
        Ok(Self {
            inputs: problem.inputs.to_vec(),
            kernel: problem.kernel,
            inv_lengths: p[..d].iter().map(|l| (-l).exp()).collect(),
            signal: p[d].exp(),
            lower: f.lower,
            alpha: f.alpha,
            mean: f.mean,
            gls: f.gls,
            centre,
            scale,
            hyperparameters: Hyperparameters {
                length_scales: p[..d].iter().map(|l| l.exp()).collect(),
                signal_variance: p[d].exp() * scale * scale,
                noise_variance: p[d + 1].exp() * scale * scale,
            },
            // change of variables y = centre + scale y_scaled
            log_marginal_likelihood: -f.neg_log_likelihood - n * scale.ln(),
        })
    }

    /// Input dimension d.
    pub fn dimension(&self) -> usize {
        self.inputs[0].len()
    }

    /// The hyperparameters in data units.
    pub fn hyperparameters(&self) -> &Hyperparameters {
        &self.hyperparameters
    }

    /// ln p(y | X) at the hyperparameters (data units; R&W Eq. 2.30).
    pub fn log_marginal_likelihood(&self) -> f64 {
        self.log_marginal_likelihood
    }

    fn cross_covariance(&self, x: &[f64]) -> Result<DVector<f64>> {
        if x.len() != self.dimension() || x.iter().any(|v| !v.is_finite()) {
            return Err(BayesError::InvalidInput {
                field: "x",
                message: format!("{x:?}: expected {} finite numbers", self.dimension()),
            });
        }
        Ok(DVector::from_iterator(
            self.inputs.len(),
            self.inputs.iter().map(|xi| {
                let r = scaled_distance(x, xi, &self.inv_lengths);
                self.signal * self.kernel.value_and_length_factor(r).0
            }),
        ))
    }

    /// Predictive mean m + k*' K^-1 (y - m 1) at x (O(n d)).
    pub fn predict_mean(&self, x: &[f64]) -> Result<f64> {
        let k = self.cross_covariance(x)?;
        Ok(self.centre + self.scale * (self.mean + k.dot(&self.alpha)))
    }

    /// Predictive mean and latent variance at x (O(n^2)).
    pub fn predict(&self, x: &[f64]) -> Result<Prediction> {
        let k = self.cross_covariance(x)?;
        let v = self
            .lower
            .solve_lower_triangular(&k)
            .ok_or_else(|| BayesError::Degenerate("singular Cholesky factor".into()))?;
        let mut variance = self.signal - v.norm_squared();
        if let Some((kinv_ones, total)) = &self.gls {
            variance += (1.0 - kinv_ones.dot(&k)).powi(2) / total;
        }
        Ok(Prediction {
            mean: self.centre + self.scale * (self.mean + k.dot(&self.alpha)),
            variance: variance.max(0.0) * self.scale * self.scale,
        })
    }
}

/// Centre (mean for a constant mean function, 0 otherwise) and spread of the outputs.
fn output_scaling(outputs: &[f64], mean: MeanFunction) -> (f64, f64) {
    let n = outputs.len() as f64;
    let centre = match mean {
        MeanFunction::Zero => 0.0,
        MeanFunction::Constant => outputs.iter().sum::<f64>() / n,
    };
    let spread = (outputs.iter().map(|y| (y - centre).powi(2)).sum::<f64>() / n).sqrt();
    (centre, if spread > 0.0 { spread } else { 1.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn data() -> (Vec<Vec<f64>>, Vec<f64>) {
        let x: Vec<Vec<f64>> = (0..9)
            .map(|i| vec![i as f64 / 8.0, ((i * 5) % 9) as f64 / 8.0])
            .collect();
        let y = x.iter().map(|v| (3.0 * v[0]).sin() + v[1] * v[1]).collect();
        (x, y)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// The analytic gradient of -ln p(y | X) matches central differences.
        #[test]
        fn gradient_matches_finite_differences(
            l0 in -1.5f64..0.5, l1 in -1.5f64..0.5, s in -1.0f64..1.0, e in -6.0f64..-1.0,
            smooth in any::<bool>(), constant in any::<bool>()
        ) {
            let (x, y) = data();
            let problem = Problem {
                inputs: &x,
                outputs: DVector::from_vec(y),
                kernel: if smooth { Kernel::Matern52 } else { Kernel::Matern32 },
                mean: if constant { MeanFunction::Constant } else { MeanFunction::Zero },
            };
            let p = [l0, l1, s, e];
            let (_, g) = problem.objective(&p).unwrap();
            for k in 0..4 {
                let h = 1e-5;
                let mut a = p;
                let mut b = p;
                a[k] += h;
                b[k] -= h;
                let fd = (problem.objective(&a).unwrap().0 - problem.objective(&b).unwrap().0)
                    / (2.0 * h);
                prop_assert!((fd - g[k]).abs() < 1e-5 * (1.0 + fd.abs()), "{k}: {fd} vs {}", g[k]);
            }
        }
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let (x, y) = data();
        let opts = GpOptions::default();
        assert!(GaussianProcess::fit(&x[..1], &y[..1], &opts).is_err());
        assert!(GaussianProcess::fit(&x, &y[..3], &opts).is_err());
        let mut bad = x.clone();
        bad[2] = vec![f64::NAN, 0.0];
        assert!(GaussianProcess::fit(&bad, &y, &opts).is_err());
        let bad_opts = GpOptions { starts: 0, ..opts };
        assert!(GaussianProcess::fit(&x, &y, &bad_opts).is_err());
        let gp = GaussianProcess::fit(&x, &y, &opts).unwrap();
        assert!(gp.predict(&[0.1]).is_err());
        assert!(gp.predict_mean(&[0.1, f64::INFINITY]).is_err());
    }

    #[test]
    fn given_hyperparameters_reproduce_the_fit() {
        let (x, y) = data();
        let gp = GaussianProcess::fit(&x, &y, &GpOptions::default()).unwrap();
        let again = GaussianProcess::with_hyperparameters(
            &x,
            &y,
            Kernel::Matern52,
            MeanFunction::Constant,
            gp.hyperparameters(),
        )
        .unwrap();
        let at = [0.3, 0.7];
        assert!((gp.predict_mean(&at).unwrap() - again.predict_mean(&at).unwrap()).abs() < 1e-9);
        assert!((gp.log_marginal_likelihood() - again.log_marginal_likelihood()).abs() < 1e-6);
    }
}
