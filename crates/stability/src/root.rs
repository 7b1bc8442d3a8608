//! Bracketed root finding by the Illinois variant of regula falsi (Dowell and Jarratt 1971),
//! shared by the boundary searches: the false-position point of the bracket replaces the end of
//! its sign, and when the same end is replaced twice in a row the function value kept at the
//! other end is halved, which keeps the convergence superlinear where plain regula falsi stalls.

/// A sign change of f: f(`negative`) < 0 <= f(`positive`). The two ends may lie either way
/// round on the line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bracket {
    /// The end where f < 0.
    pub negative: f64,
    /// f there (may be -inf).
    pub f_negative: f64,
    /// The end where f >= 0.
    pub positive: f64,
    /// f there.
    pub f_positive: f64,
}

/// Which end of a bracket the last step replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Replaced {
    Neither,
    Negative,
    Positive,
}

impl Bracket {
    /// The bracket between `(x, f(x))` with f < 0 and `(x, f(x))` with f >= 0.
    pub fn new(negative: (f64, f64), positive: (f64, f64)) -> Self {
        Self {
            negative: negative.0,
            f_negative: negative.1,
            positive: positive.0,
            f_positive: positive.1,
        }
    }

    /// The middle of the bracket.
    pub fn midpoint(&self) -> f64 {
        0.5 * (self.negative + self.positive)
    }

    /// The root the bracket stands for: its positive end where f vanishes exactly there (a
    /// false-position step that lands on the root), else its midpoint.
    pub fn root(&self) -> f64 {
        if self.f_positive == 0.0 {
            self.positive
        } else {
            self.midpoint()
        }
    }

    /// Whether the bracket is at most `relative_tolerance` of its larger end wide, or f vanishes
    /// at its positive end.
    fn converged(&self, relative_tolerance: f64) -> bool {
        let scale = self.negative.abs().max(self.positive.abs());
        self.f_positive == 0.0
            || (self.positive - self.negative).abs() <= relative_tolerance * scale
    }

    /// `x` moved, where it lies closer than a quarter of the tolerance width to an end, that far
    /// inside (Brent's minimum step): once the false-position point sits on the root, the next
    /// step lands just across it and closes the bracket, instead of creeping up to the root from
    /// one side while the other end stays put.
    fn at_least_from_ends(&self, x: f64, relative_tolerance: f64) -> f64 {
        let scale = self.negative.abs().max(self.positive.abs());
        let delta = 0.25 * relative_tolerance * scale;
        let (lo, hi) = if self.negative < self.positive {
            (self.negative, self.positive)
        } else {
            (self.positive, self.negative)
        };
        if hi - lo <= 2.0 * delta {
            return self.midpoint();
        }
        x.clamp(lo + delta, hi - delta)
    }

    /// The false-position point, or the midpoint where that is not strictly inside (infinite or
    /// equal end values).
    fn false_position(&self) -> f64 {
        let x = (self.negative * self.f_positive - self.positive * self.f_negative)
            / (self.f_positive - self.f_negative);
        let (lo, hi) = if self.negative < self.positive {
            (self.negative, self.positive)
        } else {
            (self.positive, self.negative)
        };
        if x > lo && x < hi { x } else { self.midpoint() }
    }
}

/// Shrink `bracket` by Illinois steps on `f` until it is converged to `relative_tolerance`
/// or `max_steps` evaluations are spent; an error of `f` ends the search.
pub(crate) fn illinois<E>(
    mut bracket: Bracket,
    relative_tolerance: f64,
    max_steps: usize,
    mut f: impl FnMut(f64) -> Result<f64, E>,
) -> Result<Bracket, E> {
    let mut last = Replaced::Neither;
    for _ in 0..max_steps {
        if bracket.converged(relative_tolerance) {
            break;
        }
        let x = bracket.at_least_from_ends(bracket.false_position(), relative_tolerance);
        let fx = f(x)?;
        if fx < 0.0 {
            bracket.negative = x;
            bracket.f_negative = fx;
            if last == Replaced::Negative {
                bracket.f_positive *= 0.5;
            }
            last = Replaced::Negative;
        } else {
            bracket.positive = x;
            bracket.f_positive = fx;
            if last == Replaced::Positive {
                bracket.f_negative *= 0.5;
            }
            last = Replaced::Positive;
        }
    }
    Ok(bracket)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::convert::Infallible;

    #[test]
    fn finds_roots_from_either_orientation() {
        let f = |x: f64| Ok::<_, Infallible>(x.powi(3) - 2.0);
        let root = 2f64.cbrt();
        for bracket in [
            Bracket {
                negative: 0.0,
                f_negative: -2.0,
                positive: 3.0,
                f_positive: 25.0,
            },
            Bracket {
                negative: 1.0,
                f_negative: -1.0,
                positive: 1.5,
                f_positive: 1.375,
            },
        ] {
            let b = illinois(bracket, 1e-12, 100, f).unwrap();
            assert!((b.midpoint() - root).abs() < 1e-11, "{b:?}");
        }
        // decreasing function: the negative end lies to the right
        let g = |x: f64| Ok::<_, Infallible>(1.0 - x * x);
        let b = illinois(
            Bracket {
                negative: 2.0,
                f_negative: -3.0,
                positive: 0.0,
                f_positive: 1.0,
            },
            1e-12,
            100,
            g,
        )
        .unwrap();
        assert!((b.midpoint() - 1.0).abs() < 1e-11);
    }

    /// A linear function: the first false-position step lands on the root exactly (f = 0), and
    /// the root is that point, not the midpoint of the bracket it leaves.
    #[test]
    fn exact_hit_is_the_root() {
        let f = |x: f64| Ok::<_, Infallible>(0.5 * x - 0.5);
        let b = illinois(Bracket::new((0.0, -0.5), (1.25, 0.125)), 1e-4, 100, f).unwrap();
        assert_eq!(b.f_positive, 0.0);
        assert_eq!(b.root(), 1.0);
    }

    #[test]
    fn infinite_end_values_fall_back_to_bisection() {
        let f = |x: f64| Ok::<_, Infallible>(if x < 0.3 { f64::NEG_INFINITY } else { 1.0 });
        let b = illinois(
            Bracket {
                negative: 0.0,
                f_negative: f64::NEG_INFINITY,
                positive: 1.0,
                f_positive: 1.0,
            },
            1e-9,
            200,
            f,
        )
        .unwrap();
        assert!((b.midpoint() - 0.3).abs() < 1e-8);
    }
}
