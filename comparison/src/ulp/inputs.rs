//! The probe's inputs, recomputed on the CPU bit for bit: the same integer
//! hash and the same operand rules as shaders/lab/ulp.glsl, so that `twinray
//! ulp` knows every input of every result without reading one back. Keep the
//! two files in step; `--ulp-op bits` (which returns operand 0's bits
//! untouched) checks them against each other on every run.

use twinray_common::lab::experiment::UlpOp;

/// Chris Wellons' lowbias32, as `ulp_hash` in the shader.
pub fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The classes of inputs, by the value of `class`: four of eight are random.
pub const CLASSES: [&str; 8] = [
    "random", "random", "random", "random", "near-one", "tiny", "denormal", "large",
];

/// The distinct class names, in report order.
pub const CLASS_NAMES: [&str; 5] = ["random", "near-one", "tiny", "denormal", "large"];

/// What the classes hold, for the report.
pub const CLASS_TEXT: &str =
    "random: sign and mantissa random, |x| in [2^-20, 2^21) (half the inputs); \
     near-one: within 64 ULPs of +1 or -1; tiny: normals in [2^-126, 2^-102); \
     denormal: exponent field 0, mantissa random and non-zero; large: |x| in [2^100, 2^128). \
     All operands of one input share its class";

/// The class of input `i`, as `ulp_class`.
pub fn class(i: u32) -> u32 {
    hash(i ^ 0xa511_e9b3) & 7
}

/// The bits of operand `slot` of input `i`, of class `cls`, as `ulp_operand`.
pub fn operand(i: u32, slot: u32, cls: u32) -> u32 {
    let h = hash(i.wrapping_mul(16).wrapping_add(slot));
    let g = hash(h ^ 0x9e37_79b9);
    let sign = h & 0x8000_0000;
    let mant = h & 0x7f_ffff;
    match cls {
        4 => (0x3f80_0000 + g % 129 - 64) | (g & 0x8000_0000),
        5 => sign | ((1 + g % 24) << 23) | mant,
        6 => sign | mant | 1,
        7 => sign | ((227 + g % 28) << 23) | mant,
        _ => sign | ((107 + g % 41) << 23) | mant,
    }
}

fn float(i: u32, slot: u32) -> f32 {
    f32::from_bits(operand(i, slot, class(i)))
}

fn positive(i: u32, slot: u32) -> f32 {
    f32::from_bits(operand(i, slot, class(i)) & 0x7fff_ffff)
}

/// A positive number in [2^(lo-127), 2^(lo-127+span)), as `ulp_ranged`.
fn ranged(i: u32, slot: u32, lo: u32, span: u32) -> f32 {
    let h = hash(i.wrapping_mul(16).wrapping_add(slot));
    let g = hash(h ^ 0x9e37_79b9);
    f32::from_bits(((lo + g % span) << 23) | (h & 0x7f_ffff))
}

/// The total order of floats as unsigned integers, as `ulp_key`.
fn key(b: u32) -> u32 {
    if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// The operands of input `i` of `op`, in the order `ops::eval` reads them:
/// scalars `x[0..3]`; vectors `a = x[0..3]`, `b = x[3..6]`; refract's eta
/// and pow's exponent as the shader draws them.
pub fn operands(op: UlpOp, i: u32) -> [f32; 7] {
    let mut x = [0.0f32; 7];
    match op {
        UlpOp::Sqrt | UlpOp::Inversesqrt => x[0] = positive(i, 0),
        UlpOp::Pow => {
            x[0] = positive(i, 0);
            x[1] = ranged(i, 1, 124, 10);
        }
        UlpOp::Clamp => {
            let cls = class(i);
            let (a, b) = (operand(i, 1, cls), operand(i, 2, cls));
            let (lo, hi) = if key(b) < key(a) { (b, a) } else { (a, b) };
            x[0] = float(i, 0);
            x[1] = f32::from_bits(lo);
            x[2] = f32::from_bits(hi);
        }
        _ => {
            for (slot, v) in x.iter_mut().enumerate().take(6) {
                *v = float(i, slot as u32);
            }
            if op == UlpOp::Refract {
                x[6] = ranged(i, 6, 126, 2);
            }
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_class_draws_what_it_says() {
        let mut seen = [0u32; 8];
        for i in 0..4096 {
            let cls = class(i);
            seen[cls as usize] += 1;
            let v = f32::from_bits(operand(i, 0, cls)).abs();
            let ok = match CLASSES[cls as usize] {
                "random" => (2f32.powi(-20)..2f32.powi(21)).contains(&v),
                "near-one" => (v - 1.0).abs() <= 64.0 * f32::EPSILON,
                "tiny" => (f32::MIN_POSITIVE..2f32.powi(-102)).contains(&v),
                "denormal" => v > 0.0 && v < f32::MIN_POSITIVE,
                _ => v >= 2f32.powi(100) && v.is_finite(),
            };
            assert!(ok, "input {i}, class {cls}: {v:e}");
        }
        assert!(seen.iter().all(|&n| n > 300), "{seen:?}");
    }

    #[test]
    fn clamp_bounds_are_ordered_and_pow_and_eta_in_range() {
        for i in 0..4096 {
            let c = operands(UlpOp::Clamp, i);
            assert!(c[1] <= c[2] || (c[1] == 0.0 && c[2] == 0.0), "{c:?}");
            let p = operands(UlpOp::Pow, i);
            assert!(p[0] >= 0.0 && (0.125..128.0).contains(&p[1]), "{p:?}");
            let r = operands(UlpOp::Refract, i);
            assert!((0.5..2.0).contains(&r[6]), "{r:?}");
        }
    }
}
