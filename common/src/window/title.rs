//! The window title both apps show, and the clock that refreshes it twice a second.

use crate::cli::RenderPath;
use std::time::{Duration, Instant};

/// The window title, identical in both apps:
/// `twinray — box — Vulkan compute — 61.3 FPS — 12.41 ms` (`n/a ms` where the
/// GPU time is unknown, e.g. OpenGL on llvmpipe; `— starting` until the first
/// figures, and after a switch until new ones).
pub fn window_title(
    scene: &str,
    api: &str,
    path: RenderPath,
    fps_gpu: Option<(f64, Option<f64>)>,
) -> String {
    let head = format!("twinray — {scene} — {api} {path}");
    match fps_gpu {
        None => format!("{head} — starting"),
        Some((fps, gpu_ms)) => {
            let gpu = gpu_ms.map_or_else(|| "n/a".to_string(), |ms| format!("{ms:.2}"));
            format!("{head} — {fps:.1} FPS — {gpu} ms")
        }
    }
}

/// Averages frames over half-second windows for the title.
#[derive(Debug)]
pub struct TitleClock {
    since: Instant,
    frames: u32,
    gpu_sum: f64,
    gpu_n: u32,
}

impl TitleClock {
    pub const PERIOD: Duration = Duration::from_millis(500);

    pub fn new(now: Instant) -> TitleClock {
        TitleClock {
            since: now,
            frames: 0,
            gpu_sum: 0.0,
            gpu_n: 0,
        }
    }

    /// Counts a frame; every `PERIOD` returns (FPS, mean GPU ms) and starts over.
    pub fn frame(&mut self, now: Instant, gpu_ms: Option<f64>) -> Option<(f64, Option<f64>)> {
        self.frames += 1;
        if let Some(g) = gpu_ms {
            self.gpu_sum += g;
            self.gpu_n += 1;
        }
        let elapsed = now - self.since;
        if elapsed < Self::PERIOD {
            return None;
        }
        let fps = self.frames as f64 / elapsed.as_secs_f64();
        let gpu = (self.gpu_n > 0).then(|| self.gpu_sum / self.gpu_n as f64);
        *self = TitleClock::new(now);
        Some((fps, gpu))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn title_format_is_fixed() {
        assert_eq!(
            window_title(
                "box",
                "Vulkan",
                RenderPath::Compute,
                Some((61.26, Some(12.414)))
            ),
            "twinray — box — Vulkan compute — 61.3 FPS — 12.41 ms"
        );
        assert_eq!(
            window_title("teapot", "OpenGL", RenderPath::Fragment, Some((5.0, None))),
            "twinray — teapot — OpenGL fragment — 5.0 FPS — n/a ms"
        );
        assert_eq!(
            window_title("box", "OpenGL", RenderPath::Compute, None),
            "twinray — box — OpenGL compute — starting"
        );
    }

    #[test]
    fn title_clock_reports_twice_a_second() {
        let t0 = Instant::now();
        let mut c = TitleClock::new(t0);
        assert_eq!(c.frame(t0 + Duration::from_millis(100), Some(2.0)), None);
        assert_eq!(c.frame(t0 + Duration::from_millis(200), None), None);
        let (fps, gpu) = c.frame(t0 + Duration::from_millis(500), Some(4.0)).unwrap();
        assert!((fps - 6.0).abs() < 1e-9, "3 frames in 0.5 s: {fps}");
        assert_eq!(gpu, Some(3.0));
        assert_eq!(
            c.frame(t0 + Duration::from_millis(600), None),
            None,
            "starts over"
        );
    }
}
