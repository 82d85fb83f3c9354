//! The values of the options that both apps and the orchestrator share:
//! each parser refuses, in one sentence, what no app would take, so that
//! clap names the option and nothing runs.

use super::{Size, Workgroup};

/// Every device allows at least 128 invocations per workgroup (Vulkan) or 1024
/// (GL 4.3+); each app checks its own device's limits. Here only the shape.
pub fn parse_workgroup(s: &str) -> Result<Workgroup, String> {
    let (x, y) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH (for example 16x8)"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| (1..=1024).contains(&n))
    };
    match (parse(x), parse(y)) {
        (Some(x), Some(y)) if x * y <= 1024 => Ok(Workgroup { x, y }),
        _ => Err(format!("'{s}' is not a workgroup size: two whole numbers from 1 to 1024 with a product of at most 1024")),
    }
}

/// `WxH`, each from 1 to `limits::MAX_IMAGE_DIMENSION`, and an image whose
/// buffers fit the memory available (`limits::check_image_size`). Each app then
/// checks its device's own limits.
pub fn parse_size(s: &str) -> Result<Size, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{s}' is not WxH (for example 800x600)"))?;
    let parse = |v: &str, what: &str| -> Result<u32, String> {
        let v = v.trim();
        if v.starts_with('-') {
            return Err(format!(
                "the {what} in '{s}' is negative; width and height must be at least 1"
            ));
        }
        v.parse::<u32>().map_err(|e| match e.kind() {
            std::num::IntErrorKind::PosOverflow => format!(
                "the {what} in '{s}' is larger than {}",
                crate::limits::MAX_IMAGE_DIMENSION
            ),
            _ => format!("the {what} in '{s}' is not a whole number"),
        })
    };
    let (width, height) = (parse(w, "width")?, parse(h, "height")?);
    if width == 0 || height == 0 {
        return Err(format!(
            "'{s}' has a zero dimension; width and height must be at least 1"
        ));
    }
    crate::limits::check_image_size(width, height).map_err(|e| e.to_string())?;
    Ok(Size { width, height })
}

/// `--frames`: a whole number from 1 to 100,000 (clap prefixes the option and
/// value). The orchestrator's `--frames` takes the same parser, so that a
/// count every app would refuse is refused before the first run.
pub fn parse_frames(s: &str) -> Result<u32, String> {
    const MAX: u32 = 100_000;
    match s.trim().parse::<i64>() {
        Ok(n) if (1..=MAX as i64).contains(&n) => Ok(n as u32),
        _ => Err(format!("give a whole number of frames from 1 to {MAX}")),
    }
}

/// `--settle`: a percentage above 0 and at most 50.
pub(super) fn parse_settle(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(p) if p > 0.0 && p <= 50.0 => Ok(p),
        _ => Err(
            "give the interval's half-width as a percentage above 0 and at most 50, e.g. 1".into(),
        ),
    }
}

/// A time in seconds that bounds a run (`compare --seconds-per-point`): a
/// finite number above 0 and at most a day. It divides into a frame count, so
/// NaN, infinity, 0 or 1e300 would each give a count no app takes.
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    const MAX: f64 = 86_400.0;
    match s.trim().parse::<f64>() {
        Ok(x) if x > 0.0 && x <= MAX => Ok(x),
        _ => Err(format!(
            "give a number of seconds above 0 and at most {MAX}"
        )),
    }
}
