//! Eigenvalues of a small real upper Hessenberg matrix by the implicit Francis double-shift QR
//! iteration (Francis 1961; Golub and Van Loan, Matrix Computations, Algorithm 7.5.2, with the
//! deflation rule of the EISPACK routine `hqr` and the exceptional shifts and iteration budget of
//! LAPACK `dlahqr`: a shift every 10 iterations without deflation, which the far-from-normal
//! Arnoldi matrices of monodromy operators need).
//!
//! When the iteration stalls, it is rerun with a second rule: besides the local `hqr` test, a
//! subdiagonal element below the unit round-off times the matrix norm counts as zero (the normwise criterion of Golub and Van Loan, Section 7.5.1): an Arnoldi
//! matrix whose Krylov space is numerically invariant ends in a block of round-off noise, on
//! which the local test alone asks for relative accuracy that noise cannot have (issue 14: an
//! 8 x 8 matrix of the zero-depth monodromy at 23 500 rpm cycled through the whole budget). The
//! exceptional shifts are the classic bottom ones (EISPACK) for the first half of the budget, then
//! alternate between the bottom of the active block and its top (LAPACK), with a varied
//! magnitude, so that no fixed cycle survives them. When the budget is
//! spent anyway the caller falls back to a dense solver ([`crate::eigen`]).
//!
//! The Arnoldi iterations of [`crate::monodromy`] test convergence on the eigenvalues of their
//! k x k Hessenberg matrix (k <= 20) several times per multiplier; a general dense eigensolver
//! first reduces to Hessenberg form and allocates, which cost a quarter of a milling likelihood
//! evaluation. This works in place on the Hessenberg matrix with no allocation beyond the output.

use num_complex::Complex64;

/// Iterations between exceptional shifts (LAPACK `dlahqr`).
const EXCEPTIONAL_EVERY: usize = 10;
/// Multiples of the subdiagonal scale used as exceptional shifts in successive rounds (0.75 is
/// the EISPACK and LAPACK value; the others break cycles that survive it).
const EXCEPTIONAL_FACTORS: [f64; 4] = [0.75, 1.6, 0.3, -1.1];

/// The eigenvalues of the upper Hessenberg matrix `a` (row-major n x n, entries below the first
/// subdiagonal ignored), destroyed in the process. `None` when the iteration does not converge.
pub(crate) fn hessenberg_eigenvalues(a: &mut [f64], n: usize) -> Option<Vec<Complex64>> {
    francis(a, n, Deflation::Local)
}

/// Which subdiagonal elements count as zero.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Deflation {
    /// The local `hqr` test only (fastest on the Arnoldi matrices of the solvers).
    Local,
    /// Also those below the unit round-off times the matrix norm (the retry after a stall).
    Normwise,
}

/// The Francis iteration with the deflation rule `deflation`.
pub(crate) fn francis(a: &mut [f64], n: usize, deflation: Deflation) -> Option<Vec<Complex64>> {
    debug_assert_eq!(a.len(), n * n);
    let at = |i: usize, j: usize| i * n + j;
    let norm: f64 = (0..n)
        .flat_map(|i| (i.saturating_sub(1)..n).map(move |j| (i, j)))
        .map(|(i, j)| a[at(i, j)].abs())
        .sum();
    let negligible = match deflation {
        Deflation::Local => 0.0,
        Deflation::Normwise => f64::EPSILON * norm,
    };
    let mut values = vec![Complex64::new(0.0, 0.0); n];
    // accumulated exceptional shifts
    let mut shift = 0.0;
    // `hi` is the last row of the active block; the block above it is deflated from below
    let mut hi = n as isize - 1;
    while hi >= 0 {
        let nn = hi as usize;
        let mut iterations = 0;
        loop {
            // the lowest negligible subdiagonal element splits off the active block [l, nn]
            let mut l = nn;
            while l >= 1 {
                let mut s = a[at(l - 1, l - 1)].abs() + a[at(l, l)].abs();
                if s == 0.0 {
                    s = norm;
                }
                if a[at(l, l - 1)].abs() + s == s || a[at(l, l - 1)].abs() <= negligible {
                    a[at(l, l - 1)] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[at(nn, nn)];
            if l == nn {
                // one real root
                values[nn] = Complex64::new(x + shift, 0.0);
                hi -= 1;
                break;
            }
            let mut y = a[at(nn - 1, nn - 1)];
            let mut w = a[at(nn, nn - 1)] * a[at(nn - 1, nn)];
            if l == nn - 1 {
                // a 2 x 2 block: two real roots or a complex pair
                let p = 0.5 * (y - x);
                let q = p * p + w;
                let z = q.abs().sqrt();
                x += shift;
                if q >= 0.0 {
                    let z = p + z.copysign(p);
                    let lower = if z != 0.0 { x - w / z } else { x + z };
                    values[nn - 1] = Complex64::new(x + z, 0.0);
                    values[nn] = Complex64::new(lower, 0.0);
                } else {
                    values[nn - 1] = Complex64::new(x + p, -z);
                    values[nn] = Complex64::new(x + p, z);
                }
                hi -= 2;
                break;
            }
            // LAPACK's budget: 30 max(10, n) iterations for a block
            if iterations == 30 * n.max(10) {
                return None;
            }
            if iterations > 0 && iterations % EXCEPTIONAL_EVERY == 0 {
                // exceptional shift against cycling (badly scaled, far from normal matrices):
                // from the bottom of the block (EISPACK) and from its top (LAPACK) in turn, the
                // magnitude varied from one round to the next
                // (the first half of the budget uses the classic bottom shift only)
                let round = iterations.saturating_sub(15 * n.max(10)) / EXCEPTIONAL_EVERY;
                let factor = EXCEPTIONAL_FACTORS[(round / 2) % EXCEPTIONAL_FACTORS.len()];
                if round.is_multiple_of(2) {
                    shift += x;
                    for i in 0..=nn {
                        a[at(i, i)] -= x;
                    }
                    let s = a[at(nn, nn - 1)].abs() + a[at(nn - 1, nn - 2)].abs();
                    x = factor * s;
                    y = x;
                    w = -0.4375 * s * s;
                } else {
                    let s = a[at(l + 1, l)].abs() + a[at(l + 2, l + 1)].abs();
                    x = factor * s + a[at(l, l)];
                    y = x;
                    w = -0.4375 * s * s;
                }
            }
            iterations += 1;
            francis_step(a, n, l, nn, x, y, w);
        }
    }
    Some(values)
}

/// One implicit double-shift QR step on the active block [l, nn] with the shifts the roots of
/// lambda^2 - (x + y) lambda + (x y - w), started at the lowest row m where two consecutive small
/// subdiagonal elements allow it.
fn francis_step(a: &mut [f64], n: usize, l: usize, nn: usize, x: f64, y: f64, w: f64) {
    let at = |i: usize, j: usize| i * n + j;
    let (mut p, mut q, mut r);
    let mut m = nn - 2;
    loop {
        let z = a[at(m, m)];
        let (rx, sy) = (x - z, y - z);
        p = (rx * sy - w) / a[at(m + 1, m)] + a[at(m, m + 1)];
        q = a[at(m + 1, m + 1)] - z - rx - sy;
        r = a[at(m + 2, m + 1)];
        let s = p.abs() + q.abs() + r.abs();
        p /= s;
        q /= s;
        r /= s;
        if m == l {
            break;
        }
        let u = a[at(m, m - 1)].abs() * (q.abs() + r.abs());
        let v = p.abs() * (a[at(m - 1, m - 1)].abs() + z.abs() + a[at(m + 1, m + 1)].abs());
        if u + v == v {
            break;
        }
        m -= 1;
    }
    for i in m + 2..=nn {
        a[at(i, i - 2)] = 0.0;
        if i != m + 2 {
            a[at(i, i - 3)] = 0.0;
        }
    }
    let mut scale = 0.0;
    for k in m..nn {
        if k != m {
            p = a[at(k, k - 1)];
            q = a[at(k + 1, k - 1)];
            r = if k != nn - 1 {
                a[at(k + 2, k - 1)]
            } else {
                0.0
            };
            scale = p.abs() + q.abs() + r.abs();
            if scale != 0.0 {
                p /= scale;
                q /= scale;
                r /= scale;
            }
        }
        let s = (p * p + q * q + r * r).sqrt().copysign(p);
        if s == 0.0 {
            continue;
        }
        if k == m {
            if l != m {
                a[at(k, k - 1)] = -a[at(k, k - 1)];
            }
        } else {
            a[at(k, k - 1)] = -s * scale;
        }
        // Householder reflector I - v v^T / (v_0) with v = (p + s, q, r) / s
        p += s;
        let (hx, hy, hz) = (p / s, q / s, r / s);
        let (hq, hr) = (q / p, r / p);
        for j in k..=nn {
            let mut t = a[at(k, j)] + hq * a[at(k + 1, j)];
            if k != nn - 1 {
                t += hr * a[at(k + 2, j)];
                a[at(k + 2, j)] -= t * hz;
            }
            a[at(k + 1, j)] -= t * hy;
            a[at(k, j)] -= t * hx;
        }
        for i in l..=nn.min(k + 3) {
            let mut t = hx * a[at(i, k)] + hy * a[at(i, k + 1)];
            if k != nn - 1 {
                t += hz * a[at(i, k + 2)];
                a[at(i, k + 2)] -= t * hr;
            }
            a[at(i, k + 1)] -= t * hq;
            a[at(i, k)] -= t;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    fn sorted(mut v: Vec<Complex64>) -> Vec<Complex64> {
        v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        v
    }

    /// Random Hessenberg matrices of every size up to 22 (including non-normal ones with a wide
    /// range of scales) against nalgebra's dense eigenvalues: every eigenvalue within 1e-9 of the
    /// matrix norm, and the trace and determinant invariants.
    #[test]
    fn matches_dense_eigenvalues() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for n in 1..=22 {
            for trial in 0..20 {
                let grade: f64 = if trial % 2 == 0 { 1.0 } else { 1e3 };
                let m = DMatrix::from_fn(n, n, |i, j| {
                    if i > j + 1 {
                        0.0
                    } else {
                        next() * grade.powf((j as f64 - i as f64) / n as f64)
                    }
                });
                let mut a: Vec<f64> = (0..n * n).map(|k| m[(k / n, k % n)]).collect();
                let ours = sorted(hessenberg_eigenvalues(&mut a, n).unwrap());
                let reference = sorted(m.complex_eigenvalues().iter().copied().collect());
                let scale = m.norm().max(1.0);
                for (x, y) in ours.iter().zip(&reference) {
                    assert!((x - y).norm() < 1e-9 * scale, "n {n}: {x} vs {y}");
                }
                let trace: Complex64 = ours.iter().sum();
                assert!(
                    (trace.re - m.trace()).abs() < 1e-10 * scale && trace.im.abs() < 1e-10 * scale
                );
            }
        }
    }

    /// An Arnoldi matrix of the seed-000 turning monodromy (badly scaled, far from normal) on
    /// which two exceptional shifts are not enough: the iteration needs LAPACK's periodic ones.
    #[test]
    fn converges_on_a_badly_scaled_arnoldi_matrix() {
        let v = [
            6.409659692244606,
            -0.41412295355866857,
            -0.13321970119984172,
            1.9635929656075939,
            -3.430257424772569,
            105.86789862762126,
            -6.92441492965071,
            -2.201390598100442,
            47.65910590886067,
            -57.461027058752784,
            0.0,
            0.2623722872674127,
            0.00270853415252571,
            -47.46613298341543,
            2.5053884735355894,
            0.0,
            0.0,
            0.0009639857489148474,
            -0.16474171375804256,
            0.008675380561958842,
            0.0,
            0.0,
            0.0,
            0.19898206062084198,
            -0.01047073884768995,
        ];
        let m = DMatrix::from_row_slice(5, 5, &v);
        let reference = sorted(m.complex_eigenvalues().iter().copied().collect());
        let ours = sorted(hessenberg_eigenvalues(&mut v.to_vec(), 5).unwrap());
        for (x, y) in ours.iter().zip(&reference) {
            assert!((x - y).norm() < 1e-10, "{x} vs {y}");
        }
    }

    #[test]
    fn handles_exact_structure() {
        // a rotation (complex pair on the unit circle), a Jordan block and a zero matrix
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let mut rot = [c, -s, s, c];
        let v = hessenberg_eigenvalues(&mut rot, 2).unwrap();
        assert!((v[0] - Complex64::new(c, -s)).norm() < 1e-15);
        assert!((v[1] - Complex64::new(c, s)).norm() < 1e-15);
        let mut jordan = [2.0, 1.0, 0.0, 0.0, 2.0, 1.0, 0.0, 0.0, 2.0];
        for z in hessenberg_eigenvalues(&mut jordan, 3).unwrap() {
            assert!((z - 2.0).norm() < 1e-12);
        }
        let mut zero = [0.0; 16];
        assert!(
            hessenberg_eigenvalues(&mut zero, 4)
                .unwrap()
                .iter()
                .all(|z| z.norm() == 0.0)
        );
    }
}
