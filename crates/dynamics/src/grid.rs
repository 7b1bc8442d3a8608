//! Evenly spaced grids: the one linear-grid helper of the workspace (speeds, depths,
//! frequencies, parameter values), so that every caller spaces its points the same way, bit
//! for bit.

/// `n >= 2` values from `min` to `max` inclusive, the i-th `min + (max - min) i / (n - 1)`
/// (both ends exact); one value `min` for `n = 1` and none for `n = 0`.
///
/// ```
/// use chatter_dynamics::grid::evenly_spaced;
/// assert_eq!(evenly_spaced(1000.0, 2000.0, 3), vec![1000.0, 1500.0, 2000.0]);
/// ```
pub fn evenly_spaced(min: f64, max: f64, n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![min; n];
    }
    (0..n)
        .map(|i| min + (max - min) * i as f64 / (n - 1) as f64)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both ends are the given values to the bit, and the spacing is constant within one ulp of
    /// the span (the points are computed from the ends, not accumulated).
    #[test]
    fn ends_are_exact_and_steps_even() {
        let g = evenly_spaced(0.1, 0.7, 7);
        assert_eq!((g[0], g[6]), (0.1, 0.7));
        for w in g.windows(2) {
            assert!((w[1] - w[0] - 0.1).abs() < 1e-15, "{w:?}");
        }
        assert_eq!(evenly_spaced(3.0, 4.0, 1), vec![3.0]);
        assert!(evenly_spaced(3.0, 4.0, 0).is_empty());
    }
}
