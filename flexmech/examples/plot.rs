//! Job 3: a chart for the paper. The study file
//! `data/examples/ellipse_cam_study.toml` (the cam's `b` swept) runs, then
//! one result — the follower's position along t_r — is drawn across its runs,
//! each curve labelled by its value of b, as PNG, SVG and an editable
//! PGFPlots copy (`.tex` + `.csv`).
//!
//! `cargo run --release -p flexmech --example plot` writes `plots/follower.png`.

mod ellipse_cam;

use ellipse_cam::EllipseCam;
use flexmech::prelude::*;

/// Runs the study below `out` and draws `out/follower.{png,svg,tex,csv}`.
fn chart(out: &Path) -> Result<LineChart, Box<dyn std::error::Error>> {
    let app = App::new().joint::<EllipseCam>();
    let study = app.load_study(flexmech::data("examples/ellipse_cam_study.toml"))?;
    let report = study.run(out)?;
    let mut chart = report.overlay("/joints/cam/released_translation[x]")?;
    chart.title = "Elliptical cam: the follower over half a turn".into();
    (chart.x_label, chart.y_label) = ("time (s)".into(), "follower along t_r (m)".into());
    let (png, _svg) = chart.render(&out.join("follower"))?;
    println!("{}", png.display());
    Ok(chart)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    chart(Path::new("plots"))?;
    Ok(())
}

#[cfg(test)]
#[path = "plot/tests.rs"]
mod tests;
