//! `flexmech export RESULT.h5 --vtk DIR`: a result file as a ParaView time
//! series.
//!
//! Format: a `.pvd` collection of `.vtu` files (VTK XML, one per stored
//! step and part). It opens in one click in every ParaView and VisIt release
//! of the last decade and in the VTK library's own readers, one file per step
//! can be streamed while a run goes on, and every reader honours the
//! quadratic cells; the VTKHDF alternative needs ParaView ≥ 5.11 for time
//! series and its temporal layout was still changing.
//!
//! What it holds, per step `k` (`DIR/<stem>/<stem>_<k>.vtu`, part 0):
//! beams as **ribbons** — each beam node `x` gives the points
//! `x ∓ ½w R e₂` (`R` the node's rotation, `e₂` its initial section
//! director), so the ribbon's twist is the section's — with one cell per
//! element: a quad (2-node elements) or a quadratic-linear quad through the
//! mid node (3-node elements, smooth along the beam). Point data, equal on
//! both points of a node: `node` (index into `/configuration`),
//! `displacement`, `rotation_vector`, `velocity` and `angular_velocity`
//! (dynamics). Cell data: `element`, `beam` (indices in `/mesh` order) and,
//! with `[output] resultants = true`, `resultant_force` and
//! `resultant_moment` (mean over the element's Gauss points). Part 1
//! (`<stem>_joints_<k>.vtu`): each joint as a point at its slave node, with
//! `joint` (model order), `angle` (NaN without a released angle),
//! `released_translation` and `constraint_error`. Times are `/time`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use thiserror::Error;

use super::frames::Frames;
use super::vtu::{self, Array, Entry, Grid};
use crate::reader::ReadError;

/// Default ribbon width as a fraction of the diagonal of the mechanism's
/// initial bounding box: wide enough to see the section turn, narrow
/// enough not to hide the beams' neighbours.
pub const RIBBON_WIDTH_FRACTION: f64 = 0.02;

/// Why an export failed.
#[derive(Debug, Error)]
pub enum ExportError {
    /// The result file could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Writing an output file failed.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// An option is out of range.
    #[error("{option}: {why}")]
    Option {
        /// The option, e.g. `--width`.
        option: &'static str,
        /// What is wrong and how to fix it.
        why: String,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ExportError + '_ {
    move |source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The ribbon's fixed structure: which nodes carry points, the cells.
struct Ribbon {
    /// Beam nodes in point order (node `nodes[s]` has points `2s`, `2s+1`).
    nodes: Vec<usize>,
    /// Initial tangent at each ribbon node (for files without directors).
    tangents: Vec<Vector3<f64>>,
    cells: Grid,
}

impl Ribbon {
    fn new(f: &Frames) -> Self {
        let mut slot: HashMap<usize, usize> = HashMap::new();
        let mut nodes = Vec::new();
        let mut tangents = Vec::new();
        let mut beam_of = HashMap::new();
        for (b, (_, beam)) in f.beams.iter().enumerate() {
            for (k, &n) in beam.iter().enumerate() {
                beam_of.insert(n, b);
                if slot.contains_key(&n) {
                    continue;
                }
                slot.insert(n, nodes.len());
                nodes.push(n);
                let (a, c) = (beam[k.saturating_sub(1)], beam[(k + 1).min(beam.len() - 1)]);
                tangents.push(f.initial[c] - f.initial[a]);
            }
        }
        let mut cells = Grid::default();
        let (mut element_ids, mut beam_ids) = (Vec::new(), Vec::new());
        for (e, en) in f.elements.iter().enumerate() {
            let Some(s) = en
                .iter()
                .map(|n| slot.get(n).copied())
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let p = |s: usize, side: usize| (2 * s + side) as i64;
            let (a, b) = (s[0], s[s.len() - 1]);
            if s.len() == 3 {
                let m = s[1];
                cells.add_cell(
                    vtu::VTK_QUADRATIC_LINEAR_QUAD,
                    &[p(a, 0), p(b, 0), p(b, 1), p(a, 1), p(m, 0), p(m, 1)],
                );
            } else {
                cells.add_cell(vtu::VTK_QUAD, &[p(a, 0), p(b, 0), p(b, 1), p(a, 1)]);
            }
            element_ids.push(e as i64);
            beam_ids.push(beam_of.get(&en[0]).map_or(-1, |&b| b as i64));
        }
        cells.cell_data = vec![
            Array::i64("element", element_ids),
            Array::i64("beam", beam_ids),
        ];
        Self {
            nodes,
            tangents,
            cells,
        }
    }

    /// The element indices of the cells, in cell order.
    fn elements(&self) -> Vec<usize> {
        match &self.cells.cell_data[0].values {
            vtu::Values::I64(v) => v.iter().map(|&e| e as usize).collect(),
            _ => Vec::new(),
        }
    }
}

/// The default ribbon width for `f` ([`RIBBON_WIDTH_FRACTION`] of the
/// initial bounding box's diagonal; 1 for a single point).
pub fn default_width(f: &Frames) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for x in &f.initial {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let d = (hi - lo).norm();
    if d.is_finite() && d > 0.0 {
        RIBBON_WIDTH_FRACTION * d
    } else {
        1.0
    }
}

fn flat(v: impl Iterator<Item = Vector3<f64>>) -> Vec<f64> {
    v.flat_map(|x| [x.x, x.y, x.z]).collect()
}

/// The beams' grid of step `k`.
fn beams_grid(f: &Frames, ribbon: &Ribbon, k: usize, width: f64) -> Grid {
    let mut g = ribbon.cells.clone();
    let twice = |v: Vec<Vector3<f64>>| flat(v.into_iter().flat_map(|x| [x, x]));
    let per_node = |field: &dyn Fn(usize) -> Vector3<f64>| {
        twice(ribbon.nodes.iter().map(|&n| field(n)).collect())
    };
    let mut points = Vec::with_capacity(6 * ribbon.nodes.len());
    for (s, &n) in ribbon.nodes.iter().enumerate() {
        let x = f.positions[k][n];
        let half = f.width_direction(k, n, &ribbon.tangents[s]) * (0.5 * width);
        points.extend_from_slice((x - half).as_slice());
        points.extend_from_slice((x + half).as_slice());
    }
    g.points = points;
    g.point_data = vec![
        Array::i64(
            "node",
            ribbon
                .nodes
                .iter()
                .flat_map(|&n| [n as i64, n as i64])
                .collect(),
        ),
        Array::f64(
            "displacement",
            3,
            per_node(&|n| f.positions[k][n] - f.initial[n]),
        ),
        Array::f64(
            "rotation_vector",
            3,
            per_node(&|n| f.rotations[k][n].scaled_axis()),
        ),
    ];
    for (name, field) in [
        ("velocity", &f.velocities),
        ("angular_velocity", &f.angular_velocities),
    ] {
        if let Some(v) = field {
            g.point_data
                .push(Array::f64(name, 3, per_node(&|n| v[k][n])));
        }
    }
    if let Some((force, moment)) = &f.resultants {
        // Gauss points in element order: nodes − 1 per element.
        let mut first = Vec::with_capacity(f.elements.len() + 1);
        first.push(0usize);
        for e in &f.elements {
            first.push(first[first.len() - 1] + e.len() - 1);
        }
        let mean = |rows: &[[f64; 3]], e: usize| -> Vector3<f64> {
            let pts = &rows[first[e]..first[e + 1]];
            pts.iter().map(|r| Vector3::from(*r)).sum::<Vector3<f64>>() / pts.len() as f64
        };
        let elements = ribbon.elements();
        for (name, rows) in [("resultant_force", force), ("resultant_moment", moment)] {
            g.cell_data.push(Array::f64(
                name,
                3,
                flat(elements.iter().map(|&e| mean(&rows[k], e))),
            ));
        }
    }
    g
}

/// The joints' grid of step `k` (None when no joint records its node).
fn joints_grid(f: &Frames, k: usize) -> Option<Grid> {
    let joints: Vec<_> = f
        .joints
        .iter()
        .filter_map(|j| Some((j, j.slave?)))
        .collect();
    if joints.is_empty() {
        return None;
    }
    let mut g = Grid::default();
    for (i, (_, n)) in joints.iter().enumerate() {
        g.points.extend_from_slice(f.positions[k][*n].as_slice());
        g.add_cell(vtu::VTK_VERTEX, &[i as i64]);
    }
    g.point_data = vec![
        Array::i64(
            "joint",
            joints.iter().map(|(j, _)| j.index as i64).collect(),
        ),
        Array::f64("angle", 1, joints.iter().map(|(j, _)| j.angle[k]).collect()),
        Array::f64(
            "released_translation",
            3,
            joints
                .iter()
                .flat_map(|(j, _)| j.released_translation[k])
                .collect(),
        ),
        Array::f64(
            "constraint_error",
            1,
            joints.iter().map(|(j, _)| j.constraint_error[k]).collect(),
        ),
    ];
    Some(g)
}

/// Writes the ParaView series of the result file `result` into `dir`:
/// `dir/<stem>.pvd` and the `.vtu` files under `dir/<stem>/` (module docs);
/// `width` is the ribbon width (None: [`default_width`]). Returns the
/// `.pvd` file.
pub fn export_vtk(result: &Path, dir: &Path, width: Option<f64>) -> Result<PathBuf, ExportError> {
    let frames = Frames::read(result)?;
    let stem = result
        .file_stem()
        .map_or_else(|| "result".to_owned(), |s| s.to_string_lossy().into_owned());
    write_series(&frames, &stem, dir, width)
}

/// [`export_vtk`] of mode `mode` (from 1) of a modal or buckling result:
/// one cycle about its stored state ([`super::mode_frames()`]), the phase
/// (0 to 1) as the series' time, written as `<dir>/<stem>_mode<k>.pvd`.
pub fn export_mode_vtk(
    result: &Path,
    dir: &Path,
    width: Option<f64>,
    mode: usize,
) -> Result<PathBuf, ExportError> {
    let frames = super::mode_frames(result, mode)?;
    let stem = result
        .file_stem()
        .map_or_else(|| "result".to_owned(), |s| s.to_string_lossy().into_owned());
    write_series(&frames, &format!("{stem}_mode{mode}"), dir, width)
}

/// Writes `frames` as the series `<dir>/<stem>.pvd` with its `.vtu` files
/// under `<dir>/<stem>/`.
fn write_series(
    frames: &Frames,
    stem: &str,
    dir: &Path,
    width: Option<f64>,
) -> Result<PathBuf, ExportError> {
    if let Some(w) = width {
        if !(w.is_finite() && w > 0.0) {
            return Err(ExportError::Option {
                option: "--width",
                why: format!("the ribbon width must be a positive length, not {w}"),
            });
        }
    }
    let sub = dir.join(stem);
    std::fs::create_dir_all(&sub).map_err(io(&sub))?;
    let width = width.unwrap_or_else(|| default_width(frames));
    let ribbon = Ribbon::new(frames);
    let mut entries = Vec::new();
    for k in 0..frames.steps() {
        let time = frames.time[k];
        let name = format!("{stem}_{k:06}.vtu");
        let path = sub.join(&name);
        beams_grid(frames, &ribbon, k, width)
            .write(&path)
            .map_err(io(&path))?;
        entries.push(Entry {
            time,
            part: 0,
            file: format!("{stem}/{name}"),
        });
        if let Some(g) = joints_grid(frames, k) {
            let name = format!("{stem}_joints_{k:06}.vtu");
            let path = sub.join(&name);
            g.write(&path).map_err(io(&path))?;
            entries.push(Entry {
                time,
                part: 1,
                file: format!("{stem}/{name}"),
            });
        }
    }
    let pvd = dir.join(format!("{stem}.pvd"));
    vtu::write_collection(&pvd, &entries).map_err(io(&pvd))?;
    Ok(pvd)
}
