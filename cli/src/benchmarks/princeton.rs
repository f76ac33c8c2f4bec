//! The Princeton beam (2016 problem 1): tip deflections under two forces
//! at load angles 0–90°, against the tabulated reference solution.

use super::reference::{numbers, PRINCETON};
use super::table::{sig, Row};
use super::{rows3, solve, Outcome, ReproduceError};
use flexmech_plot::charts::{auto_style, Dash, LineChart, Marker, Panels, Series};
use std::path::Path;

const MODEL: &str = include_str!("../../../data/benchmarks/princeton_beam.toml");
const PATH: &str = "data/benchmarks/princeton_beam.toml";
/// The load line of the model file, replaced for every case.
const LOAD_LINE: &str = "force = [0.0, -6.290421925435528, 6.290421925435528]";
const MESH: &str = "16 three-node elements";
const STEP: &str = "static, 10 load steps";

/// One case: the tip's (−y, z) at the end of the load path.
fn case(dir: &Path, force: f64, beta_deg: f64) -> Result<[f64; 2], ReproduceError> {
    let beta = beta_deg.to_radians();
    let load = format!(
        "force = [0.0, {:?}, {:?}]",
        -force * beta.cos(),
        force * beta.sin()
    );
    if !MODEL.contains(LOAD_LINE) {
        return Err(ReproduceError::Run {
            model: PATH.into(),
            integrator: "its own".into(),
            message: format!("its load line `{LOAD_LINE}` is not in the file any more"),
        });
    }
    let text = MODEL.replace(LOAD_LINE, &load);
    let stem = format!("princeton_{force}_{beta_deg}");
    let r = solve(&text, PATH, dir, &stem)?;
    let tip = rows3(&r, "/nodes/strip.end/displacement")?;
    let last = tip.last().copied().unwrap_or([f64::NAN; 3]);
    Ok([-last[1], last[2]])
}

/// Runs the 14 cases and sets them beside the reference.
pub fn run(dir: &Path, titles: bool) -> Result<Outcome, ReproduceError> {
    let reference = numbers(PRINCETON);
    let mut ours = Vec::new();
    let mut worst = (0.0f64, 0.0, 0.0);
    for r in &reference {
        let tip = case(dir, r[0], r[1])?;
        let scale = r[2].hypot(r[3]);
        let error = (tip[0] - r[2]).abs().max((tip[1] - r[3]).abs()) / scale;
        if error > worst.0 {
            worst = (error, r[0], r[1]);
        }
        ours.push(tip);
    }
    let mut rows = Vec::new();
    for (r, tip) in reference
        .iter()
        .zip(&ours)
        .filter(|(r, _)| r[0] > 13.0 && r[1] == 45.0)
    {
        for (name, o, p) in [("−y", tip[0], r[2]), ("z", tip[1], r[3])] {
            rows.push(row(
                format!("tip {name} (m), F = {} N, β = 45°", r[0]),
                sig(p),
                sig(o),
                super::table::difference_of(o, p, r[2].hypot(r[3]), "of |u|"),
            ));
        }
    }
    rows.push(row(
        "largest difference over the 14 cases, of |u|".into(),
        "table of 14".into(),
        format!("F = {} N, β = {}°", worst.1, worst.2),
        format!("{:.2} %", 100.0 * worst.0),
    ));
    Ok(Outcome {
        rows,
        chart: chart(&reference, &ours, titles),
    })
}

fn row(quantity: String, reference: String, ours: String, difference: String) -> Row {
    Row {
        benchmark: "Princeton beam, 2016 problem 1 (`princeton_beam.toml`)".into(),
        quantity,
        reference,
        source: "reference solution",
        ours,
        difference,
        mesh: MESH,
        step: STEP,
    }
}

/// One panel per force: −y and z against β, ours as lines, the reference
/// as marks.
fn chart(reference: &[Vec<f64>], ours: &[[f64; 2]], titles: bool) -> Panels {
    let mut panels = Vec::new();
    for force in [8.896, 13.345] {
        let pick = |f: &dyn Fn(usize) -> f64| -> Vec<f64> {
            (0..reference.len())
                .filter(|&k| reference[k][0] == force)
                .map(f)
                .collect()
        };
        let beta = pick(&|k| reference[k][1]);
        let mut chart = LineChart::new("", "load angle β (°)", "tip deflection (m)");
        if titles {
            chart.title = format!("Princeton beam, F = {force} N");
        }
        chart.series = vec![
            Series::new("−y, flexmech", beta.clone(), pick(&|k| ours[k][0])).marker(Marker::None),
            Series::new("z, flexmech", beta.clone(), pick(&|k| ours[k][1])).marker(Marker::None),
            reference_marks("−y, reference", beta.clone(), pick(&|k| reference[k][2]), 0),
            reference_marks("z, reference", beta, pick(&|k| reference[k][3]), 1),
        ];
        panels.push(chart);
    }
    Panels::row(panels)
}

/// Reference values as square marks in the colour of the `index`-th curve.
pub(super) fn reference_marks(label: &str, x: Vec<f64>, y: Vec<f64>, index: usize) -> Series {
    Series::new(label, x, y)
        .dash(Dash::Markers)
        .marker(Marker::Square)
        .color(auto_style(index).0)
}
