//! A joint kind written outside flexmech, used from model files and studies.
//!
//! `HarmonicCam` is a cam of `n` lobes whose follower strokes by `rise` and
//! back `n` times a turn, `f(ψ) = −(a + rise (1 − cos nψ)/2) t_r`. The kind is
//! the joint (`DependentJoint`: the axis and `f`; num-dual derives `N`, `G`,
//! `Ñ` and the tangents) plus its model-file name and parameters
//! (`ModelJoint`). The binary is flexmech's command line with the kind
//! registered, so `cam.toml` can name `type = "harmonic_cam"` and `study.toml`
//! can sweep its `rise` and `lobes`:
//!
//! ```text
//! cargo run --release -p flexmech --example harmonic_cam -- \
//!     run flexmech/examples/harmonic_cam/cam.toml --out results
//! cargo run --release -p flexmech --example harmonic_cam -- \
//!     study flexmech/examples/harmonic_cam/study.toml --out studies
//! ```

use flexmech::core::{cst, Scalar};
use flexmech::joints::model_joint::{direction, perpendicular_slide, ModelJoint, ParamError};
use flexmech::joints::{parameter_slopes, DependentJoint};
use flexmech::model::JointRegistry;
use nalgebra::Vector3;
use serde::Deserialize;

/// A cam of `lobes` lobes: `f(ψ) = −(offset + rise (1 − cos(lobes ψ))/2) slide`.
#[derive(Debug)]
pub struct HarmonicCam {
    axis: Vector3<f64>,
    slide: Vector3<f64>,
    rise: f64,
    lobes: f64,
    offset: f64,
}

impl DependentJoint for HarmonicCam {
    fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    fn translation<T: Scalar>(&self, psi: T) -> Vector3<T> {
        self.profile(psi, cst(self.rise), cst(self.offset))
    }

    /// Exact sensitivities by `rise` and `offset` (`[output] sensitivity =
    /// ["joint.cam.rise"]`): the same profile in hyper-dual numbers.
    fn translation_by(&self, name: &str, psi: f64) -> Option<[Vector3<f64>; 2]> {
        let (rise, offset) = (cst(self.rise), cst(self.offset));
        match name {
            "rise" => Some(parameter_slopes(psi, self.rise, |psi, r| {
                self.profile(psi, r, offset)
            })),
            "offset" => Some(parameter_slopes(psi, self.offset, |psi, a| {
                self.profile(psi, rise, a)
            })),
            _ => None,
        }
    }
}

impl HarmonicCam {
    /// `f(ψ) = −(a + rise (1 − cos nψ)/2) t_r` for any scalar, `rise` and `a`
    /// among them.
    fn profile<T: Scalar>(&self, psi: T, rise: T, offset: T) -> Vector3<T> {
        let stroke = T::one() - (psi * cst::<T>(self.lobes)).cos();
        let lift = offset + stroke * rise * cst::<T>(0.5);
        self.slide.map(cst::<T>) * (-lift)
    }
}

/// Its keys in a `[[joint]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarmonicCamParams {
    axis: [f64; 3],
    slide: [f64; 3],
    rise: f64,
    lobes: u32,
    #[serde(default)]
    offset: f64,
}

impl ModelJoint for HarmonicCam {
    const NAME: &'static str = "harmonic_cam";
    type Params = HarmonicCamParams;

    fn from_params(p: HarmonicCamParams) -> Result<Self, ParamError> {
        let axis = direction("axis", p.axis)?;
        let slide = perpendicular_slide(Self::NAME, p.slide, &axis)?;
        let (rise, lobes, offset) = (p.rise, f64::from(p.lobes), p.offset);
        Ok(HarmonicCam {
            axis,
            slide,
            rise,
            lobes,
            offset,
        })
    }
}

/// flexmech's joint kinds and the harmonic cam.
pub fn registry() -> JointRegistry {
    let mut registry = JointRegistry::builtin();
    // "harmonic_cam" is not a built-in name.
    let _ = registry.register::<HarmonicCam>();
    registry
}

fn main() -> std::process::ExitCode {
    flexmech::cli::main_with(registry())
}

#[cfg(test)]
mod tests {
    use super::*;
    use flexmech::cli::run_with;
    use flexmech::model::parse_model_with;
    use flexmech::results::{run_model, ResultReader};
    use nalgebra::Rotation3;
    use std::path::{Path, PathBuf};
    use std::process::ExitCode;

    fn here(file: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/harmonic_cam")
            .join(file)
    }

    fn read(file: &Path, dataset: &str) -> Vec<f64> {
        ResultReader::open(file).unwrap().values(dataset).unwrap()
    }

    /// Both runs stop Newton at a residual of 1e-10 of the force scale, so
    /// their positions may differ at that level times the arm's compliance
    /// (< 1e-8 m); a wrong profile (a sign, a factor 2 in the stroke) would
    /// move the follower by centimetres.
    const SAME_RUN: f64 = 1e-8;

    #[test]
    fn one_lobe_of_stroke_2r_is_the_builtin_cam_of_radius_r() {
        let out = tempfile::tempdir().unwrap();
        // The user's kind, through the user's binary.
        let code = run_with(
            registry(),
            [
                "harmonic_cam",
                "run",
                here("cam.toml").to_str().unwrap(),
                "--out",
            ]
            .into_iter()
            .map(String::from)
            .chain([out.path().to_str().unwrap().to_string()]),
        );
        assert_eq!(code, ExitCode::SUCCESS);
        let mine = out.path().join("harmonic-cam.h5");
        // The built-in cam (R = 0.05, a = 0.02), validated against the paper
        // in the test suite, on the same 1 s.
        let paper = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper/cam.toml");
        let text = std::fs::read_to_string(&paper)
            .unwrap()
            .replace("t_end = 3.0", "t_end = 1.0");
        let model = parse_model_with(&text, &paper, &registry()).unwrap();
        let builtin = run_model(&model, out.path()).unwrap().file;
        for node in ["arm.end", "arm.start"] {
            let a = read(&mine, &format!("/nodes/{node}/position"));
            let b = read(&builtin, &format!("/nodes/{node}/position"));
            assert_eq!(a.len(), b.len());
            assert!(a.len() > 300, "{} values", a.len());
            let worst = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(worst <= SAME_RUN, "{node}: {worst:e}");
        }
        // The follower really moved: at ψ = π (t = 1 s) it has stroked 2R.
        let angle = read(&mine, "/joints/cam/angle");
        assert!((angle.last().unwrap() - std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn a_study_sweeps_the_users_parameters() {
        let out = tempfile::tempdir().unwrap();
        let code = run_with(
            registry(),
            [
                "harmonic_cam",
                "study",
                here("study.toml").to_str().unwrap(),
                "--out",
            ]
            .into_iter()
            .map(String::from)
            .chain([out.path().to_str().unwrap().to_string()]),
        );
        assert_eq!(code, ExitCode::SUCCESS);
        let dir = out.path().join("harmonic-cam");
        let csv = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
        assert_eq!(csv.lines().count(), 5, "{csv}");
        assert!(
            csv.lines().skip(1).all(|l| l.contains("completed")),
            "{csv}"
        );
        for figure in [
            "max_displacement",
            "energy_drift",
            "newton_iterations",
            "follower_x",
        ] {
            assert!(
                dir.join(format!("charts/{figure}.png")).is_file(),
                "{figure}"
            );
        }
        // The study's own figure: the drive table reaches ψ = π/2 − 1 at
        // t = 0.5 s, ψ grows all the way and nψ < π, so the deepest follower
        // position is the last, −(a + rise (1 − cos nψ)/2).
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let col = header.iter().position(|h| *h == "follower_x").unwrap();
        let psi = std::f64::consts::FRAC_PI_2 - 1.0;
        let params = [(0.05, 1.0), (0.05, 2.0), (0.1, 1.0), (0.1, 2.0)];
        for (line, (rise, lobes)) in csv.lines().skip(1).zip(params) {
            let value: f64 = line.split(',').nth(col).unwrap().parse().unwrap();
            let expected = -(0.02 + 0.5 * rise * (1.0 - (lobes * psi).cos()));
            assert!(
                (value - expected).abs() <= 1e-12,
                "{line}: {value} vs {expected}"
            );
        }
        // Every run obeys the joint relation (1) of its own parameters,
        // x_s = x_m + Λ_m f(ψ), at every stored step — checked against the
        // profile written out here, not the kind's code.
        for (run, (rise, lobes)) in [(0.05, 1.0), (0.05, 2.0), (0.1, 1.0), (0.1, 2.0)]
            .into_iter()
            .enumerate()
        {
            let file = dir.join(format!("runs/run-{run:04}.h5"));
            let xs = read(&file, "/nodes/arm.start/position");
            let xm = read(&file, "/nodes/post.end/position");
            let rot = read(&file, "/nodes/post.end/rotation");
            let psi = read(&file, "/joints/cam/angle");
            for (k, &p) in psi.iter().enumerate() {
                let f = Vector3::x() * -(0.02 + 0.5 * rise * (1.0 - (lobes * p).cos()));
                let v = |a: &[f64]| Vector3::new(a[3 * k], a[3 * k + 1], a[3 * k + 2]);
                let expected = v(&xm) + Rotation3::new(v(&rot)) * f;
                let gap = (v(&xs) - expected).norm();
                assert!(gap <= 1e-12, "run {run} step {k}: {gap:e}");
            }
        }
    }

    /// `cam.toml`'s text with the cam written as an expression joint: the
    /// same `f(ψ) = −(a + rise (1 − cos nψ)/2) t_r` in the model file.
    fn as_expression(rust_text: &str) -> String {
        rust_text
            .replace("type = \"harmonic_cam\"", "type = \"expression\"")
            .replace("slide = [1.0, 0.0, 0.0]", "")
            .replace("rise = 0.1", "")
            .replace("offset = 0.02 ", "#")
            .replace(
                "lobes = 1 ",
                "translation = [\"-(a + (1 - cos(psi*n))*(0.5*rise))\", \"0\", \"0\"]\n\
                 parameters = { a = 0.02, rise = 0.1, n = 1.0 }\n#",
            )
    }

    #[test]
    fn sensitivities_by_the_users_rise_equal_the_expression_joints() {
        // The Rust kind's `translation_by` and the expression joint's
        // parameter (itself checked against central differences in the
        // suite) give the tip's derivative by the rise, 0.3 s of the spin-up.
        let rust_text = std::fs::read_to_string(here("cam.toml"))
            .unwrap()
            .replace("t_end = 1.0", "t_end = 0.3")
            .replace(
                "integrator = \"energy-momentum\"",
                "integrator = \"newmark\"",
            );
        let expression_text = as_expression(&rust_text);
        let derivative = |text: &str, key: &str| {
            let mut model = parse_model_with(text, &here("cam.toml"), &registry()).unwrap();
            model.add_sensitivity(&[key.to_string()]).unwrap();
            let mut memory = flexmech::results::Memory::default();
            flexmech::results::run(&model, &mut memory).unwrap();
            assert_eq!(memory.status(), "completed");
            let tip = flexmech::model::build(&model)
                .unwrap()
                .node(model.output.track[0].1);
            (memory.records.iter())
                .map(|r| r.sensitivities[0].displacement[tip])
                .collect::<Vec<_>>()
        };
        let mine = derivative(&rust_text, "joint.cam.rise");
        let theirs = derivative(&expression_text, "joint.cam.parameters.rise");
        let scale = theirs.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 1e-3, "a derivative that moves the tip: {scale}");
        for (a, b) in mine.iter().zip(&theirs) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 1e-9 * scale, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn the_harmonic_cam_written_as_an_expression_runs_as_the_rust_kind() {
        // No compiling: the same f(ψ) = −(a + rise (1 − cos nψ)/2) t_r in the
        // model file. The two evaluate the same operations in the same
        // order, so the runs agree to round-off of the positions (1e-12 of
        // the mechanism's size) at every stored step.
        let rust_text = std::fs::read_to_string(here("cam.toml"))
            .unwrap()
            .replace("t_end = 1.0", "t_end = 0.5");
        let expression_text = as_expression(&rust_text);
        let positions = |text: &str| {
            let model = parse_model_with(text, &here("cam.toml"), &registry()).unwrap();
            let mut memory = flexmech::results::Memory::default();
            flexmech::results::run(&model, &mut memory).unwrap();
            assert_eq!(memory.status(), "completed");
            memory.positions("arm.end").unwrap()
        };
        let (a, b) = (positions(&rust_text), positions(&expression_text));
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            for c in 0..3 {
                assert!((x[c] - y[c]).abs() <= 1e-12, "{x:?} vs {y:?}");
            }
        }
    }
}
