//! `flexmech animate RESULT.h5 --out FILE`: the mechanism moving, as an
//! animated GIF (or an MP4 through `ffmpeg`, or one PNG frame).
//!
//! The view is an orthographic projection with equal scales on both screen
//! axes, so lengths and angles in the viewing plane are true. The automatic
//! camera looks along the normal of the plane that best fits every node
//! over the whole motion (the covariance's least principal direction), with
//! the global z axis (or y, when z is nearly the viewing direction) up; a
//! coordinate plane or azimuth/elevation angles can be chosen instead.
//! Beams are drawn as polylines through their nodes, joints as dots at their
//! slave nodes, tracked nodes with the trail of their past positions, and
//! the time stamp in a corner.

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use plotters::prelude::*;

use crate::charts::font;
use flexmech_results::export::ExportError;
use flexmech_results::export::Frames;

/// Background, beams (Okabe–Ito colours, as the charts), joints, trails.
const BACKGROUND: RGBColor = WHITE;
const BEAM_COLORS: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];
const JOINT_COLOR: RGBColor = RGBColor(30, 30, 30);
const TRAIL_COLOR: RGBColor = RGBColor(150, 150, 150);
/// Beam stroke width and joint dot radius, pixels.
const BEAM_STROKE: u32 = 4;
const JOINT_RADIUS: i32 = 5;
/// Margin around the drawing and height of the time stamp band, pixels.
const MARGIN: f64 = 30.0;
const STAMP_BAND: f64 = 36.0;

/// Where the camera looks from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    /// Normal to the best-fit plane of the motion (module docs).
    Auto,
    /// Azimuth about z from the x axis and elevation above the xy plane,
    /// degrees (`0, 90`: from +z; `−90, 0`: from −y, the xz plane).
    Angles {
        /// Degrees about z, from x.
        azimuth: f64,
        /// Degrees above the xy plane.
        elevation: f64,
    },
}

impl View {
    /// `xy`, `xz`, `yz`, `iso` or `auto`.
    pub fn parse(name: &str) -> Option<Self> {
        let a = |azimuth, elevation| Some(View::Angles { azimuth, elevation });
        match name {
            "auto" => Some(View::Auto),
            "xy" => a(-90.0, 90.0),
            "xz" => a(-90.0, 0.0),
            "yz" => a(0.0, 0.0),
            "iso" => Some(ISO),
            _ => None,
        }
    }
}

/// What to draw and how.
#[derive(Debug, Clone)]
pub struct AnimationOptions {
    /// The camera.
    pub view: View,
    /// Image size, pixels.
    pub size: (u32, u32),
    /// Frames per second of the GIF/MP4.
    pub fps: f64,
    /// At most this many frames: the stored steps are thinned evenly (the
    /// last is always drawn).
    pub max_frames: usize,
    /// Labels of nodes drawn with their trails.
    pub track: Vec<String>,
    /// For a PNG: the time of the frame (the nearest stored step; None: the last).
    pub time: Option<f64>,
    /// Draw mode `k` (from 1) of a modal or buckling result, one cycle
    /// about its stored state, instead of the stored steps.
    pub mode: Option<usize>,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        Self {
            view: View::Auto,
            size: (800, 600),
            fps: 25.0,
            max_frames: 250,
            track: Vec::new(),
            time: None,
            mode: None,
        }
    }
}

/// The orthographic camera: screen axes `u` (right), `v` (up) and the map
/// from world to pixels with equal scales.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    /// Screen right, unit.
    pub u: Vector3<f64>,
    /// Screen up, unit.
    pub v: Vector3<f64>,
    scale: f64,
    origin: (f64, f64),
}

impl Camera {
    /// Pixel coordinates (x right, y down) of the world point `p`.
    pub fn project(&self, p: &Vector3<f64>) -> (f64, f64) {
        (
            self.origin.0 + self.scale * p.dot(&self.u),
            self.origin.1 - self.scale * p.dot(&self.v),
        )
    }

    /// Pixels per unit length.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The camera for `frames` in an image of `size` (every node of every
    /// step fits, equal scales).
    pub fn fit(frames: &Frames, view: View, size: (u32, u32)) -> Self {
        let points = || frames.positions.iter().flatten();
        let (u, v) = screen_axes(frames, view);
        let (mut lo, mut hi) = (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for p in points() {
            let (a, b) = (p.dot(&u), p.dot(&v));
            if a.is_finite() && b.is_finite() {
                lo = (lo.0.min(a), lo.1.min(b));
                hi = (hi.0.max(a), hi.1.max(b));
            }
        }
        if !lo.0.is_finite() {
            lo = (-1.0, -1.0);
            hi = (1.0, 1.0);
        }
        let (w, h) = (
            f64::from(size.0) - 2.0 * MARGIN,
            f64::from(size.1) - 2.0 * MARGIN - STAMP_BAND,
        );
        let span = (hi.0 - lo.0, hi.1 - lo.1);
        let tiny = 1e-12 * span.0.abs().max(span.1.abs()).max(1.0);
        let scale = (w / span.0.max(tiny)).min(h / span.1.max(tiny));
        let centre = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
        Self {
            u,
            v,
            scale,
            origin: (
                f64::from(size.0) / 2.0 - scale * centre.0,
                STAMP_BAND + MARGIN + h / 2.0 + scale * centre.1,
            ),
        }
    }
}

/// Screen axes `(u, v)` for a view: `u × v` points at the viewer.
fn screen_axes(frames: &Frames, view: View) -> (Vector3<f64>, Vector3<f64>) {
    let towards_viewer = match view {
        View::Angles { azimuth, elevation } => {
            let (a, e) = (azimuth.to_radians(), elevation.to_radians());
            Vector3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
        }
        View::Auto => best_fit_normal(frames).unwrap_or_else(|| {
            let View::Angles { azimuth, elevation } = ISO else {
                unreachable!("ISO is a pair of angles")
            };
            let (a, e) = (azimuth.to_radians(), elevation.to_radians());
            Vector3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
        }),
    };
    let n = towards_viewer.try_normalize(0.0).unwrap_or_else(Vector3::z);
    let up_of = |g: Vector3<f64>| (g - n * n.dot(&g)).try_normalize(1e-6);
    let v = up_of(Vector3::z())
        .filter(|_| n.z.abs() < 0.9)
        .or_else(|| up_of(Vector3::y()))
        .unwrap_or_else(Vector3::x);
    (v.cross(&n), v)
}

/// The isometric view (from the octant of +x, −y, +z).
const ISO: View = View::Angles {
    azimuth: -45.0,
    elevation: 35.264_389_682_754_654,
};

/// A motion is planar when its least principal variance is below this
/// fraction of its largest: it is then viewed along that plane's normal;
/// otherwise from [`ISO`].
const PLANAR_VARIANCE: f64 = 1e-2;

/// The least principal direction of the nodes' positions over the motion,
/// turned to look from the positive side of its largest component; None when
/// the motion is not planar ([`PLANAR_VARIANCE`]).
fn best_fit_normal(frames: &Frames) -> Option<Vector3<f64>> {
    let pts: Vec<&Vector3<f64>> = frames
        .positions
        .iter()
        .flatten()
        .filter(|p| p.iter().all(|c| c.is_finite()))
        .collect();
    if pts.len() < 3 {
        return Some(Vector3::z());
    }
    let mean = pts.iter().copied().sum::<Vector3<f64>>() / pts.len() as f64;
    let mut cov = Matrix3::zeros();
    for p in &pts {
        let d = *p - mean;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let k = eig.eigenvalues.imin();
    if eig.eigenvalues[k] > PLANAR_VARIANCE * eig.eigenvalues.max() {
        return None;
    }
    let n = eig.eigenvectors.column(k).into_owned();
    let big = n.iamax();
    Some(if n[big] < 0.0 { -n } else { n })
}

/// The stored steps drawn as frames (evenly thinned to `max`, last kept).
pub fn frame_steps(steps: usize, max: usize) -> Vec<usize> {
    if steps == 0 {
        return Vec::new();
    }
    let max = max.max(1);
    if steps <= max {
        return (0..steps).collect();
    }
    let mut s: Vec<usize> = (0..max)
        .map(|i| i * (steps - 1) / (max - 1).max(1))
        .collect();
    s.dedup();
    s
}

/// Draws step `k` onto `area`.
fn draw_frame<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    frames: &Frames,
    camera: &Camera,
    k: usize,
    tracked: &[usize],
    unit: &str,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    area.fill(&BACKGROUND).map_err(e)?;
    let px = |p: &Vector3<f64>| {
        let (x, y) = camera.project(p);
        (x.round() as i32, y.round() as i32)
    };
    for &n in tracked {
        let trail: Vec<(i32, i32)> = (0..=k).map(|s| px(&frames.positions[s][n])).collect();
        area.draw(&PathElement::new(trail, TRAIL_COLOR.stroke_width(2)))
            .map_err(e)?;
    }
    for (b, (_, nodes)) in frames.beams.iter().enumerate() {
        let line: Vec<(i32, i32)> = nodes.iter().map(|&n| px(&frames.positions[k][n])).collect();
        let style = BEAM_COLORS[b % BEAM_COLORS.len()].stroke_width(BEAM_STROKE);
        area.draw(&PathElement::new(line, style)).map_err(e)?;
    }
    for j in &frames.joints {
        if let Some(n) = j.slave {
            area.draw(&Circle::new(
                px(&frames.positions[k][n]),
                JOINT_RADIUS,
                JOINT_COLOR.filled(),
            ))
            .map_err(e)?;
        }
    }
    for &n in tracked {
        area.draw(&Circle::new(
            px(&frames.positions[k][n]),
            3,
            TRAIL_COLOR.filled(),
        ))
        .map_err(e)?;
    }
    let stamp = format!("{unit} = {:.3}", frames.time[k]);
    area.draw(&Text::new(
        stamp,
        (MARGIN as i32, (MARGIN * 0.5) as i32),
        font::text(22.0),
    ))
    .map_err(e)?;
    Ok(())
}

/// The nodes of `labels` (refused by name if one is unknown).
fn tracked_nodes(frames: &Frames, labels: &[String]) -> Result<Vec<usize>, ExportError> {
    labels
        .iter()
        .map(|l| {
            frames.labels.iter().position(|x| x == l).ok_or_else(|| ExportError::Option {
                option: "--track",
                why: format!(
                    "no node \"{l}\" in this result; node labels are <beam>.start, <beam>.<k>, <beam>.end (see /mesh/node_labels)"
                ),
            })
        })
        .collect()
}

/// Draws the result file `result` into `out`: a `.gif` animation, an
/// `.mp4` (frames encoded by `ffmpeg`, refused when it is not installed) or
/// a `.png` of one frame. Returns the file written.
pub fn animate(result: &Path, out: &Path, opts: &AnimationOptions) -> Result<PathBuf, ExportError> {
    if !(opts.fps.is_finite() && opts.fps > 0.0) || opts.size.0 < 100 || opts.size.1 < 100 {
        return Err(ExportError::Option {
            option: "--fps/--size",
            why: "give a positive frame rate and an image of at least 100 x 100 pixels".into(),
        });
    }
    let ext = out
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if !["gif", "png", "mp4"].contains(&ext.as_str()) {
        return Err(ExportError::Option {
            option: "--out",
            why: format!("{}: write a .gif, .mp4 or .png file", out.display()),
        });
    }
    let frames = match opts.mode {
        Some(k) => flexmech_results::export::mode_frames(result, k)?,
        None => Frames::read(result)?,
    };
    if frames.steps() == 0 {
        return Err(ExportError::Option {
            option: "RESULT",
            why: format!("{} holds no stored step to draw", result.display()),
        });
    }
    if !font::ensure_registered() {
        return Err(ExportError::Option {
            option: "font",
            why: "the embedded font could not be registered (a packaging bug)".into(),
        });
    }
    let tracked = tracked_nodes(&frames, &opts.track)?;
    let camera = Camera::fit(&frames, opts.view, opts.size);
    let unit = if frames.velocities.is_some() {
        "t"
    } else {
        "λ"
    };
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| ExportError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    let failed = |why: String| ExportError::Io {
        path: out.to_path_buf(),
        source: std::io::Error::other(why),
    };
    match ext.as_str() {
        "png" => {
            let k = match opts.time {
                Some(t) => nearest(&frames.time, t),
                None => frames.steps() - 1,
            };
            let area = BitMapBackend::new(out, opts.size).into_drawing_area();
            draw_frame(&area, &frames, &camera, k, &tracked, unit).map_err(failed)?;
            area.present().map_err(|e| failed(e.to_string()))?;
        }
        "gif" => {
            let delay = (1000.0 / opts.fps).round().max(10.0) as u32;
            let area = BitMapBackend::gif(out, opts.size, delay)
                .map_err(|e| failed(e.to_string()))?
                .into_drawing_area();
            for k in frame_steps(frames.steps(), opts.max_frames) {
                draw_frame(&area, &frames, &camera, k, &tracked, unit).map_err(failed)?;
                area.present().map_err(|e| failed(e.to_string()))?;
            }
        }
        _ => mp4(&frames, &camera, &tracked, unit, out, opts).map_err(failed)?,
    }
    Ok(out.to_path_buf())
}

/// Index of the stored time nearest `t`.
fn nearest(time: &[f64], t: f64) -> usize {
    let mut best = 0;
    for (k, s) in time.iter().enumerate() {
        if (s - t).abs() < (time[best] - t).abs() {
            best = k;
        }
    }
    best
}

/// Frames as PNGs in a scratch directory, encoded by `ffmpeg` (H.264,
/// yuv420p so every player shows it).
fn mp4(
    frames: &Frames,
    camera: &Camera,
    tracked: &[usize],
    unit: &str,
    out: &Path,
    opts: &AnimationOptions,
) -> Result<(), String> {
    let ffmpeg_ok = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ffmpeg_ok {
        return Err(
            "ffmpeg is not installed: install it (apt-get install ffmpeg) or write a .gif".into(),
        );
    }
    let dir = out.with_extension("frames");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let result = (|| {
        for (i, k) in frame_steps(frames.steps(), opts.max_frames)
            .into_iter()
            .enumerate()
        {
            let path = dir.join(format!("frame_{i:06}.png"));
            let area = BitMapBackend::new(&path, opts.size).into_drawing_area();
            draw_frame(&area, frames, camera, k, tracked, unit)?;
            area.present().map_err(|e| e.to_string())?;
        }
        // Even dimensions for yuv420p.
        let status = std::process::Command::new("ffmpeg")
            .args(["-y", "-loglevel", "error", "-framerate"])
            .arg(format!("{}", opts.fps))
            .arg("-i")
            .arg(dir.join("frame_%06d.png"))
            .args([
                "-vf",
                "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                "-c:v",
                "libx264",
                "-pix_fmt",
                "yuv420p",
            ])
            .arg(out)
            .status()
            .map_err(|e| e.to_string())?;
        if status.success() {
            Ok(())
        } else {
            Err(format!("ffmpeg failed ({status})"))
        }
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}
