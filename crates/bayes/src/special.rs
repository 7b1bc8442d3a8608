//! Special functions of the samplers and likelihoods, written once: log-sum-exp and its
//! relatives (sums of probabilities kept in log space, shifted by the maximum so that no term
//! overflows), the standard normal distribution function and its inverse.

/// The maximum of `x` and sum_i e^{x_i - max}; the maximum alone (`Err`) where it is not finite
/// (no terms, all -inf, an inf or a NaN): that is then the answer.
fn shifted_sum(x: &[f64]) -> Result<(f64, f64), f64> {
    let m = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() {
        return Err(m);
    }
    Ok((m, x.iter().map(|v| (v - m).exp()).sum()))
}

/// ln sum_i e^{x_i}, shifted by the maximum so that no term overflows; -inf for no terms.
pub fn log_sum_exp(x: &[f64]) -> f64 {
    match shifted_sum(x) {
        Ok((m, sum)) => m + sum.ln(),
        Err(m) => m,
    }
}

/// ln mean_i e^{x_i} (ln of (1/n) sum_i e^{x_i}), shifted as [`log_sum_exp`].
pub fn log_mean_exp(x: &[f64]) -> f64 {
    match shifted_sum(x) {
        Ok((m, sum)) => m + (sum / x.len() as f64).ln(),
        Err(m) => m,
    }
}

/// The weights e^{x_i} / sum_j e^{x_j} of log weights `ln_w` (a softmax), shifted by the maximum.
pub fn normalized_weights(ln_w: &[f64]) -> Vec<f64> {
    let m = ln_w.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w: Vec<f64> = ln_w.iter().map(|x| (x - m).exp()).collect();
    let total: f64 = w.iter().sum();
    w.iter().map(|x| x / total).collect()
}

/// The weighted `q` quantile of `(value, weight)` pairs: the smallest value whose cumulative
/// weight reaches q times the total, inf{x : F(x) >= q} of the weighted empirical distribution
/// (no interpolation); NaN for no pairs.
pub fn weighted_quantile(mut values: Vec<(f64, f64)>, q: f64) -> f64 {
    values.sort_by(|a, b| a.0.total_cmp(&b.0));
    let target = q * values.iter().map(|v| v.1).sum::<f64>();
    let mut acc = 0.0;
    for (x, w) in &values {
        acc += w;
        if acc >= target {
            return *x;
        }
    }
    values.last().map_or(f64::NAN, |x| x.0)
}

/// The `q` quantile of the finite `values`, linearly interpolated between order statistics
/// (Hyndman & Fan type 7, R's default); NaN when there are none. The unweighted companion of
/// [`weighted_quantile`], both the one home of empirical quantiles.
pub fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let h = (values.len() - 1) as f64 * q.clamp(0.0, 1.0);
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    values[lo] + (h - lo as f64) * (values[hi] - values[lo])
}

/// The standard normal distribution function Phi(x) = erfc(-x / sqrt 2) / 2 (relative error
/// < 1.2e-7, from [`erfc`]).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Complementary error function (Numerical Recipes erfcc, relative error < 1.2e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.265_512_23
            + t * (1.000_023_68
                + t * (0.374_091_96
                    + t * (0.096_784_18
                        + t * (-0.186_288_06
                            + t * (0.278_868_07
                                + t * (-1.135_203_98
                                    + t * (1.488_515_87
                                        + t * (-0.822_152_23 + t * 0.170_872_77)))))))))
            .exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Inverse standard normal CDF (Acklam's rational approximation, relative error < 1.2e-9).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against direct sums where they do not overflow, and where they would (1000 + ln 2).
    #[test]
    fn log_sums_match_direct_sums() {
        let x = [0.1, -2.0, 1.5];
        let direct: f64 = x.iter().map(|v: &f64| v.exp()).sum();
        assert!((log_sum_exp(&x) - direct.ln()).abs() < 1e-14);
        assert!((log_mean_exp(&x) - (direct / 3.0).ln()).abs() < 1e-14);
        assert!((log_sum_exp(&[1000.0, 1000.0]) - (1000.0 + 2f64.ln())).abs() < 1e-12);
        assert_eq!(log_sum_exp(&[]), f64::NEG_INFINITY);
        assert_eq!(log_mean_exp(&[f64::NEG_INFINITY]), f64::NEG_INFINITY);
        // 1000 + ln 3 holds ln 3 to an ulp of 1000 (1.1e-13)
        let w = normalized_weights(&[1000.0, 1000.0 + 3f64.ln()]);
        assert!(
            (w[0] - 0.25).abs() < 1e-12 && (w[1] - 0.75).abs() < 1e-12,
            "{w:?}"
        );
    }

    /// Phi and its inverse at tabulated values (Abramowitz and Stegun, Table 26.1 and 26.5);
    /// Phi to the 1.2e-7 of erfc (relative to erfc <= 2, so absolute on Phi).
    #[test]
    fn normal_distribution_matches_tables() {
        assert!((normal_cdf(0.0) - 0.5).abs() < 1.2e-7);
        assert!((normal_cdf(1.959_963_984_540_054) - 0.975).abs() < 1.2e-7);
        assert!((normal_cdf(-1.0) - 0.158_655_253_931_457).abs() < 1.2e-7);
        assert!(normal_quantile(0.5).abs() < 1e-12);
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-8);
        assert!((normal_quantile(0.001) + 3.090_232_306_167_813).abs() < 1e-8);
    }
}
