//! Reading a result file and making a chart that `flexmech plot` does not:
//! one dataset over another instead of over time.
//!
//! For every joint of the run, the released translation `|r_R|` (the slave's
//! offset from the master in the master's frame) is drawn over the released
//! angle ψ — for a screw the straight line `|r_R| = c ψ`, for a cam the
//! profile. The chart has one curve per joint and is written as
//! `<out>/released_translation.png` and `.svg`:
//!
//! ```text
//! cargo run --release -p flexmech --bin flexmech -- run data/paper/screw_driven.toml
//! cargo run --release -p flexmech --example read_result -- results/screw_driven.h5 charts
//! ```

use flexmech::plot::charts::{LineChart, Series};
use flexmech::results::{ReadError, ResultReader};
use std::path::{Path, PathBuf};

/// One curve per joint: `|r_R|` over ψ.
fn curves(result: &ResultReader) -> Result<Vec<Series>, ReadError> {
    let mut series = Vec::new();
    for joint in result.joint_names()? {
        let angle = result.values(&format!("/joints/{joint}/angle"))?;
        let offset: Vec<f64> = result
            .rows3(&format!("/joints/{joint}/released_translation"))?
            .iter()
            .map(|r| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt())
            .collect();
        series.push(Series::new(joint, angle, offset));
    }
    Ok(series)
}

/// Reads `file` and draws the chart into `out`; returns the PNG and SVG.
fn chart(file: &Path, out: &Path) -> Result<(PathBuf, PathBuf), Box<dyn std::error::Error>> {
    let result = ResultReader::open(file)?;
    let chart = LineChart {
        title: format!(
            "{}: released translation ({})",
            file.file_name().unwrap_or_default().to_string_lossy(),
            result.status()?
        ),
        x_label: "released angle ψ (rad)".into(),
        y_label: "|r_R| (m)".into(),
        log_y: false,
        series: curves(&result)?,
        markers: Vec::new(),
    };
    std::fs::create_dir_all(out)?;
    Ok(chart.render(&out.join("released_translation"))?)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [file, out] = args.as_slice() else {
        return Err("usage: read_result RESULT.h5 OUT_DIR".into());
    };
    let (png, svg) = chart(Path::new(file), Path::new(out))?;
    println!("{}\n{}", png.display(), svg.display());
    Ok(())
}

#[test]
fn a_screw_draws_the_line_of_its_pitch() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/paper/screw_driven.toml");
    let text = std::fs::read_to_string(&model)
        .unwrap()
        .replace("t_end = 3.0", "t_end = 1.0");
    let model = flexmech::model::parse_model(&text, &model).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = flexmech::results::run_model(&model, dir.path())
        .unwrap()
        .file;
    let (png, svg) = chart(&file, &dir.path().join("charts")).unwrap();
    assert!(std::fs::metadata(png).unwrap().len() > 10_000);
    assert!(std::fs::read_to_string(svg).unwrap().contains("<svg"));
    // The curve is the screw law |r_R| = c ψ (c = 0.02 m/rad): positions are
    // stored to double precision, so to round-off of the ≈ 0.1 m offsets.
    let series = curves(&ResultReader::open(&file).unwrap()).unwrap();
    assert_eq!(series.len(), 1);
    let r = ResultReader::open(&file).unwrap();
    let psi = r.values("/joints/screw/angle").unwrap();
    assert!(psi.last().unwrap() > &1.0, "the screw turned");
    for (k, row) in r
        .rows3("/joints/screw/released_translation")
        .unwrap()
        .iter()
        .enumerate()
    {
        assert!((row[2] - 0.02 * psi[k]).abs() <= 1e-15, "step {k}");
        assert_eq!((row[0], row[1]), (0.0, 0.0));
    }
}
