//! Job 2: a study over the new joint's parameter, from Rust. The elliptical
//! cam's semi-axis `b` is swept over the shipped model; each run gets its
//! own result file, the summary a row per run and a chart per figure.
//!
//! `cargo run --release -p flexmech --example study` writes `studies/ellipse-cam/`.

mod ellipse_cam;

use ellipse_cam::EllipseCam;
use flexmech::prelude::*;

/// Runs the study below `out`.
fn study(out: &Path) -> Result<StudyReport, Box<dyn std::error::Error>> {
    let app = App::new().joint::<EllipseCam>();
    let base = app.load(flexmech::data("examples/ellipse_cam.toml"))?;
    let follower = "/joints/cam/released_translation[x]";
    let study = app
        .study("ellipse-cam", &base)
        .grid("joint.cam.b", [0.02, 0.03, 0.04])
        .grid("solver.t_end", [0.5])
        .figure(Figure::dataset("follower_x", follower, "min")?)
        .figure(Figure::NewtonIterations);
    Ok(study.run(out)?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("{}", study(Path::new("studies"))?);
    Ok(())
}

#[cfg(test)]
#[path = "study/tests.rs"]
mod tests;
