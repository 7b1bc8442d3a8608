//! The small dense eigenproblems of the stability solvers, with fallbacks so that a finite matrix
//! always gets its eigenvalues.
//!
//! The first choice is the allocation-free Francis iteration of [`crate::hessenberg`] (with its
//! exceptional shifts), rerun with normwise deflation when it stalls. When that spends its
//! iteration budget too, the same matrix goes to faer's dense
//! real eigensolver (Hessenberg reduction and a multishift QR with aggressive early deflation, a
//! different algorithm with different failure modes), and when that fails too, to nalgebra's
//! Schur decomposition with a bounded iteration count. Only a matrix with non-finite entries
//! (an operator that overflowed) or one on which all three fail is an error.

use crate::error::{Result, StabilityError};
use crate::hessenberg::{Deflation, francis, hessenberg_eigenvalues};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Sweeps (per order) allowed to nalgebra's Schur decomposition, the last fallback.
const SCHUR_SWEEPS_PER_ORDER: usize = 100;

/// Which algorithm produced a set of eigenvalues (for tests and diagnostics).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum EigenSolver {
    /// The Francis double-shift QR of [`crate::hessenberg`].
    Francis,
    /// faer's dense real eigensolver.
    Faer,
    /// nalgebra's Schur decomposition with a bounded number of sweeps.
    Schur,
}

/// The eigenvalues of the n x n upper Hessenberg matrix with entries `entry(i, j)` (entries below
/// the first subdiagonal ignored), with the algorithm that produced them. The entries are read
/// once into the Francis iteration's work array, and again only for a fallback.
pub(crate) fn hessenberg_eigenvalues_robust(
    n: usize,
    entry: impl Fn(usize, usize) -> f64,
) -> Result<(Vec<Complex64>, EigenSolver)> {
    let mut work: Vec<f64> = (0..n * n).map(|k| entry(k / n, k % n)).collect();
    check_finite(&work, n)?;
    if let Some(values) = hessenberg_eigenvalues(&mut work, n) {
        return Ok((values, EigenSolver::Francis));
    }
    let mut work: Vec<f64> = (0..n * n).map(|k| entry(k / n, k % n)).collect();
    if let Some(values) = francis(&mut work, n, Deflation::Normwise) {
        return Ok((values, EigenSolver::Francis));
    }
    let dense = DMatrix::from_fn(n, n, |i, j| if i > j + 1 { 0.0 } else { entry(i, j) });
    dense_fallback(&dense)
}

/// The eigenvalues of a general dense matrix: Hessenberg reduction and the Francis iteration,
/// then the same fallbacks as [`hessenberg_eigenvalues_robust`].
pub(crate) fn dense_eigenvalues(m: &DMatrix<f64>) -> Result<Vec<Complex64>> {
    let n = m.nrows();
    debug_assert_eq!(n, m.ncols());
    check_finite(m.as_slice(), n)?;
    if n == 0 {
        return Ok(Vec::new());
    }
    let h = m.clone().hessenberg().h();
    let mut rows: Vec<f64> = (0..n * n).map(|k| h[(k / n, k % n)]).collect();
    if let Some(values) = hessenberg_eigenvalues(&mut rows, n) {
        return Ok(values);
    }
    let mut rows: Vec<f64> = (0..n * n).map(|k| h[(k / n, k % n)]).collect();
    if let Some(values) = francis(&mut rows, n, Deflation::Normwise) {
        return Ok(values);
    }
    Ok(dense_fallback(m)?.0)
}

/// faer's eigenvalues of `m`, else nalgebra's bounded Schur decomposition.
fn dense_fallback(m: &DMatrix<f64>) -> Result<(Vec<Complex64>, EigenSolver)> {
    let n = m.nrows();
    let fm = faer::Mat::<f64>::from_fn(n, n, |i, j| m[(i, j)]);
    if let Ok(values) = fm.eigenvalues()
        && values.iter().all(|z| z.re.is_finite() && z.im.is_finite())
    {
        return Ok((values, EigenSolver::Faer));
    }
    nalgebra::Schur::try_new(m.clone(), f64::EPSILON, SCHUR_SWEEPS_PER_ORDER * n.max(1))
        .map(|schur| {
            (
                schur.complex_eigenvalues().iter().copied().collect(),
                EigenSolver::Schur,
            )
        })
        .ok_or_else(|| StabilityError::NoConvergence {
            solver: "eigenvalues",
            detail: format!(
                "Francis QR, faer and nalgebra's Schur decomposition all failed on a {n} x {n} \
                 matrix"
            ),
        })
}

/// An error unless every entry is finite.
fn check_finite(values: &[f64], n: usize) -> Result<()> {
    if values.iter().all(|x| x.is_finite()) {
        return Ok(());
    }
    Err(StabilityError::NoConvergence {
        solver: "eigenvalues",
        detail: format!("{n} x {n} matrix with non-finite entries (the operator overflowed)"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut v: Vec<Complex64>) -> Vec<Complex64> {
        v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        v
    }

    /// The 8 x 8 Arnoldi matrix of issue 14 (zero-depth FDM monodromy of the 3-tooth, 75 %
    /// immersion model at 23 500 rpm): a 4 x 4 block of round-off noise under the invariant
    /// Krylov space. The Francis iteration must now converge on it, to the eigenvalues faer
    /// finds (within 1e-12 of the norm, about 1e3).
    #[test]
    fn issue_14_arnoldi_matrix() {
        let rows = ISSUE_14_ARNOLDI;
        let (ours, solver) = hessenberg_eigenvalues_robust(8, |i, j| rows[i * 8 + j]).unwrap();
        assert_eq!(solver, EigenSolver::Francis);
        let m = DMatrix::from_row_slice(8, 8, &rows);
        let (reference, _) = dense_fallback(&m).unwrap();
        let (ours, reference) = (sorted(ours), sorted(reference));
        for (x, y) in ours.iter().zip(&reference) {
            assert!((x - y).norm() < 1e-12 * 1e3, "{x} vs {y}");
        }
        // the four eigenvalues of the noise block are round-off: below 1e-10 of the norm
        assert_eq!(ours.iter().filter(|z| z.norm() < 1e-7).count(), 4);
    }

    /// The fallbacks agree with the Francis iteration where all converge, on random dense
    /// matrices of orders 1 to 30 (every eigenvalue within 1e-9 of the norm).
    #[test]
    fn fallbacks_agree_with_francis() {
        let mut seed = 99u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for n in 1..=30 {
            let m = DMatrix::from_fn(n, n, |_, _| next());
            let scale = m.norm().max(1.0);
            let francis = sorted(dense_eigenvalues(&m).unwrap());
            let (faer_values, solver) = dense_fallback(&m).unwrap();
            assert_eq!(solver, EigenSolver::Faer);
            let schur: Vec<Complex64> = nalgebra::Schur::try_new(m.clone(), f64::EPSILON, 3000)
                .unwrap()
                .complex_eigenvalues()
                .iter()
                .copied()
                .collect();
            for other in [sorted(faer_values), sorted(schur)] {
                for (x, y) in francis.iter().zip(&other) {
                    assert!((x - y).norm() < 1e-9 * scale, "n {n}: {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn non_finite_matrices_are_errors() {
        let mut m = DMatrix::<f64>::identity(3, 3);
        m[(1, 2)] = f64::NAN;
        assert!(dense_eigenvalues(&m).is_err());
        assert!(hessenberg_eigenvalues_robust(1, |_, _| f64::INFINITY).is_err());
    }

    /// Row-major, from the failing run of `chatter lobes --method fdm --speeds 23500:23501:2`.
    const ISSUE_14_ARNOLDI: [f64; 64] = [
        170.70648104916629,
        -36.2643230930672,
        -7.222458689092438,
        221.1116911046926,
        -163.56669670911498,
        -155.1800706236428,
        -247.84861015030305,
        21.755287461254124,
        802.6629053064366,
        -170.5372093224622,
        -34.002995300476826,
        1112.1841772526157,
        -622.7527633044804,
        -606.5075040905488,
        -1077.7564782675381,
        245.67713847211954,
        0.0,
        0.13270281739389464,
        0.2687889185423068,
        -455.155257809446,
        -918.5218356890778,
        -772.9739063365631,
        -550.0213786864309,
        -899.9716849506893,
        0.0,
        0.0,
        0.0016577332222303595,
        -2.2264783168976576,
        -4.493559845999922,
        -3.781527211784622,
        -2.6909006385051564,
        -4.40267969398914,
        0.0,
        0.0,
        0.0,
        1.0901916386015686,
        2.2003486872220512,
        1.8516940452391104,
        1.3176698817967005,
        2.155821519805878,
        0.0,
        0.0,
        0.0,
        0.0,
        5.3767382779596705e-14,
        4.3870799287903826e-14,
        3.6432990394590964e-14,
        4.1731738845030905e-14,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.447859058116285e-14,
        8.495408154284992e-15,
        3.6747259241197555e-15,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.96485812671928e-14,
        -5.633587499030439e-17,
    ];
}
