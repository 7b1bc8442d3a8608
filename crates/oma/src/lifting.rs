//! Lifting of a signal of a time-periodic system at its period (002 Eq. 6-7).
//!
//! A record sampled r times per period tau is cut into cycles M_c = [x_{c,1}, ..., x_{c,r}]
//! (Eq. 6); stacking the cycles as rows gives X (Eq. 7), whose column j is a virtual sensor that
//! sees the system at the same phase of every period. The lifted channels are the output of a
//! time-invariant discrete system sampled once per period, whose poles are the Floquet
//! multipliers; forced periodic responses become constants in every channel.

use crate::error::{OmaError, Result};

/// The `samples_per_period` lifted channels of `data` (002 Eq. 6-7): channel j holds
/// `data[c * samples_per_period + j]` for every complete cycle c. The record must hold at least
/// two complete cycles.
pub fn lift(data: &[f64], samples_per_period: usize) -> Result<Vec<Vec<f64>>> {
    let cycles = data.len().checked_div(samples_per_period).unwrap_or(0);
    if cycles < 2 {
        return Err(OmaError::InvalidInput {
            field: "samples_per_period",
            message: format!(
                "{samples_per_period} samples per period leave {cycles} complete cycles in {} \
                 samples; need at least 2",
                data.len()
            ),
        });
    }
    Ok((0..samples_per_period)
        .map(|j| {
            (0..cycles)
                .map(|c| data[c * samples_per_period + j])
                .collect()
        })
        .collect())
}

/// `data` sampled at `sample_rate_hz`, resampled at `new_rate_hz` by linear interpolation
/// between neighbouring samples, over the same time span (t_k = k / new_rate_hz up to the last
/// input sample). Linear interpolation attenuates a component at f by at most
/// (pi f / sample_rate_hz)^2 / 2 (5e-4 relative for a 195 Hz mode sampled at 20 kHz), so
/// keep the input well oversampled.
pub fn resample_linear(data: &[f64], sample_rate_hz: f64, new_rate_hz: f64) -> Result<Vec<f64>> {
    for (field, v) in [
        ("sample_rate_hz", sample_rate_hz),
        ("new_rate_hz", new_rate_hz),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(OmaError::InvalidInput {
                field,
                message: format!("{v}; expected a rate > 0"),
            });
        }
    }
    if data.len() < 2 {
        return Err(OmaError::InvalidInput {
            field: "samples",
            message: format!("{} samples; need at least 2", data.len()),
        });
    }
    let last = (data.len() - 1) as f64;
    let ratio = sample_rate_hz / new_rate_hz;
    let n = (last / ratio).floor() as usize + 1;
    Ok((0..n)
        .map(|k| {
            let x = (k as f64 * ratio).min(last);
            let i = (x.floor() as usize).min(data.len() - 2);
            let w = x - i as f64;
            data[i] + w * (data[i + 1] - data[i])
        })
        .collect())
}

/// Lifted channels of `data` (sampled at `sample_rate_hz`) at the period `period_s`.
///
/// When the period holds an integer number r of samples (to within 1 % of a sample of drift over
/// the whole record), the record is lifted as it is; otherwise it is first resampled by
/// [`resample_linear`] at r = ceil(sample_rate_hz * period_s) samples per period. Returns the r
/// channels.
pub fn lift_at_period(data: &[f64], sample_rate_hz: f64, period_s: f64) -> Result<Vec<Vec<f64>>> {
    let per = sample_rate_hz * period_s;
    if !(per.is_finite() && per >= 1.0) {
        return Err(OmaError::InvalidInput {
            field: "period_s",
            message: format!(
                "{period_s} s at {sample_rate_hz} Hz is {per} samples; need at least one \
                 sample per period"
            ),
        });
    }
    let r = per.round();
    let cycles = data.len() as f64 / per;
    if (per - r).abs() * cycles <= 0.01 {
        lift(data, r as usize)
    } else {
        let r = per.ceil();
        lift(
            &resample_linear(data, sample_rate_hz, r / period_s)?,
            r as usize,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lift_orders_cycles_by_phase() {
        let x: Vec<f64> = (0..11).map(f64::from).collect();
        let l = lift(&x, 3).unwrap();
        assert_eq!(
            l,
            vec![
                vec![0.0, 3.0, 6.0],
                vec![1.0, 4.0, 7.0],
                vec![2.0, 5.0, 8.0]
            ]
        );
        assert!(lift(&x, 0).is_err());
        assert!(lift(&x, 6).is_err());
    }

    #[test]
    fn resampling_a_line_is_exact() {
        let x: Vec<f64> = (0..100).map(|k| 2.0 + 0.5 * k as f64).collect();
        let y = resample_linear(&x, 1000.0, 730.0).unwrap();
        assert_eq!(y.len(), 73); // t = 0 .. 99 ms in steps of 1/730 s
        for (k, v) in y.iter().enumerate() {
            let t_samples = k as f64 * 1000.0 / 730.0;
            assert!((v - (2.0 + 0.5 * t_samples)).abs() < 1e-12);
        }
        assert!(resample_linear(&x, 0.0, 1.0).is_err());
        assert!(resample_linear(&x[..1], 1.0, 1.0).is_err());
    }

    #[test]
    fn non_integer_periods_are_resampled() {
        // period 7.5 samples: resampled to 8 per period; a signal periodic in tau lifts to
        // channels that are constant up to the interpolation error
        let fs = 1000.0;
        let tau = 7.5e-3;
        let x: Vec<f64> = (0..3000)
            .map(|k| (2.0 * std::f64::consts::PI * k as f64 / fs / tau).sin())
            .collect();
        let l = lift_at_period(&x, fs, tau).unwrap();
        assert_eq!(l.len(), 8);
        for (j, ch) in l.iter().enumerate() {
            let expected = (2.0 * std::f64::consts::PI * j as f64 / 8.0).sin();
            // linear interpolation of a sine at 7.5 samples per period: error < (pi/7.5)^2/2
            assert!(
                ch.iter().all(|v| (v - expected).abs() < 0.09),
                "channel {j}"
            );
        }
        assert_eq!(lift_at_period(&x, fs, 10e-3).unwrap().len(), 10);
        assert!(lift_at_period(&x, fs, 0.1e-3).is_err());
    }
}
