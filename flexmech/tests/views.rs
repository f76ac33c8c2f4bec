//! The ParaView series and the animations, checked by outside readers: the
//! VTK library itself reads every `.vtu` of a series back and compares it
//! with the HDF5 file (`scripts/check_vtk.py`), and the GIF decoder reads
//! the animation back, whose last frame must show the mechanism where the
//! result file says it is.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

use flexmech::model::parse_model;
use flexmech::plot::animation::{animate, frame_steps, AnimationOptions, Camera, View};
use flexmech::results::export::{export_vtk, ExportError, Frames};
use flexmech::results::run_model;

/// One test at a time: a child process (the Python check) inherits the
/// descriptors of HDF5 files another test thread has open, and with them
/// their locks, so a test re-opening its file meanwhile would be refused.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Exit status of `check_vtk.py` when `vtk` or `h5py` is missing.
const MISSING_MODULES: i32 = 3;

/// The free chain of data/dynamics (every joint kind, spun and thrown) with
/// its odd links in 3-node elements, resultants stored, the ParaView series
/// written by the run, a tenth of a second with the momentum scheme.
fn chain_model(dir: &Path) -> PathBuf {
    let text =
        std::fs::read_to_string(common::data("dynamics/free_chain.toml")).expect("free chain");
    let mut out = String::new();
    let mut beam = 0;
    for line in text.lines() {
        out.push_str(line);
        out.push('\n');
        if line.starts_with("elements = ") {
            if beam % 2 == 1 {
                out.push_str("nodes_per_element = 3\n");
            }
            beam += 1;
        }
    }
    let out = out
        .replace(
            "integrator = \"energy-momentum\"",
            "integrator = \"momentum\"",
        )
        .replace("t_end = 1.0", "t_end = 0.1")
        .replace("[output]\n", "[output]\nresultants = true\nvtk = true\n");
    let path = dir.join("chain.toml");
    std::fs::write(&path, out).expect("write the model");
    path
}

fn run(path: &Path, out: &Path) -> flexmech::results::RunSummary {
    let text = std::fs::read_to_string(path).expect("model text");
    let model = parse_model(&text, path).expect("valid model");
    run_model(&model, out).expect("the run completes")
}

/// Runs the VTK library's check; Ok(false) when its Python modules are not
/// installed and the environment does not require them.
fn vtk_check(h5: &Path, pvd: &Path, width: Option<f64>) -> bool {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/check_vtk.py");
    let mut cmd = Command::new("python3");
    cmd.arg(&script).arg(h5).arg(pvd);
    if let Some(w) = width {
        cmd.arg(format!("{w:e}"));
    }
    let required = std::env::var_os("FLEXMECH_REQUIRE_VTK").is_some();
    let Ok(out) = cmd.output() else {
        assert!(
            !required,
            "python3 is required (FLEXMECH_REQUIRE_VTK is set)"
        );
        eprintln!("skipped: python3 is not installed, the VTK read-back check did not run");
        return false;
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    if out.status.code() == Some(MISSING_MODULES) {
        assert!(
            !required,
            "the VTK check needs its Python modules: {stderr}"
        );
        eprintln!("skipped: {stderr}");
        return false;
    }
    assert!(
        out.status.success(),
        "the VTK library disagrees with the result file: {stderr}"
    );
    eprintln!("{}", String::from_utf8_lossy(&out.stdout));
    true
}

#[test]
fn the_runs_paraview_series_reads_back_in_vtk_equal_to_the_result_file() {
    let _serial = serial();
    let dir = tempfile::tempdir().expect("temp dir");
    let summary = run(&chain_model(dir.path()), dir.path());
    let pvd = summary
        .vtk
        .clone()
        .expect("[output] vtk = true writes the series");
    assert_eq!(pvd, dir.path().join("free-chain.pvd"));
    // One beams file and one joints file per stored step.
    let files = std::fs::read_dir(dir.path().join("free-chain"))
        .expect("series dir")
        .count();
    assert_eq!(files, 2 * summary.written);
    vtk_check(&summary.file, &pvd, None);
    // An explicit width, through `flexmech export`'s function.
    let pvd2 = export_vtk(&summary.file, &dir.path().join("again"), Some(0.03)).expect("export");
    vtk_check(&summary.file, &pvd2, Some(0.03));
}

#[test]
fn a_bad_width_is_refused_by_name() {
    let _serial = serial();
    let dir = tempfile::tempdir().expect("temp dir");
    let summary = run(&chain_model(dir.path()), dir.path());
    for w in [0.0, -1.0, f64::NAN] {
        let Err(e) = export_vtk(&summary.file, dir.path(), Some(w)) else {
            panic!("width {w} accepted")
        };
        assert!(
            matches!(
                e,
                ExportError::Option {
                    option: "--width",
                    ..
                }
            ),
            "{e}"
        );
    }
}

/// Whether an RGBA pixel is the white background.
fn is_background(p: &[u8]) -> bool {
    p[..3].iter().all(|&c| c > 245)
}

#[test]
fn the_animation_decodes_and_its_last_frame_shows_the_rod_where_the_file_says() {
    let _serial = serial();
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string(common::data("dynamics/ground_pendulum.toml"))
        .expect("model")
        .replace("t_end = 3.4", "t_end = 0.5");
    let path = dir.path().join("pendulum.toml");
    std::fs::write(&path, text).expect("write");
    let summary = run(&path, dir.path());
    let gif_path = dir.path().join("anim/pendulum.gif");
    let size = (320u32, 240u32);
    let opts = AnimationOptions {
        size,
        max_frames: 20,
        track: vec!["rod.end".into()],
        ..Default::default()
    };
    animate(&summary.file, &gif_path, &opts).expect("animate");
    let frames = Frames::read(&summary.file).expect("frames");
    let expected = frame_steps(frames.steps(), 20);
    assert_eq!(expected.len(), 20);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&gif_path).expect("gif"))
        .expect("a GIF");
    assert_eq!(
        (u32::from(decoder.width()), u32::from(decoder.height())),
        size
    );
    let mut last = Vec::new();
    let mut count = 0;
    while let Some(frame) = decoder.read_next_frame().expect("a frame") {
        assert_eq!(
            (u32::from(frame.width), u32::from(frame.height)),
            size,
            "full frames"
        );
        last = frame.buffer.to_vec();
        count += 1;
    }
    assert_eq!(count, expected.len());
    let camera = Camera::fit(&frames, View::Auto, size);
    let k = *expected.last().expect("frames");
    let pixel = |x: i64, y: i64| {
        let i = 4 * (y as usize * size.0 as usize + x as usize);
        &last[i..i + 4]
    };
    // The rod's middle node, drawn 4 px wide: a non-background pixel
    // within 2 px of its projection.
    let mid = frames.beams[0].1[frames.beams[0].1.len() / 2];
    let (px, py) = camera.project(&frames.positions[k][mid]);
    let near = (-2..=2).flat_map(|dx| (-2..=2).map(move |dy| (dx, dy)));
    let hit = near
        .clone()
        .any(|(dx, dy)| !is_background(pixel(px.round() as i64 + dx, py.round() as i64 + dy)));
    assert!(
        hit,
        "nothing drawn at the rod's middle node ({px:.1}, {py:.1})"
    );
    // Everything fits inside the margins: the corners are background.
    for (x, y) in [(1, 1), (i64::from(size.0) - 2, i64::from(size.1) - 2)] {
        assert!(is_background(pixel(x, y)), "corner ({x}, {y}) drawn on");
    }
    // A single frame as PNG at a chosen time.
    let png = dir.path().join("frame.png");
    let still = AnimationOptions {
        size,
        time: Some(0.25),
        ..Default::default()
    };
    animate(&summary.file, &png, &still).expect("png frame");
    let img = image::open(&png).expect("png").to_rgba8();
    assert_eq!(img.dimensions(), size);
}

#[test]
fn animation_options_are_refused_by_name() {
    let _serial = serial();
    let dir = tempfile::tempdir().expect("temp dir");
    let summary = run(&chain_model(dir.path()), dir.path());
    let bad_track = AnimationOptions {
        track: vec!["no.such".into()],
        ..Default::default()
    };
    let Err(e) = animate(&summary.file, &dir.path().join("a.gif"), &bad_track) else {
        panic!("unknown node accepted")
    };
    assert!(e.to_string().contains("no node \"no.such\""), "{e}");
    let Err(e) = animate(
        &summary.file,
        &dir.path().join("a.avi"),
        &AnimationOptions::default(),
    ) else {
        panic!("unknown format accepted")
    };
    assert!(e.to_string().contains(".gif, .mp4 or .png"), "{e}");
    // MP4 through ffmpeg where it is installed; refused by name where not.
    let small = AnimationOptions {
        size: (200, 150),
        max_frames: 5,
        ..Default::default()
    };
    let mp4 = dir.path().join("a.mp4");
    let ffmpeg = Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    match animate(&summary.file, &mp4, &small) {
        Ok(_) => assert!(ffmpeg && std::fs::metadata(&mp4).is_ok_and(|m| m.len() > 0)),
        Err(e) => assert!(
            !ffmpeg && e.to_string().contains("ffmpeg is not installed"),
            "{e}"
        ),
    }
    assert!(
        !dir.path().join("a.frames").exists(),
        "the scratch frames are removed"
    );
}

#[test]
fn frames_are_thinned_evenly_and_keep_both_ends() {
    assert_eq!(frame_steps(0, 10), Vec::<usize>::new());
    assert_eq!(frame_steps(5, 10), vec![0, 1, 2, 3, 4]);
    let s = frame_steps(1001, 11);
    assert_eq!(s, (0..=10).map(|i| 100 * i).collect::<Vec<_>>());
}
