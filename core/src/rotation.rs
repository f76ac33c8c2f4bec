//! Rotations: the maps of SO(3) used by the beams, joints and integrators
//! (FORMULATION §1), generic over the [`Scalar`] so that num-dual can
//! differentiate through them.
//!
//! Conventions: `â` is the skew matrix of `a` (`â w = a × w`); rotation vectors
//! `ψ` with `Λ = exp(ψ̂)`; *spatial* (left) perturbations `Λ ← exp(δφ̂) Λ`;
//! tangent-scaled (Cayley) vectors `θ` with `Λ = cay(θ)`.
//!
//! Coefficients with removable singularities at `|ψ| = 0` are evaluated by
//! their Taylor series in `|ψ|²` when `|ψ|² < 10⁻²` (terms through `|ψ|⁸`, so
//! the truncation error is below 10⁻¹⁷ relative), and never through `|ψ|`
//! itself there: derivatives of every order stay finite at the identity.

use crate::scalar::{cst, Scalar};
use nalgebra::{Matrix3, Vector3, Vector4};

/// Below this `|ψ|²` the series branches are used.
pub(crate) const SERIES_LIMIT: f64 = 1e-2;

/// `â`: the skew-symmetric matrix with `â w = a × w`.
#[inline]
pub fn skew<T: Scalar>(a: &Vector3<T>) -> Matrix3<T> {
    let z = T::zero();
    Matrix3::new(z, -a.z, a.y, a.z, z, -a.x, -a.y, a.x, z)
}

/// `â² = a aᵀ − |a|² I`, written out (cheaper than `â â` on dual numbers).
#[inline]
pub fn skew_squared<T: Scalar>(a: &Vector3<T>) -> Matrix3<T> {
    let n = a.norm_squared();
    Matrix3::from_fn(|i, j| if i == j { a[i] * a[i] - n } else { a[i] * a[j] })
}

/// The product `a b` of 3 × 3 matrices written out: nalgebra's generic
/// product spends several times as many scalar operations (`αAB + βC` with
/// `α = β = 1` multiplied in), which dominates on dual numbers.
#[inline]
pub fn mm<T: Scalar>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(0, j)] + a[(i, 1)] * b[(1, j)] + a[(i, 2)] * b[(2, j)])
}

/// `aᵀ b` of 3 × 3 matrices, written out (see [`mm`]).
#[inline]
pub fn mtm<T: Scalar>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    Matrix3::from_fn(|i, j| a[(0, i)] * b[(0, j)] + a[(1, i)] * b[(1, j)] + a[(2, i)] * b[(2, j)])
}

/// `a bᵀ` of 3 × 3 matrices, written out (see [`mm`]).
#[inline]
pub fn mmt<T: Scalar>(a: &Matrix3<T>, b: &Matrix3<T>) -> Matrix3<T> {
    Matrix3::from_fn(|i, j| a[(i, 0)] * b[(j, 0)] + a[(i, 1)] * b[(j, 1)] + a[(i, 2)] * b[(j, 2)])
}

/// `a v` for a 3 × 3 matrix, written out (see [`mm`]).
#[inline]
pub fn mv<T: Scalar>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::from_fn(|i, _| a[(i, 0)] * v[0] + a[(i, 1)] * v[1] + a[(i, 2)] * v[2])
}

/// `aᵀ v` of a 3 × 3 matrix and a vector, written out (see [`mm`]).
#[inline]
pub fn mtv<T: Scalar>(a: &Matrix3<T>, v: &Vector3<T>) -> Vector3<T> {
    Vector3::from_fn(|i, _| a[(0, i)] * v[0] + a[(1, i)] * v[1] + a[(2, i)] * v[2])
}

/// The axial vector of the skew-symmetric part of `m`: `vee(â) = a`.
#[inline]
pub fn vee<T: Scalar>(m: &Matrix3<T>) -> Vector3<T> {
    let h = cst::<T>(0.5);
    Vector3::new(
        (m[(2, 1)] - m[(1, 2)]) * h,
        (m[(0, 2)] - m[(2, 0)]) * h,
        (m[(1, 0)] - m[(0, 1)]) * h,
    )
}

/// Evaluates `Σ_k c_k x^k` (Horner) for a short series in `x = |ψ|²`.
#[inline]
pub(crate) fn series<T: Scalar>(x: T, c: &[f64]) -> T {
    let mut acc = cst::<T>(c[c.len() - 1]);
    for &ck in c.iter().rev().skip(1) {
        acc = acc * x + cst::<T>(ck);
    }
    acc
}

/// Coefficients `(sin ψ/ψ, (1 − cos ψ)/ψ², (ψ − sin ψ)/ψ³)` as functions of `ψ² = |ψ|²`.
pub(crate) fn rodrigues_coefficients<T: Scalar>(t2: T) -> (T, T, T) {
    if t2.value() < SERIES_LIMIT {
        let a = series(
            t2,
            &[1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0],
        );
        let b = series(
            t2,
            &[
                0.5,
                -1.0 / 24.0,
                1.0 / 720.0,
                -1.0 / 40320.0,
                1.0 / 3628800.0,
            ],
        );
        let c = series(
            t2,
            &[
                1.0 / 6.0,
                -1.0 / 120.0,
                1.0 / 5040.0,
                -1.0 / 362880.0,
                1.0 / 39916800.0,
            ],
        );
        (a, b, c)
    } else {
        let t = t2.sqrt();
        let s = t.sin();
        let half_s = (t * cst::<T>(0.5)).sin();
        // 1 − cos ψ = 2 sin²(ψ/2): no cancellation for small ψ.
        let b = half_s * half_s * cst::<T>(2.0) / t2;
        (s / t, b, (t - s) / (t2 * t))
    }
}

/// Exponential map (Rodrigues): `exp(ψ̂) = I + (sin ψ/ψ) ψ̂ + ((1−cos ψ)/ψ²) ψ̂²`.
pub fn exp<T: Scalar>(psi: &Vector3<T>) -> Matrix3<T> {
    let (a, b, _) = rodrigues_coefficients(psi.norm_squared());
    Matrix3::identity() + skew(psi) * a + skew_squared(psi) * b
}

/// Spatial tangent of the exponential map (paper eq. 4): with `Λ = exp(ψ̂)`,
/// `δΛ Λᵀ = (H(ψ) δψ)^` where
/// `H(ψ) = I + ((1−cos ψ)/ψ²) ψ̂ + ((ψ − sin ψ)/ψ³) ψ̂²`.
/// The material tangent is `Hᵀ(ψ) = H(−ψ)`. `H(ψ) ψ = ψ`.
pub fn tangent<T: Scalar>(psi: &Vector3<T>) -> Matrix3<T> {
    let (_, b, c) = rodrigues_coefficients(psi.norm_squared());
    Matrix3::identity() + skew(psi) * b + skew_squared(psi) * c
}

/// Inverse of [`tangent`]:
/// `H⁻¹(ψ) = I − ½ψ̂ + ((1 − (ψ/2) cot(ψ/2))/ψ²) ψ̂²`, valid for `|ψ| < 2π`.
pub fn tangent_inverse<T: Scalar>(psi: &Vector3<T>) -> Matrix3<T> {
    let d = tangent_inverse_coefficient(psi.norm_squared());
    Matrix3::identity() - skew(psi) * cst::<T>(0.5) + skew_squared(psi) * d
}

/// The coefficient of `ψ̂²` in [`tangent_inverse`] as a function of
/// `t = ψ²`: `D(t) = (1 − (ψ/2) cot(ψ/2))/ψ²`, by its series near zero.
pub fn tangent_inverse_coefficient<T: Scalar>(t2: T) -> T {
    if t2.value() < SERIES_LIMIT {
        series(
            t2,
            &[
                1.0 / 12.0,
                1.0 / 720.0,
                1.0 / 30240.0,
                1.0 / 1209600.0,
                1.0 / 47900160.0,
            ],
        )
    } else {
        let h = t2.sqrt() * cst::<T>(0.5);
        (T::one() - h * h.cos() / h.sin()) / t2
    }
}

/// Unit quaternion `(w, x, y, z)` of a rotation matrix, `w ≥ 0`
/// (Shepperd's method: the largest of `w², x², y², z²` is taken from the
/// diagonal, the others from off-diagonal sums, so it is accurate at any angle).
pub fn quaternion_from_matrix<T: Scalar>(r: &Matrix3<T>) -> Vector4<T> {
    let one = T::one();
    let quarter = cst::<T>(0.25);
    let (r00, r11, r22) = (r[(0, 0)], r[(1, 1)], r[(2, 2)]);
    let tr = r00 + r11 + r22;
    let (t, a, b, c) = (tr.value(), r00.value(), r11.value(), r22.value());
    let q = if t >= a && t >= b && t >= c {
        let w = (one + tr).sqrt() * cst::<T>(0.5);
        let f = quarter / w;
        Vector4::new(
            w,
            (r[(2, 1)] - r[(1, 2)]) * f,
            (r[(0, 2)] - r[(2, 0)]) * f,
            (r[(1, 0)] - r[(0, 1)]) * f,
        )
    } else if a >= b && a >= c {
        let x = (one + r00 - r11 - r22).sqrt() * cst::<T>(0.5);
        let f = quarter / x;
        Vector4::new(
            (r[(2, 1)] - r[(1, 2)]) * f,
            x,
            (r[(0, 1)] + r[(1, 0)]) * f,
            (r[(0, 2)] + r[(2, 0)]) * f,
        )
    } else if b >= c {
        let y = (one - r00 + r11 - r22).sqrt() * cst::<T>(0.5);
        let f = quarter / y;
        Vector4::new(
            (r[(0, 2)] - r[(2, 0)]) * f,
            (r[(0, 1)] + r[(1, 0)]) * f,
            y,
            (r[(1, 2)] + r[(2, 1)]) * f,
        )
    } else {
        let z = (one - r00 - r11 + r22).sqrt() * cst::<T>(0.5);
        let f = quarter / z;
        Vector4::new(
            (r[(1, 0)] - r[(0, 1)]) * f,
            (r[(0, 2)] + r[(2, 0)]) * f,
            (r[(1, 2)] + r[(2, 1)]) * f,
            z,
        )
    };
    if q.x.value() < 0.0 {
        -q
    } else {
        q
    }
}

/// Rotation matrix of a unit quaternion `(w, x, y, z)`.
pub fn matrix_from_quaternion<T: Scalar>(q: &Vector4<T>) -> Matrix3<T> {
    let [r00, r01, r02, r10, r11, r12, r20, r21, r22] =
        rotation_entries([q.x, q.y, q.z, q.w], T::one(), cst::<T>(2.0));
    Matrix3::new(r00, r01, r02, r10, r11, r12, r20, r21, r22)
}

/// The entries, row by row, of the rotation matrix of the unit quaternion
/// `(w, x, y, z)` — [`matrix_from_quaternion`]'s, for any numbers with the
/// four operations (also pairs of nodes' at once, `pose_pair`).
pub(crate) fn rotation_entries<T>([w, x, y, z]: [T; 4], one: T, two: T) -> [T; 9]
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T> + std::ops::Mul<Output = T>,
{
    [
        one - two * (y * y + z * z),
        two * (x * y - w * z),
        two * (x * z + w * y),
        two * (x * y + w * z),
        one - two * (x * x + z * z),
        two * (y * z - w * x),
        two * (x * z - w * y),
        two * (y * z + w * x),
        one - two * (x * x + y * y),
    ]
}

/// Rotation vector of a unit quaternion `(w, x, y, z)`, `|ψ| ≤ π`:
/// `ψ = 2·atan2(|v|, w)·v/|v|` (after making `w ≥ 0`), by series near 0.
pub fn log_quaternion<T: Scalar>(q: &Vector4<T>) -> Vector3<T> {
    let q = if q.x.value() < 0.0 { -q } else { *q };
    let w = q.x;
    let v = Vector3::new(q.y, q.z, q.w);
    let s2 = v.norm_squared();
    let factor = if s2.value() < 1e-6 * w.value() * w.value() {
        // 2 atan(s/w)/s = (2/w)(1 − u/3 + u²/5 − u³/7 + u⁴/9), u = s²/w².
        let u = s2 / (w * w);
        series(u, &[1.0, -1.0 / 3.0, 1.0 / 5.0, -1.0 / 7.0, 1.0 / 9.0]) * cst::<T>(2.0) / w
    } else {
        let s = s2.sqrt();
        s.atan2(w) * cst::<T>(2.0) / s
    };
    v * factor
}

/// Hamilton product `a ⊗ b` of quaternions `(w, x, y, z)`: the quaternion
/// of the rotation `Λ(a) Λ(b)`.
pub fn quaternion_product<T: Scalar>(a: &Vector4<T>, b: &Vector4<T>) -> Vector4<T> {
    let (aw, av) = (a.x, Vector3::new(a.y, a.z, a.w));
    let (bw, bv) = (b.x, Vector3::new(b.y, b.z, b.w));
    let v = bv * aw + av * bw + av.cross(&bv);
    Vector4::new(aw * bw - av.dot(&bv), v.x, v.y, v.z)
}

/// The conjugate `(w, −v)` of a quaternion: the quaternion of `Λᵀ`.
pub fn quaternion_conjugate<T: Scalar>(q: &Vector4<T>) -> Vector4<T> {
    Vector4::new(q.x, -q.y, -q.z, -q.w)
}

/// The quaternion of `exp(½ψ̂)` from the unit quaternion `q` of `exp(ψ̂)`,
/// `|ψ| ≤ π` (`q` with `w ≥ 0`, as [`quaternion_from_matrix`] gives it): the
/// square root `(1 + w, v)/√(2(1 + w))` — no trigonometry, and `1 + w ≥ 1`.
pub fn quaternion_half<T: Scalar>(q: &Vector4<T>) -> Vector4<T> {
    let w1 = T::one() + q.x;
    let f = T::one() / (w1 * cst::<T>(2.0)).sqrt();
    Vector4::new(w1 * f, q.y * f, q.z * f, q.w * f)
}

/// The quaternion of `cay(θ)`: `(1, ½θ)/√(1 + ¼|θ|²)`.
pub fn cayley_quaternion<T: Scalar>(theta: &Vector3<T>) -> Vector4<T> {
    let half = cst::<T>(0.5);
    let f = T::one() / (T::one() + theta.norm_squared() * cst::<T>(0.25)).sqrt();
    Vector4::new(
        f,
        theta.x * half * f,
        theta.y * half * f,
        theta.z * half * f,
    )
}

/// The Cayley vector `θ = 2v/w` of the rotation of a quaternion `(w, v)`:
/// [`cayley_inverse`] without the matrix (undefined for half turns, `w = 0`).
pub fn cayley_of_quaternion<T: Scalar>(q: &Vector4<T>) -> Vector3<T> {
    Vector3::new(q.y, q.z, q.w) * (cst::<T>(2.0) / q.x)
}

/// The unit quaternion of `exp(ψ̂)`, `(cos ½|ψ|, sin(½|ψ|) ψ/|ψ|)`, by
/// series near the identity.
pub fn exp_quaternion<T: Scalar>(psi: &Vector3<T>) -> Vector4<T> {
    let t2 = psi.norm_squared();
    let (w, f) = if t2.value() < SERIES_LIMIT {
        // cos(½t) and sin(½t)/t in t².
        let x = t2 * cst::<T>(0.25);
        (
            series(x, &[1.0, -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0]),
            series(
                x,
                &[
                    0.5,
                    -1.0 / 12.0,
                    1.0 / 240.0,
                    -1.0 / 10080.0,
                    1.0 / 725760.0,
                ],
            ),
        )
    } else {
        let t = t2.sqrt();
        let h = t * cst::<T>(0.5);
        (h.cos(), h.sin() / t)
    };
    Vector4::new(w, psi.x * f, psi.y * f, psi.z * f)
}

/// Logarithm: the rotation vector `ψ`, `|ψ| ≤ π`, with `exp(ψ̂) = Λ`.
/// Computed through the quaternion (never `acos` of the trace), so it is
/// accurate near 0 and near π.
pub fn log<T: Scalar>(r: &Matrix3<T>) -> Vector3<T> {
    log_quaternion(&quaternion_from_matrix(r))
}

/// Cayley transform: `cay(θ) = I + 4/(4+|θ|²)·(θ̂ + ½θ̂²) = (I − ½θ̂)⁻¹(I + ½θ̂)`.
pub fn cayley<T: Scalar>(theta: &Vector3<T>) -> Matrix3<T> {
    let f = cst::<T>(4.0) / (cst::<T>(4.0) + theta.norm_squared());
    Matrix3::identity() + (skew(theta) + skew_squared(theta) * cst::<T>(0.5)) * f
}

/// Below this `1 + tr Λ` (rotations beyond 120°) [`cayley_inverse`] goes
/// through the quaternion, whose largest component is then not `w`.
pub(crate) const CAYLEY_DIRECT: f64 = 1.0;

/// Inverse Cayley transform: the tangent-scaled vector `θ` with `cay(θ) = Λ`
/// (undefined for half turns). From `cay(θ) = I + f(θ̂ + ½θ̂²)`,
/// `f = 4/(4 + |θ|²) = ¼(1 + tr Λ)`: `θ = 2 vee(Λ − Λᵀ)/(1 + tr Λ)` directly
/// (one division, no square root) while `1 + tr Λ ≥ 1`; beyond that,
/// `θ = 2v/w` from the quaternion (Shepperd), accurate towards half turns.
pub fn cayley_inverse<T: Scalar>(r: &Matrix3<T>) -> Vector3<T> {
    let tr1 = T::one() + r[(0, 0)] + r[(1, 1)] + r[(2, 2)];
    if tr1.value() >= CAYLEY_DIRECT {
        let f = cst::<T>(2.0) / tr1;
        return Vector3::new(
            (r[(2, 1)] - r[(1, 2)]) * f,
            (r[(0, 2)] - r[(2, 0)]) * f,
            (r[(1, 0)] - r[(0, 1)]) * f,
        );
    }
    let q = quaternion_from_matrix(r);
    Vector3::new(q.y, q.z, q.w) * (cst::<T>(2.0) / q.x)
}

/// The inverse of the Cayley map's tangent, `Q(θ)⁻¹ = I − ½θ̂ + ¼ θ⊗θ`:
/// `δθ = Q(θ)⁻¹ δφ` for `cay(θ) ← exp(δφ̂) cay(θ)` (a spatial spin; from
/// `θ = 2v/w` of the quaternion `(w, v)` and `(w, v) ← (1, ½δφ) ⊗ (w, v)`).
pub fn cayley_tangent_inverse<T: Scalar>(theta: &Vector3<T>) -> Matrix3<T> {
    Matrix3::identity() - skew(theta) * cst::<T>(0.5) + theta * theta.transpose() * cst::<T>(0.25)
}

/// Tangent-scaled rotation: `θ = tan(|ω|/2)/(|ω|/2)·ω`, so that `cay(θ) = exp(ω̂)`.
pub fn tan_scaled<T: Scalar>(omega: &Vector3<T>) -> Vector3<T> {
    let x2 = omega.norm_squared() * cst::<T>(0.25);
    let f = if x2.value() < SERIES_LIMIT {
        series(
            x2,
            &[
                1.0,
                1.0 / 3.0,
                2.0 / 15.0,
                17.0 / 315.0,
                62.0 / 2835.0,
                1382.0 / 155925.0,
            ],
        )
    } else {
        let x = x2.sqrt();
        x.tan() / x
    };
    omega * f
}

/// Inverse of [`tan_scaled`]: `ω = arctan(|θ|/2)/(|θ|/2)·θ`.
pub fn untan_scaled<T: Scalar>(theta: &Vector3<T>) -> Vector3<T> {
    let x2 = theta.norm_squared() * cst::<T>(0.25);
    let f = if x2.value() < SERIES_LIMIT {
        series(
            x2,
            &[
                1.0,
                -1.0 / 3.0,
                1.0 / 5.0,
                -1.0 / 7.0,
                1.0 / 9.0,
                -1.0 / 11.0,
            ],
        )
    } else {
        let x = x2.sqrt();
        x.atan() / x
    };
    theta * f
}

/// `S(θ)⁻¹ = ½(cay(θ) + I) = (I − ½θ̂)⁻¹ = (I + ½θ̂ + ¼θ⊗θ)/(1 + ¼|θ|²)`.
/// With `Λₙ₊₁ = cay(θ)Λₙ`, the algebraic mid-point is `Λₙ₊½ = S(θ)⁻¹Λₙ` and
/// `(Λₙ₊₁ − Λₙ)v = θ × (Λₙ₊½ v)` for every `v`.
pub fn cayley_mid<T: Scalar>(theta: &Vector3<T>) -> Matrix3<T> {
    let q = cst::<T>(0.25);
    let m = Matrix3::identity() + skew(theta) * cst::<T>(0.5) + theta * theta.transpose() * q;
    m / (T::one() + theta.norm_squared() * q)
}

/// Composition of Cayley rotations: `cay(a)·cay(b) = cay(c)` with
/// `c = (a + b + ½ a×b)/(1 − ¼ a·b)`.
pub fn cayley_compose<T: Scalar>(a: &Vector3<T>, b: &Vector3<T>) -> Vector3<T> {
    (a + b + a.cross(b) * cst::<T>(0.5)) / (T::one() - a.dot(b) * cst::<T>(0.25))
}

#[cfg(test)]
#[path = "rotation_tests.rs"]
mod tests;
