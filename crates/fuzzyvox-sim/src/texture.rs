//! Procedural texture fixed to world coordinates, so that every view of a surface agrees (what
//! stereo matching needs), and deterministic hashing for sensor noise.

use nalgebra::Point3;

use super::scene::SurfaceKind;

/// A well-mixed 64-bit hash of three lattice coordinates and a seed (SplitMix64 finaliser).
#[inline]
pub(crate) fn hash3(x: i64, y: i64, z: i64, seed: u64) -> u64 {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for v in [x, y, z] {
        h = (h ^ v as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 31;
    }
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 29)
}

/// A seed scrambled by the same finaliser, for hashes that must be independent from one seed to
/// the next. [`hash3`] takes its seed and its first coordinate by exclusive or before mixing, so
/// seeds that differ in a few low bits give the same values at coordinates that differ in those
/// bits: two frames rendered with such seeds carried the same sensor noise with columns swapped
/// (`u` xor the seeds' difference), a pattern that stereo matched at a disparity of 1 to 63
/// pixels wherever the image had no texture of its own (false surfaces 1-2 m in front of a
/// camera that looked at the sky). Scrambling the seed first makes that relation land at
/// coordinates far outside any image.
#[inline]
pub(crate) fn scramble(seed: u64) -> u64 {
    hash3(0, 0, 0, seed)
}

/// A deterministic hash of an integer triple and a seed, mapped to `[0, 1)`: the texture's noise,
/// and a seeded choice wherever one is needed (goals, flight queries).
#[inline]
pub fn unit_hash(x: i64, y: i64, z: i64, seed: u64) -> f32 {
    (hash3(x, y, z, seed) >> 40) as f32 / (1u64 << 24) as f32
}

/// Smooth value noise in `[0, 1]` at `p` (lattice spacing 1).
fn value_noise(p: [f64; 3], seed: u64) -> f32 {
    let base = p.map(|v| v.floor());
    let frac = [p[0] - base[0], p[1] - base[1], p[2] - base[2]].map(|t| {
        let t = t as f32;
        t * t * (3.0 - 2.0 * t)
    });
    let [bx, by, bz] = base.map(|v| v as i64);
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let corner = |dx, dy, dz| unit_hash(bx + dx, by + dy, bz + dz, seed);
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), frac[0]);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), frac[0]);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), frac[0]);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), frac[0]);
    lerp(lerp(x00, x10, frac[1]), lerp(x01, x11, frac[1]), frac[2])
}

/// The surface's reflectance at a world point: a per-kind base with four octaves of value
/// noise (features from about 3 cm to 50 cm), in `[0.05, 0.95]`.
pub(crate) fn albedo(point: &Point3<f64>, kind: SurfaceKind) -> f32 {
    let (base, seed) = match kind {
        SurfaceKind::Ground => (0.45, 11),
        SurfaceKind::Wall => (0.55, 23),
        SurfaceKind::Building => (0.5, 37),
        SurfaceKind::Trunk => (0.35, 41),
        SurfaceKind::Crown => (0.4, 53),
    };
    let mut value = 0.0;
    let mut amplitude = 0.5;
    let mut frequency = 2.0;
    for octave in 0..4 {
        let p = [
            point.x * frequency,
            point.y * frequency,
            point.z * frequency,
        ];
        value += amplitude * (value_noise(p, seed + octave) - 0.5);
        amplitude *= 0.6;
        frequency *= 2.5;
    }
    (base + 1.2 * value).clamp(0.05, 0.95)
}
