//! `/mesh` of a result file (node labels, element connectivity, beams) and
//! the creation time stamp.

use hdf5::types::VarLenUnicode;
use hdf5::File;

use super::layout as names;

/// The mesh as the result file records it under `/mesh`, enough to draw the
/// mechanism without the model text.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshMeta {
    /// Every node's label, in `/configuration` order (`arm.0`, `arm.end`, ...).
    pub node_labels: Vec<String>,
    /// Every element's nodes (2 or 3), in element order.
    pub elements: Vec<Vec<usize>>,
    /// Every beam's name and its nodes in order along it.
    pub beams: Vec<(String, Vec<usize>)>,
    /// Each node's initial directors `[e₁, e₂, e₃]` (zeros for nodes on no
    /// beam): `/mesh/node_directors`, omitted when empty.
    pub node_directors: Vec<[[f64; 3]; 3]>,
}

/// Writes `/mesh`: labels, and elements and beams as flattened lists with
/// offsets (the compressed-row layout VTK and ParaView use).
pub(crate) fn write(file: &File, mesh: &MeshMeta, initial: &[[f64; 3]]) -> hdf5::Result<()> {
    file.create_group(names::MESH)?;
    let strings = |name: &str, values: &[String]| -> hdf5::Result<()> {
        let v: Vec<VarLenUnicode> = values
            .iter()
            .map(|s| s.parse().unwrap_or_default())
            .collect();
        let set = file
            .new_dataset::<VarLenUnicode>()
            .shape([v.len()])
            .create(name)?;
        write_strings(&set, &v)
    };
    let lists = |nodes: &str, offsets: &str, lists: &[&[usize]]| -> hdf5::Result<()> {
        let flat: Vec<u64> = lists
            .iter()
            .flat_map(|l| l.iter().map(|&n| n as u64))
            .collect();
        let mut off = vec![0u64];
        for l in lists {
            off.push(off[off.len() - 1] + l.len() as u64);
        }
        file.new_dataset::<u64>()
            .shape([flat.len()])
            .create(nodes)?
            .write_raw(&flat)?;
        file.new_dataset::<u64>()
            .shape([off.len()])
            .create(offsets)?
            .write_raw(&off)
    };
    strings(names::MESH_NODE_LABELS, &mesh.node_labels)?;
    let elements: Vec<&[usize]> = mesh.elements.iter().map(Vec::as_slice).collect();
    lists(
        names::MESH_ELEMENT_NODES,
        names::MESH_ELEMENT_OFFSETS,
        &elements,
    )?;
    let beam_names: Vec<String> = mesh.beams.iter().map(|(n, _)| n.clone()).collect();
    strings(names::MESH_BEAM_NAMES, &beam_names)?;
    let beams: Vec<&[usize]> = mesh.beams.iter().map(|(_, n)| n.as_slice()).collect();
    lists(names::MESH_BEAM_NODES, names::MESH_BEAM_OFFSETS, &beams)?;
    if !mesh.node_directors.is_empty() {
        let flat: Vec<f64> = mesh
            .node_directors
            .iter()
            .flat_map(|d| d.iter().flatten().copied())
            .collect();
        file.new_dataset::<f64>()
            .shape([mesh.node_directors.len(), 3, 3])
            .create(names::MESH_NODE_DIRECTORS)?
            .write_raw(&flat)?;
    }
    if !initial.is_empty() {
        let flat: Vec<f64> = initial.iter().flatten().copied().collect();
        file.new_dataset::<f64>()
            .shape([initial.len(), 3])
            .create(names::MESH_INITIAL_POSITION)?
            .write_raw(&flat)?;
    }
    Ok(())
}

/// Bytes of conversion buffer per string: the larger of the file's and
/// memory's size of one variable-length string (16 and 8), with room.
const STRING_CONVERSION_BYTES: usize = 32;

/// Writes the variable-length strings `v` into the whole of `set`, as
/// `write_raw` does, but with the conversion buffers sized to them.
/// Strings always take HDF5's type conversion, whose buffers are otherwise
/// its default 1 MiB each, allocated zeroed for every write: two such
/// writes were a tenth of a small model's whole run.
fn write_strings(set: &hdf5::Dataset, v: &[VarLenUnicode]) -> hdf5::Result<()> {
    use hdf5_sys::{h5d, h5p, h5s};
    let memory = hdf5::Datatype::from_type::<VarLenUnicode>()?;
    let bytes = STRING_CONVERSION_BYTES * v.len().max(1);
    hdf5::sync::sync(|| {
        // SAFETY: under the library's lock (`sync`), with ids that live
        // through the calls; `v` holds `set`'s number of strings in the
        // memory type `memory` describes; the property list is closed
        // whatever happens.
        unsafe {
            let xfer = h5p::H5Pcreate(*h5p::H5P_CLS_DATASET_XFER);
            if xfer < 0 {
                return Err("creating a transfer property list failed".into());
            }
            let written =
                h5p::H5Pset_buffer(xfer, bytes, std::ptr::null_mut(), std::ptr::null_mut()) >= 0
                    && h5d::H5Dwrite(
                        set.id(),
                        memory.id(),
                        h5s::H5S_ALL,
                        h5s::H5S_ALL,
                        xfer,
                        v.as_ptr().cast(),
                    ) >= 0;
            h5p::H5Pclose(xfer);
            if written {
                Ok(())
            } else {
                Err("writing strings failed".into())
            }
        }
    })
}

/// The current UTC time as `YYYY-MM-DDThh:mm:ssZ`.
pub(crate) fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    iso_utc(secs)
}

/// `secs` after 1970-01-01T00:00:00Z as ISO 8601 (proleptic Gregorian
/// calendar, days to civil date by H. Hinnant's algorithm).
fn iso_utc(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::iso_utc;

    #[test]
    fn known_dates() {
        assert_eq!(iso_utc(0), "1970-01-01T00:00:00Z");
        // `date -u -d @951782400`: the leap day of 2000.
        assert_eq!(iso_utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(iso_utc(1_798_761_599), "2026-12-31T23:59:59Z");
    }
}
