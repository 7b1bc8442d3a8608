//! Measured vibration records: CSV (first row names the channels, rows are samples) or WAV
//! (its own sample rate), as in the signals section of the formats spec.

use crate::error::{OmaError, Result};
use std::path::Path;

/// Equally sampled channels; the first is the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Signals {
    /// Channel names.
    pub names: Vec<String>,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Samples per channel, all the same length.
    pub data: Vec<Vec<f64>>,
}

impl Signals {
    /// Validated signals: at least one channel, equal lengths >= 2, finite samples, rate > 0.
    pub fn new(names: Vec<String>, sample_rate_hz: f64, data: Vec<Vec<f64>>) -> Result<Self> {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(OmaError::InvalidInput {
                field: "sample_rate_hz",
                message: format!("{sample_rate_hz}; expected a rate > 0"),
            });
        }
        if data.is_empty() || names.len() != data.len() {
            return Err(OmaError::InvalidInput {
                field: "channels",
                message: format!("{} names for {} channels", names.len(), data.len()),
            });
        }
        let n = data[0].len();
        if n < 2 || data.iter().any(|c| c.len() != n) {
            return Err(OmaError::InvalidInput {
                field: "samples",
                message: "every channel needs the same number (>= 2) of samples".into(),
            });
        }
        Ok(Self {
            names,
            sample_rate_hz,
            data,
        })
    }

    /// Index of a channel by name.
    pub fn channel(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Mean interval (s) between the rising edges of the pulse train in `channel` (a
    /// once-per-revolution tachometer): crossings of the level halfway between the channel's
    /// minimum and maximum, located to a fraction of a sample by linear interpolation. Needs at
    /// least two edges.
    pub fn pulse_period_s(&self, channel: usize) -> Result<f64> {
        let x = self
            .data
            .get(channel)
            .ok_or_else(|| OmaError::InvalidInput {
                field: "once_per_rev_channel",
                message: format!("channel {channel} of {}", self.data.len()),
            })?;
        let (lo, hi) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(*v), hi.max(*v))
            });
        let level = 0.5 * (lo + hi);
        let edges: Vec<f64> = x
            .windows(2)
            .enumerate()
            .filter(|(_, w)| w[0] < level && w[1] >= level)
            .map(|(k, w)| k as f64 + (level - w[0]) / (w[1] - w[0]))
            .collect();
        match (edges.first(), edges.last()) {
            (Some(first), Some(last)) if edges.len() >= 2 => {
                Ok((last - first) / (edges.len() - 1) as f64 / self.sample_rate_hz)
            }
            _ => Err(OmaError::InvalidInput {
                field: "once_per_rev_channel",
                message: format!(
                    "channel `{}` has {} rising edges; need at least two pulses",
                    self.names[channel],
                    edges.len()
                ),
            }),
        }
    }

    /// These signals without the channel `channel` (e.g. a tachometer before identification).
    pub fn without_channel(&self, channel: usize) -> Result<Self> {
        let (names, data) = self
            .names
            .iter()
            .zip(&self.data)
            .enumerate()
            .filter(|(c, _)| *c != channel)
            .map(|(_, (n, d))| (n.clone(), d.clone()))
            .unzip();
        Self::new(names, self.sample_rate_hz, data)
    }

    /// Read a CSV record at `sample_rate_hz`.
    pub fn from_csv(path: &Path, sample_rate_hz: f64) -> Result<Self> {
        let err = |message: String| OmaError::File {
            path: path.to_path_buf(),
            message,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines.next().ok_or_else(|| err("empty file".into()))?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        let mut data = vec![Vec::new(); names.len()];
        for (i, line) in lines {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != names.len() {
                return Err(err(format!(
                    "line {}: {} values for {} channels",
                    i + 1,
                    fields.len(),
                    names.len()
                )));
            }
            for (c, f) in fields.iter().enumerate() {
                let v: f64 = f.trim().parse().map_err(|_| {
                    err(format!(
                        "line {}, channel `{}`: `{}` is not a number",
                        i + 1,
                        names[c],
                        f.trim()
                    ))
                })?;
                if !v.is_finite() {
                    return Err(err(format!(
                        "line {}, channel `{}`: not finite",
                        i + 1,
                        names[c]
                    )));
                }
                data[c].push(v);
            }
        }
        Self::new(names, sample_rate_hz, data).map_err(|e| err(e.to_string()))
    }

    /// Read a WAV record (integer or float samples, any channel count); channels are named
    /// `ch1`, `ch2`, ... unless `names` gives them.
    pub fn from_wav(path: &Path, names: Option<Vec<String>>) -> Result<Self> {
        let err = |message: String| OmaError::File {
            path: path.to_path_buf(),
            message,
        };
        let mut reader = hound::WavReader::open(path).map_err(|e| err(e.to_string()))?;
        let spec = reader.spec();
        let nc = spec.channels as usize;
        let samples: Vec<f64> = match spec.sample_format {
            hound::SampleFormat::Float => reader
                .samples::<f32>()
                .map(|s| s.map(f64::from))
                .collect::<std::result::Result<_, _>>(),
            hound::SampleFormat::Int => {
                let scale = 2f64.powi(spec.bits_per_sample as i32 - 1);
                reader
                    .samples::<i32>()
                    .map(|s| s.map(|v| v as f64 / scale))
                    .collect::<std::result::Result<_, _>>()
            }
        }
        .map_err(|e| err(e.to_string()))?;
        let mut data = vec![Vec::with_capacity(samples.len() / nc.max(1)); nc];
        for (k, v) in samples.into_iter().enumerate() {
            data[k % nc].push(v);
        }
        let names = names.unwrap_or_else(|| (1..=nc).map(|i| format!("ch{i}")).collect());
        Self::new(names, spec.sample_rate as f64, data).map_err(|e| err(e.to_string()))
    }

    /// Decode an MP3 record (with symphonia) into channels `ch1`, `ch2`, ... at its own
    /// sample rate. Packets that fail to decode are skipped (as players do).
    pub fn from_mp3(path: &Path) -> Result<Self> {
        use symphonia::core::codecs::audio::AudioDecoderOptions;
        use symphonia::core::formats::probe::Hint;
        use symphonia::core::formats::{FormatOptions, TrackType};
        use symphonia::core::io::MediaSourceStream;
        use symphonia::core::meta::MetadataOptions;
        let err = |message: String| OmaError::File {
            path: path.to_path_buf(),
            message,
        };
        let file = std::fs::File::open(path).map_err(|e| err(e.to_string()))?;
        let stream = MediaSourceStream::new(Box::new(file), Default::default());
        let mut hint = Hint::new();
        hint.with_extension("mp3");
        let mut format = symphonia::default::get_probe()
            .probe(
                &hint,
                stream,
                FormatOptions::default(),
                MetadataOptions::default(),
            )
            .map_err(|e| err(format!("not a decodable MP3: {e}")))?;
        let track = format
            .default_track(TrackType::Audio)
            .ok_or_else(|| err("no audio track".into()))?;
        let track_id = track.id;
        let params = track
            .codec_params
            .as_ref()
            .and_then(|p| p.audio())
            .ok_or_else(|| err("no audio codec parameters".into()))?;
        let mut decoder = symphonia::default::get_codecs()
            .make_audio_decoder(params, &AudioDecoderOptions::default())
            .map_err(|e| err(format!("no decoder: {e}")))?;
        let mut interleaved: Vec<f32> = Vec::new();
        let mut buffer: Vec<f32> = Vec::new();
        let (mut rate, mut channels) = (0u32, 0usize);
        loop {
            let packet = match format.next_packet() {
                Ok(Some(p)) => p,
                Ok(None) => break,
                Err(e) => return Err(err(format!("reading packets: {e}"))),
            };
            if packet.track_id != track_id {
                continue;
            }
            match decoder.decode(&packet) {
                Ok(audio) => {
                    let spec = audio.spec();
                    rate = spec.rate();
                    channels = spec.channels().count();
                    buffer.resize(audio.samples_interleaved(), 0.0);
                    audio.copy_to_slice_interleaved(&mut buffer);
                    interleaved.extend_from_slice(&buffer);
                }
                Err(symphonia::core::errors::Error::DecodeError(_)) => continue,
                Err(e) => return Err(err(format!("decoding: {e}"))),
            }
        }
        if channels == 0 || rate == 0 {
            return Err(err("no audio decoded".into()));
        }
        let mut data = vec![Vec::with_capacity(interleaved.len() / channels); channels];
        for (k, v) in interleaved.into_iter().enumerate() {
            data[k % channels].push(f64::from(v));
        }
        let names = (1..=channels).map(|i| format!("ch{i}")).collect();
        Self::new(names, f64::from(rate), data).map_err(|e| err(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trip_and_errors_name_line_and_channel() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rec.csv");
        std::fs::write(&path, "a, b,tach\n1.0,2,0\n-1e-3,4,1\n\n5,6,0\n").unwrap();
        let s = Signals::from_csv(&path, 100.0).unwrap();
        assert_eq!(s.names, vec!["a", "b", "tach"]);
        assert_eq!(s.data[0], vec![1.0, -1e-3, 5.0]);
        assert_eq!(s.channel("tach"), Some(2));
        let without = s.without_channel(2).unwrap();
        assert_eq!(without.names, vec!["a", "b"]);
        std::fs::write(&path, "a,b\n1,2\n3,x\n").unwrap();
        let e = Signals::from_csv(&path, 100.0).unwrap_err().to_string();
        assert!(
            e.contains("rec.csv") && e.contains("line 3") && e.contains("`b`"),
            "{e}"
        );
        std::fs::write(&path, "a,b\n1,2\n3\n").unwrap();
        let e = Signals::from_csv(&path, 100.0).unwrap_err().to_string();
        assert!(e.contains("line 3: 1 values for 2 channels"), "{e}");
    }

    #[test]
    fn wav_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rec.wav");
        let spec = hound::WavSpec {
            channels: 2,
            sample_rate: 8000,
            bits_per_sample: 32,
            sample_format: hound::SampleFormat::Float,
        };
        let mut w = hound::WavWriter::create(&path, spec).unwrap();
        for k in 0..10 {
            w.write_sample(k as f32 * 0.1).unwrap();
            w.write_sample(-(k as f32)).unwrap();
        }
        w.finalize().unwrap();
        let s = Signals::from_wav(&path, None).unwrap();
        assert_eq!(s.names, vec!["ch1", "ch2"]);
        assert_eq!(s.sample_rate_hz, 8000.0);
        assert_eq!(s.data[1][3], -3.0);
        assert!((s.data[0][4] - 0.4).abs() < 1e-7);
    }

    #[test]
    fn pulse_period_from_rising_edges() {
        // one pulse every 12.5 samples at 1 kHz: 12.5 ms, located to a fraction of a sample
        let tach: Vec<f64> = (0..200)
            .map(|k| if (k as f64 % 12.5) < 2.0 { 1.0 } else { 0.0 })
            .collect();
        let s = Signals::new(vec!["tach".into()], 1000.0, vec![tach]).unwrap();
        let period = s.pulse_period_s(0).unwrap();
        // edges at integer samples only: the mean over 15 intervals is within 1/15 sample
        assert!((period - 12.5e-3).abs() < 1e-3 / 15.0, "{period}");
        let flat = Signals::new(vec!["tach".into()], 1000.0, vec![vec![0.0; 10]]).unwrap();
        assert!(flat.pulse_period_s(0).is_err());
        assert!(s.pulse_period_s(3).is_err());
    }
}
