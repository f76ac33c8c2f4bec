//! Tables as HDF5 files: one 1-D dataset per column at the root (the study
//! summaries' `summary.h5`). The study crate describes the table; this module
//! is the only place that writes it, so `hdf5` stays inside this crate.

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use thiserror::Error;

/// The values of one column.
#[derive(Debug, Clone, PartialEq)]
pub enum TableValues {
    /// `f64` values.
    Numbers(Vec<f64>),
    /// Variable-length UTF-8 strings.
    Texts(Vec<String>),
}

/// One column: its name (a `/` in it becomes `_` in the file), its
/// `description` attribute and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct TableColumn {
    /// The column's name.
    pub name: String,
    /// What it holds.
    pub description: String,
    /// Its values, one per row.
    pub values: TableValues,
}

/// Why a table could not be written: the file and what was being done.
#[derive(Debug, Error)]
#[error("{}: HDF5 error while {what}: {source}", .file.display())]
pub struct TableError {
    /// The HDF5 file.
    pub file: PathBuf,
    /// What was being done.
    pub what: String,
    /// The library's error.
    #[source]
    pub source: hdf5::Error,
}

/// Writes `columns` to `file` as 1-D datasets with a `description` each, the
/// UTF-8 string attributes `attrs` at the root, and the root attribute
/// `columns` listing the column names in order.
pub fn write_table(
    file: &Path,
    columns: &[TableColumn],
    attrs: &[(&str, &str)],
) -> Result<(), TableError> {
    let err = |what: String| {
        move |source| TableError {
            file: file.to_path_buf(),
            what,
            source,
        }
    };
    let h5 = hdf5::File::create(file).map_err(err("creating the file".into()))?;
    for col in columns {
        let name = col.name.replace('/', "_");
        let builder = h5.new_dataset_builder();
        let ds = match &col.values {
            TableValues::Numbers(v) => builder.with_data(v.as_slice()).create(name.as_str()),
            TableValues::Texts(v) => {
                let v: Vec<VarLenUnicode> = v.iter().map(|t| varlen(t)).collect();
                builder.with_data(v.as_slice()).create(name.as_str())
            }
        }
        .map_err(err(format!("writing dataset {name}")))?;
        str_attr(&ds, "description", &col.description)
            .map_err(err(format!("writing the description of {name}")))?;
    }
    for (name, value) in attrs {
        str_attr(&h5, name, value).map_err(err(format!("writing root attribute {name}")))?;
    }
    let names: Vec<VarLenUnicode> = columns.iter().map(|c| varlen(&c.name)).collect();
    h5.new_attr_builder()
        .with_data(names.as_slice())
        .create("columns")
        .map_err(err("writing root attribute columns".into()))?;
    h5.flush().map_err(err("flushing the file".into()))
}

/// HDF5 strings cannot hold NUL; it becomes U+FFFD.
pub(crate) fn varlen(text: &str) -> VarLenUnicode {
    text.replace('\0', "\u{FFFD}")
        .parse::<VarLenUnicode>()
        .unwrap_or_default()
}

/// Creates the scalar UTF-8 string attribute `name` on `loc`.
pub(crate) fn str_attr(loc: &hdf5::Location, name: &str, value: &str) -> hdf5::Result<()> {
    let attr = loc.new_attr::<VarLenUnicode>().shape(()).create(name)?;
    attr.as_writer().write_scalar(&varlen(value))
}
