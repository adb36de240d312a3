//! Error-free transformations and the exact reduction of huge hub angles.
//!
//! The mesh depends on the hub angles only through the transmission error
//! `TE = φp·g_p + φg·g_g` (Eq. 16) and the phase of the pinion within one pitch 2π/z_p. Both
//! are differences of large, nearly equal numbers when the angles are large: after 10¹² rad the
//! products φ·g are about 4·10¹⁰ m with an ulp of 8·10⁻⁶ m, and the pitch 2π/z_p rounded to a
//! double is off by up to 1.4·10⁻¹⁷ rad, which 5·10¹² pitches turn into 7·10⁻⁵ rad. Computed
//! naively, TE is then wrong by micrometres — as much as the whole static TE.
//!
//! This module computes both exactly in the given doubles, with Knuth's and Dekker's
//! error-free transformations:
//!
//! * [`two_sum`]: `a + b = s + e` exactly, s = fl(a + b) (six flops, no branch).
//! * [`two_prod`]: `a·b = p + e` exactly, p = fl(a·b), e = fma(a, b, −p).
//! * [`dot2`]: `a·b + c·d` as if computed in twice the precision and rounded once (the
//!   Ogita–Rump–Oishi "Dot2" for two terms): the error is at most ½ ulp of the result plus
//!   about 2⁻¹⁰⁴·(|a·b| + |c·d|), i.e. ≤ 10⁻²⁰ m for TE at 10¹² rad.
//! * [`Pitch`]: the angular pitch 2π/z as a double-double (hi + lo, about 106 bits: 2π is
//!   carried as fl(2π) + 2.449…·10⁻¹⁶) and [`Pitch::reduce`], the remainder φ − k·2π/z with k
//!   the nearest whole number of pitches, computed with `two_prod` on k·hi so that no digit of φ
//!   is lost. The error is at most ½ ulp of the remainder plus |k|·2⁻¹⁰⁴·2π/z, i.e. about
//!   10⁻²⁰ rad at 10¹² rad. This requires |k| ≤ 2⁵³ = [`MAX_PITCHES`] (every such integer is
//!   a double, and k·hi is then split exactly): |φ| ≤ [`Pitch::max_angle`] = 2⁵³·2π/z, i.e.
//!   1.9·10¹⁵ rad for z = 30 and 3.8·10¹⁴ rad for z = 150. Beyond it the computed quotient
//!   φ·z/2π is off by more than a pitch and k no longer exact as the nearest whole number, and
//!   from 2⁶³ pitches k is not even representable in an `i64`: callers check the bound first
//!   ([`crate::mesh::validity`]).
//!
//! What cannot be recovered is the rounding of the inputs themselves: a hub angle near 10¹² rad
//! is a double with an ulp of 1.2·10⁻⁴ rad, i.e. a TE granularity of ½ ulp(φ)·g ≈ 3–4 µm per
//! gear. The outputs are those of the state the given doubles describe exactly; the base radii
//! g are the doubles of the geometry (whose ratio differs from z_p/z_g by a few ulps, so that
//! exact whole-pitch shifts of both angles change TE by |k|·|2π/z_p·g_p − 2π/z_g·g_g|, again a
//! few ulp(φ)·g at most).

use std::f64::consts::TAU;

/// Largest number of whole pitches |k| of an exact reduction ([`Pitch::reduce`]): 2⁵³, up to
/// which every integer is a double.
pub const MAX_PITCHES: f64 = 9_007_199_254_740_992.0;

/// fl(2π) − 2π to double precision: 2π = `TAU` + `TAU_LO` to about 2⁻¹⁰⁶ relative.
pub const TAU_LO: f64 = 2.449_293_598_294_706_4e-16;

/// Knuth's two-sum: returns (s, e) with s = fl(a + b) and a + b = s + e exactly (barring
/// overflow).
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Dekker's fast two-sum: like [`two_sum`] but requires |a| ≥ |b| (or a = 0).
#[inline(always)]
pub fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let e = b - (s - a);
    (s, e)
}

/// Two-product: returns (p, e) with p = fl(a·b) and a·b = p + e exactly (barring overflow and
/// underflow of e), via one fused multiply-add.
#[inline(always)]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let e = a.mul_add(b, -p);
    (p, e)
}

/// `a·b + c·d` computed in twice the working precision and rounded once (see the module docs
/// for the bound).
#[inline(always)]
pub fn dot2(a: f64, b: f64, c: f64, d: f64) -> f64 {
    let (p1, e1) = two_prod(a, b);
    let (p2, e2) = two_prod(c, d);
    let (s, es) = two_sum(p1, p2);
    s + (es + (e1 + e2))
}

/// The gear angle φg with φp·g_p + φg·g_g = `te`: (te − φp·g_p)/g_g with the product exact
/// (two rounding errors in all, so that a huge φp loses no digits of TE before the division).
#[inline]
pub fn phi_g_for_te(phi_p: f64, te: f64, g_p: f64, g_g: f64) -> f64 {
    let (p, e) = two_prod(phi_p, g_p);
    ((te - p) - e) / g_g
}

/// An angular pitch 2π/z as a double-double, with the exact reduction of an angle modulo it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pitch {
    /// Leading part, fl(2π/z).
    pub hi: f64,
    /// Trailing part: 2π/z − hi to about 2⁻¹⁰⁶ relative.
    pub lo: f64,
    inv: f64,
}

impl Pitch {
    /// The pitch 2π/z of a gear with `z` teeth (z ≥ 1).
    pub fn of_teeth(z: u32) -> Self {
        let zf = f64::from(z.max(1));
        let hi = TAU / zf;
        // TAU − hi·z exactly (z has at most 32 bits, so hi·z is exact in two_prod's split).
        let (p, e) = two_prod(hi, zf);
        let r = (TAU - p) - e; // TAU − p is exact (Sterbenz): p is within one ulp of TAU
        let lo = (r + TAU_LO) / zf;
        let (hi, lo) = fast_two_sum(hi, lo);
        Self { hi, lo, inv: zf / TAU }
    }

    /// The pitch as one double (fl(2π/z)).
    pub fn value(&self) -> f64 {
        self.hi
    }

    /// The largest |φ| (rad) that [`Pitch::reduce`] reduces exactly: [`MAX_PITCHES`] pitches.
    pub fn max_angle(&self) -> f64 {
        MAX_PITCHES * self.hi
    }

    /// Returns (r, k): k the nearest whole number of pitches to `phi` (as a float holding an
    /// integer) and r = φ − k·2π/z computed without loss of the digits of φ, |r| ≤ ½ pitch (up
    /// to 10⁻¹² of it: the rounding of the quotient φ·z/2π, up to 2⁻⁵²·|k| pitches, is
    /// corrected from the exact remainder when it moves k off the nearest whole number by more
    /// than that). Exact for |φ| ≤ [`Pitch::max_angle`];
    /// beyond it k is a whole number of pitches near φ, no longer the nearest, and the
    /// remainder loses digits. Non-finite φ gives a non-finite r.
    #[inline(always)]
    pub fn reduce(&self, phi: f64) -> (f64, f64) {
        self.reduce_with::<false>(phi)
    }

    /// [`Pitch::reduce`] with the roundings of [`round_with`]: the same (r, k).
    #[inline(always)]
    pub fn reduce_with<const NATIVE: bool>(&self, phi: f64) -> (f64, f64) {
        let round = round_with::<NATIVE>;
        let k = round(phi * self.inv);
        if k == 0.0 || !k.is_finite() {
            return (phi, if k.is_finite() { 0.0 } else { k });
        }
        let r = self.remainder(phi, k);
        if r.abs() <= 0.5 * self.hi * (1.0 + 1e-12) {
            return (r, k);
        }
        // The quotient's rounding (2⁻⁵²·|k| pitches) moved k off the nearest whole number
        // (at huge |k| only; a remainder within 10⁻¹² of half a pitch is left as it is, so
        // that moderate angles reduce bit for bit as without this step): correct it from the
        // exact remainder (k + k1 stays exact for |φ| within `max_angle`).
        let k = k + round(r * self.inv);
        (self.remainder(phi, k), k)
    }

    /// φ − k·(hi + lo), exactly up to the rounding of the result and of k·lo.
    #[inline(always)]
    fn remainder(&self, phi: f64, k: f64) -> f64 {
        let (p1, e1) = two_prod(k, self.hi); // k·hi = p1 + e1 exactly
        let p2 = k * self.lo; // |k·lo| ≤ 2⁻⁵³·|k·hi|: its rounding is far below ulp(r)
        let (s, es) = two_sum(phi, -p1); // φ − p1, exact
        let (t, et) = two_sum(s, -e1);
        t + (et + es - p2)
    }
}

/// `x.round()` (nearest integer, ties away from zero), bit for bit, without the library call
/// that `f64::round` compiles to on a baseline x86-64 target (no SSE4.1 rounding instruction):
/// below 2⁵² in magnitude the truncation `t` is exact and so is `x − t`; above, every double
/// is an integer already. The sign of a zero result is that of `x`, as for `f64::round`.
#[inline(always)]
pub fn round(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = x as i64 as f64;
        let d = x - t;
        let r = if d >= 0.5 {
            t + 1.0
        } else if d <= -0.5 {
            t - 1.0
        } else {
            t
        };
        r.copysign(x)
    } else {
        x.round()
    }
}

/// ⌊x⌉ as [`round`]: with `NATIVE` `f64::round` itself, which a caller compiled with SSE4.1
/// turns into rounding instructions (the library call is what [`round`] avoids on a baseline
/// target), otherwise [`round`]; the same value either way.
#[inline(always)]
pub fn round_with<const NATIVE: bool>(x: f64) -> f64 {
    if NATIVE { x.round() } else { round(x) }
}

/// ⌊x⌋ as [`floor`]: with `NATIVE` `f64::floor` itself (one rounding instruction in a caller
/// compiled with SSE4.1), otherwise [`floor`]; the same value either way.
#[inline(always)]
pub fn floor_with<const NATIVE: bool>(x: f64) -> f64 {
    if NATIVE { x.floor() } else { floor(x) }
}

/// `x.floor()`, bit for bit, without the library call of a baseline x86-64 target (see
/// [`round`]).
#[inline(always)]
pub fn floor(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = x as i64 as f64;
        let r = if t > x { t - 1.0 } else { t };
        r.copysign(x)
    } else {
        x.floor()
    }
}

/// Single-sided amplitude spectrum of `x` (one period sampled uniformly): amplitude of bin j,
/// the mean at j = 0, for j = 0 … n/2. By an FFT of length n (`rustfft`, any n, O(n·log n)):
/// the 10⁶ samples a spectrum may hold take well under a second, where the direct DFT
/// (O(n²)) took hours. The amplitude is |X_j|/n at j = 0 and j = n/2, 2·|X_j|/n otherwise.
pub fn amplitude_spectrum(x: &[f64]) -> Vec<f64> {
    use rustfft::num_complex::Complex;
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let mut buf: Vec<Complex<f64>> = x.iter().map(|&v| Complex::new(v, 0.0)).collect();
    rustfft::FftPlanner::<f64>::new().plan_fft_forward(n).process(&mut buf);
    (0..=n / 2)
        .map(|j| {
            let scale = if j == 0 || 2 * j == n { 1.0 } else { 2.0 };
            scale * buf[j].norm() / n as f64
        })
        .collect()
}

/// 64-bit FNV-1a hash of `bytes` (offset basis 0xcbf29ce484222325, prime 0x100000001b3): the
/// checksum of serialised FMU states and unit snapshots. Not cryptographic; any single flipped
/// bit changes it, and a random corruption passes with probability 2⁻⁶⁴.
pub fn fnv1a_64(bytes: &[u8]) -> u64 {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    bytes.iter().fold(OFFSET, |h, &b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

/// True when the CPU has AVX2 and FMA (x86-64; the answer is cached by the standard library).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn has_avx2_fma() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// True when the CPU has FMA and SSE4.1 (x86-64): code compiled for them turns the exact
/// products of [`two_prod`] into one instruction instead of a library call, and the floors and
/// roundings of [`floor_with`] and [`round_with`] into SSE4.1 rounding instructions, with the
/// same values bit for bit (a fused multiply-add is exact either way, floor and round are
/// exact), so results do not depend on the CPU.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn has_fma_sse41() -> bool {
    std::arch::is_x86_feature_detected!("fma") && std::arch::is_x86_feature_detected!("sse4.1")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `round` and `floor` are `f64::round` and `f64::floor` bit for bit: halves, values next
    /// to integers and halves, signed zeros, the 2⁵² boundary, huge values, infinities, NaN.
    #[test]
    fn round_and_floor_match_the_library_bit_for_bit() {
        let mut xs = vec![0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, 1e300];
        for k in -40_i64..=40 {
            for base in [k as f64, k as f64 + 0.5] {
                xs.extend([base, base.next_up(), base.next_down()]);
            }
        }
        for e in 50..=54 {
            let b = 2f64.powi(e);
            xs.extend([b, b.next_up(), b.next_down(), b + 0.5, b - 0.5, b + 1.5]);
        }
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        for _ in 0..100_000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
            xs.push((u - 0.5) * 10f64.powi((seed % 40) as i32 - 20));
        }
        for x in xs.into_iter().flat_map(|x| [x, -x]) {
            assert_eq!(round(x).to_bits(), x.round().to_bits(), "round({x:e})");
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "floor({x:e})");
        }
        assert!(round(f64::NAN).is_nan() && floor(f64::NAN).is_nan());
    }

    /// Exact value of a finite double as (mantissa, exponent): x = m·2^e.
    fn split(x: f64) -> (i128, i32) {
        if x == 0.0 {
            return (0, 0);
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let frac = (bits & ((1u64 << 52) - 1)) as i128;
        let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | (1 << 52), exp - 1075) };
        (if x < 0.0 { -m } else { m }, e)
    }

    /// Exact a·b − (p + e) in i128 arithmetic for moderate exponents: zero for an exact
    /// two-product.
    fn residual_prod(a: f64, b: f64, p: f64, e: f64) -> i128 {
        let (ma, ea) = split(a);
        let (mb, eb) = split(b);
        let (mp, ep) = split(p);
        let (me, ee) = split(e);
        let base = (ea + eb).min(ep).min(if me == 0 { ep } else { ee });
        let sh = |m: i128, e: i32| m << (e - base);
        sh(ma * mb, ea + eb) - sh(mp, ep) - sh(me, ee)
    }

    #[test]
    fn two_sum_is_error_free() {
        let cases = [
            (1.0, 1e-17),
            (1e12, -0.1),
            (0.1, 0.2),
            (-3.5e10, 3.5e10 + 1.0),
            (1e-300, 1.0),
            (2f64.powi(53), 1.0),
        ];
        for (a, b) in cases {
            let (s, e) = two_sum(a, b);
            assert_eq!(s, a + b);
            // s + e == a + b exactly: check in the other order and with the fast variant.
            let (s2, e2) = two_sum(b, a);
            assert_eq!((s, e), (s2, e2));
            let (big, small) = if a.abs() >= b.abs() { (a, b) } else { (b, a) };
            assert_eq!(fast_two_sum(big, small), (s, e));
            // And e is what is left over: (a − s) + b == e when |a| ≥ |b|.
            if a.abs() >= b.abs() {
                assert_eq!((a - s) + b, e, "{a} + {b}");
            }
        }
    }

    #[test]
    fn two_prod_is_error_free() {
        let cases = [
            (0.1, 0.3),
            (1e12, 0.042_860_6),
            (-4.77e12, 0.209_439_510_239_319_55),
            (std::f64::consts::PI, std::f64::consts::E),
            (3.0, 1.0 / 3.0),
        ];
        for (a, b) in cases {
            let (p, e) = two_prod(a, b);
            assert_eq!(p, a * b);
            assert_eq!(residual_prod(a, b, p, e), 0, "{a}·{b}");
        }
    }

    #[test]
    fn dot2_rounds_once() {
        // 1e12·g_p − 1e12·(g_p − 2⁻⁴⁰) = 2⁻⁴⁰·1e12 exactly representable; naive loses it.
        let g = 0.042_860_6;
        let a = 1e12;
        let c = -1e12;
        let d = g - 2f64.powi(-40);
        let exact = dot2(a, g, c, d);
        let (ma, ea) = split(a);
        let (mg, eg) = split(g);
        let (mc, ec) = split(c);
        let (md, ed) = split(d);
        let base = (ea + eg).min(ec + ed);
        let sum = ((ma * mg) << (ea + eg - base)) + ((mc * md) << (ec + ed - base));
        let reference = sum as f64 * 2f64.powi(base);
        assert_eq!(exact, reference);
        assert!((a * g + c * d - reference).abs() > 1e-6, "the naive sum should be off");
    }

    #[test]
    fn pitch_is_double_double_and_reduce_is_exact() {
        for z in [1u32, 12, 17, 30, 47, 150] {
            let p = Pitch::of_teeth(z);
            // hi + lo carries 2π/z: z·(hi + lo) − TAU equals TAU_LO to a few 2⁻¹⁰⁶.
            let (ph, pe) = two_prod(p.hi, f64::from(z));
            let rest = ((ph - TAU) + pe) + p.lo * f64::from(z);
            assert!((rest - TAU_LO).abs() <= 4.0 * TAU * 2f64.powi(-104), "z {z}: {rest:e}");
            assert!(p.lo.abs() <= 0.5 * p.hi * f64::EPSILON);
        }
        let p = Pitch::of_teeth(30);
        // Small angles pass unchanged; one pitch off reduces to the small angle.
        assert_eq!(p.reduce(0.05), (0.05, 0.0));
        let (r, k) = p.reduce(p.hi + 0.05);
        assert_eq!(k, 1.0);
        assert!((r - 0.05).abs() < 1e-17);
        // A multiple of the double-double pitch: k·(hi + lo) + r0 built exactly in pieces.
        for k in [4.0e12_f64, -7.123_456_789e11, 2.0f64.powi(45)] {
            let (h1, h2) = two_prod(k, p.hi);
            let phi = h1; // the double nearest to k·hi: φ = k·hi + k·lo − (h2 + k·lo)
            let expected = -(h2 + k * p.lo);
            let (r, kk) = p.reduce(phi);
            assert_eq!(kk, k);
            assert!((r - expected).abs() <= 1e-19, "k {k}: {r:e} vs {expected:e}");
        }
        assert!(p.reduce(f64::NAN).0.is_nan());
        assert!(!p.reduce(f64::INFINITY).0.is_finite());
    }
}
