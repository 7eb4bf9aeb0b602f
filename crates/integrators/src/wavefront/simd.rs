//! Lanes of `f32` for the shading kernels: one kernel, written once against [`Lanes`], runs on
//! eight lanes at a time with AVX ([`avx::L8`]) or on one at a time ([`L1`]). Both forms use
//! only IEEE basic operations (add, subtract, multiply, divide, square root: correctly
//! rounded, so the same bits in a vector register as in a scalar one), comparisons and
//! selects, in the order the kernel writes them. So the two forms, and the scalar tracer
//! whose arithmetic a kernel copies, give the same bits.
//!
//! Deliberately missing: fused multiply-add (it rounds once where the scalar code rounds
//! twice) and any approximate reciprocal or square root.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// A vector of `N` lanes of `f32` with lane-wise masks.
pub(crate) trait Lanes:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Lane-wise truth values.
    type Mask: Copy
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// Lanes per vector.
    const N: usize;
    fn splat(x: f32) -> Self;
    /// The first `N` values of `s`.
    fn load(s: &[f32]) -> Self;
    /// Writes the lanes to the first `N` slots of `s`.
    fn store(self, s: &mut [f32]);
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `1.0` with the sign of each lane (`f32::copysign(1.0, x)`).
    fn sign_one(self) -> Self;
    /// Lane-wise `f32::max(self, 0.0)` for lanes that are not NaN; a NaN lane gives 0 too.
    fn max_zero(self) -> Self;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn eq(self, o: Self) -> Self::Mask;
    fn lt(self, o: Self) -> Self::Mask;
    /// Lane-wise equality of two masks.
    fn same(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// `a` where `m`, else `b`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
}

/// One lane: plain `f32` arithmetic (the portable form, and the tail of a batch).
#[derive(Clone, Copy, Debug)]
pub(crate) struct L1(pub f32);

macro_rules! l1_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for L1 {
            type Output = L1;
            #[inline(always)]
            fn $f(self, o: L1) -> L1 {
                L1(self.0 $op o.0)
            }
        }
    };
}
l1_op!(Add, add, +);
l1_op!(Sub, sub, -);
l1_op!(Mul, mul, *);
l1_op!(Div, div, /);

impl Neg for L1 {
    type Output = L1;
    #[inline(always)]
    fn neg(self) -> L1 {
        L1(-self.0)
    }
}

impl Lanes for L1 {
    type Mask = bool;
    const N: usize = 1;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        L1(x)
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        L1(s[0])
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        s[0] = self.0;
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        L1(self.0.sqrt())
    }
    #[inline(always)]
    fn abs(self) -> Self {
        L1(self.0.abs())
    }
    #[inline(always)]
    fn sign_one(self) -> Self {
        L1(1.0f32.copysign(self.0))
    }
    #[inline(always)]
    fn max_zero(self) -> Self {
        L1(self.0.max(0.0))
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self.0 > o.0
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self.0 >= o.0
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self.0 == o.0
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self.0 < o.0
    }
    #[inline(always)]
    fn same(a: bool, b: bool) -> bool {
        a == b
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
}

/// Eight AVX lanes. Private to this module's users in `wavefront`: an [`avx::L8`] may only be
/// made inside a function compiled with AVX enabled that runs after the CPU was checked for it
/// (see [`super::lambert`]'s dispatch), which is what makes its safe methods sound.
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)] // the intrinsics, sound under the rule above
pub(crate) mod avx {
    use super::Lanes;
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

    #[derive(Clone, Copy, Debug)]
    pub(crate) struct L8(__m256);

    /// Eight lane masks (all bits set or clear per lane).
    #[derive(Clone, Copy, Debug)]
    pub(crate) struct M8(__m256);

    macro_rules! l8_op {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl $tr for L8 {
                type Output = L8;
                #[inline(always)]
                fn $f(self, o: L8) -> L8 {
                    // SAFETY: an L8 exists only where AVX is available (see the type's doc).
                    L8(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
    l8_op!(Add, add, _mm256_add_ps);
    l8_op!(Sub, sub, _mm256_sub_ps);
    l8_op!(Mul, mul, _mm256_mul_ps);
    l8_op!(Div, div, _mm256_div_ps);

    macro_rules! m8_op {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl $tr for M8 {
                type Output = M8;
                #[inline(always)]
                fn $f(self, o: M8) -> M8 {
                    // SAFETY: as for L8.
                    M8(unsafe { $intr(self.0, o.0) })
                }
            }
        };
    }
    m8_op!(BitAnd, bitand, _mm256_and_ps);
    m8_op!(BitOr, bitor, _mm256_or_ps);

    impl Not for M8 {
        type Output = M8;
        #[inline(always)]
        fn not(self) -> M8 {
            // SAFETY: as for L8.
            M8(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
        }
    }

    impl Neg for L8 {
        type Output = L8;
        #[inline(always)]
        fn neg(self) -> L8 {
            // SAFETY: as for L8. Flipping the sign bit is exactly scalar negation.
            L8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
        }
    }

    #[inline(always)]
    fn cmp<const P: i32>(a: L8, b: L8) -> M8 {
        // SAFETY: as for L8.
        M8(unsafe { _mm256_cmp_ps::<P>(a.0, b.0) })
    }

    impl Lanes for L8 {
        type Mask = M8;
        const N: usize = 8;
        #[inline(always)]
        fn splat(x: f32) -> Self {
            // SAFETY: as for L8.
            L8(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        fn load(s: &[f32]) -> Self {
            let s = &s[..8];
            // SAFETY: as for L8; `s` holds eight floats (checked by the slice above).
            L8(unsafe { _mm256_loadu_ps(s.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, s: &mut [f32]) {
            let s = &mut s[..8];
            // SAFETY: as for L8; `s` has room for eight floats.
            unsafe { _mm256_storeu_ps(s.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            // SAFETY: as for L8.
            L8(unsafe { _mm256_sqrt_ps(self.0) })
        }
        #[inline(always)]
        fn abs(self) -> Self {
            // SAFETY: as for L8.
            L8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
        }
        #[inline(always)]
        fn sign_one(self) -> Self {
            // SAFETY: as for L8. The sign bit of `self` on the bits of 1.0.
            L8(unsafe {
                let sign = _mm256_and_ps(self.0, _mm256_set1_ps(-0.0));
                _mm256_or_ps(sign, _mm256_set1_ps(1.0))
            })
        }
        #[inline(always)]
        fn max_zero(self) -> Self {
            // SAFETY: as for L8. `maxps` returns its second operand when either is NaN,
            // so a NaN lane gives 0, as `f32::max` does.
            L8(unsafe { _mm256_max_ps(self.0, _mm256_setzero_ps()) })
        }
        #[inline(always)]
        fn gt(self, o: Self) -> M8 {
            cmp::<_CMP_GT_OQ>(self, o)
        }
        #[inline(always)]
        fn ge(self, o: Self) -> M8 {
            cmp::<_CMP_GE_OQ>(self, o)
        }
        #[inline(always)]
        fn eq(self, o: Self) -> M8 {
            cmp::<_CMP_EQ_OQ>(self, o)
        }
        #[inline(always)]
        fn lt(self, o: Self) -> M8 {
            cmp::<_CMP_LT_OQ>(self, o)
        }
        #[inline(always)]
        fn same(a: M8, b: M8) -> M8 {
            !(M8(
                // SAFETY: as for L8.
                unsafe { _mm256_xor_ps(a.0, b.0) },
            ))
        }
        #[inline(always)]
        fn select(m: M8, a: Self, b: Self) -> Self {
            // SAFETY: as for L8.
            L8(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
        }
    }
}
