//! Lobe joint: a cam whose follower lift is any smooth periodic profile.
//!
//! The released rotation is `ψ` about the unit axis `t` (master body frame) and
//! the follower slides along the unit direction `t_r` by the lift `ρ(ψ)`:
//!
//! ```text
//! f(ψ) = ρ(ψ) t_r          f′(ψ) = ρ′(ψ) t_r          Λ_R = exp((ψ − ψ₀) t̂)
//! ```
//!
//! (FORMULATION §3, "custom lobe profile"). The paper's eccentric cam is the
//! special case `ρ(ψ) = R cos ψ − R − a`. Two lift descriptions are provided:
//!
//! * [`Lift::Table`] — measured or designed `(angle, lift)` rows, interpolated
//!   by a periodic cubic spline ([`PeriodicSpline`], C² everywhere including
//!   across the period boundary);
//! * [`Lift::Fourier`] — a truncated Fourier series
//!   `ρ(ψ) = a₀ + Σₖ (aₖ cos kψ + bₖ sin kψ)`.
//!
//! Both are evaluated for any [`Scalar`], so `N`, `G`, `Ñ` and the tangents of
//! [`crate::dependent`] follow by automatic differentiation like for every
//! other [`DependentJoint`]. A tabulated lift is C² but not C³ at its knots;
//! the secant `G` still reproduces `f(ψₙ₊₁) − f(ψₙ)` to round-off when a step
//! crosses a knot ([`crate::DependentJointMaps::mean_slope`] detects that its
//! quadrature is not exact there and falls back to the difference quotient).

use crate::dependent::DependentJoint;
use crate::model_joint::{common_key_help, direction, perpendicular_slide, ModelJoint, ParamError};
use flexmech_core::{cst, Scalar};
use nalgebra::Vector3;
use serde::Deserialize;
use thiserror::Error;

/// Why a lobe (its lift table, Fourier coefficients or directions) was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LobeError {
    /// A periodic spline needs at least three rows (two intervals).
    #[error("a lift table needs at least 3 rows (angle, lift), got {rows}")]
    TooFewRows {
        /// Rows given.
        rows: usize,
    },
    /// An angle or a lift is NaN or infinite.
    #[error("row {row} of the lift table is not finite: angle {angle}, lift {lift}")]
    NonFiniteRow {
        /// Row index, from 0.
        row: usize,
        /// Its angle.
        angle: f64,
        /// Its lift.
        lift: f64,
    },
    /// Angles must be strictly increasing.
    #[error("the angles of the lift table must be strictly increasing: row {row} has angle {angle} after {previous}")]
    NonIncreasing {
        /// Row index, from 0.
        row: usize,
        /// The previous row's angle.
        previous: f64,
        /// This row's angle.
        angle: f64,
    },
    /// The lift of the last row must equal the lift of the first (one full period).
    #[error("the lift table is not periodic: the first row has lift {first}, the last {last} (they must be equal)")]
    NotPeriodic {
        /// Lift of the first row.
        first: f64,
        /// Lift of the last row.
        last: f64,
    },
    /// Fourier coefficients come as `[a0, a1, b1, a2, b2, …]`: an odd count.
    #[error("Fourier lift coefficients are [a0, a1, b1, a2, b2, ...]: expected an odd count, got {count}")]
    FourierCount {
        /// Coefficients given.
        count: usize,
    },
    /// A Fourier coefficient is NaN or infinite.
    #[error("Fourier lift coefficient {index} is not finite: {value}")]
    NonFiniteCoefficient {
        /// Coefficient index, from 0.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The axis and the slide direction must be finite unit vectors.
    #[error("the lobe's {name} must be a unit vector, its length is {norm}")]
    NotUnit {
        /// `"axis"` or `"slide"`.
        name: &'static str,
        /// Its length.
        norm: f64,
    },
}

/// A periodic cubic spline through `(xᵢ, yᵢ)`, `i = 0..n`, with period
/// `P = xₙ − x₀` and `yₙ = y₀`.
///
/// On the interval `[xᵢ, xᵢ₊₁]` (width `hᵢ`), with `s = x − xᵢ`,
///
/// ```text
/// S(x) = yᵢ + bᵢ s + ½Mᵢ s² + (Mᵢ₊₁ − Mᵢ)/(6hᵢ) s³
/// bᵢ   = (yᵢ₊₁ − yᵢ)/hᵢ − hᵢ(2Mᵢ + Mᵢ₊₁)/6
/// ```
///
/// where the knot curvatures `Mᵢ = S″(xᵢ)` (`Mₙ = M₀`) solve the cyclic
/// tridiagonal system that makes `S′` continuous at every knot, the period
/// boundary included (indices modulo `n`):
///
/// ```text
/// hᵢ₋₁Mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ)Mᵢ + hᵢMᵢ₊₁ = 6[(yᵢ₊₁ − yᵢ)/hᵢ − (yᵢ − yᵢ₋₁)/hᵢ₋₁].
/// ```
///
/// The system is symmetric and strictly diagonally dominant; it is solved once,
/// at construction, by the Thomas algorithm with a Sherman–Morrison correction
/// for the two corner entries. `S` is C² and `P`-periodic, and interpolates the
/// rows exactly (`S(xᵢ) = yᵢ` with no round-off: the cubic is evaluated from
/// the left knot of its interval).
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicSpline {
    /// Knots `x₀ < x₁ < … < xₙ`.
    knots: Vec<f64>,
    /// Per interval `i < n`: `[yᵢ, bᵢ, ½Mᵢ, (Mᵢ₊₁ − Mᵢ)/(6hᵢ)]`.
    coefficients: Vec<[f64; 4]>,
    /// `P = xₙ − x₀`.
    period: f64,
}

impl PeriodicSpline {
    /// The spline through the rows `(angle, lift)`: at least three rows, finite,
    /// strictly increasing angles, and the last lift equal to the first (to
    /// `10⁻¹²` relative to the largest lift; the first row's value is then used
    /// for both). The period is `last angle − first angle`.
    pub fn new(rows: &[(f64, f64)]) -> Result<Self, LobeError> {
        if rows.len() < 3 {
            return Err(LobeError::TooFewRows { rows: rows.len() });
        }
        for (row, &(angle, lift)) in rows.iter().enumerate() {
            if !angle.is_finite() || !lift.is_finite() {
                return Err(LobeError::NonFiniteRow { row, angle, lift });
            }
        }
        for (row, w) in rows.windows(2).enumerate() {
            if w[1].0 <= w[0].0 {
                return Err(LobeError::NonIncreasing {
                    row: row + 1,
                    previous: w[0].0,
                    angle: w[1].0,
                });
            }
        }
        let first = rows[0].1;
        let last = rows[rows.len() - 1].1;
        let scale = rows.iter().fold(0.0f64, |m, r| m.max(r.1.abs()));
        if (last - first).abs() > 1e-12 * scale {
            return Err(LobeError::NotPeriodic { first, last });
        }

        let n = rows.len() - 1; // number of intervals = number of unknowns
        let x: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let mut y: Vec<f64> = rows.iter().map(|r| r.1).collect();
        y[n] = y[0];
        let h: Vec<f64> = (0..n).map(|i| x[i + 1] - x[i]).collect();
        let slope: Vec<f64> = (0..n).map(|i| (y[i + 1] - y[i]) / h[i]).collect();
        // Row i couples M_{i-1}, M_i, M_{i+1} (cyclic).
        let prev = |i: usize| (i + n - 1) % n;
        let diag: Vec<f64> = (0..n).map(|i| 2.0 * (h[prev(i)] + h[i])).collect();
        let rhs: Vec<f64> = (0..n).map(|i| 6.0 * (slope[i] - slope[prev(i)])).collect();
        let m = solve_cyclic(&h, &diag, &rhs);

        let coefficients = (0..n)
            .map(|i| {
                let (mi, mj) = (m[i], m[(i + 1) % n]);
                [
                    y[i],
                    slope[i] - h[i] * (2.0 * mi + mj) / 6.0,
                    0.5 * mi,
                    (mj - mi) / (6.0 * h[i]),
                ]
            })
            .collect();
        Ok(Self {
            period: x[n] - x[0],
            knots: x,
            coefficients,
        })
    }

    /// The period `P`.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The knots `x₀ < … < xₙ` (the table's angles).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// `S(x)` for any scalar. `x` is first reduced into `[x₀, x₀ + P)` by
    /// subtracting an integer number of periods, chosen on the real part and
    /// subtracted as a constant so that derivatives pass through unchanged;
    /// the interval is found by binary search on the real part.
    pub fn eval<T: Scalar>(&self, x: T) -> T {
        let x0 = self.knots[0];
        let turns = ((x.value() - x0) / self.period).floor();
        let xr = if turns == 0.0 {
            x
        } else {
            x - cst::<T>(turns * self.period)
        };
        let v = xr.value();
        let n = self.coefficients.len();
        // Largest i with x_i ≤ v, clamped to a valid interval (round-off of the
        // reduction may leave v a hair outside [x₀, x₀ + P)).
        let i = self.knots[..n]
            .partition_point(|&k| k <= v)
            .saturating_sub(1);
        let s = xr - cst::<T>(self.knots[i]);
        let [a, b, c, d] = self.coefficients[i];
        ((cst::<T>(d) * s + cst::<T>(c)) * s + cst::<T>(b)) * s + cst::<T>(a)
    }
}

/// Solves the symmetric cyclic tridiagonal system
/// `h[i−1] m[i−1] + diag[i] m[i] + h[i] m[i+1] = rhs[i]` (indices mod `n`, `n ≥ 2`).
fn solve_cyclic(h: &[f64], diag: &[f64], rhs: &[f64]) -> Vec<f64> {
    let n = diag.len();
    if n == 2 {
        // Both off-diagonal couplings land on the same entry: h₀ + h₁.
        let off = h[0] + h[1];
        let det = diag[0] * diag[1] - off * off;
        return vec![
            (rhs[0] * diag[1] - off * rhs[1]) / det,
            (diag[0] * rhs[1] - off * rhs[0]) / det,
        ];
    }
    // A = B + u vᵀ with u = (γ, 0, …, 0, c), v = (1, 0, …, 0, a/γ), where the
    // corner entries are A[0][n−1] = h[n−1] (= c, the sub-diagonal coupling of
    // row 0) and A[n−1][0] = h[n−1] (= a). B is tridiagonal with its first and
    // last diagonal entries modified.
    let corner = h[n - 1];
    let gamma = -diag[0];
    let mut b = diag.to_vec();
    b[0] -= gamma;
    b[n - 1] -= corner * corner / gamma;
    // Off-diagonals of B: B[i][i+1] = B[i+1][i] = h[i], i = 0..n−2.
    let thomas = |d: &[f64]| -> Vec<f64> {
        let mut cp = vec![0.0; n];
        let mut dp = vec![0.0; n];
        cp[0] = h[0] / b[0];
        dp[0] = d[0] / b[0];
        for i in 1..n {
            let denom = b[i] - h[i - 1] * cp[i - 1];
            cp[i] = if i < n - 1 { h[i] / denom } else { 0.0 };
            dp[i] = (d[i] - h[i - 1] * dp[i - 1]) / denom;
        }
        let mut out = vec![0.0; n];
        out[n - 1] = dp[n - 1];
        for i in (0..n - 1).rev() {
            out[i] = dp[i] - cp[i] * out[i + 1];
        }
        out
    };
    let mut u = vec![0.0; n];
    u[0] = gamma;
    u[n - 1] = corner;
    let z = thomas(rhs);
    let q = thomas(&u);
    // vᵀ = (1, 0, …, 0, corner/γ).
    let vz = z[0] + corner / gamma * z[n - 1];
    let vq = q[0] + corner / gamma * q[n - 1];
    let factor = vz / (1.0 + vq);
    z.iter().zip(&q).map(|(zi, qi)| zi - factor * qi).collect()
}

/// The lift `ρ(ψ)` of a [`Lobe`].
#[derive(Debug, Clone, PartialEq)]
pub enum Lift {
    /// A periodic cubic spline through `(angle, lift)` rows.
    Table(PeriodicSpline),
    /// `ρ(ψ) = a₀ + Σₖ₌₁ (aₖ cos kψ + bₖ sin kψ)` from `[a₀, a₁, b₁, a₂, b₂, …]`.
    Fourier(Vec<f64>),
}

impl Lift {
    /// A tabulated lift ([`PeriodicSpline::new`]).
    pub fn table(rows: &[(f64, f64)]) -> Result<Self, LobeError> {
        PeriodicSpline::new(rows).map(Lift::Table)
    }

    /// A Fourier lift from `[a₀, a₁, b₁, a₂, b₂, …]` (odd count, finite).
    pub fn fourier(coefficients: &[f64]) -> Result<Self, LobeError> {
        if coefficients.len() % 2 != 1 {
            return Err(LobeError::FourierCount {
                count: coefficients.len(),
            });
        }
        if let Some((index, &value)) = coefficients
            .iter()
            .enumerate()
            .find(|(_, c)| !c.is_finite())
        {
            return Err(LobeError::NonFiniteCoefficient { index, value });
        }
        Ok(Lift::Fourier(coefficients.to_vec()))
    }

    /// `ρ(ψ)` for any scalar.
    pub fn eval<T: Scalar>(&self, psi: T) -> T {
        match self {
            Lift::Table(spline) => spline.eval(psi),
            Lift::Fourier(c) => {
                let mut acc = cst::<T>(c.first().copied().unwrap_or(0.0));
                for (k, ab) in c.get(1..).unwrap_or(&[]).chunks(2).enumerate() {
                    let kpsi = psi * cst::<T>((k + 1) as f64);
                    acc += kpsi.cos() * cst::<T>(ab[0]);
                    if let Some(&b) = ab.get(1) {
                        acc += kpsi.sin() * cst::<T>(b);
                    }
                }
                acc
            }
        }
    }
}

/// The lobe joint: `f(ψ) = ρ(ψ) t_r`, released rotation `ψ` about `t`.
#[derive(Debug, Clone, PartialEq)]
pub struct Lobe {
    /// Unit axis `t` of the lobe's rotation.
    pub axis: Vector3<f64>,
    /// Unit direction `t_r` of the follower (usually perpendicular to `t`).
    pub slide: Vector3<f64>,
    /// The lift `ρ(ψ)`.
    pub lift: Lift,
}

impl Lobe {
    /// A lobe with checked directions: `axis` and `slide` must be finite unit
    /// vectors (to `10⁻⁹`).
    pub fn new(axis: Vector3<f64>, slide: Vector3<f64>, lift: Lift) -> Result<Self, LobeError> {
        for (name, v) in [("axis", axis), ("slide direction", slide)] {
            let norm = v.norm();
            if !norm.is_finite() || (norm - 1.0).abs() > 1e-9 {
                return Err(LobeError::NotUnit { name, norm });
            }
        }
        Ok(Self { axis, slide, lift })
    }
}

/// Parameters of a `lobe` joint in model files.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LobeParams {
    /// Lobe axis `t` (normalised).
    pub axis: [f64; 3],
    /// Follower direction `t_r`, perpendicular to `axis`.
    pub slide: [f64; 3],
    /// The lift profile.
    pub lift: LiftParams,
}

/// `lift = { table = [[angle, lift], ...] }` or `lift = { fourier = [a0, a1, b1, ...] }`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiftParams {
    /// Periodic table of `(angle, lift)` rows.
    pub table: Option<Vec<[f64; 2]>>,
    /// Fourier coefficients `[a0, a1, b1, a2, b2, …]`.
    pub fourier: Option<Vec<f64>>,
}

impl LiftParams {
    /// The lift, with the model-file checks: one of the two forms; a table of
    /// at least 3 rows with strictly increasing angles whose last lift equals
    /// the first (to `10⁻¹²` of the largest lift); an odd number of Fourier
    /// coefficients.
    pub fn lift(&self) -> Result<Lift, ParamError> {
        match (&self.table, &self.fourier) {
            (Some(_), Some(_)) => Err(ParamError::new(
                "lift.fourier",
                "give either `table` or `fourier`, not both",
            )),
            (None, None) => Err(ParamError::new(
                "lift",
                "expected lift = { table = [[angle, lift], ...] } or lift = { fourier = [a0, a1, b1, ...] }",
            )),
            (Some(rows), None) => {
                let key = "lift.table";
                if rows.len() < 3 {
                    return Err(ParamError::new(
                        key,
                        format!(
                            "a periodic lift table needs at least 3 rows [angle, lift], found {}",
                            rows.len()
                        ),
                    ));
                }
                let pairs: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[1])).collect();
                for (r, w) in pairs.windows(2).enumerate() {
                    if w[1].0 <= w[0].0 {
                        return Err(ParamError::new(
                            key,
                            format!(
                                "angles must be strictly increasing, but row {} has angle {:?} \
                                 after {:?} in row {r}",
                                r + 1,
                                w[1].0,
                                w[0].0
                            ),
                        )
                        .at_item(r + 1));
                    }
                }
                let (first, last) = (pairs[0], pairs[pairs.len() - 1]);
                let scale = pairs.iter().fold(0.0_f64, |m, p| m.max(p.1.abs()));
                if (last.1 - first.1).abs() > PERIODIC_LIFT_TOLERANCE * scale {
                    return Err(ParamError::new(
                        key,
                        format!(
                            "the lift profile is periodic (period = last angle − first angle = {:?}), \
                             so the last lift must equal the first: found {:?} at angle {:?} and \
                             {:?} at angle {:?}; end the table with [{:?}, {:?}]",
                            last.0 - first.0,
                            first.1,
                            first.0,
                            last.1,
                            last.0,
                            last.0,
                            first.1
                        ),
                    )
                    .at_item(pairs.len() - 1));
                }
                Lift::table(&pairs).map_err(|e| ParamError::new(key, e.to_string()))
            }
            (None, Some(c)) => {
                if c.len() % 2 != 1 {
                    return Err(ParamError::new(
                        "lift.fourier",
                        format!(
                            "expected [a0, a1, b1, a2, b2, ...], an odd number of coefficients \
                             (a0, then cos/sin pairs), found {}",
                            c.len()
                        ),
                    ));
                }
                Lift::fourier(c).map_err(|e| ParamError::new("lift.fourier", e.to_string()))
            }
        }
    }
}

/// Relative mismatch of a lift table's first and last lifts accepted as periodic.
pub const PERIODIC_LIFT_TOLERANCE: f64 = 1e-12;

impl ModelJoint for Lobe {
    const NAME: &'static str = "lobe";
    type Params = LobeParams;
    fn from_params(p: LobeParams) -> Result<Self, ParamError> {
        let axis = direction("axis", p.axis)?;
        let slide = perpendicular_slide(Self::NAME, p.slide, &axis)?;
        let lift = p.lift.lift()?;
        Lobe::new(axis, slide, lift).map_err(|e| ParamError::new("lift", e.to_string()))
    }

    fn key_help(key: &str) -> Option<&'static str> {
        match key {
            "lift" => Some(
                "its lift profile: lift = { table = [[angle, lift], ...] } or \
                 lift = { fourier = [a0, a1, b1, ...] }",
            ),
            _ => common_key_help(key),
        }
    }
}

impl DependentJoint for Lobe {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        self.slide.map(cst::<T>) * self.lift.eval(psi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dependent::DependentJointMaps;
    use std::f64::consts::PI;

    fn z() -> Vector3<f64> {
        Vector3::z()
    }

    fn x() -> Vector3<f64> {
        Vector3::x()
    }

    /// An irregular, non-uniformly spaced table over one turn starting at −1.
    fn irregular_rows() -> Vec<(f64, f64)> {
        let angles = [
            -1.0,
            -0.6,
            0.1,
            0.35,
            1.2,
            2.0,
            2.2,
            3.5,
            4.4,
            5.0,
            -1.0 + 2.0 * PI,
        ];
        let lifts = [0.3, 0.5, 0.45, 0.9, 1.4, 0.2, -0.1, 0.0, 0.25, 0.31, 0.3];
        angles.iter().copied().zip(lifts).collect()
    }

    fn lobe(lift: Lift) -> Lobe {
        Lobe::new(z(), x(), lift).unwrap()
    }

    /// Value, first and second derivative of interval `i`'s cubic at `s`.
    fn piece(spline: &PeriodicSpline, i: usize, s: f64) -> [f64; 3] {
        let [a, b, c, d] = spline.coefficients[i];
        [
            a + s * (b + s * (c + s * d)),
            b + s * (2.0 * c + 3.0 * d * s),
            2.0 * c + 6.0 * d * s,
        ]
    }

    #[test]
    fn table_rows_are_interpolated_exactly() {
        let rows = irregular_rows();
        let joint = lobe(Lift::table(&rows).unwrap());
        for &(angle, lift) in &rows[..rows.len() - 1] {
            assert_eq!(joint.lift.eval(angle), lift, "row at {angle}");
            assert_eq!(joint.translation(angle), x() * lift);
        }
        // The last row is one period after the first: reduced, up to the
        // round-off of the reduction (one ulp of the angle times the slope).
        let (last_angle, last_lift) = rows[rows.len() - 1];
        assert!((joint.lift.eval(last_angle) - last_lift).abs() < 1e-14);
        // Whole periods later and earlier, again up to the reduction's round-off.
        for &(angle, lift) in &rows {
            for k in [-3.0, -1.0, 1.0, 4.0] {
                let v = joint.lift.eval(angle + k * 2.0 * PI);
                assert!(
                    (v - lift).abs() < 1e-13,
                    "row at {angle} shifted by {k} periods: {v} vs {lift}"
                );
            }
        }
    }

    #[test]
    fn spline_is_c2_at_every_knot_including_the_period_boundary() {
        let spline = PeriodicSpline::new(&irregular_rows()).unwrap();
        let n = spline.coefficients.len();
        for i in 0..n {
            let j = (i + 1) % n;
            let h = spline.knots[i + 1] - spline.knots[i];
            let left = piece(&spline, i, h);
            let right = piece(&spline, j, 0.0);
            for (order, (l, r)) in left.iter().zip(&right).enumerate() {
                let scale = 1.0 + r.abs();
                assert!(
                    (l - r).abs() < 1e-13 * scale,
                    "knot {j}, derivative {order}: {l} vs {r}"
                );
            }
        }
    }

    #[test]
    fn spline_is_periodic_in_value_slope_and_curvature() {
        let joint = lobe(Lift::table(&irregular_rows()).unwrap());
        let p = 2.0 * PI;
        // Points inside intervals, at knots, and just either side of the period boundary.
        let mut points: Vec<f64> = (0..40).map(|k| -7.0 + 0.713 * k as f64).collect();
        points.extend([-1.0, -1.0 + 1e-9, -1.0 - 1e-9, 1.2, 5.0]);
        for &psi in &points {
            for k in [1.0, 2.0, -3.0] {
                let shifted = psi + k * p;
                let (f0, f1) = (joint.translation(psi), joint.translation(shifted));
                let (d0, d1) = (joint.derivative(psi), joint.derivative(shifted));
                let (s0, s1) = (
                    joint.second_derivative(psi),
                    joint.second_derivative(shifted),
                );
                // The shifted argument carries round-off |ψ + kP|·ε, which the
                // slope (≲ 5 here) and curvature (≲ 50) turn into these errors.
                assert!((f0 - f1).norm() < 1e-13, "value at {psi} + {k}P");
                assert!((d0 - d1).norm() < 1e-12, "slope at {psi} + {k}P");
                assert!((s0 - s1).norm() < 1e-11, "curvature at {psi} + {k}P");
            }
        }
        // Across the boundary: the one-sided limits agree (C² wrap).
        let eps = 1e-7;
        let (a, b) = (-1.0 + p - eps, -1.0 + eps);
        assert!((joint.translation(a) - joint.translation(b)).norm() < 1e-5);
        assert!((joint.derivative(a) - joint.derivative(b)).norm() < 1e-5);
        assert!((joint.second_derivative(a) - joint.second_derivative(b)).norm() < 1e-4);
    }

    #[test]
    fn spline_reproduces_a_sinusoid() {
        let n = 64;
        let amp = 0.7;
        let rows: Vec<(f64, f64)> = (0..=n)
            .map(|i| {
                let a = 2.0 * PI * i as f64 / n as f64;
                (a, if i == n { 0.0 } else { amp * a.sin() })
            })
            .collect();
        let joint = lobe(Lift::table(&rows).unwrap());
        let mut worst = [0.0f64; 3];
        for k in 0..1000 {
            let psi = -9.0 + 0.0273 * k as f64;
            let exact = [amp * psi.sin(), amp * psi.cos(), -amp * psi.sin()];
            let got = [
                joint.lift.eval(psi),
                joint.derivative(psi).x,
                joint.second_derivative(psi).x,
            ];
            for o in 0..3 {
                worst[o] = worst[o].max((got[o] - exact[o]).abs() / amp);
            }
        }
        // Periodic cubic spline, h = 2π/64: value O(h⁴), slope O(h³), curvature O(h²).
        assert!(worst[0] < 1e-6, "value error {}", worst[0]);
        assert!(worst[1] < 2e-5, "slope error {}", worst[1]);
        assert!(worst[2] < 2e-3, "curvature error {}", worst[2]);
    }

    #[test]
    fn fourier_matches_its_closed_form_and_derivatives() {
        let c = [0.2, 0.5, -0.3, 0.05, 0.1, -0.02, 0.01];
        let joint =
            Lobe::new(z(), Vector3::new(0.0, 0.6, 0.8), Lift::fourier(&c).unwrap()).unwrap();
        for k in 0..200 {
            let psi = -20.0 + 0.2 * k as f64 + 0.01;
            let mut rho = c[0];
            let mut drho = 0.0;
            let mut ddrho = 0.0;
            for j in 1..=3 {
                let (a, b, jf) = (c[2 * j - 1], c[2 * j], j as f64);
                let (s, co) = (jf * psi).sin_cos();
                rho += a * co + b * s;
                drho += jf * (-a * s + b * co);
                ddrho += -jf * jf * (a * co + b * s);
            }
            let slide = joint.slide;
            assert!((joint.translation(psi) - slide * rho).norm() <= 1e-15 * (1.0 + rho.abs()));
            assert!((joint.derivative(psi) - slide * drho).norm() <= 1e-14 * (1.0 + drho.abs()));
            assert!(
                (joint.second_derivative(psi) - slide * ddrho).norm()
                    <= 1e-14 * (1.0 + ddrho.abs())
            );
        }
    }

    #[test]
    fn paper_cam_is_a_fourier_lobe() {
        // ρ(ψ) = R cos ψ − R − a.
        let (r, a) = (0.4, 0.1);
        let lobe = lobe(Lift::fourier(&[-r - a, r, 0.0]).unwrap());
        let cam = crate::Cam {
            axis: z(),
            slide: x(),
            radius: r,
            offset: a,
        };
        for k in 0..50 {
            let psi = -10.0 + 0.41 * k as f64;
            assert!((lobe.translation(psi) - cam.translation(psi)).norm() < 1e-15);
            assert!((lobe.derivative(psi) - cam.derivative(psi)).norm() < 1e-15);
        }
    }

    #[test]
    fn three_row_table_works() {
        let rows = [(0.0, 1.0), (2.0, 3.0), (2.0 * PI, 1.0)];
        let spline = PeriodicSpline::new(&rows).unwrap();
        assert_eq!(spline.eval(0.0), 1.0);
        assert_eq!(spline.eval(2.0), 3.0);
        for i in 0..2 {
            let j = (i + 1) % 2;
            let h = spline.knots[i + 1] - spline.knots[i];
            let (l, r) = (piece(&spline, i, h), piece(&spline, j, 0.0));
            for o in 0..3 {
                assert!((l[o] - r[o]).abs() < 1e-13 * (1.0 + r[o].abs()));
            }
        }
    }

    #[test]
    fn bad_input_is_refused() {
        assert_eq!(
            Lift::table(&[(0.0, 1.0), (1.0, 1.0)]),
            Err(LobeError::TooFewRows { rows: 2 })
        );
        assert!(matches!(
            Lift::table(&[(0.0, 1.0), (2.0, 0.0), (2.0, 0.5), (6.0, 1.0)]),
            Err(LobeError::NonIncreasing { row: 2, .. })
        ));
        assert!(matches!(
            Lift::table(&[(0.0, 1.0), (1.0, 0.0), (6.0, 1.5)]),
            Err(LobeError::NotPeriodic { .. })
        ));
        assert!(matches!(
            Lift::table(&[(0.0, 1.0), (f64::NAN, 0.0), (6.0, 1.0)]),
            Err(LobeError::NonFiniteRow { row: 1, .. })
        ));
        assert!(matches!(
            Lift::fourier(&[1.0, 2.0]),
            Err(LobeError::FourierCount { count: 2 })
        ));
        assert!(matches!(
            Lift::fourier(&[]),
            Err(LobeError::FourierCount { count: 0 })
        ));
        assert!(matches!(
            Lift::fourier(&[1.0, f64::INFINITY, 0.0]),
            Err(LobeError::NonFiniteCoefficient { index: 1, .. })
        ));
        let lift = Lift::fourier(&[0.0, 1.0, 0.0]).unwrap();
        assert!(matches!(
            Lobe::new(Vector3::new(0.0, 0.0, 2.0), x(), lift),
            Err(LobeError::NotUnit { name: "axis", .. })
        ));
        let msg = Lift::table(&[(0.0, 1.0), (1.0, 0.0), (6.0, 1.5)])
            .unwrap_err()
            .to_string();
        assert!(msg.contains("not periodic"), "{msg}");
    }
}
