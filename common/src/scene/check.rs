//! The checks every value of a scene passes, against what the GPU receives
//! (an f32) and the limits of `limits`, each failing with a message naming the value.

use crate::error::bad_input;
use crate::limits;
use glam::DVec3;

// Every value is checked against what the GPU receives: an f32. A value finite
// in f64 may overflow f32 (1e300 becomes infinity) or underflow to zero
// (1e-300), so each check looks at the f32 as well.

/// Finite in f32.
pub(super) fn finite(at: &str, v: f64) -> anyhow::Result<f64> {
    if v.is_finite() && (v as f32).is_finite() {
        Ok(v)
    } else {
        Err(bad_input(format!(
            "{at} = {v:?} is not finite in f32 (the GPU's precision)"
        )))
    }
}

/// From `lo` to `hi` (both finite in f32).
pub(super) fn within(at: &str, v: f64, lo: f64, hi: f64) -> anyhow::Result<f64> {
    if !(lo..=hi).contains(&v) {
        return Err(bad_input(format!("{at} = {v:?} must be from {lo} to {hi}")));
    }
    Ok(v)
}

/// Above zero in f32 too (no zero or subnormal after rounding), and at most `hi`.
pub(super) fn positive(at: &str, v: f64, hi: f64) -> anyhow::Result<f64> {
    let v = finite(at, v)?;
    if !(v > 0.0 && (v as f32) >= f32::MIN_POSITIVE) {
        return Err(bad_input(format!(
            "{at} = {v:?} must be positive (at least {:e} in f32)",
            f32::MIN_POSITIVE
        )));
    }
    if v > hi {
        return Err(bad_input(format!("{at} = {v:?} must be at most {hi:e}")));
    }
    Ok(v)
}

/// Finite and within `limits::MAX_COORDINATE`; for the hot loops over mesh
/// vertices, which format a label only for a vertex that fails.
pub(super) fn coord_ok(p: DVec3) -> bool {
    p.is_finite() && p.abs().max_element() <= limits::MAX_COORDINATE
}

/// A point or offset within `limits::MAX_COORDINATE`.
pub(super) fn coord3(at: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let p = DVec3::from_array(v);
    if !p.is_finite() {
        return Err(bad_input(format!(
            "{at} = {v:?} is not finite (NaN or infinity)"
        )));
    }
    if p.abs().max_element() > limits::MAX_COORDINATE {
        return Err(bad_input(format!(
            "{at} = {v:?} lies beyond the coordinate limit of {:e}",
            limits::MAX_COORDINATE
        )));
    }
    Ok(p)
}

/// A colour: each component from 0 to `limits::MAX_COLOUR`.
pub(super) fn colour3(at: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let c = DVec3::from_array(v);
    if !c.is_finite() {
        return Err(bad_input(format!(
            "{at} = {v:?} is not finite (NaN or infinity)"
        )));
    }
    if c.min_element() < 0.0 {
        return Err(bad_input(format!("{at} = {v:?} has a negative component")));
    }
    if c.max_element() > limits::MAX_COLOUR {
        return Err(bad_input(format!(
            "{at} = {v:?} has a component above the limit of {:e}",
            limits::MAX_COLOUR
        )));
    }
    Ok(c)
}

/// A count against its limit, as a usize.
pub(super) fn count(at: &str, n: u32, max: u32) -> anyhow::Result<usize> {
    limits::check_count(at, n as usize, max as usize)?;
    Ok(n as usize)
}

pub(super) fn unit_normal(at: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let n = DVec3::from_array(v);
    if !n.is_finite() {
        return Err(bad_input(format!(
            "{at} = {v:?} is not finite (NaN or infinity)"
        )));
    }
    let len = n.length();
    if !(len > 1e-12 && len.is_finite()) {
        return Err(bad_input(format!("{at} = {v:?} has zero length")));
    }
    Ok(n / len)
}

/// The unit geometric normal, or zero for a degenerate triangle: the tracer never
/// hits those, so their normal is never used.
pub(super) fn flat_normal(p: &[DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
}
