//! A result file's motion, read once for drawing: every stored step's node
//! positions and triads, the mesh, the joints and (when stored) velocities
//! and stress resultants. Shared by the ParaView export and the animations.

use std::path::Path;

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

use crate::layout as names;
use crate::reader::{ReadError, ResultReader};

/// Rows of three per step: `[step][row]`.
pub type PerStep = Vec<Vec<[f64; 3]>>;

/// One joint's records: where it is and its coordinates.
#[derive(Debug, Clone)]
pub struct JointFrames {
    /// The joint's name (`/joints/<name>`).
    pub name: String,
    /// Its index in model order.
    pub index: usize,
    /// Its slave node (where it is drawn), when the file records it.
    pub slave: Option<usize>,
    /// Released angle per step (NaN for joints without one).
    pub angle: Vec<f64>,
    /// Released translation `r_R` per step.
    pub released_translation: Vec<[f64; 3]>,
    /// Constraint error per step.
    pub constraint_error: Vec<f64>,
}

/// Every stored step of a result file, ready to draw.
#[derive(Debug, Clone)]
pub struct Frames {
    /// `/time`.
    pub time: Vec<f64>,
    /// Node labels in `/configuration` order.
    pub labels: Vec<String>,
    /// Initial position of every node.
    pub initial: Vec<Vector3<f64>>,
    /// `positions[step][node]`.
    pub positions: Vec<Vec<Vector3<f64>>>,
    /// `rotations[step][node]`: the rotation `R` from the initial triad.
    pub rotations: Vec<Vec<UnitQuaternion<f64>>>,
    /// `velocities[step][node]` (dynamics only).
    pub velocities: Option<Vec<Vec<Vector3<f64>>>>,
    /// `angular_velocities[step][node]` (dynamics only).
    pub angular_velocities: Option<Vec<Vec<Vector3<f64>>>>,
    /// Each node's initial directors `[e₁, e₂, e₃]` (None: not recorded).
    pub directors: Option<Vec<Matrix3<f64>>>,
    /// Every element's nodes.
    pub elements: Vec<Vec<usize>>,
    /// Every beam's name and nodes in order.
    pub beams: Vec<(String, Vec<usize>)>,
    /// The joints, in model order.
    pub joints: Vec<JointFrames>,
    /// Stress resultants `(N, M)` per step, `[step][gauss point]`.
    pub resultants: Option<(PerStep, PerStep)>,
}

/// A `T × n × 3` dataset as `[step][n]` vectors.
fn vectors(r: &ResultReader, name: &str) -> Result<Vec<Vec<Vector3<f64>>>, ReadError> {
    let shape = r.shape(name)?;
    let values = r.values(name)?;
    let per = shape.get(1).copied().unwrap_or(0) * 3;
    Ok(values
        .chunks_exact(per.max(1))
        .map(|row| {
            row.chunks_exact(3)
                .map(Vector3::from_column_slice)
                .collect()
        })
        .collect())
}

fn optional<T>(
    r: &ResultReader,
    name: &str,
    read: impl Fn() -> Result<T, ReadError>,
) -> Result<Option<T>, ReadError> {
    if r.has(name) {
        read().map(Some)
    } else {
        Ok(None)
    }
}

impl Frames {
    /// Reads the motion of `path` (a file written by `flexmech run`; one
    /// without `/mesh`, from before it was written, is refused by name).
    pub fn read(path: &Path) -> Result<Self, ReadError> {
        let r = ResultReader::open(path)?;
        let time = r.time()?;
        let labels = r.mesh_node_labels()?;
        let positions = vectors(&r, names::CONFIGURATION_POSITION)?;
        let q = r.values(names::CONFIGURATION_QUATERNION)?;
        let rotations: Vec<Vec<UnitQuaternion<f64>>> = q
            .chunks_exact((labels.len() * 4).max(1))
            .map(|row| {
                row.chunks_exact(4)
                    .map(|c| {
                        UnitQuaternion::from_quaternion(Quaternion::new(c[0], c[1], c[2], c[3]))
                    })
                    .collect()
            })
            .collect();
        let initial = match optional(&r, names::MESH_INITIAL_POSITION, || {
            r.values(names::MESH_INITIAL_POSITION)
        })? {
            Some(v) => v.chunks_exact(3).map(Vector3::from_column_slice).collect(),
            None => positions.first().cloned().unwrap_or_default(),
        };
        let directors = optional(&r, names::MESH_NODE_DIRECTORS, || {
            r.values(names::MESH_NODE_DIRECTORS)
        })?
        .map(|v| v.chunks_exact(9).map(Matrix3::from_column_slice).collect());
        let lists = |nodes: &str, offsets: &str| -> Result<Vec<Vec<usize>>, ReadError> {
            let n = r.counts(nodes)?;
            let o = r.counts(offsets)?;
            Ok(o.windows(2)
                .map(|w| {
                    n[w[0] as usize..w[1] as usize]
                        .iter()
                        .map(|&i| i as usize)
                        .collect()
                })
                .collect())
        };
        let elements = lists(names::MESH_ELEMENT_NODES, names::MESH_ELEMENT_OFFSETS)?;
        let beam_nodes = lists(names::MESH_BEAM_NODES, names::MESH_BEAM_OFFSETS)?;
        let beam_names = r.strings(names::MESH_BEAM_NAMES)?;
        let beams = beam_names.into_iter().zip(beam_nodes).collect();
        let mut joints = Vec::new();
        for name in r.joint_names()? {
            let group = names::joint_group(&name);
            let steps = time.len();
            let angle_path = names::joint_path(&name, names::JOINT_ANGLE);
            joints.push(JointFrames {
                index: r
                    .group_u64_attr(&group, names::ATTR_JOINT_INDEX)
                    .unwrap_or(0) as usize,
                slave: r
                    .group_u64_attr(&group, names::ATTR_JOINT_SLAVE_NODE)
                    .map(|n| n as usize),
                angle: match optional(&r, &angle_path, || r.values(&angle_path))? {
                    Some(a) => a,
                    None => vec![f64::NAN; steps],
                },
                released_translation: r
                    .rows3(&names::joint_path(&name, names::JOINT_RELEASED_TRANSLATION))?,
                constraint_error: r
                    .values(&names::joint_path(&name, names::JOINT_CONSTRAINT_ERROR))?,
                name,
            });
        }
        joints.sort_by_key(|j| j.index);
        let rows = |name: &str| -> Result<PerStep, ReadError> {
            Ok(vectors(&r, name)?
                .into_iter()
                .map(|row| row.iter().map(|v| [v.x, v.y, v.z]).collect())
                .collect())
        };
        let resultants = if r.has(names::RESULTANTS_FORCE) {
            Some((
                rows(names::RESULTANTS_FORCE)?,
                rows(names::RESULTANTS_MOMENT)?,
            ))
        } else {
            None
        };
        Ok(Self {
            velocities: optional(&r, names::CONFIGURATION_VELOCITY, || {
                vectors(&r, names::CONFIGURATION_VELOCITY)
            })?,
            angular_velocities: optional(&r, names::CONFIGURATION_ANGULAR_VELOCITY, || {
                vectors(&r, names::CONFIGURATION_ANGULAR_VELOCITY)
            })?,
            time,
            labels,
            initial,
            positions,
            rotations,
            directors,
            elements,
            beams,
            joints,
            resultants,
        })
    }

    /// Number of stored steps.
    pub fn steps(&self) -> usize {
        self.time.len().min(self.positions.len())
    }

    /// The section's width direction at `node` in `step`: `R e₂`, `e₂` the
    /// node's initial director; without recorded directors, a unit vector
    /// normal to the beam's initial tangent `tangent` (the one nearest the
    /// global y axis, or z for beams along y), rotated by `R`.
    pub fn width_direction(
        &self,
        step: usize,
        node: usize,
        tangent: &Vector3<f64>,
    ) -> Vector3<f64> {
        let e2 = match &self.directors {
            Some(d) if d[node].column(1).norm() > 0.0 => d[node].column(1).into_owned(),
            _ => {
                let t = tangent.try_normalize(0.0).unwrap_or_else(Vector3::x);
                let up = if t.y.abs() > 0.9 {
                    Vector3::z()
                } else {
                    Vector3::y()
                };
                (up - t * t.dot(&up)).normalize()
            }
        };
        self.rotations[step][node] * e2
    }
}
