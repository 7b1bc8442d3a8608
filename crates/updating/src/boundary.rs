//! Limiting depth at one spindle speed by the zero-order method with process damping, fast enough
//! to compute thousands of sampled boundaries (the random-walk paths of 003 and the Monte Carlo
//! stability maps of 004).
//!
//! Zero-order characteristic equation (Altintas and Budak; 003 Section 2 with process damping):
//! with A_0 the average directional matrix and G_b the receptance whose modal damping includes the
//! process damping of width b (equivalent damping ratio zeta_n + b s_n, s_n from
//! [`with_equivalent_damping`]),
//!
//! 1 + b (1 - e^{-i w tau}) Lambda(w; b) = 0, Lambda an eigenvalue of A_0 G_b(i w).
//!
//! It holds where Re Lambda < 0, with b = -1 / (2 Re Lambda) and phase
//! w tau = eps + 2 pi k, eps = (2 arg Lambda - pi) mod 4 pi in (0, 2 pi). So the chatter frequency
//! of lobe k lies in [k / tau, (k + 1) / tau] and is found there by bisection on
//! w tau - eps(w) - 2 pi k (the eigenvalue with the more negative real part is followed). The
//! limiting depth at the speed is the lowest lobe, M(b) = min_k b_k. Lobes are visited in the
//! order of a coarse lower bound of b over their frequency interval and skipped once that bound
//! exceeds twice the best depth found.
//!
//! Process damping: 003 iterates b_{j+1} = M(b_j) from the boundary without process damping. The
//! iteration increases monotonically to the smallest fixed point of b = M(b); here that fixed
//! point is bracketed and refined by the Illinois method, which needs far fewer evaluations of M.

use crate::error::{Result, UpdatingError};
use chatter_dynamics::ModalModel;
use chatter_stability::boundary::LobePoint;
use chatter_stability::process_damping::with_equivalent_damping;
use num_complex::Complex64;
use std::f64::consts::PI;

/// Frequency samples of the coarse scan (geometric, from half the lowest to twice the highest
/// natural frequency, as the zero-order lobes of `chatter-stability`).
const SCAN_SAMPLES: usize = 800;
/// Bisection steps for the chatter frequency of one lobe.
const BISECTION_STEPS: usize = 48;
/// Lobes whose coarse lower bound exceeds this multiple of the best depth are skipped.
const PRUNE_FACTOR: f64 = 2.0;
/// Largest phase residual (rad) accepted as a lobe crossing after bisection.
const PHASE_TOLERANCE: f64 = 1e-3;
/// Relative size below which a real part counts as rounding.
const ROUNDING: f64 = 1e-10;
/// Growth of the fixed-point bracket.
const BRACKET_GROWTH: f64 = 1.5;

/// Options of [`limiting_depth`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryOptions {
    /// Depths above this count as unconditionally stable (m); default 0.1 m.
    pub max_depth_m: f64,
    /// Relative tolerance of the process-damping fixed point; default 1e-4.
    pub relative_tolerance: f64,
}

impl Default for BoundaryOptions {
    fn default() -> Self {
        Self {
            max_depth_m: 0.1,
            relative_tolerance: 1e-4,
        }
    }
}

/// The zero-order problem at one speed.
struct Problem {
    a0: [[f64; 2]; 2],
    omegas: Vec<f64>,
    zetas: Vec<f64>,
    /// d zeta_n / d b (1/m) from process damping.
    slopes: Vec<f64>,
    shapes: Vec<[f64; 2]>,
    tau: f64,
    f_lo: f64,
    f_hi: f64,
}

/// The eigenvalue with the more negative real part of a 2 x 2 complex matrix, or NaN when no
/// real part is negative beyond rounding (a zero eigenvalue, as for modes along one direction,
/// must not count).
fn leading_eigenvalue(m: [[Complex64; 2]; 2]) -> Complex64 {
    let tr = m[0][0] + m[1][1];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let disc = (tr * tr * 0.25 - det).sqrt();
    let (a, b) = (tr * 0.5 + disc, tr * 0.5 - disc);
    let l = if a.re <= b.re { a } else { b };
    if l.re < -ROUNDING * (a.norm() + b.norm()) {
        l
    } else {
        Complex64::new(f64::NAN, f64::NAN)
    }
}

impl Problem {
    fn new(model: &ModalModel, speed_rpm: f64) -> Result<Self> {
        let h = model.average_directional_matrix();
        let zetas = model.damping_ratios();
        let slopes = if model.process_damping_n_per_m().is_some() {
            // the equivalent damping is linear in b; a small reference width keeps it < 1
            let mut reference = 1e-3;
            let damped = loop {
                match with_equivalent_damping(model, speed_rpm, reference) {
                    Ok(m) => break m,
                    Err(_) if reference > 1e-9 => reference *= 1e-3,
                    Err(e) => return Err(e.into()),
                }
            };
            damped
                .damping_ratios()
                .iter()
                .zip(&zetas)
                .map(|(z, z0)| (z - z0) / reference)
                .collect()
        } else {
            vec![0.0; zetas.len()]
        };
        let freqs: Vec<f64> = model.modes().iter().map(|m| m.frequency_hz()).collect();
        Ok(Self {
            a0: [[h[(0, 0)], h[(0, 1)]], [h[(1, 0)], h[(1, 1)]]],
            omegas: model.omegas_rad_s(),
            zetas,
            slopes,
            shapes: model
                .modes()
                .iter()
                .map(|m| m.mass_normalized_shape())
                .collect(),
            tau: model.operation().delay_s(speed_rpm),
            f_lo: 0.5 * freqs.iter().copied().fold(f64::INFINITY, f64::min),
            f_hi: 2.0 * freqs.iter().copied().fold(0.0, f64::max),
        })
    }

    /// Lambda(w; b): the leading eigenvalue of A_0 G_b(i w).
    fn lambda(&self, w: f64, b: f64) -> Complex64 {
        let mut g = [[Complex64::new(0.0, 0.0); 2]; 2];
        for (((&wn, &z), &s), phi) in self
            .omegas
            .iter()
            .zip(&self.zetas)
            .zip(&self.slopes)
            .zip(&self.shapes)
        {
            let zeta = z + b * s;
            let inv = Complex64::new(wn * wn - w * w, 2.0 * zeta * wn * w).inv();
            for (r, row) in g.iter_mut().enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v += inv * (phi[r] * phi[c]);
                }
            }
        }
        let mut m = [[Complex64::new(0.0, 0.0); 2]; 2];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = g[0][c] * self.a0[r][0] + g[1][c] * self.a0[r][1];
            }
        }
        leading_eigenvalue(m)
    }

    /// Depth and phase residual w tau - eps - 2 pi k at w, or None where Re Lambda >= 0.
    fn lobe_point(&self, w: f64, b: f64, k: f64) -> Option<(f64, f64)> {
        let l = self.lambda(w, b);
        if l.re.is_nan() || l.re >= 0.0 {
            return None;
        }
        let eps = (2.0 * l.arg() - PI).rem_euclid(4.0 * PI);
        if !(eps > 0.0 && eps < 2.0 * PI) {
            return None;
        }
        Some((-0.5 / l.re, w * self.tau - eps - 2.0 * PI * k))
    }

    /// M(b): the lowest lobe at this speed with the modal damping of width `b`, with its chatter
    /// frequency (Hz); infinite depth when no lobe exists.
    fn lowest_lobe(&self, b: f64) -> (f64, f64) {
        // coarse lower bound of the depth per lobe interval
        let ratio = self.f_hi / self.f_lo;
        let mut bounds: Vec<(f64, i64)> = Vec::new();
        for i in 0..SCAN_SAMPLES {
            let f = self.f_lo * ratio.powf(i as f64 / (SCAN_SAMPLES - 1) as f64);
            let w = 2.0 * PI * f;
            let l = self.lambda(w, b);
            if l.re.is_nan() || l.re >= 0.0 {
                continue;
            }
            let depth = -0.5 / l.re;
            let k = (f * self.tau).floor() as i64;
            match bounds.iter_mut().find(|e| e.1 == k) {
                Some(e) => e.0 = e.0.min(depth),
                None => bounds.push((depth, k)),
            }
        }
        bounds.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best = (f64::INFINITY, f64::NAN);
        let mut visited: Vec<i64> = Vec::new();
        for &(bound, k) in &bounds {
            if bound > PRUNE_FACTOR * best.0 {
                break;
            }
            for kk in [k - 1, k, k + 1] {
                if kk < 0 || visited.contains(&kk) {
                    continue;
                }
                visited.push(kk);
                if let Some((depth, f)) = self.lobe(kk as f64, b)
                    && depth < best.0
                {
                    best = (depth, f);
                }
            }
        }
        best
    }

    /// The crossing of lobe k: bisection on the phase residual over the part of
    /// [k / tau, (k + 1) / tau] where Re Lambda < 0 (one transition at either end is located by
    /// bisection first, e.g. the resonance inside the interval).
    fn lobe(&self, k: f64, b: f64) -> Option<(f64, f64)> {
        let (mut lo, mut hi) = (
            (2.0 * PI * k / self.tau).max(2.0 * PI * self.f_lo),
            (2.0 * PI * (k + 1.0) / self.tau).min(2.0 * PI * self.f_hi),
        );
        if hi <= lo {
            return None;
        }
        let valid = |w: f64| self.lobe_point(w, b, k).is_some();
        match (valid(lo), valid(hi)) {
            (true, true) => {}
            (false, false) => return None,
            (lo_valid, _) => {
                // shrink to the valid side of the single transition
                let (mut a, mut c) = (lo, hi);
                for _ in 0..BISECTION_STEPS {
                    let mid = 0.5 * (a + c);
                    if valid(mid) == lo_valid {
                        a = mid;
                    } else {
                        c = mid;
                    }
                }
                if lo_valid {
                    hi = a;
                } else {
                    lo = c;
                }
            }
        }
        let g_lo = self.lobe_point(lo, b, k)?.1;
        let g_hi = self.lobe_point(hi, b, k)?.1;
        if !(g_lo < 0.0 && g_hi > 0.0) {
            return None;
        }
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (lo + hi);
            match self.lobe_point(mid, b, k) {
                Some((_, g)) if g < 0.0 => lo = mid,
                Some(_) => hi = mid,
                None => return None,
            }
        }
        let w = 0.5 * (lo + hi);
        // a jump of the followed eigenvalue is not a crossing
        self.lobe_point(w, b, k)
            .filter(|(_, g)| g.abs() < PHASE_TOLERANCE)
            .map(|(depth, _)| (depth, w / (2.0 * PI)))
    }
}

/// Zero-order limiting depth at `speed_rpm`, including the model's process damping (003) when it
/// has one. `depth_m` is infinite when the cut is stable up to `options.max_depth_m`.
pub fn limiting_depth(
    model: &ModalModel,
    speed_rpm: f64,
    options: &BoundaryOptions,
) -> Result<LobePoint> {
    if !(speed_rpm.is_finite() && speed_rpm > 0.0) {
        return Err(UpdatingError::InvalidInput {
            field: "speed_rpm",
            message: format!("{speed_rpm}; expected > 0"),
        });
    }
    let problem = Problem::new(model, speed_rpm)?;
    let unbounded = LobePoint {
        speed_rpm,
        depth_m: f64::INFINITY,
        chatter_hz: f64::NAN,
    };
    let point = |(depth_m, chatter_hz): (f64, f64)| LobePoint {
        speed_rpm,
        depth_m,
        chatter_hz,
    };
    let bare = problem.lowest_lobe(0.0);
    if bare.0.is_nan() || bare.0 > options.max_depth_m {
        return Ok(unbounded);
    }
    if problem.slopes.iter().all(|s| *s == 0.0) {
        return Ok(point(bare));
    }
    // g(b) = M(b) - b >= 0 at the boundary without process damping; bracket the fixed point
    let g = |b: f64| -> (f64, (f64, f64)) {
        let m = problem.lowest_lobe(b);
        (m.0 - b, m)
    };
    let mut lo = bare.0;
    let (mut g_lo, _) = g(lo);
    let mut hi = lo * BRACKET_GROWTH;
    let (mut g_hi, mut at_hi) = g(hi);
    while g_hi >= 0.0 {
        lo = hi;
        g_lo = g_hi;
        hi *= BRACKET_GROWTH;
        if hi > options.max_depth_m {
            return Ok(unbounded);
        }
        (g_hi, at_hi) = g(hi);
    }
    let g_lo_finite = |v: f64| {
        if v.is_finite() {
            v
        } else {
            options.max_depth_m
        }
    };
    g_lo = g_lo_finite(g_lo);
    let mut side = 0i8;
    for _ in 0..100 {
        if hi - lo <= options.relative_tolerance * hi {
            break;
        }
        let mut b = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        if !(b > lo && b < hi) {
            b = 0.5 * (lo + hi);
        }
        let (gb, at) = g(b);
        if gb >= 0.0 {
            lo = b;
            g_lo = g_lo_finite(gb);
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        } else {
            hi = b;
            g_hi = gb;
            at_hi = at;
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        }
    }
    Ok(point((0.5 * (lo + hi), at_hi.1)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use chatter_dynamics::{
        CuttingCoefficients, Milling, MillingDirection, Mode, ModeShape, Operation,
    };
    use chatter_stability::process_damping::process_damping_limiting_depth;
    use chatter_stability::zero_order::zoa_limiting_depth;

    /// A 003-like flexure: 228 Hz, single tooth, 50 % up milling, 18.54 mm tool.
    fn flexure(c: Option<f64>) -> ModalModel {
        let mode = Mode::new(
            228.0,
            0.02,
            ModeShape::Directional {
                coordinate: 0,
                stiffness_n_per_m: 5.6e6,
            },
        )
        .unwrap();
        let op = Operation::Milling(
            Milling::new(1, 0.5, MillingDirection::Up, Some(18.54e-3), None).unwrap(),
        );
        ModalModel::new(
            None,
            op,
            CuttingCoefficients::new(2111.2e6, 1052.6e6).unwrap(),
            vec![mode],
            c,
        )
        .unwrap()
    }

    #[test]
    fn agrees_with_the_zero_order_lobes_of_chatter_stability() {
        let options = BoundaryOptions::default();
        for model in [
            flexure(None),
            chatter_dynamics::examples::schmitz_2023_milling(),
        ] {
            for speed in [400.0, 1100.0, 2900.0, 5660.0, 6960.0, 11298.0] {
                let ours = limiting_depth(&model, speed, &options).unwrap();
                let theirs = zoa_limiting_depth(&model, speed).unwrap();
                let rel = (ours.depth_m - theirs.depth_m).abs() / theirs.depth_m;
                assert!(
                    rel < 5e-3,
                    "{speed}: {} vs {}",
                    ours.depth_m,
                    theirs.depth_m
                );
                let df = (ours.chatter_hz - theirs.chatter_hz).abs();
                assert!(df < 0.01 * theirs.chatter_hz, "{speed}: {df}");
            }
        }
    }

    #[test]
    fn agrees_with_the_iterative_process_damping_algorithm() {
        let model = flexure(Some(2.5e5));
        for speed in [300.0, 600.0, 1000.0, 2000.0] {
            let ours = limiting_depth(&model, speed, &BoundaryOptions::default()).unwrap();
            let theirs = process_damping_limiting_depth(&model, speed).unwrap();
            let rel = (ours.depth_m - theirs.depth_m).abs() / theirs.depth_m;
            assert!(
                rel < 5e-3,
                "{speed}: {} vs {}",
                ours.depth_m,
                theirs.depth_m
            );
        }
        // process damping raises the low-speed limit
        let bare = limiting_depth(&flexure(None), 300.0, &BoundaryOptions::default()).unwrap();
        let damped = limiting_depth(&model, 300.0, &BoundaryOptions::default()).unwrap();
        assert!(damped.depth_m > 1.5 * bare.depth_m);
        // and a huge C makes the cut unconditionally stable up to the ceiling
        let stiff = flexure(Some(1e9));
        let options = BoundaryOptions {
            max_depth_m: 0.01,
            ..Default::default()
        };
        assert!(
            limiting_depth(&stiff, 300.0, &options)
                .unwrap()
                .depth_m
                .is_infinite()
        );
        assert!(limiting_depth(&model, -1.0, &options).is_err());
    }
}
