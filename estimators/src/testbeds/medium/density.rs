//! The extinction fields of paper 002 §4: the analytic medium of Eq. 21 and a 12-octave fractional
//! Brownian motion of Perlin's improved gradient noise (book: testbeds.md).

use mcbench_core::math::Vec3;

/// Paper 002 Eq. 21, the one place this formula lives, with the exponent `k` of its first factor
/// (the test bed's parameter `exponent`; maximum 1 for every `k`):
/// `sigma_t = ((cos(1.5 (x + y + z)) + 1) / 2)^k * ((sin(z / 2) + 2) / 3)` inside the sphere.
/// At `k = 1` the value is the product of the two factors bit for bit.
pub fn eq21(p: Vec3, k: i32) -> f64 {
    let wave = ((1.5 * (p.x + p.y + p.z)).cos() + 1.0) / 2.0;
    let wave = if k == 1 { wave } else { wave.powi(k) };
    wave * (((p.z / 2.0).sin() + 2.0) / 3.0)
}

/// Ken Perlin's reference permutation ("Improving noise", SIGGRAPH 2002).
const PERM: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37, 240,
    21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177, 33, 88,
    237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83,
    111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216,
    80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173, 186,
    3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206, 59, 227, 47, 16, 58, 17,
    182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153, 101, 155, 167, 43, 172, 9, 129,
    22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238,
    210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184,
    84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195,
    78, 66, 215, 61, 156, 180,
];

#[inline]
fn perm(i: usize) -> usize {
    PERM[i & 255] as usize
}

#[inline]
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn lerp(t: f64, a: f64, b: f64) -> f64 {
    a + t * (b - a)
}

/// Perlin's gradient of `hash` dotted with `(x, y, z)`: `±u ± v` with `u` and `v` two of the
/// coordinates chosen by the low 4 bits. Written without branches (the hash is random, so the
/// branches of the textbook form mispredict half the time): the coordinates are picked by index
/// and negated by flipping the sign bit, which is exactly what `-u` does, so the value is the
/// textbook one bit for bit (a test compares them).
#[inline]
fn grad(hash: usize, x: f64, y: f64, z: f64) -> f64 {
    /// Per low 4 bits of the hash: which coordinate is `u` and which is `v` (0 = x, 1 = y, 2 = z).
    const U: [u8; 16] = [0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1];
    const V: [u8; 16] = [1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 0, 2, 0, 2];
    const SIGN: u64 = 1 << 63;
    let h = hash & 15;
    let c = [x, y, z];
    let u = f64::from_bits(c[U[h] as usize].to_bits() ^ ((h as u64 & 1) << 63));
    let v = f64::from_bits(c[V[h] as usize].to_bits() ^ (((h as u64 >> 1) & 1) * SIGN));
    u + v
}

/// `x.floor()` without the library call (the default x86-64 target has no rounding instruction):
/// the truncation, one less for negative non-integers, with the sign of zero kept (`floor(-0.0)`
/// is `-0.0`). Exact for every `|x| < 2^52`; larger values, infinities and NaN go to `floor`.
#[inline]
fn floor(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = (x as i64 as f64).copysign(x);
        if t > x {
            t - 1.0
        } else {
            t
        }
    } else {
        x.floor()
    }
}

/// Perlin's improved noise (2002), in about [-1, 1].
pub fn improved_noise(x: f64, y: f64, z: f64) -> f64 {
    let (fx, fy, fz) = (floor(x), floor(y), floor(z));
    let (xi, yi, zi) = ((fx as i64 & 255) as usize, (fy as i64 & 255) as usize, (fz as i64 & 255) as usize);
    let (x, y, z) = (x - fx, y - fy, z - fz);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let a = perm(xi) + yi;
    let (aa, ab) = (perm(a) + zi, perm(a + 1) + zi);
    let b = perm(xi + 1) + yi;
    let (ba, bb) = (perm(b) + zi, perm(b + 1) + zi);
    lerp(
        w,
        lerp(
            v,
            lerp(u, grad(perm(aa), x, y, z), grad(perm(ba), x - 1.0, y, z)),
            lerp(u, grad(perm(ab), x, y - 1.0, z), grad(perm(bb), x - 1.0, y - 1.0, z)),
        ),
        lerp(
            v,
            lerp(u, grad(perm(aa + 1), x, y, z - 1.0), grad(perm(ba + 1), x - 1.0, y, z - 1.0)),
            lerp(u, grad(perm(ab + 1), x, y - 1.0, z - 1.0), grad(perm(bb + 1), x - 1.0, y - 1.0, z - 1.0)),
        ),
    )
}

/// The Perlin medium's constants (book: testbeds.md): `sigma_t = clamp(BIAS + GAIN_K * fbm(FREQ p), 0, 1)`
/// with `fbm(q) = sum_{o < OCTAVES} 0.5^o noise(2^o q + o * OFFSET)` (lacunarity 2, gain 0.5; the
/// per-octave offset keeps octaves from sharing the lattice's zeros at the origin).
pub mod perlin_constants {
    /// Octaves of the full stack.
    pub const OCTAVES: usize = 12;
    /// Base frequency (lattice cells per unit length): base features about 4 units wide.
    pub const FREQ: f64 = 0.25;
    /// Offset of the fbm.
    pub const BIAS: f64 = 0.3;
    /// Gain of the fbm.
    pub const GAIN_K: f64 = 1.1;
    /// Per-octave lattice offset.
    pub const OFFSET: f64 = 0.37;
    /// Octaves of the cheap approximate extinction (control variates).
    pub const CHEAP_OCTAVES: usize = 3;
}

/// The first `octaves` octaves of the fbm at `p` (world coordinates).
pub fn fbm(p: Vec3, octaves: usize) -> f64 {
    use perlin_constants::*;
    let (mut sum, mut amp, mut f) = (0.0, 1.0, FREQ);
    for o in 0..octaves {
        let off = o as f64 * OFFSET;
        sum += amp * improved_noise(p.x * f + off, p.y * f + off, p.z * f + off);
        amp *= 0.5;
        f *= 2.0;
    }
    sum
}

/// The Perlin medium's extinction from the first `octaves` octaves.
pub fn perlin(p: Vec3, octaves: usize) -> f64 {
    use perlin_constants::*;
    (BIAS + GAIN_K * fbm(p, octaves)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook gradient (Perlin 2002), which [`grad`] must equal bit for bit.
    fn textbook_grad(hash: usize, x: f64, y: f64, z: f64) -> f64 {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let v = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    }

    #[test]
    fn branchless_grad_and_floor_are_the_textbook_ones_bit_for_bit() {
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let specials = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.5, -2.5, 1e-300, -1e-300, 4.5e15, -4.5e15, 1e300, -1e300];
        for _ in 0..200_000 {
            let r = next();
            let x = match r % 4 {
                0 => f64::from_bits(next()),
                1 => (next() as i64 as f64) * 1e-12,
                2 => ((next() % 2001) as f64 - 1000.0) * 0.125,
                _ => specials[(next() % specials.len() as u64) as usize],
            };
            if !x.is_nan() {
                assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "floor({x:e})");
            }
            let (y, z) = ((next() as i64 as f64) * 1e-18, -((next() as i64 as f64) * 1e-18));
            for h in 0..16 {
                let (a, b) = (grad(h, x, y, z), textbook_grad(h, x, y, z));
                assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "grad {h} at {x:e}");
            }
        }
        assert!(floor(f64::NAN).is_nan());
        assert_eq!(floor(f64::NEG_INFINITY), f64::NEG_INFINITY);
    }

    #[test]
    fn permutation_is_a_permutation_and_noise_is_pinned() {
        let mut seen = [false; 256];
        PERM.iter().for_each(|&p| seen[p as usize] = true);
        assert!(seen.iter().all(|&s| s));
        assert_eq!(improved_noise(1.0, 2.0, 3.0), 0.0); // zero on the lattice
        assert!(improved_noise(0.5, 0.25, 0.125).abs() <= 1.0);
    }

    #[test]
    fn eq21_maximum_is_one_for_every_exponent() {
        // Both factors reach 1 at z = pi with x + y + z = 4 pi / 3 * k.
        let z = std::f64::consts::PI;
        let p = Vec3::new(4.0 * std::f64::consts::PI / 3.0 - z, 0.0, z);
        for k in [1, 2, 5, 16] {
            assert!((eq21(p, k) - 1.0).abs() < 1e-12, "k = {k}");
        }
        // Elsewhere the exponent thins the medium: the wave factor below 1 shrinks with k.
        let q = Vec3::new(0.3, -1.2, 7.0);
        let wave = ((1.5 * (q.x + q.y + q.z)).cos() + 1.0) / 2.0;
        assert!(wave < 0.99);
        assert!((eq21(q, 5) / eq21(q, 1) - wave.powi(4)).abs() < 1e-12);
        assert!(eq21(q, 5) < eq21(q, 1));
    }
}
