//! Eight lanes of `f32` for the shading kernels: a kernel is written once against [`L8`] and
//! compiled twice, inside a function with AVX enabled (chosen at run time when the CPU has it)
//! and without (the portable form). `L8`'s operations are lane-by-lane loops over arrays that
//! LLVM turns into one vector instruction each where the target has them (`vmulps`,
//! `vsqrtps`, `vcmpps`, `vblendvps`, ...). Only IEEE basic operations (add, subtract, multiply,
//! divide, square root: correctly rounded, so the same bits in a vector register as in a scalar
//! one), comparisons and selects, in the order the kernel writes them: both forms, and the
//! scalar code a kernel copies, give the same bits.
//!
//! Deliberately missing: fused multiply-add (it rounds once where the scalar code rounds
//! twice) and any approximate reciprocal or square root. Written without intrinsics, because
//! an intrinsic called from a trait method is not inlined into the AVX function that uses it.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Lanes per vector.
pub(crate) const LANES: usize = 8;

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct L8(pub [f32; LANES]);

/// Eight lane masks: all bits set (true) or clear (false) per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct M8([i32; LANES]);

#[inline(always)]
fn map(f: impl Fn(usize) -> f32) -> L8 {
    L8(std::array::from_fn(f))
}

#[inline(always)]
fn mask(f: impl Fn(usize) -> bool) -> M8 {
    M8(std::array::from_fn(|i| -(f(i) as i32)))
}

macro_rules! l8_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for L8 {
            type Output = L8;
            #[inline(always)]
            fn $f(self, o: L8) -> L8 {
                map(|i| self.0[i] $op o.0[i])
            }
        }
    };
}
l8_op!(Add, add, +);
l8_op!(Sub, sub, -);
l8_op!(Mul, mul, *);
l8_op!(Div, div, /);

impl Neg for L8 {
    type Output = L8;
    #[inline(always)]
    fn neg(self) -> L8 {
        map(|i| -self.0[i])
    }
}

impl BitAnd for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitand(self, o: M8) -> M8 {
        M8(std::array::from_fn(|i| self.0[i] & o.0[i]))
    }
}

impl BitOr for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitor(self, o: M8) -> M8 {
        M8(std::array::from_fn(|i| self.0[i] | o.0[i]))
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(std::array::from_fn(|i| !self.0[i]))
    }
}

impl M8 {
    /// Lane-wise equality of two masks.
    #[inline(always)]
    pub fn same(self, o: M8) -> M8 {
        !M8(std::array::from_fn(|i| self.0[i] ^ o.0[i]))
    }
}

impl L8 {
    #[inline(always)]
    pub fn splat(x: f32) -> Self {
        L8([x; LANES])
    }

    /// The first eight values of `s`.
    #[inline(always)]
    pub fn load(s: &[f32]) -> Self {
        L8(s[..LANES].try_into().expect("eight lanes"))
    }

    /// Writes the lanes to the first eight slots of `s`.
    #[inline(always)]
    pub fn store(self, s: &mut [f32]) {
        s[..LANES].copy_from_slice(&self.0);
    }

    #[inline(always)]
    pub fn sqrt(self) -> Self {
        map(|i| self.0[i].sqrt())
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        map(|i| self.0[i].abs())
    }

    /// `f32::copysign(1.0, x)` per lane.
    #[inline(always)]
    pub fn sign_one(self) -> Self {
        map(|i| 1.0f32.copysign(self.0[i]))
    }

    /// `f32::max(x, 0.0)` per lane (a NaN lane gives 0).
    #[inline(always)]
    pub fn max_zero(self) -> Self {
        map(|i| self.0[i].max(0.0))
    }

    #[inline(always)]
    pub fn gt(self, o: Self) -> M8 {
        mask(|i| self.0[i] > o.0[i])
    }

    #[inline(always)]
    pub fn ge(self, o: Self) -> M8 {
        mask(|i| self.0[i] >= o.0[i])
    }

    #[inline(always)]
    pub fn eq(self, o: Self) -> M8 {
        mask(|i| self.0[i] == o.0[i])
    }

    #[inline(always)]
    pub fn lt(self, o: Self) -> M8 {
        mask(|i| self.0[i] < o.0[i])
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M8, a: Self, b: Self) -> Self {
        map(|i| if m.0[i] != 0 { a.0[i] } else { b.0[i] })
    }
}
