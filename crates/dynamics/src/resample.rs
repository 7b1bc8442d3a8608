//! Band-limited resampling of a uniformly sampled stream at arbitrary output instants: the
//! anti-aliasing low-pass and the decimation of the simulator in one step.
//!
//! Each output is y(t) = sum_k v_k g(t - t_k) / sum_k g(t - t_k) over the input samples within
//! the kernel's support, with g a Blackman-windowed sinc of cutoff
//! [`CUTOFF_FRACTION`] x f_eff and half-width [`HALF_WIDTH_PERIODS`] / f_eff, where
//! f_eff = min(output rate, input rate). Normalizing by the sum of the weights gives unit gain
//! at DC whatever the fractional position. The Blackman window's transition band is about
//! 5.5 / (2 x half-width) = 0.17 f_eff wide and its stopband below -74 dB, so content above
//! 0.49 f_eff, which would fold into the band, is removed, and the band up to about 0.3 f_eff is
//! passed with a gain within 1e-3 of one.
//!
//! Evaluation. The taps of an output are g(-W + (i + p) h), i = 0, 1, ..., for the phase p in
//! [0, 1) of its first input: the kernel is tabulated in polyphase form, rows of taps at phases
//! q / Q no further apart than 1 / 4096 of the half-width, and an output's weights are the
//! linear interpolation between two contiguous rows (error below 1e-5 of the peak, as the
//! former table interpolated along t). The inputs are kept in a contiguous buffer whose consumed
//! front is dropped in blocks. When the rows would exceed 2^21 values (a very low output rate
//! against the input rate) the kernel is interpolated along t from a table of 4096 points per
//! half-width instead, walked by a constant increment per input. Both give the same filter.

use std::f64::consts::PI;

/// Cutoff of the low-pass as a fraction of the effective rate (half-amplitude point).
pub const CUTOFF_FRACTION: f64 = 0.4;
/// Half-width of the kernel in periods of the effective rate.
pub const HALF_WIDTH_PERIODS: f64 = 16.0;
/// Points of the tabulated kernel per half-width (linear interpolation between them).
const TABLE_POINTS: usize = 4096;

/// A streaming windowed-sinc resampler of `N` channels from a rate 1 / `input_step_s` to
/// `output_rate_hz`.
#[derive(Debug, Clone)]
pub(crate) struct Resampler<const N: usize> {
    input_step_s: f64,
    output_rate_hz: f64,
    half_width_s: f64,
    /// The kernel over [-W, W] at 2 [`TABLE_POINTS`] + 1 points, each with the difference to
    /// the next (zero past the end), so one load gives both ends of the interpolation; built
    /// only when the polyphase rows are not (empty otherwise).
    table: Vec<[f64; 2]>,
    /// Table points per second of kernel argument.
    table_scale: f64,
    /// Polyphase form of the kernel (empty when it would be too large): for phases
    /// p = q / [`Self::phases`], q = 0..phases, row q holds g(-W + (i + p) h) for taps
    /// i = 0..[`Self::taps`], and the same row of `poly_slope` the change to row q + 1, so the
    /// weights of an output are two contiguous rows and a fraction.
    poly_value: Vec<f64>,
    poly_slope: Vec<f64>,
    phases: usize,
    taps: usize,
    /// Input samples kept, the first being input index `first`; the consumed front is dropped
    /// in blocks (a contiguous slice per output).
    buffer: Vec<[f64; N]>,
    first: usize,
    /// Input samples pushed so far.
    pushed: usize,
    /// Next output index.
    next: usize,
}

impl<const N: usize> Resampler<N> {
    /// A resampler for inputs every `input_step_s` and outputs at `output_rate_hz` (both > 0).
    pub(crate) fn new(input_step_s: f64, output_rate_hz: f64) -> Self {
        let f_eff = output_rate_hz.min(1.0 / input_step_s);
        let fc = CUTOFF_FRACTION * f_eff;
        let half_width_s = HALF_WIDTH_PERIODS / f_eff;
        // the Blackman-windowed sinc at any t (zero outside [-W, W])
        let exact = |t: f64| {
            let t = t.abs();
            if t >= half_width_s {
                return 0.0;
            }
            let x = 2.0 * fc * t;
            let sinc = if x == 0.0 {
                1.0
            } else {
                (PI * x).sin() / (PI * x)
            };
            let u = PI * (t / half_width_s + 1.0);
            sinc * (0.42 - 0.5 * u.cos() + 0.08 * (2.0 * u).cos())
        };
        // phases spaced no wider than the table's points
        let phases = ((input_step_s * TABLE_POINTS as f64 / half_width_s).ceil() as usize).max(1);
        let taps = (2.0 * half_width_s / input_step_s).floor() as usize + 2;
        let (mut poly_value, mut poly_slope, mut table) = (Vec::new(), Vec::new(), Vec::new());
        if (phases + 1).saturating_mul(taps) <= 1 << 21 {
            // rows 0..=phases, each evaluated once: row q is the values, row q + 1 - row q the
            // slopes
            let rows: Vec<f64> = (0..=phases)
                .flat_map(|q| {
                    (0..taps).map(move |i| {
                        exact(-half_width_s + (i as f64 + q as f64 / phases as f64) * input_step_s)
                    })
                })
                .collect();
            poly_value = rows[..phases * taps].to_vec();
            poly_slope = rows[taps..]
                .iter()
                .zip(&poly_value)
                .map(|(b, a)| b - a)
                .collect();
        } else {
            // symmetric table over [-W, W]: point i at t = (i - TABLE_POINTS) W / TABLE_POINTS
            let values: Vec<f64> = (0..=2 * TABLE_POINTS)
                .map(|i| {
                    let from_centre = i.abs_diff(TABLE_POINTS);
                    exact(half_width_s * from_centre as f64 / TABLE_POINTS as f64)
                })
                .chain([0.0])
                .collect();
            table = values
                .windows(2)
                .map(|w| [w[0], w[1] - w[0]])
                .chain([[0.0, 0.0]])
                .collect();
        }
        Self {
            input_step_s,
            output_rate_hz,
            half_width_s,
            table,
            table_scale: TABLE_POINTS as f64 / half_width_s,
            poly_value,
            poly_slope,
            phases,
            taps,
            buffer: Vec::new(),
            first: 0,
            pushed: 0,
            next: 0,
        }
    }

    /// Time after the last output instant that the input must cover (s).
    pub(crate) fn half_width_s(&self) -> f64 {
        self.half_width_s
    }

    /// Add the next input sample and write every output that is now complete into `out` (one
    /// slice per channel) up to its length.
    #[inline]
    pub(crate) fn push(&mut self, value: [f64; N], out: &mut [Vec<f64>; N]) {
        self.buffer.push(value);
        self.pushed += 1;
        // most inputs complete no output: test that before the call
        let last_time = (self.pushed - 1) as f64 * self.input_step_s;
        if self.next < out[0].len()
            && self.next as f64 / self.output_rate_hz + self.half_width_s <= last_time
        {
            self.write_outputs(last_time, out);
        }
    }

    /// Write every output complete once the input reaches `last_time`.
    fn write_outputs(&mut self, last_time: f64, out: &mut [Vec<f64>; N]) {
        let n_out = out[0].len();
        while self.next < n_out {
            let ts = self.next as f64 / self.output_rate_hz;
            if ts + self.half_width_s > last_time {
                break;
            }
            let lo = ((ts - self.half_width_s) / self.input_step_s)
                .ceil()
                .max(0.0) as usize;
            let hi = ((ts + self.half_width_s) / self.input_step_s).floor() as usize;
            let (lo, hi) = (lo.max(self.first), hi.min(self.pushed - 1));
            let (mut acc, mut weight) = ([0.0; N], 0.0);
            if lo <= hi && !self.poly_value.is_empty() {
                // position of input lo in the kernel, in input steps from -W
                let position = ((lo as f64 * self.input_step_s - ts + self.half_width_s)
                    / self.input_step_s)
                    .max(0.0);
                let first_tap = position.floor();
                let phase = (position - first_tap) * self.phases as f64;
                let q = (phase as usize).min(self.phases - 1);
                let fraction = phase - q as f64;
                let start = q * self.taps + (first_tap as usize).min(self.taps);
                let end = (q + 1) * self.taps;
                let inputs = &self.buffer[lo - self.first..=hi - self.first];
                let n = inputs.len().min(end - start);
                let (inputs, values, slopes) = (
                    &inputs[..n],
                    &self.poly_value[start..start + n],
                    &self.poly_slope[start..start + n],
                );
                // four independent partial sums (the additions of one sum form a chain)
                let (mut part, mut part_weight) = ([[0.0; N]; 4], [0.0; 4]);
                let whole = n / 4 * 4;
                for ((v4, g4), d4) in inputs[..whole]
                    .chunks_exact(4)
                    .zip(values[..whole].chunks_exact(4))
                    .zip(slopes[..whole].chunks_exact(4))
                {
                    for l in 0..4 {
                        let g = g4[l] + fraction * d4[l];
                        for c in 0..N {
                            part[l][c] += g * v4[l][c];
                        }
                        part_weight[l] += g;
                    }
                }
                for ((v, g0), dg) in inputs[whole..]
                    .iter()
                    .zip(&values[whole..])
                    .zip(&slopes[whole..])
                {
                    let g = g0 + fraction * dg;
                    for c in 0..N {
                        part[0][c] += g * v[c];
                    }
                    part_weight[0] += g;
                }
                for l in 0..4 {
                    for c in 0..N {
                        acc[c] += part[l][c];
                    }
                    weight += part_weight[l];
                }
            } else if lo <= hi {
                // table position of input lo, advancing by a constant per input
                let mut x =
                    (lo as f64 * self.input_step_s - ts + self.half_width_s) * self.table_scale;
                let dx = self.input_step_s * self.table_scale;
                for v in &self.buffer[lo - self.first..=hi - self.first] {
                    // x >= 0 up to rounding (a negative x saturates to point 0)
                    let i = (x as usize).min(self.table.len() - 1);
                    let [g0, dg] = self.table[i];
                    let g = g0 + (x - i as f64) * dg;
                    for c in 0..N {
                        acc[c] += g * v[c];
                    }
                    weight += g;
                    x += dx;
                }
            }
            for c in 0..N {
                out[c][self.next] = if weight != 0.0 { acc[c] / weight } else { 0.0 };
            }
            self.next += 1;
            // drop inputs no later output needs, in blocks
            let t_next = self.next as f64 / self.output_rate_hz - self.half_width_s;
            let keep_from = ((t_next / self.input_step_s).ceil().max(0.0) as usize)
                .clamp(self.first, self.pushed);
            let drop = keep_from - self.first;
            if drop >= 1024 && 2 * drop >= self.buffer.len() {
                self.buffer.drain(..drop);
                self.first = keep_from;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine in the passband keeps its amplitude and phase; one above the folding frequency
    /// is removed instead of aliasing.
    #[test]
    fn passband_kept_stopband_removed() {
        let h = 1.0 / 97_300.0; // input rate not a multiple of the output rate
        let fs = 10_000.0;
        let run = |f: f64| {
            let mut r = Resampler::<1>::new(h, fs);
            let mut out = [vec![0.0; 2000]];
            let steps = ((0.2 + r.half_width_s()) / h) as usize + 2;
            for k in 0..steps {
                r.push([(2.0 * PI * f * k as f64 * h).sin()], &mut out);
            }
            out[0].clone()
        };
        let y = run(2500.0);
        let max_err = (400..1600)
            .map(|n| (y[n] - (2.0 * PI * 2500.0 * n as f64 / fs).sin()).abs())
            .fold(0.0, f64::max);
        assert!(max_err < 2e-3, "{max_err}");
        let z = run(7600.0); // would alias to 2400 Hz
        let max = (400..1600).map(|n| z[n].abs()).fold(0.0, f64::max);
        assert!(max < 1e-3, "{max}");
    }
}
