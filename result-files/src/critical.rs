//! `/stability` of a static result: the critical points located on the
//! path (see [`flexmech_integrators::critical`]).

use flexmech_integrators::critical::CriticalPoint;
use hdf5::types::VarLenUnicode;
use hdf5::File;

use super::layout as names;
use crate::table::str_attr;

/// Writes `/stability` with `critical_load_factor`, `critical_kind`
/// (`"limit"` or `"bifurcation"`), `critical_bracket` and
/// `negative_before`/`negative_after`, one entry per point in path order;
/// nothing when the path crossed none.
pub(crate) fn write(file: &File, points: &[CriticalPoint]) -> hdf5::Result<()> {
    if points.is_empty() {
        return Ok(());
    }
    let g = file.create_group(names::STABILITY)?;
    str_attr(
        &g,
        names::ATTR_DESCRIPTION,
        "critical points where the tangent's count of negative eigenvalues changed, \
         located by bisection between the bracketing steps",
    )?;
    let k = points.len();
    let reals: [(&str, Vec<f64>); 4] = [
        (
            "critical_load_factor",
            points.iter().map(|p| p.load_factor).collect(),
        ),
        (
            "critical_bracket",
            points.iter().map(|p| p.bracket).collect(),
        ),
        (
            "negative_before",
            points.iter().map(|p| p.negative_before as f64).collect(),
        ),
        (
            "negative_after",
            points.iter().map(|p| p.negative_after as f64).collect(),
        ),
    ];
    for (name, values) in reals {
        g.new_dataset::<f64>()
            .shape([k])
            .create(name)?
            .write_raw(&values)?;
    }
    let kinds: Vec<VarLenUnicode> = points
        .iter()
        .map(|p| p.kind.name().parse().unwrap_or_default())
        .collect();
    g.new_dataset::<VarLenUnicode>()
        .shape([k])
        .create("critical_kind")?
        .write_raw(&kinds)
}
