//! Monte Carlo probability-of-stability maps (Schmitz et al. 2022, seed 004, Fig. 2): parameter
//! samples drawn here ([`gaussian_draws`]), their boundaries by the prepared solvers and the map
//! from them in `chatter_updating::sampled` (re-exported), the one home of sampled stability
//! boundaries, which the random-walk paths of `chatter plan` share.
//!
//! Each parameter sample gives its own stability boundary b_lim,s(Omega); the probability that a
//! cut (Omega, b) is stable is the fraction of samples whose boundary lies above it. A sample
//! that gives no valid model, or whose boundary search fails at a speed, is counted as a
//! [`SampleFailure`] and reported, never read as stable; one failure does not stop the map.

use crate::error::{Result, UncertaintyError};
use chatter_bayes::Prior;
use chatter_bayes::prior::MultivariateNormalPrior;
pub use chatter_updating::sampled::{
    FailureKind, QuantileBand, SampleFailure, SampledBoundaries, StabilityMap, quantile,
    sample_boundaries,
};
use nalgebra::DMatrix;
use rand::SeedableRng;

/// One draw per sample of theta ~ N(`mean`, `covariance`), seeded: theta = mean + L z with L the
/// Cholesky factor of the covariance and z standard normal
/// ([`chatter_bayes::prior::MultivariateNormalPrior`]'s draw). The draws do not depend on threads.
pub fn gaussian_draws(
    mean: &[f64],
    covariance: &DMatrix<f64>,
    samples: usize,
    seed: u64,
) -> Result<Vec<Vec<f64>>> {
    let d = mean.len();
    if covariance.shape() != (d, d) {
        return Err(UncertaintyError::InvalidInput {
            field: "covariance",
            message: format!(
                "a {d} x {d} matrix expected for {d} parameters, got {} x {}",
                covariance.nrows(),
                covariance.ncols()
            ),
        });
    }
    let rows: Vec<Vec<f64>> = covariance
        .row_iter()
        .map(|r| r.iter().copied().collect())
        .collect();
    // the one multivariate-normal draw of the workspace: mean + L z, z ~ N(0, I)
    let normal = MultivariateNormalPrior::new(mean.to_vec(), &rows).map_err(|e| {
        UncertaintyError::InvalidInput {
            field: "covariance",
            message: e.to_string(),
        }
    })?;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    Ok((0..samples).map(|_| normal.sample(&mut rng)).collect())
}
