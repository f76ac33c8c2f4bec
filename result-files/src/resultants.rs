//! `/resultants` of a result file (`[output] resultants = true`): the
//! material stress resultants `N = C_N Γ` and `M = C_M K` (FORMULATION §2)
//! at every Gauss point of every element, at every stored step.
//!
//! | dataset | shape | meaning |
//! |---|---|---|
//! | `/resultants/force` | T × G × 3 | `N` in the section's material frame (axial, shear 2, shear 3) |
//! | `/resultants/moment` | T × G × 3 | `M` in the material frame (torsion, bending 2, bending 3) |
//! | `/resultants/arc_length` | G | each point's initial arc length from its beam's start |
//!
//! `G` counts the Gauss points in element order (one per 2-node element, two
//! per 3-node one); the attributes `beam_names` and `beam_offsets` of
//! `/resultants/force` give each beam's range: beam `b`'s points are
//! `beam_offsets[b]..beam_offsets[b+1]`.

use flexmech_core::Mesh;
use flexmech_integrators::StepRecord;
use hdf5::types::VarLenUnicode;
use hdf5::Dataset;
use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};

/// What the writer needs to compute the resultants of a step.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultantsMeta {
    /// The mechanism's mesh (elements with their sections and initial
    /// strains).
    pub mesh: Mesh,
    /// Every beam's name and its elements' range in the mesh.
    pub beams: Vec<(String, std::ops::Range<usize>)>,
}

impl ResultantsMeta {
    /// Gauss points in element order: `(arc length from the beam's start)`,
    /// and the points' offsets of every beam (beams + 1).
    pub(crate) fn points(&self) -> (Vec<f64>, Vec<u64>) {
        let mut arc = Vec::new();
        let mut offsets = vec![0u64];
        for (_, elements) in &self.beams {
            let mut start = 0.0;
            for e in &self.mesh.elements[elements.clone()] {
                let length = e.length();
                arc.extend(e.gauss_places().into_iter().map(|u| start + u * length));
                start += length;
            }
            offsets.push(arc.len() as u64);
        }
        (arc, offsets)
    }

    /// `(N, M)` at every Gauss point of `step`, in element order.
    pub(crate) fn of(&self, step: &StepRecord) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let x: Vec<Vector3<f64>> = step.positions.iter().map(|p| Vector3::from(*p)).collect();
        let rot: Vec<Matrix3<f64>> = step
            .quaternions
            .iter()
            .map(|q| {
                UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
                    .to_rotation_matrix()
                    .into_inner()
            })
            .collect();
        let mut force = Vec::new();
        let mut moment = Vec::new();
        for (_, elements) in &self.beams {
            for e in &self.mesh.elements[elements.clone()] {
                for (_, n, m) in e.stress_resultants(&x, &rot) {
                    force.push([n.x, n.y, n.z]);
                    moment.push([m.x, m.y, m.z]);
                }
            }
        }
        (force, moment)
    }
}

/// Writes the beams' ranges as attributes of `ds`.
pub(crate) fn write_ranges(
    ds: &Dataset,
    meta: &ResultantsMeta,
    offsets: &[u64],
) -> hdf5::Result<()> {
    let names: Vec<VarLenUnicode> = meta
        .beams
        .iter()
        .map(|(n, _)| n.parse().unwrap_or_default())
        .collect();
    ds.new_attr::<VarLenUnicode>()
        .shape([names.len()])
        .create("beam_names")?
        .write_raw(&names)?;
    ds.new_attr::<u64>()
        .shape([offsets.len()])
        .create("beam_offsets")?
        .write_raw(offsets)
}
