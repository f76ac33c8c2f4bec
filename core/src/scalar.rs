//! The scalar type every kernel is generic over.
//!
//! `f64` for production evaluations, num-dual's `DualSVec64<N>` (gradients,
//! Jacobians) and `HyperDualSVec64<M, N>` (mixed second derivatives) when a
//! derivative is wanted: every element kernel and joint map is written once for
//! any [`Scalar`], and automatic differentiation runs through the same code.

use nalgebra::RealField;
use num_dual::DualStruct;

/// A real scalar that nalgebra can do algebra with and whose real part is an
/// `f64` (so that kernels can branch on magnitudes, e.g. to pick a series
/// expansion near a removable singularity).
///
/// Blanket-implemented for `f64` and num-dual's vector duals and hyper-duals.
pub trait Scalar: RealField + Copy + DualStruct<Real = f64> {
    /// The real (non-derivative) part.
    #[inline]
    fn value(&self) -> f64 {
        self.re()
    }
}

impl<T: RealField + Copy + DualStruct<Real = f64>> Scalar for T {}

/// An `f64` constant as a scalar of type `T`.
#[inline]
pub fn cst<T: Scalar>(v: f64) -> T {
    nalgebra::convert(v)
}
