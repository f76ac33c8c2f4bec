//! `/sensitivity/<key>/*`: the exact derivatives of the tracked nodes'
//! displacements and of the total energy with respect to each `[output]
//! sensitivity` key.

use std::path::Path;

use flexmech_integrators::record::StepRecord;

use super::{names, Creator, ResultError, RunMeta, Series};

/// The datasets of one key.
struct KeySets {
    /// Per tracked node: its index and `d(displacement)/dp`.
    nodes: Vec<(usize, Series)>,
    /// `d(total energy)/dp`.
    energy: Series,
}

/// The datasets of every key, in the order of [`RunMeta::sensitivity`].
pub(super) struct SensitivitySets {
    keys: Vec<KeySets>,
}

impl SensitivitySets {
    /// Creates `/sensitivity` and, per key, its groups and datasets (none
    /// when the run has no keys).
    pub(super) fn create(c: Creator<'_>, meta: &RunMeta) -> Result<Self, ResultError> {
        if meta.sensitivity.is_empty() {
            return Ok(Self { keys: Vec::new() });
        }
        c.group(
            names::SENSITIVITY,
            "exact derivatives of the results with respect to model values, one group per \
             key path as written in [output] sensitivity",
        )?;
        let keys = (meta.sensitivity.iter())
            .map(|key| Self::create_key(c, meta, key))
            .collect::<Result<_, _>>()?;
        Ok(Self { keys })
    }

    fn create_key(c: Creator<'_>, meta: &RunMeta, key: &str) -> Result<KeySets, ResultError> {
        let group = names::sensitivity_group(key);
        c.group(
            &group,
            &format!("derivatives with respect to the model value {key}"),
        )?;
        c.group(&format!("{group}{}", names::NODES), "tracked nodes")?;
        c.group(&format!("{group}{}", names::ENERGY), "energies")?;
        let mut nodes = Vec::with_capacity(meta.tracked.len());
        for (label, index) in &meta.tracked {
            c.group(&format!("{group}{}/{label}", names::NODES), "tracked node")?;
            let description = format!("derivative of the node's displacement by {key}");
            let path = names::sensitivity_node_path(key, label);
            nodes.push((*index, c.f64s(&path, &[3], &description)?));
        }
        let energy = c.f64s(
            &names::sensitivity_energy_path(key),
            &[],
            &format!("derivative of the total energy by {key}"),
        )?;
        Ok(KeySets { nodes, energy })
    }

    /// The number of keys (the sensitivities every record carries).
    pub(super) fn keys(&self) -> usize {
        self.keys.len()
    }

    /// Every dataset (one row per step).
    pub(super) fn series(&self) -> impl Iterator<Item = &Series> {
        self.keys
            .iter()
            .flat_map(|k| k.nodes.iter().map(|(_, s)| s).chain([&k.energy]))
    }

    /// Writes rows `t0..` of every dataset from `recs`.
    pub(super) fn write(
        &self,
        t0: usize,
        recs: &[StepRecord],
        path: &Path,
    ) -> Result<(), ResultError> {
        for (k, sets) in self.keys.iter().enumerate() {
            for (node, series) in &sets.nodes {
                let rows: Vec<[f64; 3]> = recs
                    .iter()
                    .map(|r| r.sensitivities[k].displacement[*node])
                    .collect();
                series.push_rows(t0, &rows, path)?;
            }
            let energy: Vec<f64> = recs.iter().map(|r| r.sensitivities[k].energy).collect();
            sets.energy.push_scalars(t0, &energy, path)?;
        }
        Ok(())
    }
}
