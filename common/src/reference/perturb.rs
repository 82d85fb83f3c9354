//! Which f32 operations the GPU's bad pixels depend on (issue 26, B2): hooks
//! at the tracer's sensitive steps that, in a laboratory build (cargo feature
//! `perturb`), round one operation's result to f32 and move it by up to k f32
//! ULPs, as a GPU's arithmetic may. Without the feature every hook is the
//! identity, inlined away: the default reference is unchanged, bit for bit
//! and in speed. The harness is `common/examples/perturb.rs`
//! (comparison/investigations/accuracy/perturb.sh runs it).

/// One step of the tracer the reference can perturb (the shader's names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// The primary ray's direction (`primary_dir`), each component.
    PrimaryDir,
    /// The length of every ray direction (primary, shadow, reflected,
    /// refracted): a direction from `normalize` is unit only to its rounding,
    /// and a GPU's `inversesqrt` is approximate. Each is scaled by
    /// 1 + m 2^-24, |m| <= k, its direction unchanged.
    DirLength,
    /// The sphere test's `b = dot(f, dir)`.
    SphereB,
    /// The sphere test's `dot(l, l)`, the squared distance of the centre to
    /// the ray, whose difference with r² is the discriminant (tangency).
    SphereDist2,
    /// The sphere test's `c = dot(f, f) - r²` (the near root c/q).
    SphereC,
    /// Both roots of the sphere test.
    SphereT,
    /// The sphere hit's t after the ray loop's Newton step (its own rounding
    /// and the error of its residual).
    RefinedT,
    /// The triangle test's edge decisions: the watertight test's three edge
    /// functions, Moller-Trumbore's u and v.
    TriEdge,
    /// The triangle test's t.
    TriT,
    /// The hit point `p = o + t d` (or rebuilt from the barycentrics), each component.
    HitPoint,
    /// The geometric normal, each component.
    Normal,
    /// Where a secondary or shadow ray starts (`spawn_point`), each component.
    Spawn,
    /// The shadow ray's direction and length.
    ShadowDir,
    /// `cos_i = -dot(d, n)` at glass.
    CosI,
    /// `k = 1 - eta²(1 - cos_i²)`, the refraction against total internal reflection decision.
    TirK,
    /// The refracted direction, each component.
    RefractDir,
    /// The reflected direction, each component.
    ReflectDir,
}

impl Op {
    /// Every operation, in the order the table lists them.
    pub const ALL: [Op; 17] = [
        Op::PrimaryDir,
        Op::DirLength,
        Op::SphereB,
        Op::SphereDist2,
        Op::SphereC,
        Op::SphereT,
        Op::RefinedT,
        Op::TriEdge,
        Op::TriT,
        Op::HitPoint,
        Op::Normal,
        Op::Spawn,
        Op::ShadowDir,
        Op::CosI,
        Op::TirK,
        Op::RefractDir,
        Op::ReflectDir,
    ];

    /// The kebab-case name the harness prints and takes.
    pub fn name(self) -> &'static str {
        match self {
            Op::PrimaryDir => "primary-dir",
            Op::DirLength => "dir-length",
            Op::SphereB => "sphere-b",
            Op::SphereDist2 => "sphere-dist2",
            Op::SphereC => "sphere-c",
            Op::SphereT => "sphere-t",
            Op::RefinedT => "refined-t",
            Op::TriEdge => "tri-edge",
            Op::TriT => "tri-t",
            Op::HitPoint => "hit-point",
            Op::Normal => "normal",
            Op::Spawn => "spawn",
            Op::ShadowDir => "shadow-dir",
            Op::CosI => "cos-i",
            Op::TirK => "tir-k",
            Op::RefractDir => "refract-dir",
            Op::ReflectDir => "reflect-dir",
        }
    }
}

#[cfg(not(feature = "perturb"))]
mod hooks {
    use super::Op;
    use glam::DVec3;

    #[inline(always)]
    pub fn at(_: Op, x: f64) -> f64 {
        x
    }

    #[inline(always)]
    pub fn at3(_: Op, v: DVec3) -> DVec3 {
        v
    }

    #[inline(always)]
    pub fn scaled(_: Op, v: DVec3) -> DVec3 {
        v
    }
}

#[cfg(feature = "perturb")]
mod hooks {
    use super::Op;
    use glam::DVec3;
    use std::sync::atomic::{AtomicI64, AtomicU8, Ordering};

    /// No operation perturbed.
    const NONE: u8 = u8::MAX;
    /// Every operation perturbed at once.
    const EVERY: u8 = u8::MAX - 1;

    static OP: AtomicU8 = AtomicU8::new(NONE);
    static ULPS: AtomicI64 = AtomicI64::new(0);

    /// Perturbs `op` (every operation with None) by up to `k` ULPs from now on;
    /// `set(Some(op), -1)` or `clear()` to stop.
    pub fn set(op: Option<Op>, k: i64) {
        ULPS.store(k, Ordering::Relaxed);
        OP.store(op.map_or(EVERY, |o| o as u8), Ordering::Relaxed);
    }

    /// The reference unperturbed again.
    pub fn clear() {
        OP.store(NONE, Ordering::Relaxed);
    }

    fn mix(mut z: u64) -> u64 {
        // splitmix64: a fixed, well-spread function of the value, so a
        // perturbed render is reproducible and its errors are uncorrelated.
        z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// The f32 ordered as integers, so that stepping crosses zero correctly.
    fn ordered(x: f32) -> i64 {
        let b = x.to_bits() as i32 as i64;
        if b < 0 {
            i32::MIN as i64 - b
        } else {
            b
        }
    }

    fn from_ordered(i: i64) -> f32 {
        let b = if i < 0 { i32::MIN as i64 - i } else { i };
        f32::from_bits(b as i32 as u32)
    }

    pub fn at(op: Op, x: f64) -> f64 {
        let on = OP.load(Ordering::Relaxed);
        if on != op as u8 && on != EVERY {
            return x;
        }
        let k = ULPS.load(Ordering::Relaxed);
        let f = x as f32;
        if !f.is_finite() || k <= 0 {
            return f as f64;
        }
        let span = 2 * k as u64 + 1;
        let m = (mix(x.to_bits() ^ ((op as u64) << 56)) % span) as i64 - k;
        from_ordered(ordered(f) + m) as f64
    }

    pub fn at3(op: Op, v: DVec3) -> DVec3 {
        // Each component its own draw: the components' bits differ.
        DVec3::new(at(op, v.x), at(op, v.y), at(op, v.z))
    }

    /// `v` scaled by 1 + m 2^-24, |m| <= k: its length wrong, its direction not.
    pub fn scaled(op: Op, v: DVec3) -> DVec3 {
        let on = OP.load(Ordering::Relaxed);
        if on != op as u8 && on != EVERY {
            return v;
        }
        let k = ULPS.load(Ordering::Relaxed);
        let span = 2 * k.max(0) as u64 + 1;
        let m = (mix(v.x.to_bits() ^ v.y.to_bits().rotate_left(21) ^ ((op as u64) << 56)) % span)
            as i64
            - k.max(0);
        v * (1.0 + m as f64 * (-24f64).exp2())
    }
}

pub use hooks::*;
