//! Job 1: a new joint kind used from a model file through your own binary.
//! The kind (an elliptical cam, `ellipse_cam/mod.rs`) is registered with an
//! [`App`]; the shipped model `data/examples/ellipse_cam.toml` names it.
//!
//! `cargo run --release -p flexmech --example joint` runs that model into
//! `results/`; with arguments the binary is flexmech's command line with the
//! cam: `... --example joint -- study data/examples/ellipse_cam_study.toml`.

mod ellipse_cam;

use ellipse_cam::EllipseCam;
use flexmech::prelude::*;
use std::process::ExitCode;

/// Runs the shipped model with the cam into `out`.
fn run(out: &Path) -> Result<RunSummary, Box<dyn std::error::Error>> {
    let app = App::new().joint::<EllipseCam>();
    let model = app.load(flexmech::data("examples/ellipse_cam.toml"))?;
    Ok(run_model(&model, out)?)
}

fn main() -> ExitCode {
    if std::env::args().len() > 1 {
        return App::new().joint::<EllipseCam>().main();
    }
    match run(Path::new("results")) {
        Ok(summary) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
#[path = "joint/tests.rs"]
mod tests;
