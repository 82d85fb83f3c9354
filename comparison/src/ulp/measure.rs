//! From a probe image to error statistics: the transport (two pixels per f32
//! result, 16 bits each as two bytes k/255 in red and green, a check byte of
//! the pixel's index in blue, as shaders/lab/ulp.glsl writes them), the ULP
//! error of one result against its f64 reference, and the statistics per
//! class of input.
//!
//! The error of a result `g` against the f64 reference `r` is |g - r| in
//! units of the spacing of f32 at `round_to_f32(r)` (2^-149 at zero and among
//! the denormals; the spacing at f32::MAX where `r` overflows f32): a
//! correctly rounded result is within 0.5. Results counted apart, not in the
//! ULP statistics: *flushed* (an input or the result is denormal and the
//! driver's result is nearer the reference with denormals flushed to zero);
//! *branch* (refract: nearer the other side of the total-internal-reflection
//! test); *non-finite* (one of result and reference is NaN or infinite and
//! the other is not, or they are different infinities, not explained by a
//! flush). Two NaNs, or equal infinities, agree (error 0).

use super::inputs::{class, operands, CLASSES, CLASS_NAMES};
use super::ops::{components, flushed, ieee_f32, other_branch, reference};
use twinray_common::lab::experiment::UlpOp;

/// The check byte of pixel `p`, as `ulp_pixel`'s blue channel.
pub fn check_byte(p: u32) -> u8 {
    (super::inputs::hash(p ^ 0x5bd1_e995) & 0xff) as u8
}

/// The two RGB pixels that carry `bits` as result `r` (the shader's encoding
/// after the PNG's quantisation): used by the tests.
#[cfg(test)]
pub fn encode(bits: u32, r: u32) -> [[u8; 3]; 2] {
    let p = 2 * r;
    [
        [(bits >> 24) as u8, (bits >> 16) as u8, check_byte(p)],
        [(bits >> 8) as u8, bits as u8, check_byte(p + 1)],
    ]
}

/// The results an image carries, in order; an error names the first pixel
/// whose check byte is wrong (a transport that moved or changed pixels).
pub fn decode(rgb: &[u8]) -> anyhow::Result<Vec<u32>> {
    let pixels: Vec<&[u8]> = rgb.chunks_exact(3).collect();
    let mut out = Vec::with_capacity(pixels.len() / 2);
    for (r, pair) in pixels.chunks_exact(2).enumerate() {
        for (k, px) in pair.iter().enumerate() {
            let p = (2 * r + k) as u32;
            if px[2] != check_byte(p) {
                anyhow::bail!(
                    "pixel {p} of the probe image carries check byte {} instead of {}: the image did not come back as the shader wrote it",
                    px[2],
                    check_byte(p)
                );
            }
        }
        out.push(u32::from_be_bytes([
            pair[0][0], pair[0][1], pair[1][0], pair[1][1],
        ]));
    }
    Ok(out)
}

/// The spacing of f32 at `v` (finite).
pub fn ulp_at(v: f32) -> f64 {
    let exponent = ((v.to_bits() >> 23) & 0xff) as i32;
    2f64.powi(exponent.max(1) - 127 - 23)
}

/// `g`'s error against `r` in ULPs, `None` where one is non-finite and the
/// other is not (or the infinities differ).
pub fn ulp_error(g: f32, r: f64) -> Option<f64> {
    if r.is_nan() || g.is_nan() {
        return (r.is_nan() && g.is_nan()).then_some(0.0);
    }
    let r32 = r as f32;
    if g.is_infinite() || r.is_infinite() {
        return (r32 == g).then_some(0.0);
    }
    let at = if r32.is_infinite() { f32::MAX } else { r32 };
    Some((f64::from(g) - r).abs() / ulp_at(at))
}

/// How one result came out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    Ulp(f64),
    Flushed,
    Branch,
    NonFinite,
}

/// Whether `alt` explains `g` better than the reference's error `e` does.
fn explains(g: f32, alt: Option<f64>, e: Option<f64>) -> bool {
    let Some(alt) = alt else { return false };
    match (ulp_error(g, alt), e) {
        (Some(a), Some(e)) => e > 0.5 && a + 0.5 < e,
        (Some(_), None) => true,
        _ => false,
    }
}

pub fn outcome(op: UlpOp, x: &[f32; 7], c: usize, g: f32) -> Outcome {
    let e = ulp_error(g, reference(op, x, c));
    if explains(g, flushed(op, x, c), e) {
        Outcome::Flushed
    } else if explains(g, other_branch(op, x, c), e) {
        Outcome::Branch
    } else {
        e.map_or(Outcome::NonFinite, Outcome::Ulp)
    }
}

/// The statistics of one class of inputs (or of all).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    pub results: u64,
    /// Results in the ULP statistics.
    pub measured: u64,
    pub sum: f64,
    pub max: f64,
    /// Results within 0.5 ULP (correctly rounded).
    pub rounded: u64,
    pub flushed: u64,
    pub branch: u64,
    pub nonfinite: u64,
    /// The result with the largest error: input index, component, operand
    /// bits, the result's bits, the reference.
    pub worst: Option<(u32, usize, Vec<u32>, u32, f64)>,
}

impl Stats {
    pub fn mean(&self) -> Option<f64> {
        (self.measured > 0).then(|| self.sum / self.measured as f64)
    }

    fn add(&mut self, o: Outcome, worst: impl FnOnce() -> (u32, usize, Vec<u32>, u32, f64)) {
        self.results += 1;
        match o {
            Outcome::Ulp(e) => {
                self.measured += 1;
                self.sum += e;
                self.rounded += u64::from(e <= 0.5);
                if self.worst.is_none() || e > self.max {
                    self.max = e;
                    self.worst = Some(worst());
                }
            }
            Outcome::Flushed => self.flushed += 1,
            Outcome::Branch => self.branch += 1,
            Outcome::NonFinite => self.nonfinite += 1,
        }
    }
}

/// Statistics for all inputs, then per class (`CLASS_NAMES` order).
pub type ByClass = Vec<(&'static str, Stats)>;

/// The statistics of `results` (bits, in result order) of `op`; the
/// results past the last whole input are ignored.
pub fn measure(op: UlpOp, results: &[u32]) -> ByClass {
    measure_with(op, results.len() as u32 / components(op), |_, _, r| {
        f32::from_bits(results[r])
    })
}

/// The statistics of the IEEE f32 baseline over `inputs` inputs.
pub fn baseline(op: UlpOp, inputs: u32) -> ByClass {
    measure_with(op, inputs, |x, c, _| ieee_f32(op, x, c))
}

fn measure_with(
    op: UlpOp,
    inputs: u32,
    result: impl Fn(&[f32; 7], usize, usize) -> f32,
) -> ByClass {
    let n = components(op);
    let mut all = Stats::default();
    let mut per: Vec<Stats> = vec![Stats::default(); CLASS_NAMES.len()];
    for i in 0..inputs {
        let x = operands(op, i);
        let name = CLASSES[class(i) as usize];
        let slot = CLASS_NAMES.iter().position(|c| *c == name).unwrap_or(0);
        for c in 0..n as usize {
            let r = (i * n) as usize + c;
            let g = result(&x, c, r);
            let o = if op == UlpOp::Bits {
                // The transport check: bits, not arithmetic.
                let want = super::inputs::operand(i, 0, class(i));
                if g.to_bits() == want {
                    Outcome::Ulp(0.0)
                } else {
                    Outcome::NonFinite
                }
            } else {
                outcome(op, &x, c, g)
            };
            let worst = || {
                let bits = x.iter().map(|v| v.to_bits()).collect();
                (i, c, bits, g.to_bits(), reference(op, &x, c))
            };
            all.add(o, worst);
            per[slot].add(o, worst);
        }
    }
    std::iter::once(("all", all))
        .chain(CLASS_NAMES.iter().copied().zip(per))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_class_of_bit_pattern_round_trips_the_transport() {
        let patterns: Vec<u32> = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            f32::MIN_POSITIVE,
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::EPSILON,
        ]
        .iter()
        .map(|v| v.to_bits())
        .chain([
            1,
            0x007f_ffff,
            0x8000_0001,
            0x7fc0_0000,
            0x7f80_0001,
            0xffff_ffff,
            0x00ff_ff00,
        ])
        .chain((0..4096u32).map(super::super::inputs::hash))
        .collect();
        let rgb: Vec<u8> = patterns
            .iter()
            .enumerate()
            .flat_map(|(r, &b)| encode(b, r as u32))
            .flatten()
            .collect();
        // Through the PNG's quantisation of the shader's k/255 values, as the apps write it.
        let through: Vec<u8> = rgb
            .iter()
            .map(|&k| twinray_common::reference::image_io::quantize(f32::from(k) * (1.0 / 255.0)))
            .collect();
        assert_eq!(decode(&through).unwrap(), patterns);
        let mut moved = through.clone();
        moved.rotate_left(3);
        assert!(decode(&moved)
            .unwrap_err()
            .to_string()
            .contains("check byte"));
    }

    #[test]
    fn errors_are_counted_in_ulps_at_the_rounded_reference() {
        assert_eq!(ulp_error(1.0, 1.0), Some(0.0));
        assert_eq!(ulp_error(1.0 + f32::EPSILON, 1.0), Some(1.0));
        assert_eq!(
            ulp_error(1.0, 1.0 + f64::from(f32::EPSILON) / 2.0),
            Some(0.5)
        );
        assert_eq!(
            ulp_error(f32::from_bits(3), f64::from(f32::from_bits(1))),
            Some(2.0)
        );
        assert_eq!(ulp_error(f32::NAN, f64::NAN), Some(0.0));
        assert_eq!(ulp_error(f32::INFINITY, 1e300), Some(0.0));
        assert_eq!(ulp_error(f32::INFINITY, 1.0), None);
        assert_eq!(ulp_error(1.0, f64::NAN), None);
        // A denormal flushed to zero is counted apart, not as 5 ULPs.
        let d = f32::from_bits(5);
        let x = [d, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert_eq!(outcome(UlpOp::Add, &x, 0, 0.0), Outcome::Flushed);
        assert_eq!(outcome(UlpOp::Add, &x, 0, d), Outcome::Ulp(0.0));
        assert_eq!(
            outcome(UlpOp::Add, &x, 0, f32::from_bits(6)),
            Outcome::Ulp(1.0)
        );
    }

    #[test]
    fn the_ieee_baseline_rounds_the_single_operations_correctly() {
        for op in [
            UlpOp::Add,
            UlpOp::Mul,
            UlpOp::Div,
            UlpOp::Sqrt,
            UlpOp::Fma,
            UlpOp::Min,
            UlpOp::Clamp,
        ] {
            let all = &baseline(op, 20_000)[0].1;
            assert_eq!(all.results, 20_000, "{op:?}");
            assert!(all.max <= 0.5, "{op:?}: {all:?}");
        }
        // A composite one does not: dot's three roundings show.
        assert!(baseline(UlpOp::Dot, 20_000)[0].1.max > 0.5);
    }
}
