//! The reproduction's figures, drawn from the result files into `DIR/charts/`:
//!
//! * the paper's figures of node paths, as the table
//!   `data/paper/charts/charts.toml` ([`super::chart_table`]) gives them:
//!   * `fig6_screw_free_post_top_y` — paper Figure 6: Y displacement of the
//!     top of the vertical beam, the three schemes, Newmark's failure time
//!     marked;
//!   * `fig8_screw_driven_tip_uz`, `fig9_screw_driven_tip_rotation_x` —
//!     paper Figures 8–9: the driven screw's tip displacement `u_z` and
//!     rotation about X;
//! * per model: `<model>_energy` (total energy minus the drivers' work),
//!   `<model>_energy_error` (its relative change, logarithmic),
//!   `<model>_beta` (the energy–momentum corrections: the discrete
//!   gradient's and the paper's β, logarithmic), `<model>_dt` (step sizes)
//!   and `<model>_joint` (released translation against the joint angle);
//! * `<model>_consistency` for the consistency study's model: both
//!   energy–momentum corrections at the model's step and at half of it — the
//!   discrete gradient's falls by 4, the paper's β does not fall.

use super::chart_table::PaperChart;
use super::{ReproduceError, RunRecord, CONSISTENCY_INTEGRATORS, CONSISTENCY_MODEL, INTEGRATORS};
use flexmech_plot::charts::{LineChart, Series};
use flexmech_results::{ReadError, ResultReader};
use std::path::{Path, PathBuf};

/// Legend names of the integrators.
fn legend(integrator: &str) -> &'static str {
    match integrator {
        "newmark" => "Newmark (trapezoidal)",
        "generalized-alpha" => "generalized-α",
        "momentum" => "momentum conserving",
        "energy-momentum-paper" => "energy–momentum (paper, β)",
        _ => "energy–momentum",
    }
}

fn read_error(e: ReadError) -> ReproduceError {
    ReproduceError::Read {
        file: e.path().to_path_buf(),
        message: e.to_string(),
    }
}

/// A dataset (flattened) of a result file.
fn read(file: &Path, name: &str) -> Result<Vec<f64>, ReproduceError> {
    ResultReader::open(file)
        .and_then(|r| r.values(name))
        .map_err(read_error)
}

/// Component `c` of a T×3 dataset.
fn column(file: &Path, name: &str, c: usize) -> Result<Vec<f64>, ReproduceError> {
    let rows = ResultReader::open(file)
        .and_then(|r| r.rows3(name))
        .map_err(read_error)?;
    Ok(rows.into_iter().map(|r| r[c]).collect())
}

/// The first joint's name in a result file.
fn first_joint(file: &Path) -> Result<String, ReproduceError> {
    let names = ResultReader::open(file)
        .and_then(|r| r.joint_names())
        .map_err(read_error)?;
    names.into_iter().next().ok_or(ReproduceError::Read {
        file: file.to_path_buf(),
        message: "no joint in /joints".into(),
    })
}

/// Markers for the runs that failed: "<scheme> fails (t = …)".
fn failure_markers(runs: &[&RunRecord]) -> Vec<(f64, String)> {
    runs.iter()
        .filter_map(|r| {
            r.failure_time
                .map(|t| (t, format!("{} fails (t = {t:.3} s)", legend(&r.integrator))))
        })
        .collect()
}

/// How the reproduction's charts are written.
#[derive(Debug, Clone, Copy)]
pub struct Style {
    /// Titles inside the charts.
    pub titles: bool,
    /// Also a PDF of each chart (pdflatex on its PGFPlots copy).
    pub pdf: bool,
}

impl Style {
    /// Writes `chart` at `stem` in this style; returns the PNG.
    fn render(self, mut chart: LineChart, stem: &Path) -> Result<PathBuf, ReproduceError> {
        if !self.titles {
            chart.title.clear();
        }
        Ok(if self.pdf {
            chart.render_with_pdf(stem)?.0
        } else {
            chart.render(stem)?.0
        })
    }
}

/// How far beyond the completed runs' range a failed run is still drawn,
/// in units of that range: once past it, the run is off the chart's scale
/// (its failure marker says when it failed).
const OFF_SCALE: f64 = 1.0;

/// The range `(lo, hi)` of `values` over the completed runs, when some run
/// failed and some completed.
fn completed_band(
    runs: &[&RunRecord],
    values: impl Fn(&RunRecord) -> Vec<f64>,
) -> Option<(f64, f64)> {
    if runs.iter().all(|r| r.failure_time.is_none()) {
        return None;
    }
    let all: Vec<f64> = runs
        .iter()
        .filter(|r| r.failure_time.is_none())
        .flat_map(|r| values(r))
        .filter(|v| v.is_finite())
        .collect();
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then_some((lo, hi))
}

/// A diverged run would set the scale and flatten the others: its curve
/// stops where it leaves the completed runs' band widened by [`OFF_SCALE`],
/// and its legend says so.
fn keep_on_scale(chart: &mut LineChart, runs: &[&RunRecord], (lo, hi): (f64, f64)) {
    let span = (hi - lo).max(1e-12 * hi.abs().max(lo.abs()).max(1.0));
    let (min, max) = (lo - OFF_SCALE * span, hi + OFF_SCALE * span);
    for (s, r) in chart.series.iter_mut().zip(runs) {
        if r.failure_time.is_none() {
            continue;
        }
        if let Some(k) =
            s.y.iter()
                .position(|&y| y.is_finite() && !(min..=max).contains(&y))
        {
            let t = s.x[k];
            s.y[k..].iter_mut().for_each(|y| *y = f64::NAN);
            s.label = format!("{} (off scale from t = {t:.2} s)", s.label);
        }
    }
}

/// A time-series chart of one quantity for the three schemes of a model.
fn scheme_chart(
    runs: &[&RunRecord],
    title: &str,
    y_label: &str,
    values: impl Fn(&RunRecord) -> Result<Vec<f64>, ReproduceError>,
) -> Result<LineChart, ReproduceError> {
    let mut chart = LineChart::new(title, "time (s)", y_label);
    for r in runs {
        chart.series.push(Series::new(
            legend(&r.integrator),
            r.time.clone(),
            values(r)?,
        ));
    }
    chart.markers = failure_markers(runs);
    Ok(chart)
}

/// Draws every chart of the reproduction: per model, its figures of
/// `paper` (the table of `data/paper/charts/charts.toml`, in table order),
/// then its energy, energy error, step size, β and joint charts. Returns the
/// PNG paths.
pub fn draw_all(
    records: &[RunRecord],
    paper: &[PaperChart],
    out: &Path,
    style: Style,
) -> Result<Vec<PathBuf>, ReproduceError> {
    let dir = out.join("charts");
    let mut written = Vec::new();
    let mut models: Vec<&str> = records.iter().map(|r| r.model.as_str()).collect();
    models.dedup();
    for model in models {
        let runs = model_runs(records, model);
        let mut draw = |name: String, chart: LineChart| -> Result<(), ReproduceError> {
            let png = style.render(chart, &dir.join(name))?;
            written.push(png);
            Ok(())
        };
        for figure in paper.iter().filter(|c| c.model == model) {
            draw(figure.name.clone(), paper_chart(figure, &runs)?)?;
        }
        draw(format!("{model}_energy"), energy_chart(model, &runs)?)?;
        draw(
            format!("{model}_energy_error"),
            energy_error_chart(model, &runs)?,
        )?;
        draw(format!("{model}_dt"), dt_chart(model, &runs)?)?;
        if let Some(chart) = beta_chart(model, &runs) {
            draw(format!("{model}_beta"), chart)?;
        }
        if let Some(first) = runs.first() {
            draw(format!("{model}_joint"), joint_chart(model, &runs, first)?)?;
        }
    }
    Ok(written)
}

/// The runs of `model`, in the order of [`INTEGRATORS`].
fn model_runs<'a>(records: &'a [RunRecord], model: &str) -> Vec<&'a RunRecord> {
    INTEGRATORS
        .iter()
        .filter_map(|i| {
            records
                .iter()
                .find(|r| r.model == model && r.integrator == *i)
        })
        .collect()
}

/// A figure of the paper's table: its dataset column over time for each
/// scheme, cut where a run blew up and with its markers.
fn paper_chart(figure: &PaperChart, runs: &[&RunRecord]) -> Result<LineChart, ReproduceError> {
    let mut chart = scheme_chart(runs, &figure.title, &figure.y_label, |r| {
        let values = column(&r.file, &figure.dataset, figure.component)?;
        Ok(match figure.cut_at_energy_error {
            Some(limit) => cut_where_blown(&values, r, limit),
            None => values,
        })
    })?;
    if let Some(markers) = &figure.markers {
        for (s, r) in chart.series.iter_mut().zip(runs) {
            if r.integrator == markers.integrator {
                s.mark_every = (s.x.len() / markers.count).max(1);
            }
        }
    }
    Ok(chart)
}

/// `values` of run `r` up to the first step whose energy balance is off its
/// initial value by more than `limit` times the run's energy scale, NaN from
/// there on: a run that blew up is drawn until then (its last steps would
/// set the scale); the failure marker shows where it failed.
fn cut_where_blown(values: &[f64], r: &RunRecord, limit: f64) -> Vec<f64> {
    let b0 = r.balance.first().copied().unwrap_or(0.0);
    let mut blown = false;
    values
        .iter()
        .zip(&r.balance)
        .map(|(&y, b)| {
            blown |= (b - b0).abs() > limit * r.energy_scale;
            if blown {
                f64::NAN
            } else {
                y
            }
        })
        .collect()
}

/// `<model>_energy`: the energy balance of each scheme, a diverged run kept
/// off the scale ([`keep_on_scale`]).
fn energy_chart(model: &str, runs: &[&RunRecord]) -> Result<LineChart, ReproduceError> {
    let energy_label = if model == "screw_free" {
        "total energy (J)"
    } else {
        "total energy − work of the drive (J)"
    };
    let band = completed_band(runs, |r| r.balance.clone());
    let mut chart = scheme_chart(
        runs,
        &format!("{model}: energy balance"),
        energy_label,
        |r| Ok(r.balance.clone()),
    )?;
    if let Some(band) = band {
        keep_on_scale(&mut chart, runs, band);
    }
    Ok(chart)
}

/// `<model>_energy_error`: each scheme's relative energy error, logarithmic.
fn energy_error_chart(model: &str, runs: &[&RunRecord]) -> Result<LineChart, ReproduceError> {
    let mut chart = scheme_chart(
        runs,
        &format!("{model}: relative energy error"),
        "relative energy error",
        |r| {
            let b0 = r.balance.first().copied().unwrap_or(0.0);
            Ok(r.balance
                .iter()
                .map(|b| (b - b0).abs() / r.energy_scale)
                .collect())
        },
    )?;
    chart.log_y = true;
    Ok(chart)
}

/// `<model>_dt`: the step size each scheme used.
fn dt_chart(model: &str, runs: &[&RunRecord]) -> Result<LineChart, ReproduceError> {
    scheme_chart(
        runs,
        &format!("{model}: step size actually used"),
        "Δt (s)",
        |r| {
            Ok(r.dt
                .iter()
                .map(|&d| if d > 0.0 { d } else { f64::NAN })
                .collect())
        },
    )
}

/// `<model>_beta`: `|β|` of the energy–momentum schemes, logarithmic; none
/// when no β is finite.
fn beta_chart(model: &str, runs: &[&RunRecord]) -> Option<LineChart> {
    let em: Vec<&RunRecord> = runs
        .iter()
        .copied()
        .filter(|r| CONSISTENCY_INTEGRATORS.contains(&r.integrator.as_str()))
        .collect();
    if !em.iter().any(|r| r.beta.iter().any(|b| b.is_finite())) {
        return None;
    }
    let mut chart = LineChart::new(
        format!("{model}: energy–momentum corrections"),
        "time (s)",
        "|β|",
    );
    for r in em {
        chart.series.push(Series::new(
            legend(&r.integrator),
            r.time.clone(),
            abs_beta(r),
        ));
    }
    chart.log_y = true;
    Some(chart)
}

/// `<model>_joint`: the released translation's component that moves most
/// against the angle of the first joint of `first`'s result file.
fn joint_chart(
    model: &str,
    runs: &[&RunRecord],
    first: &RunRecord,
) -> Result<LineChart, ReproduceError> {
    let joint = first_joint(&first.file)?;
    let mut chart = LineChart::new(
        format!("{model}: joint `{joint}`"),
        "joint angle ψ (rad)",
        "released translation (m)",
    );
    for r in runs {
        let angle = read(&r.file, &format!("/joints/{joint}/angle"))?;
        let rr = read(&r.file, &format!("/joints/{joint}/released_translation"))?;
        // The component that moves most.
        let c = (0..3)
            .max_by(|&a, &b| {
                let range = |c: usize| {
                    let v = rr.chunks(3).map(|x| x[c]);
                    v.clone().fold(f64::MIN, f64::max) - v.fold(f64::MAX, f64::min)
                };
                range(a).total_cmp(&range(b))
            })
            .unwrap_or(0);
        let axis = ["x", "y", "z"][c];
        chart.y_label = format!("released translation, {axis} (m)");
        chart.series.push(Series::new(
            legend(&r.integrator),
            angle,
            rr.chunks(3).map(|x| x[c]).collect(),
        ));
    }
    Ok(chart)
}

/// `|β|` of a run, with zeros (nothing to correct) left out of a log axis.
fn abs_beta(r: &RunRecord) -> Vec<f64> {
    r.beta
        .iter()
        .map(|b| if *b != 0.0 { b.abs() } else { f64::NAN })
        .collect()
}

/// The consistency chart: the energy–momentum corrections of
/// [`CONSISTENCY_MODEL`] at its step and at half of it. Returns the PNG
/// written (none when the half-step runs are absent).
pub fn draw_consistency(
    runs: &[RunRecord],
    half_step: &[RunRecord],
    out: &Path,
    style: Style,
) -> Result<Vec<PathBuf>, ReproduceError> {
    if half_step.is_empty() {
        return Ok(Vec::new());
    }
    let mut chart = LineChart::new(
        format!("{CONSISTENCY_MODEL}: energy–momentum corrections at Δt and Δt/2"),
        "time (s)",
        "|β|",
    );
    for integrator in CONSISTENCY_INTEGRATORS {
        for (set, step) in [(runs, "Δt"), (half_step, "Δt/2")] {
            if let Some(r) = set
                .iter()
                .find(|r| r.model == CONSISTENCY_MODEL && r.integrator == integrator)
            {
                chart.series.push(Series::new(
                    format!("{}, {step}", legend(integrator)),
                    r.time.clone(),
                    abs_beta(r),
                ));
            }
        }
    }
    chart.log_y = true;
    let png = style.render(
        chart,
        &out.join("charts")
            .join(format!("{CONSISTENCY_MODEL}_consistency")),
    )?;
    Ok(vec![png])
}
