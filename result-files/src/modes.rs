//! `/modes` (vibration) and `/buckling` (linear buckling) of a result file:
//! the eigenvalues and every node's share of each mode.

use flexmech_integrators::modal::{ModeKind, ModeSet};
use hdf5::File;

use super::layout as names;
use crate::table::str_attr;

/// Writes the group of `set` (`/modes` or `/buckling`) with its datasets;
/// `joints` names the model's joints (`<group>/joints/<name>/released`).
pub(crate) fn write(file: &File, set: &ModeSet, joints: &[String]) -> hdf5::Result<()> {
    let (group, value, about) = match set.kind {
        ModeKind::Vibration => (
            names::MODES,
            "frequency",
            "vibration modes, lowest first: unit mass norm, real parts",
        ),
        ModeKind::Buckling => (
            names::BUCKLING,
            "load_factor",
            "buckling modes, lowest load factor first: largest nodal displacement 1",
        ),
    };
    let g = file.create_group(group)?;
    str_attr(&g, names::ATTR_DESCRIPTION, about)?;
    str_attr(&g, "solver", set.solver.name())?;
    scalar(&g, "unknowns", set.unknowns as f64)?;
    scalar(&g, "rigid_modes", set.rigid as f64)?;
    scalar(&g, "asymmetry", set.asymmetry)?;
    let count = set.eigenvalues.len();
    g.new_dataset::<f64>()
        .shape([count])
        .create(value)?
        .write_raw(&set.values())?;
    if set.kind == ModeKind::Vibration {
        g.new_dataset::<f64>()
            .shape([count])
            .create("eigenvalue")?
            .write_raw(&set.eigenvalues)?;
    }
    let nodes = set.displacement.first().map_or(0, Vec::len);
    let mut shapes = vec![
        ("displacement", &set.displacement),
        ("rotation", &set.rotation),
    ];
    if let Some(c) = &set.complex {
        shapes.push(("displacement_imag", &c.displacement));
        shapes.push(("rotation_imag", &c.rotation));
        for (name, values) in [("damping_ratio", &c.damping_ratio), ("whirl", &c.whirl)] {
            g.new_dataset::<f64>()
                .shape([count])
                .create(name)?
                .write_raw(values)?;
        }
    }
    if let (Some(d), None) = (&set.damping, &set.complex) {
        g.new_dataset::<f64>()
            .shape([count])
            .create("damping_ratio")?
            .write_raw(&d.ratio)?;
        scalar(&g, "damping_coupling", d.coupling)?;
    }
    for (name, per_mode) in shapes {
        let flat: Vec<f64> = per_mode
            .iter()
            .flat_map(|m| m.iter().flat_map(|v| [v.x, v.y, v.z]))
            .collect();
        g.new_dataset::<f64>()
            .shape([count, nodes, 3])
            .create(name)?
            .write_raw(&flat)?;
    }
    if !joints.is_empty() {
        g.create_group("joints")?;
        for (j, joint) in joints.iter().enumerate() {
            let width = set.released.first().map_or(0, |m| m[j].len());
            let flat: Vec<f64> = set.released.iter().flat_map(|m| m[j].clone()).collect();
            g.create_group(&format!("joints/{joint}"))?
                .new_dataset::<f64>()
                .shape([count, width])
                .create("released")?
                .write_raw(&flat)?;
        }
    }
    Ok(())
}

/// A scalar attribute.
fn scalar(g: &hdf5::Group, name: &str, v: f64) -> hdf5::Result<()> {
    g.new_attr::<f64>().create(name)?.write_scalar(&v)
}
