//! What each probed operation should give: the f64 result of the operation on
//! the f32 inputs (the "correctly rounded" reference: f64 carries 29 more
//! bits than the f32 result needs), the same with denormals flushed to zero
//! (what a driver that flushes gives), the other branch of refract's
//! total-internal-reflection test, and the operation done in IEEE f32 one
//! step at a time on the CPU (the spec's formula, no fused multiply-add), the
//! baseline that says how much of a composite operation's error any f32
//! implementation has.

use twinray_common::lab::experiment::UlpOp;

/// Results per input: one per component.
pub fn components(op: UlpOp) -> u32 {
    match op {
        UlpOp::Normalize | UlpOp::Cross | UlpOp::Reflect | UlpOp::Refract => 3,
        _ => 1,
    }
}

fn v3<T: Copy>(x: &[T], at: usize) -> [T; 3] {
    [x[at], x[at + 1], x[at + 2]]
}

/// The arithmetic both references share, generic over f32 and f64 so that
/// the formula is written once.
trait Real:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    fn of(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn pow(self, e: Self) -> Self;
    fn fma(self, b: Self, c: Self) -> Self;
    fn min(self, b: Self) -> Self;
    fn max(self, b: Self) -> Self;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            fn of(v: f32) -> Self {
                v as $t
            }
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            fn pow(self, e: Self) -> Self {
                <$t>::powf(self, e)
            }
            fn fma(self, b: Self, c: Self) -> Self {
                <$t>::mul_add(self, b, c)
            }
            fn min(self, b: Self) -> Self {
                <$t>::min(self, b)
            }
            fn max(self, b: Self) -> Self {
                <$t>::max(self, b)
            }
        }
    };
}
real!(f32);
real!(f64);

fn dot<T: Real>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Refract's `k`: below zero the ray is totally reflected (the result is 0).
fn refract_k<T: Real>(i: [T; 3], n: [T; 3], eta: T) -> T {
    let d = dot(n, i);
    T::of(1.0) - eta * eta * (T::of(1.0) - d * d)
}

/// Component `c` of `op` on the inputs `x` (as `inputs::operands` lays
/// them out), in `T`'s arithmetic. `tir` forces refract's branch: `None`
/// takes the one `k` says.
fn eval<T: Real>(op: UlpOp, x: &[T; 7], c: usize, tir: Option<bool>) -> T {
    let (a, b) = (v3(x, 0), v3(x, 3));
    let zero = T::of(0.0);
    match op {
        UlpOp::Bits => x[0],
        UlpOp::Add => x[0] + x[1],
        UlpOp::Mul => x[0] * x[1],
        UlpOp::Div => x[0] / x[1],
        UlpOp::Sqrt => x[0].sqrt(),
        UlpOp::Inversesqrt => T::of(1.0) / x[0].sqrt(),
        UlpOp::Pow => x[0].pow(x[1]),
        UlpOp::Fma => x[0].fma(x[1], x[2]),
        UlpOp::Min => x[0].min(x[1]),
        UlpOp::Max => x[0].max(x[1]),
        UlpOp::Clamp => x[0].max(x[1]).min(x[2]),
        UlpOp::Dot => dot(a, b),
        UlpOp::Length => dot(a, a).sqrt(),
        UlpOp::Normalize => a[c] / dot(a, a).sqrt(),
        UlpOp::Cross => {
            let (j, k) = ((c + 1) % 3, (c + 2) % 3);
            a[j] * b[k] - a[k] * b[j]
        }
        UlpOp::Reflect => a[c] - T::of(2.0) * dot(b, a) * b[c],
        UlpOp::Refract => {
            let eta = x[6];
            let k = refract_k(a, b, eta);
            if tir.unwrap_or(k < zero) {
                zero
            } else {
                let k = if k < zero { zero } else { k };
                eta * a[c] - (eta * dot(b, a) + k.sqrt()) * b[c]
            }
        }
    }
}

fn widen(x: &[f32; 7]) -> [f64; 7] {
    x.map(f64::from)
}

/// The reference: `op` in f64 on the f32 inputs.
pub fn reference(op: UlpOp, x: &[f32; 7], c: usize) -> f64 {
    eval(op, &widen(x), c, None)
}

/// The IEEE f32 baseline, one rounding per step.
pub fn ieee_f32(op: UlpOp, x: &[f32; 7], c: usize) -> f32 {
    eval(op, x, c, None)
}

fn is_denormal(v: f32) -> bool {
    v != 0.0 && v.abs() < f32::MIN_POSITIVE
}

fn flush(v: f32) -> f32 {
    if is_denormal(v) {
        0.0f32.copysign(v)
    } else {
        v
    }
}

/// The reference with denormal inputs and a denormal result flushed to a
/// signed zero: `None` where nothing is denormal (flushing changes nothing).
pub fn flushed(op: UlpOp, x: &[f32; 7], c: usize) -> Option<f64> {
    let r = reference(op, x, c);
    let r32 = r as f32;
    if !x.iter().any(|&v| is_denormal(v)) && !is_denormal(r32) {
        return None;
    }
    let r = eval(op, &widen(&x.map(flush)), c, None);
    Some(if is_denormal(r as f32) {
        0.0f64.copysign(r)
    } else {
        r
    })
}

/// Refract's other branch: the value had the f32 test of `k` gone the
/// other way (`None` for every other operation).
pub fn other_branch(op: UlpOp, x: &[f32; 7], c: usize) -> Option<f64> {
    if op != UlpOp::Refract {
        return None;
    }
    let w = widen(x);
    let tir = refract_k(v3(&w, 0), v3(&w, 3), w[6]) < 0.0;
    Some(eval(op, &w, c, Some(!tir)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_references_agree_with_hand_values() {
        let mut x = [0.0f32; 7];
        x[..6].copy_from_slice(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(reference(UlpOp::Dot, &x, 0), 32.0);
        assert_eq!(reference(UlpOp::Cross, &x, 0), -3.0);
        assert_eq!(reference(UlpOp::Cross, &x, 1), 6.0);
        assert_eq!(reference(UlpOp::Cross, &x, 2), -3.0);
        assert_eq!(reference(UlpOp::Reflect, &x, 0), 1.0 - 2.0 * 32.0 * 4.0);
        assert_eq!(
            reference(UlpOp::Clamp, &[5.0, 1.0, 2.0, 0., 0., 0., 0.], 0),
            2.0
        );
        assert_eq!(
            ieee_f32(UlpOp::Length, &[3.0, 4.0, 0.0, 0., 0., 0., 0.], 0),
            5.0
        );
        // Refract at normal incidence passes straight through; grazing from glass reflects.
        let straight = [0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.75];
        assert_eq!(reference(UlpOp::Refract, &straight, 2), -1.0);
        let grazing = [1.0, 0.0, -0.01, 0.0, 0.0, 1.0, 1.5];
        assert_eq!(reference(UlpOp::Refract, &grazing, 0), 0.0);
        assert!(other_branch(UlpOp::Refract, &grazing, 0).unwrap() > 1.0);
    }

    #[test]
    fn flushing_applies_only_where_a_denormal_is() {
        let d = f32::from_bits(5);
        assert_eq!(
            flushed(UlpOp::Add, &[1.0, 2.0, 0., 0., 0., 0., 0.], 0),
            None
        );
        assert_eq!(
            flushed(UlpOp::Add, &[d, d, 0., 0., 0., 0., 0.], 0),
            Some(0.0)
        );
        assert_eq!(
            flushed(UlpOp::Div, &[1.0, d, 0., 0., 0., 0., 0.], 0),
            Some(f64::INFINITY)
        );
    }
}
