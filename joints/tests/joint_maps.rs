//! Verification of the maps the joints derive by automatic differentiation.
//!
//! Every check compares an AD-derived quantity with something independent of
//! it: the paper's closed forms (eqs 10–15, 21–22), hand-derived forms for the
//! standard joints, finite differences of the exact slave placement (eq. 1),
//! or the exact increments of a placed slave. States are random (proptest,
//! deterministic seed, 64 cases per property): master rotation `exp` of a
//! vector up to ~3 rad, master position, released angle over several turns
//! (−20..20 rad), and random joint parameters (axis, slide direction, pitch,
//! radii, Fourier coefficients).
//!
//! Errors are measured against the scale the computation is conditioned by
//! (stated at each check); the worst value of every check is printed
//! (`cargo test -- --nocapture`).
//!
//! The last test is the guide for a researcher: a custom joint (a screw with
//! variable pitch) written here, outside the crate, in a few lines — and its
//! `N`, `G`, `Ñ` agree with the closed forms derived by hand.

use flexmech_core::rotation::{cayley, cayley_inverse, cayley_mid, exp, log, skew};
use flexmech_core::{cst, Scalar};
use flexmech_joints::{
    Cam, Cylindrical, DependentJoint, DependentJointMaps, JointMap, JointStep, Lift, Lobe,
    Prismatic, RackPinion, ReleasedState, Revolute, Rigid, Screw, Spherical, StepLanes, LOCAL,
    MAX_RELEASED,
};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector6};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Debug;

const EPS: f64 = f64::EPSILON;
const CASES: u32 = 64;

// ---------------------------------------------------------------------------
// The custom joint of test 8: this is all a researcher writes.
// ---------------------------------------------------------------------------

/// A screw whose pitch varies with the angle: `f(ψ) = (cψ + d sin ψ) t`.
#[derive(Debug, Clone)]
struct VariablePitchScrew {
    axis: Vector3<f64>,
    c: f64,
    d: f64,
}

impl DependentJoint for VariablePitchScrew {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }
    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        self.axis.map(cst::<T>) * (psi * cst::<T>(self.c) + psi.sin() * cst::<T>(self.d))
    }
}

// ---------------------------------------------------------------------------
// Property runner that records the worst error of every check.
// ---------------------------------------------------------------------------

#[derive(Default)]
struct Worst {
    /// label → (largest error, largest error / tolerance)
    rows: RefCell<BTreeMap<String, (f64, f64)>>,
}

impl Worst {
    /// Records `err` and fails the case if `err > tol` (or is NaN).
    fn check(&self, label: &str, err: f64, tol: f64) -> Result<(), TestCaseError> {
        let ratio = if tol > 0.0 {
            err / tol
        } else if err == 0.0 {
            0.0
        } else {
            f64::INFINITY
        };
        let mut rows = self.rows.borrow_mut();
        let row = rows.entry(label.to_owned()).or_insert((0.0, 0.0));
        if err.is_nan() || err > row.0 {
            row.0 = err;
        }
        if ratio.is_nan() || ratio > row.1 {
            row.1 = ratio;
        }
        if err <= tol {
            Ok(())
        } else {
            Err(TestCaseError::fail(format!(
                "{label}: error {err:.3e} > tolerance {tol:.3e}"
            )))
        }
    }

    /// Passes iff `err ≤ bound`; records `err/scale` (the relative error) and
    /// `err/bound`.
    fn bounded(&self, label: &str, err: f64, scale: f64, bound: f64) -> Result<(), TestCaseError> {
        let div = |a: f64, b: f64| if a == 0.0 { 0.0 } else { a / b };
        let (relative, ratio) = (div(err, scale), div(err, bound));
        let mut rows = self.rows.borrow_mut();
        let row = rows.entry(label.to_owned()).or_insert((0.0, 0.0));
        if relative.is_nan() || relative > row.0 {
            row.0 = relative;
        }
        if ratio.is_nan() || ratio > row.1 {
            row.1 = ratio;
        }
        if err <= bound {
            Ok(())
        } else {
            Err(TestCaseError::fail(format!(
                "{label}: error {err:.3e} > bound {bound:.3e} (scale {scale:.3e})"
            )))
        }
    }

    fn report(&self, name: &str) {
        let mut out = format!("--- {name}: worst error (worst error/tolerance)\n");
        for (label, (err, ratio)) in self.rows.borrow().iter() {
            out += &format!("    {label:<48} {err:9.2e}  ({ratio:.2e})\n");
        }
        eprint!("{out}");
    }
}

/// Runs `test` on `cases` random values of `strategy` (deterministic seed).
fn property<S: Strategy>(
    name: &str,
    cases: u32,
    strategy: S,
    test: impl Fn(S::Value, &Worst) -> Result<(), TestCaseError>,
) where
    S::Value: Debug,
{
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let worst = Worst::default();
    let result = runner.run(&strategy, |v| test(v, &worst));
    worst.report(name);
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
}

// ---------------------------------------------------------------------------
// Random inputs.
// ---------------------------------------------------------------------------

fn vec3(lo: f64, hi: f64) -> impl Strategy<Value = Vector3<f64>> {
    prop::array::uniform3(lo..hi).prop_map(Vector3::from)
}

fn unit() -> impl Strategy<Value = Vector3<f64>> {
    vec3(-1.0, 1.0)
        .prop_filter("not too short", |v| v.norm() > 0.2)
        .prop_map(|v| v.normalize())
}

/// Master placement: position and a rotation `exp` of a vector up to ~3 rad.
#[derive(Debug, Clone)]
struct Pose {
    x: Vector3<f64>,
    r: Matrix3<f64>,
}

fn pose() -> impl Strategy<Value = Pose> {
    (vec3(-5.0, 5.0), vec3(-1.75, 1.75)).prop_map(|(x, w)| Pose { x, r: exp(&w) })
}

/// Joint parameters.
#[derive(Debug, Clone)]
struct Params {
    axis: Vector3<f64>,
    /// Unit vector perpendicular to `axis` (rack, cam and lobe slide).
    perp: Vector3<f64>,
    /// Any unit vector (prismatic and cylindrical slide).
    slide: Vector3<f64>,
    pitch: f64,
    pinion: f64,
    cam_r: f64,
    cam_a: f64,
    fourier: [f64; 7],
    var_c: f64,
    var_d: f64,
}

fn params() -> impl Strategy<Value = Params> {
    let dirs = (unit(), unit(), unit())
        .prop_filter("slide not parallel to axis", |(t, v, _)| {
            t.cross(v).norm() > 0.2
        })
        .prop_map(|(t, v, s)| (t, (v - t * t.dot(&v)).normalize(), s));
    let numbers = (
        -0.5..0.5,
        0.05..1.0,
        0.05..1.0,
        0.0..0.5,
        prop::array::uniform7(-0.5..0.5),
        -0.5..0.5,
        -0.3..0.3,
    );
    (dirs, numbers).prop_map(
        |((axis, perp, slide), (pitch, pinion, cam_r, cam_a, fourier, var_c, var_d))| Params {
            axis,
            perp,
            slide,
            pitch,
            pinion,
            cam_r,
            cam_a,
            fourier,
            var_c,
            var_d,
        },
    )
}

/// Released coordinates: an angle over several turns, its initial value, a
/// slide, and a spherical rotation.
#[derive(Debug, Clone)]
struct Released {
    psi: f64,
    psi0: f64,
    slide: f64,
    ball: Vector3<f64>,
}

fn released() -> impl Strategy<Value = Released> {
    (-20.0..20.0, -3.0..3.0, -3.0..3.0, vec3(-1.75, 1.75)).prop_map(|(psi, psi0, slide, ball)| {
        Released {
            psi,
            psi0,
            slide,
            ball,
        }
    })
}

/// A released increment `ω`: large, small (below the secant's quadrature
/// threshold 10⁻²) or tiny, including 0.
fn released_increment() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1.2..1.2f64,
        -1e-2..1e-2f64,
        prop::sample::select(vec![0.0, 1e-9, -1e-6, 1e-4])
    ]
}

// ---------------------------------------------------------------------------
// The joint kinds with their closed forms.
// ---------------------------------------------------------------------------

/// `(ω/2)/tan(ω/2)`, 1 at ω = 0 — the paper's `arctan(|θ_R|/2)/(|θ_R|/2)`.
fn half_cot(omega: f64) -> f64 {
    if omega == 0.0 {
        1.0
    } else {
        0.5 * omega / (0.5 * omega).tan()
    }
}

/// `θ_R = 2 tan(ω/2)`.
fn tau(omega: f64) -> f64 {
    2.0 * (0.5 * omega).tan()
}

/// The conditioning limit of a secant formed from `f` values (the crate does
/// so for `|ω| ≥ 10⁻²`; below, it integrates `f′` and has no such term): the
/// round-off `ε|f|` of the values, with `|f| ≤ value`, over `|θ_R|`.
fn from_values(value: f64, omega: f64) -> f64 {
    if omega.abs() >= 1e-2 {
        8.0 * EPS * value / tau(omega).abs()
    } else {
        0.0
    }
}

/// A dependent joint as a trait object.
trait DepJoint: JointMap + DependentJointMaps {
    fn boxed_map(&self) -> Box<dyn JointMap>;
}

impl<J: JointMap + DependentJointMaps + Clone + 'static> DepJoint for J {
    fn boxed_map(&self) -> Box<dyn JointMap> {
        Box::new(self.clone())
    }
}

type F1 = Box<dyn Fn(f64) -> Vector3<f64>>;
type F2 = Box<dyn Fn(f64, f64) -> Vector3<f64>>;
type G2 = Box<dyn Fn(f64, f64) -> Matrix3<f64>>;

/// Closed forms of a dependent joint, independent of the crate's code.
struct Closed {
    /// `f(ψ)`.
    f: F1,
    /// `f′(ψ)` (paper eqs 13, 15 for screw, rack, cam).
    fp: F1,
    /// `(f(ψ+ω) − f(ψ))/(2 tan(ω/2))`, rewritten without cancellation
    /// (sum-to-product identities); `f′(ψ)` at ω = 0. `G = this ⊗ t`.
    secant: F2,
    /// The paper's literal eq.-22 form of `G` (general definition
    /// `(f(ψₙ₊₁) − f(ψₙ)) ⊗ t / (t·θ_R)` for kinds the paper has not).
    paper_g: G2,
    /// `f′` comes from the paper's eqs 13/15 (compare relative to |f′|).
    paper: bool,
    /// Bounds: `|f′| ≤ slope`, `|f″| ≤ curv`, `|f| ≤ value + slope·|ψ|`.
    slope: f64,
    curv: f64,
    value: f64,
}

struct Dep {
    name: &'static str,
    joint: Box<dyn DepJoint>,
    axis: Vector3<f64>,
    closed: Option<Closed>,
    /// Knots of a tabulated lift (kinks of f‴), to keep finite differences off them.
    knots: Option<(Vec<f64>, f64)>,
}

fn fourier_terms(c: &[f64; 7]) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
    (1..=3).map(move |k| (k as f64, c[2 * k - 1], c[2 * k]))
}

fn dependent_kinds(p: &Params) -> Vec<Dep> {
    let (t, tr) = (p.axis, p.perp);
    let mut kinds = Vec::new();

    let c = p.pitch;
    kinds.push(Dep {
        name: "screw",
        joint: Box::new(Screw { axis: t, pitch: c }),
        axis: t,
        closed: Some(Closed {
            f: Box::new(move |psi| t * (c * psi)),
            fp: Box::new(move |_| t * c),
            secant: Box::new(move |_, w| t * (c * half_cot(w))),
            paper_g: Box::new(move |_, w| {
                let theta_r = t * tau(w);
                let h = 0.5 * theta_r.norm();
                t * t.transpose() * (c * h.atan() / h)
            }),
            paper: true,
            slope: c.abs(),
            curv: 0.0,
            value: 0.0,
        }),
        knots: None,
    });

    let b = p.pinion;
    kinds.push(Dep {
        name: "rack_pinion",
        joint: Box::new(RackPinion {
            axis: t,
            slide: tr,
            radius: b,
        }),
        axis: t,
        closed: Some(Closed {
            f: Box::new(move |psi| tr.cross(&t) * b + tr * (b * psi)),
            fp: Box::new(move |_| tr * b),
            secant: Box::new(move |_, w| tr * (b * half_cot(w))),
            paper_g: Box::new(move |_, w| {
                let theta_r = t * tau(w);
                let h = 0.5 * theta_r.norm();
                tr * t.transpose() * (b * h.atan() / h)
            }),
            paper: true,
            slope: b,
            curv: 0.0,
            value: b,
        }),
        knots: None,
    });

    let (r, a) = (p.cam_r, p.cam_a);
    kinds.push(Dep {
        name: "cam",
        joint: Box::new(Cam {
            axis: t,
            slide: tr,
            radius: r,
            offset: a,
        }),
        axis: t,
        closed: Some(Closed {
            f: Box::new(move |psi| tr * (r * psi.cos() - r - a)),
            fp: Box::new(move |psi| tr * (-r * psi.sin())),
            // R(cos(ψ+ω) − cos ψ)/(2 tan(ω/2)) = −R sin(ψ + ω/2) cos(ω/2).
            secant: Box::new(move |psi, w| tr * (-r * (psi + 0.5 * w).sin() * (0.5 * w).cos())),
            paper_g: Box::new(move |psi, w| {
                let theta_r = t * tau(w);
                tr * t.transpose() * (r * ((psi + w).cos() - psi.cos()) / t.dot(&theta_r))
            }),
            paper: true,
            slope: r,
            curv: r,
            value: 2.0 * r + a,
        }),
        knots: None,
    });

    kinds.push(Dep {
        name: "revolute",
        joint: Box::new(Revolute { axis: t }),
        axis: t,
        closed: Some(Closed {
            f: Box::new(|_| Vector3::zeros()),
            fp: Box::new(|_| Vector3::zeros()),
            secant: Box::new(|_, _| Vector3::zeros()),
            paper_g: Box::new(|_, _| Matrix3::zeros()),
            paper: true,
            slope: 0.0,
            curv: 0.0,
            value: 0.0,
        }),
        knots: None,
    });

    let fc = p.fourier;
    let rho = move |psi: f64| {
        fc[0]
            + fourier_terms(&fc)
                .map(|(k, a, b)| a * (k * psi).cos() + b * (k * psi).sin())
                .sum::<f64>()
    };
    kinds.push(Dep {
        name: "lobe (Fourier)",
        joint: Box::new(Lobe::new(t, tr, Lift::fourier(&fc).unwrap()).unwrap()),
        axis: t,
        closed: Some(Closed {
            f: Box::new(move |psi| tr * rho(psi)),
            fp: Box::new(move |psi| {
                tr * fourier_terms(&fc)
                    .map(|(k, a, b)| k * (-a * (k * psi).sin() + b * (k * psi).cos()))
                    .sum::<f64>()
            }),
            // Δcos kψ = −2 sin(k(ψ+ω/2)) sin(kω/2), Δsin kψ = 2 cos(k(ψ+ω/2)) sin(kω/2);
            // divided by 2 tan(ω/2): factor sin(kω/2)/tan(ω/2) (→ k at ω = 0).
            secant: Box::new(move |psi, w| {
                tr * fourier_terms(&fc)
                    .map(|(k, a, b)| {
                        let q = if w == 0.0 {
                            k
                        } else {
                            (0.5 * k * w).sin() / (0.5 * w).tan()
                        };
                        let m = k * (psi + 0.5 * w);
                        q * (-a * m.sin() + b * m.cos())
                    })
                    .sum::<f64>()
            }),
            paper_g: Box::new(move |psi, w| {
                tr * t.transpose() * ((rho(psi + w) - rho(psi)) / t.dot(&(t * tau(w))))
            }),
            paper: false,
            slope: fourier_terms(&fc)
                .map(|(k, a, b)| k * (a.abs() + b.abs()))
                .sum(),
            curv: fourier_terms(&fc)
                .map(|(k, a, b)| k * k * (a.abs() + b.abs()))
                .sum(),
            value: fc.iter().map(|v| v.abs()).sum(),
        }),
        knots: None,
    });

    // A tabulated lobe (no independent closed form: only the placement-based checks).
    let rows: Vec<(f64, f64)> = (0..=12)
        .map(|i| {
            let ang =
                -1.0 + 2.0 * PI * i as f64 / 12.0 + if i % 12 == 0 { 0.0 } else { 0.1 * fc[i % 7] };
            (ang, if i == 12 { fc[0] } else { fc[i % 7] })
        })
        .collect();
    let knots = rows.iter().map(|r| r.0).collect();
    kinds.push(Dep {
        name: "lobe (table)",
        joint: Box::new(Lobe::new(t, tr, Lift::table(&rows).unwrap()).unwrap()),
        axis: t,
        closed: None,
        knots: Some((knots, 2.0 * PI)),
    });

    let (vc, vd) = (p.var_c, p.var_d);
    kinds.push(Dep {
        name: "custom variable-pitch screw",
        joint: Box::new(VariablePitchScrew {
            axis: t,
            c: vc,
            d: vd,
        }),
        axis: t,
        closed: Some(Closed {
            f: Box::new(move |psi| t * (vc * psi + vd * psi.sin())),
            fp: Box::new(move |psi| t * (vc + vd * psi.cos())),
            secant: Box::new(move |psi, w| {
                t * (vc * half_cot(w) + vd * (psi + 0.5 * w).cos() * (0.5 * w).cos())
            }),
            paper_g: Box::new(move |psi, w| {
                let df = vc * w + vd * ((psi + w).sin() - psi.sin());
                t * t.transpose() * (df / t.dot(&(t * tau(w))))
            }),
            paper: false,
            slope: vc.abs() + vd.abs(),
            curv: vd.abs(),
            value: vd.abs(),
        }),
        knots: None,
    });
    kinds
}

/// Whether `psi` is within `d` of a knot of a tabulated lift.
fn near_knot(dep: &Dep, psi: f64, d: f64) -> bool {
    dep.knots.as_ref().is_some_and(|(knots, period)| {
        knots.iter().any(|k| {
            let x = (psi - k) / period;
            (x - x.round()).abs() * period < d
        })
    })
}

/// A hand-derived `N` as a function of the master rotation.
type NFn = Box<dyn Fn(&Matrix3<f64>) -> SMatrix<f64, 6, LOCAL>>;

/// A joint kind prepared for the map checks 1–3.
struct Kind {
    name: String,
    map: Box<dyn JointMap>,
    state: ReleasedState,
    spherical: bool,
    /// Hand-derived `N` for a master rotation (None: no independent form).
    n_closed: Option<NFn>,
    /// Skip finite differences of N′ (tabulated lift with a knot within reach).
    skip_second_fd: bool,
}

fn blocks(
    r_m: &Matrix3<f64>,
    r_r: &Vector3<f64>,
    released_x: &[Vector3<f64>],
    released_phi: &[Vector3<f64>],
) -> SMatrix<f64, 6, LOCAL> {
    let mut n = SMatrix::<f64, 6, LOCAL>::zeros();
    n.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&Matrix3::identity());
    n.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-skew(&(r_m * r_r))));
    n.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&Matrix3::identity());
    for (j, (x, p)) in released_x.iter().zip(released_phi).enumerate() {
        n.fixed_view_mut::<3, 1>(0, 6 + j).copy_from(&(r_m * x));
        n.fixed_view_mut::<3, 1>(3, 6 + j).copy_from(&(r_m * p));
    }
    n
}

fn all_kinds(p: &Params, q: &Released) -> Vec<Kind> {
    let mut kinds = Vec::new();
    let mut dep_state = ReleasedState::new([q.psi0, 0.0, 0.0, 0.0]);
    dep_state.q[0] = q.psi;
    for dep in dependent_kinds(p) {
        let skip = near_knot(&dep, q.psi, 1e-3);
        let n_closed = dep.closed.map(|c| {
            let (f, fp, t) = ((c.f)(q.psi), (c.fp)(q.psi), dep.axis);
            Box::new(move |r_m: &Matrix3<f64>| blocks(r_m, &f, &[fp], &[t])) as NFn
        });
        kinds.push(Kind {
            name: dep.name.to_owned(),
            map: dep.joint.boxed_map(),
            state: dep_state,
            spherical: false,
            n_closed,
            skip_second_fd: skip,
        });
    }

    kinds.push(Kind {
        name: "rigid".into(),
        map: Box::new(Rigid),
        state: ReleasedState::new([0.0; 4]),
        spherical: false,
        n_closed: Some(Box::new(|r_m| blocks(r_m, &Vector3::zeros(), &[], &[]))),
        skip_second_fd: false,
    });

    let (ts, t, s) = (p.slide, p.axis, q.slide);
    let mut st = ReleasedState::new([q.slide * 0.3, 0.0, 0.0, 0.0]);
    st.q[0] = s;
    kinds.push(Kind {
        name: "prismatic".into(),
        map: Box::new(Prismatic { slide: ts }),
        state: st,
        spherical: false,
        n_closed: Some(Box::new(move |r_m| {
            blocks(r_m, &(ts * s), &[ts], &[Vector3::zeros()])
        })),
        skip_second_fd: false,
    });

    let mut st = ReleasedState::new([q.psi0, 0.5, 0.0, 0.0]);
    st.q[0] = q.psi;
    st.q[1] = s;
    kinds.push(Kind {
        name: "cylindrical".into(),
        map: Box::new(Cylindrical { axis: t, slide: ts }),
        state: st,
        spherical: false,
        n_closed: Some(Box::new(move |r_m| {
            blocks(
                r_m,
                &(ts * s),
                &[Vector3::zeros(), ts],
                &[t, Vector3::zeros()],
            )
        })),
        skip_second_fd: false,
    });

    let mut st = ReleasedState::new([0.0; 4]);
    st.rot = exp(&q.ball);
    let z = Vector3::zeros();
    kinds.push(Kind {
        name: "spherical".into(),
        map: Box::new(Spherical::default()),
        state: st,
        spherical: true,
        n_closed: Some(Box::new(move |r_m| {
            blocks(
                r_m,
                &z,
                &[z, z, z],
                &[Vector3::x(), Vector3::y(), Vector3::z()],
            )
        })),
        skip_second_fd: false,
    });
    kinds
}

/// The state perturbed in local coordinate `j` by `d`: master position
/// additively, master rotation by `exp(d ê)` on the left, released coordinates
/// additively (spherical: `exp(d ê)` on the left of the released rotation).
fn perturbed(
    kind: &Kind,
    x_m: &Vector3<f64>,
    r_m: &Matrix3<f64>,
    j: usize,
    d: f64,
) -> (Vector3<f64>, Matrix3<f64>, ReleasedState) {
    let (mut x, mut r, mut st) = (*x_m, *r_m, kind.state);
    let e = |i: usize| Vector3::ith(i, d);
    match j {
        0..3 => x[j] += d,
        3..6 => r = exp(&e(j - 3)) * r,
        _ if kind.spherical => st.rot = exp(&e(j - 6)) * st.rot,
        _ => st.q[j - 6] += d,
    }
    (x, r, st)
}

fn cols(kind: &Kind) -> usize {
    6 + kind.map.released_count()
}

// ---------------------------------------------------------------------------
// 1–3: N and the transfer Nᵀg with its derivative.
// ---------------------------------------------------------------------------

#[test]
fn n_matches_the_closed_forms() {
    property(
        "1. N vs closed forms (eqs 10-11), relative to |N|",
        CASES,
        (params(), pose(), released()),
        |(p, m, q), w| {
            for kind in all_kinds(&p, &q) {
                let Some(closed) = &kind.n_closed else {
                    continue;
                };
                let n = kind.map.variation(&m.x, &m.r, &kind.state);
                let nc = closed(&m.r);
                w.check(&kind.name, (n - nc).norm() / nc.norm(), 1e-12)?;
            }
            Ok(())
        },
    );
}

#[test]
fn n_matches_finite_differences_of_the_placement() {
    let h = 1e-5;
    property(
        "2. N vs central differences of the placement (h = 1e-5), relative to |N|",
        CASES,
        (params(), pose(), released()),
        |(p, m, q), w| {
            for kind in all_kinds(&p, &q) {
                let n = kind.map.variation(&m.x, &m.r, &kind.state);
                let mut fd = SMatrix::<f64, 6, LOCAL>::zeros();
                for j in 0..cols(&kind) {
                    let place = |d: f64| {
                        let (x, r, st) = perturbed(&kind, &m.x, &m.r, j, d);
                        kind.map.slave(&x, &r, &st)
                    };
                    let ((xp, rp), (xn, rn)) = (place(h), place(-h));
                    fd.fixed_view_mut::<3, 1>(0, j)
                        .copy_from(&((xp - xn) / (2.0 * h)));
                    fd.fixed_view_mut::<3, 1>(3, j)
                        .copy_from(&(log(&(rp * rn.transpose())) / (2.0 * h)));
                }
                w.check(&kind.name, (n - fd).norm() / n.norm(), 1e-7)?;
            }
            Ok(())
        },
    );
}

#[test]
fn transfer_is_nt_g_and_its_derivative() {
    let h = 1e-5;
    property(
        "3. transfer: N^T g (rel. |N||g|) and d(N^T g) vs central differences (h = 1e-5, rel. max(|K|,|g|))",
        CASES,
        (params(), pose(), released(), vec3(-1.0, 1.0), vec3(-1.0, 1.0)),
        |(p, m, q, gf, gm), w| {
            let gv = Vector6::new(gf.x, gf.y, gf.z, gm.x, gm.y, gm.z);
            for kind in all_kinds(&p, &q) {
                let n = kind.map.variation(&m.x, &m.r, &kind.state);
                let (ntg, k) = kind.map.transfer(&m.x, &m.r, &kind.state, &gv);
                let expect: SVector<f64, LOCAL> = n.transpose() * gv;
                w.check(&format!("{}: N^T g", kind.name), (ntg - expect).norm() / (n.norm() * gv.norm()), 1e-13)?;
                // Unused local columns stay zero.
                let used = cols(&kind);
                let outside = (used..LOCAL).map(|c| k.row(c).norm() + k.column(c).norm() + ntg[c].abs()).sum::<f64>();
                w.check(&format!("{}: unused columns", kind.name), outside, 0.0)?;
                if kind.skip_second_fd {
                    continue;
                }
                let mut fd = SMatrix::<f64, LOCAL, LOCAL>::zeros();
                for j in 0..used {
                    let ntg_at = |d: f64| {
                        let (x, r, st) = perturbed(&kind, &m.x, &m.r, j, d);
                        kind.map.variation(&x, &r, &st).transpose() * gv
                    };
                    fd.set_column(j, &((ntg_at(h) - ntg_at(-h)) / (2.0 * h)));
                }
                let scale = fd.norm().max(gv.norm());
                w.check(&format!("{}: derivative", kind.name), (k - fd).norm() / scale, 1e-6)?;
            }
            Ok(())
        },
    );
}

#[test]
fn n_and_transfer_equal_their_ad_oracles() {
    property(
        "3b. N and the transfer (N^T g, d(N^T g)) vs AD over every local coordinate (rel. |N|, |N||g|, max(|K|,|g|))",
        CASES,
        (params(), pose(), released(), vec3(-1.0, 1.0), vec3(-1.0, 1.0)),
        |(p, m, q, gf, gm), w| {
            let gv = Vector6::new(gf.x, gf.y, gf.z, gm.x, gm.y, gm.z);
            for kind in all_kinds(&p, &q) {
                let n = kind.map.variation(&m.x, &m.r, &kind.state);
                let na = kind.map.variation_ad(&m.x, &m.r, &kind.state);
                w.check(&format!("{}: N", kind.name), (n - na).norm() / na.norm(), 1e-13)?;
                let (ntg, k) = kind.map.transfer(&m.x, &m.r, &kind.state, &gv);
                let (ntga, ka) = kind.map.transfer_ad(&m.x, &m.r, &kind.state, &gv);
                w.check(
                    &format!("{}: N^T g", kind.name),
                    (ntg - ntga).norm() / (na.norm() * gv.norm()),
                    1e-13,
                )?;
                w.check(
                    &format!("{}: d(N^T g)", kind.name),
                    (k - ka).norm() / ka.norm().max(gv.norm()),
                    1e-12,
                )?;
            }
            Ok(())
        },
    );
}

// ---------------------------------------------------------------------------
// 4–6: f′, the secant G and the incremental map Ñ of the dependent joints.
// ---------------------------------------------------------------------------

#[test]
fn derivative_matches_the_closed_forms() {
    property(
        "4. f' vs eqs 13/15 (rel. |f'|; lobe/custom rel. slope bound)",
        CASES,
        (params(), -20.0..20.0f64),
        |(p, psi), w| {
            for dep in dependent_kinds(&p) {
                let Some(c) = &dep.closed else { continue };
                let fp = (c.fp)(psi);
                let scale = if c.paper { fp.norm() } else { c.slope };
                w.check(
                    dep.name,
                    (dep.joint.derivative(psi) - fp).norm(),
                    1e-13 * scale,
                )?;
                // The placement's r_R is f(ψ).
                let mut st = ReleasedState::new([0.0; 4]);
                st.q[0] = psi;
                let rr = dep.joint.released_placement(&st).0;
                w.check(
                    &format!("{}: r_R = f(psi)", dep.name),
                    (rr - (c.f)(psi)).norm(),
                    4.0 * EPS * (c.value + c.slope * psi.abs()),
                )?;
            }
            Ok(())
        },
    );
}

const OMEGAS: [f64; 7] = [1.0, 0.3, 1e-2, 1e-3, 1e-6, 1e-9, 0.0];

#[test]
fn secant_matches_the_paper_and_the_increment() {
    property(
        "5. secant G (eq. 22): relative error (error/bound)",
        CASES,
        (params(), -20.0..20.0f64, prop::bool::ANY),
        |(p, psi, negative), w| {
            for dep in dependent_kinds(&p) {
                let Some(c) = &dep.closed else { continue };
                let t = dep.axis;
                // Slope scale: |f′|, plus |f″| times the round-off ε|ψ| of the
                // argument (relative 1e-14 of it is ~45 ε|ψ||f″|).
                let s = c.slope + (psi.abs() + 1.0) * c.curv;
                for &omega in &OMEGAS {
                    let omega = if negative { -omega } else { omega };
                    let tag = |what: &str| format!("{}: {what}", dep.name);
                    let g = dep.joint.secant(psi, omega);
                    if !g.iter().all(|v| v.is_finite()) {
                        return Err(TestCaseError::fail(tag(&format!(
                            "G not finite at omega = {omega}"
                        ))));
                    }
                    // |f| bound over [ψ, ψ+ω]: the round-off of f values is ε·value.
                    let value = c.value + c.slope * (psi.abs() + omega.abs());
                    let g_exact = (c.secant)(psi, omega) * t.transpose();
                    let regime = if omega.abs() >= 1e-2 {
                        "|w| >= 1e-2"
                    } else {
                        "|w| < 1e-2"
                    };
                    let label = tag(&format!("G vs closed form ({regime}), rel. s"));
                    w.bounded(
                        &label,
                        (g - g_exact).norm(),
                        s,
                        1e-14 * s + from_values(value, omega),
                    )?;
                    if omega == 0.0 {
                        let limit = (c.fp)(psi) * t.transpose();
                        w.bounded(
                            &tag("G(omega = 0) vs f' (x) t, rel. s"),
                            (g - limit).norm(),
                            s,
                            1e-14 * s,
                        )?;
                        continue;
                    }
                    // The paper's literal forms difference f values themselves.
                    let literal = (c.paper_g)(psi, omega);
                    let literal_bound = 1e-14 * s + 8.0 * EPS * value / tau(omega).abs();
                    w.bounded(
                        &tag("G vs paper's literal form, rel. s"),
                        (g - literal).norm(),
                        s,
                        literal_bound,
                    )?;
                    // G θ_R is the increment of f: against the placements…
                    let g_theta = g * (t * tau(omega));
                    let mut st = ReleasedState::new([0.0; 4]);
                    st.q[0] = psi;
                    let f0 = dep.joint.released_placement(&st).0;
                    dep.joint.advance(&mut st, &[omega]);
                    let f1 = dep.joint.released_placement(&st).0;
                    w.bounded(
                        &tag("G theta_R vs f(psi+w) - f(psi), rel. |f|"),
                        (g_theta - (f1 - f0)).norm(),
                        value,
                        1e-14 * value,
                    )?;
                    // …and against the cancellation-free closed form of the increment.
                    let df_exact = (c.secant)(psi, omega) * tau(omega);
                    let scale = s * tau(omega).abs();
                    let bound = 1e-14 * scale
                        + if omega.abs() >= 1e-2 {
                            8.0 * EPS * value
                        } else {
                            0.0
                        };
                    w.bounded(
                        &tag("G theta_R vs exact increment, rel. s|theta_R|"),
                        (g_theta - df_exact).norm(),
                        scale,
                        bound,
                    )?;
                }
            }
            Ok(())
        },
    );
}

/// A tabulated lift is only C² at its knots: the secant must still give the
/// exact increment when `[ψ, ψ+ω]` straddles a knot (the Gauss–Legendre rule
/// that serves smooth profiles is not exact there).
#[test]
fn secant_is_exact_across_the_knots_of_a_table() {
    property(
        "5b. tabulated lift, [psi, psi+w] across a knot: G theta_R vs f(psi+w) - f(psi), rel. |f|",
        CASES,
        (
            params(),
            0usize..12,
            -3i32..3,
            0.01..0.99f64,
            prop::sample::select(vec![5e-3, 2e-3, 1e-3, 1e-4, 1e-6, 2e-2]),
        ),
        |(p, knot, turns, frac, omega), w| {
            let dep = dependent_kinds(&p)
                .into_iter()
                .find(|d| d.name == "lobe (table)")
                .unwrap();
            let (knots, period) = dep.knots.clone().unwrap();
            let psi = knots[knot] + period * turns as f64 - frac * omega;
            let g = dep.joint.secant(psi, omega);
            let g_theta = g * (dep.axis * tau(omega));
            let mut st = ReleasedState::new([0.0; 4]);
            st.q[0] = psi;
            let f0 = dep.joint.released_placement(&st).0;
            dep.joint.advance(&mut st, &[omega]);
            let f1 = dep.joint.released_placement(&st).0;
            // |lift| ≤ 2 Σ|table values| bounds the spline (overshoot included).
            let value = 2.0 * p.fourier.iter().map(|v| v.abs()).sum::<f64>();
            w.bounded(
                &format!("omega = {omega:e}"),
                (g_theta - (f1 - f0)).norm(),
                value,
                1e-14 * value,
            )?;
            Ok(())
        },
    );
}

/// `Ñ` of FORMULATION §4 built by hand from the closed-form `f` and `G`.
fn ntilde_closed(
    r_mn: &Matrix3<f64>,
    theta_m: &Vector3<f64>,
    t: &Vector3<f64>,
    f0: &Vector3<f64>,
    f1: &Vector3<f64>,
    g: &Matrix3<f64>,
    omega: f64,
) -> SMatrix<f64, 6, 7> {
    let theta_r = r_mn * t * tau(omega);
    // Λ̄_m = ½(Λ_m,n + Λ_m,n+1) with Λ_m,n+1 = cay(θ_m) Λ_m,n.
    let mid = (r_mn + cayley(theta_m) * r_mn) * 0.5;
    let r_bar = (f0 + f1) * 0.5;
    let a = (Matrix3::identity() + skew(theta_m) * 0.5 + theta_m * theta_m.transpose() * 0.25)
        * r_mn
        / (1.0 - 0.25 * theta_m.dot(&theta_r));
    let mut n = SMatrix::<f64, 6, 7>::zeros();
    n.fixed_view_mut::<3, 1>(0, 0).copy_from(&(mid * g * t));
    n.fixed_view_mut::<3, 3>(0, 1)
        .copy_from(&Matrix3::identity());
    n.fixed_view_mut::<3, 3>(0, 4)
        .copy_from(&(-skew(&(mid * r_bar))));
    n.fixed_view_mut::<3, 1>(3, 0).copy_from(&(a * t));
    n.fixed_view_mut::<3, 3>(3, 4)
        .copy_from(&Matrix3::identity());
    n
}

#[test]
fn incremental_map_reproduces_the_exact_increments() {
    property(
        "6. exact increments vs Ntilde (tau, u_m, theta_m); u rel. |u_s| + |x_s|, theta rel. 1 + |theta_s|",
        CASES,
        (params(), pose(), -20.0..20.0f64, vec3(-1.0, 1.0), vec3(-0.7, 0.7), released_increment()),
        |(p, m, psi, u_m, w_m, omega), w| {
            let theta_m = flexmech_core::rotation::tan_scaled(&w_m);
            for dep in dependent_kinds(&p) {
                let mut st = ReleasedState::new([0.3, 0.0, 0.0, 0.0]);
                st.q[0] = psi;
                let (xs0, rs0) = dep.joint.slave(&m.x, &m.r, &st);
                let mut st1 = st;
                dep.joint.advance(&mut st1, &[omega]);
                let (x_m1, r_m1) = (m.x + u_m, cayley(&theta_m) * m.r);
                let (xs1, rs1) = dep.joint.slave(&x_m1, &r_m1, &st1);
                let u_s = xs1 - xs0;
                let theta_s = cayley_inverse(&(rs1 * rs0.transpose()));

                let nt = dep.joint.incremental_map(&m.r, &theta_m, psi, omega);
                let pvec = SVector::<f64, 7>::from_column_slice(&[tau(omega), u_m.x, u_m.y, u_m.z, theta_m.x, theta_m.y, theta_m.z]);
                let out = nt * pvec;
                let u_scale = u_s.norm() + xs0.norm() + xs1.norm();
                w.check(&format!("{}: u_s", dep.name), (out.fixed_rows::<3>(0) - u_s).norm() / u_scale, 1e-12)?;
                w.check(&format!("{}: theta_s", dep.name), (out.fixed_rows::<3>(3) - theta_s).norm() / (1.0 + theta_s.norm()), 1e-12)?;
                // The composition formula of FORMULATION §4.
                let theta_r = m.r * dep.axis * tau(omega);
                let composed = (theta_m + theta_r + theta_m.cross(&theta_r) * 0.5) / (1.0 - 0.25 * theta_m.dot(&theta_r));
                w.check(&format!("{}: theta_s composition", dep.name), (composed - theta_s).norm() / (1.0 + theta_s.norm()), 1e-12)?;
                // Ñ itself against its hand-built form with the closed-form f and G.
                if let Some(c) = &dep.closed {
                    let g = (c.secant)(psi, omega) * dep.axis.transpose();
                    let hand = ntilde_closed(&m.r, &theta_m, &dep.axis, &(c.f)(psi), &(c.f)(psi + omega), &g, omega);
                    let value = c.value + c.slope * (psi.abs() + omega.abs());
                    let tol = 1e-13 * hand.norm() + from_values(value, omega);
                    w.check(&format!("{}: Ntilde vs hand-built, rel. tolerance", dep.name), (nt - hand).norm() / tol, 1.0)?;
                }
            }
            Ok(())
        },
    );
}

/// Released increments of a kind: a random increment per additive coordinate,
/// a random rotation vector for the spherical one.
fn step_of(kind: &Kind, d: &[f64; 3]) -> ReleasedState {
    let mut end = kind.state;
    let k = kind.map.released_count();
    kind.map.advance(&mut end, &d[..k.min(3)]);
    end
}

#[test]
fn every_kind_steps_exactly_through_its_incremental_map() {
    property(
        "6b. JointStep: exact increments (u_m, theta_m, tau) -> (u_s, theta_s), every kind",
        CASES,
        (
            params(),
            released(),
            pose(),
            vec3(-1.0, 1.0),
            vec3(-0.7, 0.7),
            (
                released_increment(),
                released_increment(),
                released_increment(),
            ),
        ),
        |(p, q, m, u_m, w_m, (d0, d1, d2)), w| {
            let theta_m = flexmech_core::rotation::tan_scaled(&w_m);
            let (x1, r1) = (m.x + u_m, cayley(&theta_m) * m.r);
            for kind in all_kinds(&p, &q) {
                let end = step_of(&kind, &[d0, d1, d2]);
                let (xs0, rs0) = kind.map.slave(&m.x, &m.r, &kind.state);
                let (xs1, rs1) = kind.map.slave(&x1, &r1, &end);
                let u_s = xs1 - xs0;
                let theta_s = cayley_inverse(&(rs1 * rs0.transpose()));
                let step = JointStep::new(
                    kind.map.as_ref(),
                    [(&m.x, &m.r), (&x1, &r1)],
                    [&kind.state, &end],
                );
                // τ: coordinate increments, or the released rotation increment (spherical).
                let mut xi = SVector::<f64, LOCAL>::zeros();
                xi.fixed_rows_mut::<3>(0).copy_from(&u_m);
                xi.fixed_rows_mut::<3>(3).copy_from(&theta_m);
                if kind.spherical {
                    let t = cayley_inverse(&(end.rot * kind.state.rot.transpose()));
                    xi.fixed_rows_mut::<3>(6).copy_from(&t);
                } else {
                    for c in 0..kind.map.released_count() {
                        xi[6 + c] = end.q[c] - kind.state.q[c];
                    }
                }
                let out = step.matrix() * xi;
                let u_scale = u_s.norm() + xs0.norm() + xs1.norm();
                w.check(
                    &format!("{}: u_s, rel.", kind.name),
                    (out.fixed_rows::<3>(0) - u_s).norm() / u_scale,
                    1e-13,
                )?;
                w.check(
                    &format!("{}: theta_s, rel.", kind.name),
                    (out.fixed_rows::<3>(3) - theta_s).norm() / (1.0 + theta_s.norm()),
                    1e-13,
                )?;
                // The lever is the mid-step offset of the slave from the master.
                let d = (xs0 + xs1 - m.x - x1) * 0.5;
                w.check(
                    &format!("{}: offset = mid slave - mid master", kind.name),
                    (step.offset - d).norm() / (1.0 + d.norm()),
                    1e-14,
                )?;
                // Ñᵀg is the transpose of Ñ applied to g.
                let g = Vector6::new(d0, 1.0, -2.0, 0.5, d1 + 0.3, -0.7);
                let t = step.transfer(&g);
                w.check(
                    &format!("{}: transfer = Ntilde^T g", kind.name),
                    (t - step.matrix().transpose() * g).norm() / (1.0 + t.norm()),
                    1e-14,
                )?;
            }
            Ok(())
        },
    );
}

#[test]
fn step_map_tends_to_the_variation_as_the_step_vanishes() {
    property(
        "6c. B(tau) continuous across the Taylor switch and B(0) = N's released columns (master = I)",
        CASES,
        (params(), released()),
        |(p, q), w| {
            let (x, r) = (Vector3::zeros(), Matrix3::identity());
            for kind in all_kinds(&p, &q) {
                let k = kind.map.released_count();
                if k == 0 || kind.spherical {
                    continue;
                }
                let n = kind.map.variation(&x, &r, &kind.state);
                let b0 = kind.map.step_map(&kind.state, &kind.state);
                for c in 0..k {
                    let col_n = n.column(6 + c);
                    let scale = 1.0 + col_n.norm();
                    w.check(&format!("{}: B(0) vs N", kind.name), (b0.column(c) - col_n).norm() / scale, 1e-14)?;
                    // Just above and below the switch from difference quotient to Taylor.
                    let mut d = [0.0; 3];
                    d[c] = 1.0001e-6;
                    let above = kind.map.step_map(&kind.state, &step_of(&kind, &d));
                    d[c] = 0.9999e-6;
                    let below = kind.map.step_map(&kind.state, &step_of(&kind, &d));
                    // Quotient error ≤ a few eps·|F|/1e-6 with F formed from
                    // r_R and from rotations about angles of size |q| (rounded
                    // at eps·|q|).
                    let (rr, _) = kind.map.released_placement(&kind.state);
                    let tol = 1e-9 * (1.0 + rr.norm() + kind.state.q[c].abs()) + 1e-9 * scale;
                    w.check(&format!("{}: B continuous at 1e-6", kind.name), (above.column(c) - below.column(c)).norm(), tol)?;
                }
            }
            Ok(())
        },
    );
}

// ---------------------------------------------------------------------------
// 7: the constraint along a driven path.
// ---------------------------------------------------------------------------

#[test]
fn constraint_holds_along_a_driven_path() {
    const STEPS: usize = 2000;
    property(
        "7. constraint along 5 driven turns (2000 steps), rel. |x_m| + |f| + 1",
        16,
        (
            params(),
            pose(),
            vec3(-0.7, 0.7),
            -3.0..3.0f64,
            prop::bool::ANY,
        ),
        |(p, m, spin, psi0, backwards), w| {
            let sign = if backwards { -1.0 } else { 1.0 };
            let duration = 3.0;
            // ψ(t): five turns with a wobble, so steps range over 0.003..0.028 rad
            // (both branches of the secant).
            let psi_at = |t: f64| {
                psi0 + sign * (10.0 * PI * t / duration + 2.0 * (4.0 * PI * t / duration).sin())
            };
            let x_at = |t: f64| m.x + Vector3::new(2.0 * t.sin(), (1.3 * t).cos() - 1.0, 0.5 * t);
            let r_at = |t: f64| exp(&(spin * t)) * m.r;
            for dep in dependent_kinds(&p) {
                let t_axis = dep.axis;
                let mut st = ReleasedState::new([psi0, 0.0, 0.0, 0.0]);
                // Slave propagated by the conserving schemes' increments (Ñ).
                let (mut xs, mut rs) = dep.joint.slave(&x_at(0.0), &r_at(0.0), &st);
                let (mut worst_place, mut worst_rot, mut worst_inc, mut worst_psi) =
                    (0.0f64, 0.0f64, 0.0f64, 0.0f64);
                for k in 0..STEPS {
                    let (t0, t1) = (
                        duration * k as f64 / STEPS as f64,
                        duration * (k + 1) as f64 / STEPS as f64,
                    );
                    let omega = psi_at(t1) - psi_at(t0);
                    let (x0, r0, x1, r1) = (x_at(t0), r_at(t0), x_at(t1), r_at(t1));
                    let theta_m = cayley_inverse(&(r1 * r0.transpose()));
                    let nt = dep.joint.incremental_map(&r0, &theta_m, st.q[0], omega);
                    let u_m = x1 - x0;
                    let pvec = SVector::<f64, 7>::from_column_slice(&[
                        tau(omega),
                        u_m.x,
                        u_m.y,
                        u_m.z,
                        theta_m.x,
                        theta_m.y,
                        theta_m.z,
                    ]);
                    let inc = nt * pvec;
                    xs += inc.fixed_rows::<3>(0);
                    rs = cayley(&Vector3::new(inc[3], inc[4], inc[5])) * rs;

                    dep.joint.advance(&mut st, &[omega]);
                    let psi = st.q[0];
                    worst_psi = worst_psi
                        .max((psi - psi_at(t1)).abs() / ((k + 1) as f64 * EPS * (psi.abs() + 1.0)));
                    let (xp, rp) = dep.joint.slave(&x1, &r1, &st);
                    let f = match &dep.closed {
                        Some(c) => (c.f)(psi),
                        None => dep.joint.released_placement(&st).0,
                    };
                    let scale = x1.norm() + f.norm() + 1.0;
                    worst_place = worst_place.max((xp - x1 - r1 * f).norm() / scale);
                    worst_rot =
                        worst_rot.max((r1.transpose() * rp - exp(&(t_axis * (psi - psi0)))).norm());
                    worst_inc = worst_inc.max(((xs - xp).norm() / scale).max((rs - rp).norm()));
                }
                w.check(
                    &format!("{}: r_s - r_m - R_m f(psi)", dep.name),
                    worst_place,
                    1e-12,
                )?;
                w.check(
                    &format!("{}: R_m^T R_s - exp((psi-psi0) t^)", dep.name),
                    worst_rot,
                    1e-12,
                )?;
                w.check(
                    &format!("{}: psi accumulated / (k eps |psi|)", dep.name),
                    worst_psi,
                    2.0,
                )?;
                w.check(
                    &format!("{}: slave propagated by Ntilde vs placed", dep.name),
                    worst_inc,
                    1e-12,
                )?;
            }
            Ok(())
        },
    );
}

// ---------------------------------------------------------------------------
// 8: a custom joint written outside the crate.
// ---------------------------------------------------------------------------

/// The variable-pitch screw above takes ten lines; here its maps are checked
/// against the closed forms derived by hand:
///
/// * `f′(ψ) = (c + d cos ψ) t`, so `N = [[I, −(R_m f)^, R_m f′], [0, I, R_m t]]`;
/// * `G = (f(ψ+ω) − f(ψ)) ⊗ t / (2 tan(ω/2))
///      = (c (ω/2)/tan(ω/2) + d cos(ψ + ω/2) cos(ω/2)) t ⊗ t`;
/// * `Ñ = [[Λ̄_m G t, I, −(Λ̄_m r̄_R)^], [A t, 0, I]]`, `Λ̄_m = ½(Λ_m,n + cay(θ_m)Λ_m,n)`,
///   `r̄_R = ½(f(ψ) + f(ψ+ω))`, `A = (I + ½θ̂_m + ¼θ_m⊗θ_m)Λ_m,n/(1 − ¼θ_m·Λ_m,nθ_R)`.
#[test]
fn a_custom_joint_needs_only_its_profile() {
    property(
        "8. custom variable-pitch screw: N, G, Ntilde vs hand-derived forms",
        CASES,
        (
            unit(),
            -0.5..0.5f64,
            -0.3..0.3f64,
            pose(),
            -20.0..20.0f64,
            vec3(-0.7, 0.7),
            released_increment(),
        ),
        |(t, c, d, m, psi, w_m, omega), w| {
            let joint = VariablePitchScrew { axis: t, c, d };
            let f = |x: f64| t * (c * x + d * x.sin());
            let fp = t * (c + d * psi.cos());
            let mut st = ReleasedState::new([0.0; 4]);
            st.q[0] = psi;

            // N (eqs 10–11).
            let mut n_hand = SMatrix::<f64, 6, LOCAL>::zeros();
            n_hand
                .fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&Matrix3::identity());
            n_hand
                .fixed_view_mut::<3, 3>(0, 3)
                .copy_from(&(-skew(&(m.r * f(psi)))));
            n_hand.fixed_view_mut::<3, 1>(0, 6).copy_from(&(m.r * fp));
            n_hand
                .fixed_view_mut::<3, 3>(3, 3)
                .copy_from(&Matrix3::identity());
            n_hand.fixed_view_mut::<3, 1>(3, 6).copy_from(&(m.r * t));
            let n = joint.variation(&m.x, &m.r, &st);
            w.check("N", (n - n_hand).norm() / n_hand.norm(), 1e-12)?;
            w.check(
                "f'",
                (joint.derivative(psi) - fp).norm(),
                1e-13 * (c.abs() + d.abs()),
            )?;

            // G (eq. 22) for the random ω and the small ones, including 0.
            let s = c.abs() + d.abs() * (psi.abs() + 2.0);
            for om in [omega, 1e-3, 1e-6, 1e-9, 0.0] {
                let g_hand = t
                    * t.transpose()
                    * (c * half_cot(om) + d * (psi + 0.5 * om).cos() * (0.5 * om).cos());
                let value = d.abs() + c.abs() * (psi.abs() + om.abs());
                let tol = 1e-14 * s
                    + if om.abs() >= 1e-2 {
                        8.0 * EPS * value / tau(om).abs()
                    } else {
                        0.0
                    };
                w.check(
                    "G / tolerance",
                    (joint.secant(psi, om) - g_hand).norm() / tol,
                    1.0,
                )?;
            }

            // Ñ (eqs 21–22), and its product with the increments is exact.
            let theta_m = flexmech_core::rotation::tan_scaled(&w_m);
            let g_hand = t
                * t.transpose()
                * (c * half_cot(omega) + d * (psi + 0.5 * omega).cos() * (0.5 * omega).cos());
            let lam_bar = cayley_mid(&theta_m) * m.r;
            let r_bar = (f(psi) + f(psi + omega)) * 0.5;
            let theta_r = m.r * t * tau(omega);
            let a =
                (Matrix3::identity() + skew(&theta_m) * 0.5 + theta_m * theta_m.transpose() * 0.25)
                    * m.r
                    / (1.0 - 0.25 * theta_m.dot(&theta_r));
            let mut nt_hand = SMatrix::<f64, 6, 7>::zeros();
            nt_hand
                .fixed_view_mut::<3, 1>(0, 0)
                .copy_from(&(lam_bar * g_hand * t));
            nt_hand
                .fixed_view_mut::<3, 3>(0, 1)
                .copy_from(&Matrix3::identity());
            nt_hand
                .fixed_view_mut::<3, 3>(0, 4)
                .copy_from(&(-skew(&(lam_bar * r_bar))));
            nt_hand.fixed_view_mut::<3, 1>(3, 0).copy_from(&(a * t));
            nt_hand
                .fixed_view_mut::<3, 3>(3, 4)
                .copy_from(&Matrix3::identity());
            let nt = joint.incremental_map(&m.r, &theta_m, psi, omega);
            let value = d.abs() + c.abs() * (psi.abs() + omega.abs());
            let tol = 1e-13 * nt_hand.norm() + from_values(value, omega);
            w.check("Ntilde / tolerance", (nt - nt_hand).norm() / tol, 1.0)?;
            Ok(())
        },
    );
}

/// A random step: a joint's master moving from `m` to `(x1, r1)`, released
/// increments `d` and a slave residual `g`.
#[derive(Debug, Clone)]
struct Step {
    p: Params,
    q: Released,
    m: Pose,
    x1: Vector3<f64>,
    r1: Matrix3<f64>,
    g: Vector6<f64>,
    d: [f64; 3],
}

fn steps() -> impl Strategy<Value = Step> {
    let increments = (
        released_increment(),
        released_increment(),
        released_increment(),
    );
    let ends = (vec3(-1.0, 1.0), vec3(-0.7, 0.7), increments);
    (params(), released(), pose(), ends).prop_map(|(p, q, m, (u_m, w_m, (d0, d1, d2)))| {
        let theta_m = flexmech_core::rotation::tan_scaled(&w_m);
        Step {
            x1: m.x + u_m,
            r1: cayley(&theta_m) * m.r,
            g: Vector6::new(d0 + 0.2, 1.0, -2.0, 0.5, d1 + 0.3, -0.7),
            d: [d0, d1, d2],
            p,
            q,
            m,
        }
    })
}

/// The central differences' step for local coordinate `c` of `kind` over
/// the step to `end`. `B` switches form at |τ| = 1e-6: a released column
/// whose τ lies near it has no smooth stencil (`None`); a τ below it takes a
/// stencil that stays in the Taylor form; above, the divided difference
/// inside `B` carries eps|F|/τ of round-off, so the stencil grows with τ to
/// keep it below [`FD_TOL`].
fn stencil(kind: &Kind, end: &ReleasedState, c: usize) -> Option<f64> {
    let tau = if c >= 6 && !kind.spherical {
        (end.q[c - 6] - kind.state.q[c - 6]).abs()
    } else {
        1.0
    };
    if (0.5e-6..=2e-6).contains(&tau) {
        return None;
    }
    Some(if tau < 1e-5 {
        1e-8
    } else {
        (0.1 * tau).clamp(1e-6, 1e-4)
    })
}

/// Central differences of `Ñᵀg` (quotients over `τ` inside `B`) agree with
/// the derivative to their own truncation and round-off, ~1e-6 relative.
const FD_TOL: f64 = 1e-5;

#[test]
fn incremental_transfer_derivative_matches_differences() {
    property(
        "6d. d(Ntilde^T g)/d(end state) by AD = central differences, every kind",
        CASES,
        steps(),
        |Step {
             p,
             q,
             m,
             x1,
             r1,
             g,
             d: [d0, d1, d2],
         },
         w| {
            for kind in all_kinds(&p, &q) {
                if kind.skip_second_fd {
                    continue;
                }
                let end = step_of(&kind, &[d0, d1, d2]);
                let k = kind.map.released_count();
                let at = |e: &SVector<f64, LOCAL>| {
                    let x = x1 + e.fixed_rows::<3>(0);
                    let r = flexmech_core::rotation::exp(&e.fixed_rows::<3>(3).into_owned()) * r1;
                    let mut rel = end;
                    let inc: Vec<f64> = (0..k).map(|c| e[6 + c]).collect();
                    kind.map.advance(&mut rel, &inc);
                    kind.map
                        .incremental_step([(&m.x, &m.r), (&x, &r)], [&kind.state, &rel])
                        .transfer(&g)
                };
                let (value, ad) = kind.map.incremental_transfer(
                    [(&m.x, &m.r), (&x1, &r1)],
                    [&kind.state, &end],
                    &g,
                );
                // The same arithmetic in duals and in f64, up to the divided
                // difference's cancellation (eps/τ at τ ≥ 1e-6).
                w.check(
                    &format!("{}: value", kind.name),
                    (value - at(&SVector::zeros())).norm() / (1.0 + value.norm()),
                    1e-9,
                )?;
                for c in 0..6 + k {
                    let Some(h) = stencil(&kind, &end, c) else {
                        continue;
                    };
                    let mut e = SVector::<f64, LOCAL>::zeros();
                    e[c] = h;
                    let fd = (at(&e) - at(&(-e))) / (2.0 * h);
                    w.check(
                        &format!("{}: column {c}", kind.name),
                        (fd - ad.column(c)).norm() / (1.0 + ad.column(c).norm()),
                        FD_TOL,
                    )?;
                }
            }
            Ok(())
        },
    );
}

/// The seeded map along chosen lanes (released lanes by AD, the master's
/// spin closed form) agrees with the ten-lane AD of `Ñᵀg`: the value and
/// every seeded column to round-off, the other columns zero.
#[test]
fn seeded_step_lanes_match_the_ten_lane_ad() {
    property(
        "6e. Ntilde^T g and its derivative along chosen lanes = ten-lane AD, every kind",
        CASES,
        steps(),
        |Step {
             m,
             x1,
             r1,
             g,
             d: [d0, d1, d2],
             p,
             q,
         },
         w| {
            for kind in all_kinds(&p, &q) {
                let end = step_of(&kind, &[d0, d1, d2]);
                let k = kind.map.released_count();
                let (master, released) = ([(&m.x, &m.r), (&x1, &r1)], [&kind.state, &end]);
                let (value, ad) = kind.map.incremental_transfer(master, released, &g);
                let scale = 1.0 + ad.norm() + value.norm();
                for spin in [true, false] {
                    for seeded in 0..=k {
                        let lanes = StepLanes {
                            spin,
                            released: seeded,
                        };
                        let step = kind.map.incremental_step_lanes(master, released, lanes);
                        let (v, kk) = step.transfer(&g, k);
                        let at = format!("{}: {lanes:?}", kind.name);
                        w.check(&format!("{at} value"), (v - value).norm() / scale, 1e-12)?;
                        for c in 0..LOCAL {
                            let wanted =
                                (3..6).contains(&c) && spin || (6..6 + seeded).contains(&c);
                            let expected = if wanted {
                                ad.column(c).into_owned()
                            } else {
                                SVector::zeros()
                            };
                            let err = (kk.column(c) - expected).norm() / scale;
                            w.check(&format!("{at} column {c}"), err, 1e-12)?;
                        }
                    }
                }
            }
            Ok(())
        },
    );
}

/// A kind's `translation_by` at one angle.
type Slopes<'a> = dyn Fn() -> Option<[Vector3<f64>; 2]> + 'a;

#[test]
fn parameter_slopes_match_the_closed_forms() {
    // ∂f/∂p and ∂²f/∂ψ∂p of the built-in kinds' real parameters, by hyper-dual
    // AD, against the derivatives of paper eqs 12–14 written by hand.
    property(
        "9. ∂f/∂p, ∂²f/∂ψ∂p of screw, rack-and-pinion, cam, rel. 1 + |ψ|",
        CASES,
        (params(), released()),
        |(p, q), w| {
            let psi = q.psi;
            let screw = Screw {
                axis: p.axis,
                pitch: p.pitch,
            };
            let rack = RackPinion {
                axis: p.axis,
                slide: p.perp,
                radius: p.pinion,
            };
            let cam = Cam {
                axis: p.axis,
                slide: p.perp,
                radius: p.cam_r,
                offset: p.cam_a,
            };
            let t_r = p.perp;
            let cases: [(&Slopes, [Vector3<f64>; 2]); 4] = [
                (
                    &|| screw.translation_by("pitch", psi),
                    [p.axis * psi, p.axis],
                ),
                (
                    &|| rack.translation_by("radius", psi),
                    [t_r.cross(&p.axis) + t_r * psi, t_r],
                ),
                (
                    &|| cam.translation_by("radius", psi),
                    [t_r * (psi.cos() - 1.0), -t_r * psi.sin()],
                ),
                (
                    &|| cam.translation_by("offset", psi),
                    [-t_r, Vector3::zeros()],
                ),
            ];
            let scale = 1.0 + psi.abs();
            for (k, (ad, [f_p, f_psi_p])) in cases.into_iter().enumerate() {
                let [a, b] = ad().ok_or_else(|| TestCaseError::fail("no slope"))?;
                let err = (a - f_p).norm().max((b - f_psi_p).norm());
                w.bounded(&format!("kind {k}"), err, scale, 16.0 * EPS * scale)?;
            }
            prop_assert!(cam.translation_by("axis", psi).is_none());
            Ok(())
        },
    );
}

#[test]
fn incremental_transfer_start_derivative_matches_differences() {
    property(
        "6e. d(Ntilde^T g)/d(start state) by AD = central differences, every kind",
        CASES,
        steps(),
        |Step {
             p,
             q,
             m,
             x1,
             r1,
             g,
             d: [d0, d1, d2],
         },
         w| {
            for kind in all_kinds(&p, &q) {
                if kind.skip_second_fd {
                    continue;
                }
                let end = step_of(&kind, &[d0, d1, d2]);
                let k = kind.map.released_count();
                // The step's start moved by `e`, its end held.
                let at = |e: &SVector<f64, LOCAL>| {
                    let x = m.x + e.fixed_rows::<3>(0);
                    let r = flexmech_core::rotation::exp(&e.fixed_rows::<3>(3).into_owned()) * m.r;
                    let mut start = kind.state;
                    let inc: Vec<f64> = (0..k).map(|c| e[6 + c]).collect();
                    kind.map.advance(&mut start, &inc);
                    kind.map
                        .incremental_step([(&x, &r), (&x1, &r1)], [&start, &end])
                        .transfer(&g)
                };
                for c in 0..6 + k {
                    // Moving the start moves τ as moving the end does.
                    let Some(h) = stencil(&kind, &end, c) else {
                        continue;
                    };
                    let mut e = SVector::<f64, LOCAL>::zeros();
                    e[c] = h;
                    let fd = (at(&e) - at(&(-e))) / (2.0 * h);
                    let mut dir = ([0.0; 6], [0.0; MAX_RELEASED]);
                    if c < 6 {
                        dir.0[c] = 1.0;
                    } else {
                        dir.1[c - 6] = 1.0;
                    }
                    let ad = kind
                        .map
                        .incremental_transfer_start(
                            [(&m.x, &m.r), (&x1, &r1)],
                            [&kind.state, &end],
                            &g,
                            (&dir.0, &dir.1),
                        )
                        .ok_or_else(|| TestCaseError::fail("no start derivative"))?;
                    w.check(
                        &format!("{}: start column {c}", kind.name),
                        (fd - ad).norm() / (1.0 + ad.norm()),
                        FD_TOL,
                    )?;
                }
            }
            Ok(())
        },
    );
}

#[test]
fn incremental_transfer_by_a_parameter_matches_differences() {
    // (∂Ñ/∂p)ᵀ g of the built-in kinds' values against central differences
    // of Ñᵀ g with the value moved (both ends of the step held).
    property(
        "6f. d(Ntilde^T g)/dp = central differences, screw / rack / cam values",
        CASES,
        (
            params(),
            released(),
            pose(),
            vec3(-1.0, 1.0),
            vec3(-0.7, 0.7),
            released_increment(),
        ),
        |(p, q, m, u_m, w_m, d0), w| {
            let theta_m = flexmech_core::rotation::tan_scaled(&w_m);
            let (x1, r1) = (m.x + u_m, cayley(&theta_m) * m.r);
            let g = Vector6::new(d0 + 0.2, 1.0, -2.0, 0.5, 0.3, -0.7);
            let mut start = ReleasedState::new([q.psi0, 0.0, 0.0, 0.0]);
            start.q[0] = q.psi;
            let mut end = start;
            end.q[0] += d0;
            let screw = |c: f64| Screw {
                axis: p.axis,
                pitch: c,
            };
            let rack = |b: f64| RackPinion {
                axis: p.axis,
                slide: p.perp,
                radius: b,
            };
            let cam = |r: f64, a: f64| Cam {
                axis: p.axis,
                slide: p.perp,
                radius: r,
                offset: a,
            };
            type Kind<'a> = (&'a str, f64, &'a dyn Fn(f64) -> Box<dyn JointMap>);
            let kinds: [Kind; 4] = [
                ("pitch", p.pitch, &|v| Box::new(screw(v))),
                ("radius", p.pinion, &|v| Box::new(rack(v))),
                ("radius", p.cam_r, &|v| Box::new(cam(v, p.cam_a))),
                ("offset", p.cam_a, &|v| Box::new(cam(p.cam_r, v))),
            ];
            let master = [(&m.x, &m.r), (&x1, &r1)];
            for (k, (name, value, make)) in kinds.into_iter().enumerate() {
                let ad = make(value)
                    .incremental_transfer_by(name, master, [&start, &end], &g)
                    .ok_or_else(|| TestCaseError::fail("no derivative"))?;
                // Each value enters `f` linearly: a wide stencil is exact and
                // keeps the secant's round-off (eps|f|/τ) small against h.
                let h = 1e-2;
                let at = |v: f64| {
                    make(v)
                        .incremental_step(master, [&start, &end])
                        .transfer(&g)
                };
                let fd = (at(value + h) - at(value - h)) / (2.0 * h);
                w.check(
                    &format!("kind {k} by {name}"),
                    (fd - ad).norm() / (1.0 + ad.norm()),
                    FD_TOL,
                )?;
            }
            Ok(())
        },
    );
}
