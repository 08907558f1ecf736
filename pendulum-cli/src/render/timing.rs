//! When frames are taken and how fast they play: the frame interval in simulated time (a
//! whole number of samples), the GIF frame delay (a whole number of 10 ms, the format's
//! unit, and at least 20 ms: browsers play shorter delays at 100 ms) and the playback
//! speed the two make.

/// The shortest frame delay, centiseconds: browsers slow anything shorter to 100 ms.
pub const MIN_DELAY: u16 = 2;
/// The longest frame delay the automatic choice uses, centiseconds.
const AUTO_MAX_DELAY: u16 = 12;
/// The longest frame delay allowed, centiseconds (a minute).
const MAX_DELAY: u16 = 6000;
/// Frames per drive period, at least, when the speed is chosen.
pub const FRAMES_PER_PERIOD: f64 = 8.0;

/// What the timing depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Request {
    /// Length of the time window, s (0 for a single sample).
    pub span: f64,
    /// Time between samples of the trajectory, s.
    pub sample: f64,
    /// Most frames.
    pub frames: usize,
    /// The playback speed asked for (simulated seconds per second shown); `None`: chosen.
    pub speed: Option<f64>,
    /// Period of a periodic drive, s.
    pub period: Option<f64>,
}

/// The timing of the animation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timing {
    /// Samples per frame.
    pub stride: u64,
    /// Simulated time between frames, s (`stride` samples).
    pub interval: f64,
    /// GIF frame delay, centiseconds.
    pub delay: u16,
    /// Playback speed, simulated seconds per second shown (`interval / delay`).
    pub speed: f64,
    /// Whether the frames span the whole window; if not, they span
    /// `(frames − 1) × interval` of it.
    pub covers: bool,
}

/// The timing for `request`.
///
/// The frame interval is at least `span / (frames − 1)`, so the frames cover the window,
/// and never less than one sample. With a speed given, the delay is the shortest one
/// (≥ 20 ms) that gives that speed within 1 % (else the closest), frames thinned to fit.
/// Chosen: for a periodic drive of period P the interval is at most P/8, so the drive is
/// seen turning or shaking, not aliased (if the window then needs more frames than
/// allowed, the frames cover only part of it); the delay is the interval itself (real
/// time) if that lies in 20–120 ms, else the nearer bound (slow motion or fast forward).
///
/// Errors: a speed so slow that a frame would show for more than a minute.
pub fn plan(request: &Request) -> Result<Timing, String> {
    let dt = request.sample;
    let cover = if request.span > 0.0 && request.frames > 1 {
        let per_frame = request.span / ((request.frames - 1) as f64 * dt);
        ((per_frame * (1.0 - 1e-9)).ceil() as u64).max(1)
    } else {
        1
    };
    let (stride, delay) = match request.speed {
        Some(speed) => {
            let slowest = cover as f64 * dt / (speed * 0.01);
            if slowest > f64::from(MAX_DELAY) {
                return Err(format!(
                    "--speed {speed}: frames {:.3e} s apart would show for {:.3e} s each (at most {} s)",
                    cover as f64 * dt,
                    slowest * 0.01,
                    MAX_DELAY / 100
                ));
            }
            let first = (slowest * (1.0 - 1e-9)).ceil().max(f64::from(MIN_DELAY)) as u16;
            let mut best = (f64::INFINITY, cover, first);
            for delay in first..=first.saturating_add(100).min(MAX_DELAY) {
                let stride = ((speed * f64::from(delay) * 0.01 / dt).round() as u64).max(cover);
                let error = (stride as f64 * dt / (f64::from(delay) * 0.01) / speed).ln().abs();
                if error < best.0 {
                    best = (error, stride, delay);
                }
                if error < 0.01 {
                    break;
                }
            }
            (best.1, best.2)
        }
        None => {
            let alias =
                request.period.map(|p| ((p / FRAMES_PER_PERIOD / dt * (1.0 + 1e-9)).floor() as u64).max(1));
            let stride = alias.map_or(cover, |a| a.min(cover));
            let delay =
                (stride as f64 * dt / 0.01).round().clamp(f64::from(MIN_DELAY), f64::from(AUTO_MAX_DELAY));
            (stride, delay as u16)
        }
    };
    let interval = stride as f64 * dt;
    Ok(Timing {
        stride,
        interval,
        delay,
        speed: interval / (f64::from(delay) * 0.01),
        covers: stride >= cover,
    })
}

/// The speed in words: "real time", "0.25× (slow motion)", "6.8× (fast)".
pub fn speed_words(speed: f64) -> String {
    if (speed - 1.0).abs() < 1e-9 {
        return "real time".into();
    }
    let shown = format!("{:.3}", speed);
    let shown = shown.trim_end_matches('0').trim_end_matches('.');
    if speed < 1.0 { format!("{shown}× (slow motion)") } else { format!("{shown}× (fast)") }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn request(span: f64, sample: f64, frames: usize, speed: Option<f64>, period: Option<f64>) -> Request {
        Request { span, sample, frames, speed, period }
    }

    #[test]
    fn a_slow_drive_plays_in_real_time_over_the_whole_run() {
        // The README's whirl: 10 s sampled every 10 ms, 150 frames, drive period 1.26 s.
        let t = plan(&request(10.0, 0.01, 150, None, Some(TAU / 5.0))).unwrap();
        assert_eq!((t.stride, t.delay, t.covers), (7, 7, true));
        assert!((t.speed - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_fast_drive_gets_eight_frames_a_period_in_slow_motion() {
        // Kapitza: 4 s sampled every 2 ms, drive period 31.4 ms: P/8 = 3.9 ms, one sample.
        let t = plan(&request(4.0, 0.002, 150, None, Some(TAU / 200.0))).unwrap();
        assert_eq!((t.stride, t.delay, t.covers), (1, MIN_DELAY, false));
        assert!((t.speed - 0.1).abs() < 1e-12 && t.interval <= TAU / 200.0 / 8.0);
    }

    #[test]
    fn a_long_run_without_drive_fast_forwards() {
        let t = plan(&request(100.0, 0.02, 150, None, None)).unwrap();
        assert_eq!((t.stride, t.delay, t.covers), (34, 12, true));
        assert!((t.speed - 0.68 / 0.12).abs() < 1e-9);
        assert_eq!(speed_words(t.speed), "5.667× (fast)");
        // Frames 120 ms apart still play in real time.
        let t = plan(&request(10.0, 0.01, 91, None, None)).unwrap();
        assert_eq!((t.stride, t.delay), (12, 12));
    }

    #[test]
    fn a_given_speed_is_met_with_the_frames_thinned_to_fit() {
        let t = plan(&request(1.0, 0.01, 21, Some(1.0), None)).unwrap();
        assert_eq!((t.stride, t.delay, t.covers), (5, 5, true));
        let t = plan(&request(1.0, 0.01, 21, Some(0.25), None)).unwrap();
        assert_eq!((t.stride, t.delay), (5, 20));
        assert_eq!(speed_words(t.speed), "0.25× (slow motion)");
        // Faster than the samples allow at 20 ms: every other sample.
        let t = plan(&request(1.0, 0.01, 1000, Some(1.0), None)).unwrap();
        assert_eq!((t.stride, t.delay), (2, 2));
        // A speed that no whole number of samples per 10 ms meets exactly: the closest.
        let t = plan(&request(1.0, 0.01, 1000, Some(0.3), None)).unwrap();
        assert!((t.speed / 0.3 - 1.0).abs() < 0.01, "{t:?}");
        assert!(plan(&request(1.0, 0.01, 10, Some(1e-6), None)).unwrap_err().starts_with("--speed 0.000001"));
    }

    #[test]
    fn a_single_sample_is_one_frame() {
        let t = plan(&request(0.0, 0.02, 150, None, None)).unwrap();
        assert_eq!((t.stride, t.delay, t.covers), (1, 2, true));
    }
}
