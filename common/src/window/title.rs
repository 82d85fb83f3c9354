//! The window title both apps show, and the clock that refreshes it twice a second.

use crate::cli::RenderPath;
use crate::rays::grays_per_s;
use std::time::{Duration, Instant};

/// The window title, identical in both apps:
/// `twinray — box — Vulkan compute — 61.3 FPS — 12.41 ms` (`n/a ms` where the
/// GPU time is unknown, e.g. OpenGL on llvmpipe; `— starting` until the first
/// figures, and after a switch until new ones). With `--count-rays`, `rays` is
/// the current view's ray count and the title ends with `— 0.52 Grays/s`: the
/// rays over the mean GPU time, or over the frame time where that is unknown.
pub fn window_title(
    scene: &str,
    api: &str,
    path: RenderPath,
    fps_gpu: Option<(f64, Option<f64>)>,
    rays: Option<u64>,
) -> String {
    let head = format!("twinray — {scene} — {api} {path}");
    match fps_gpu {
        None => format!("{head} — starting"),
        Some((fps, gpu_ms)) => {
            let gpu = gpu_ms.map_or_else(|| "n/a".to_string(), |ms| format!("{ms:.2}"));
            let rate = match rays {
                Some(total) if fps > 0.0 => {
                    let ms = gpu_ms.unwrap_or(1e3 / fps);
                    format!(" — {:.2} Grays/s", grays_per_s(total, ms))
                }
                _ => String::new(),
            };
            format!("{head} — {fps:.1} FPS — {gpu} ms{rate}")
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
                Some((61.26, Some(12.414))),
                None
            ),
            "twinray — box — Vulkan compute — 61.3 FPS — 12.41 ms"
        );
        assert_eq!(
            window_title(
                "box",
                "Vulkan",
                RenderPath::Compute,
                Some((61.26, Some(12.5))),
                Some(6_500_000)
            ),
            "twinray — box — Vulkan compute — 61.3 FPS — 12.50 ms — 0.52 Grays/s"
        );
        assert_eq!(
            window_title(
                "box",
                "OpenGL",
                RenderPath::Fragment,
                Some((50.0, None)),
                Some(10_000_000)
            ),
            "twinray — box — OpenGL fragment — 50.0 FPS — n/a ms — 0.50 Grays/s",
            "without a GPU time, the frame time"
        );
        assert_eq!(
            window_title(
                "teapot",
                "OpenGL",
                RenderPath::Fragment,
                Some((5.0, None)),
                None
            ),
            "twinray — teapot — OpenGL fragment — 5.0 FPS — n/a ms"
        );
        assert_eq!(
            window_title("box", "OpenGL", RenderPath::Compute, None, Some(1)),
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
