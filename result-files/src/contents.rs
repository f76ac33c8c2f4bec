//! A result file (or a study summary) read whole: every dataset with its
//! path, shape and values, and the attributes of the root, of every group
//! and of every dataset — for bindings that hand a whole file to another
//! language (the Python package's `Result`), without their naming HDF5.

use std::path::Path;

use hdf5::types::{TypeDescriptor, VarLenAscii, VarLenUnicode};

use crate::ReadError;

/// The values of a dataset or attribute, flattened in row-major order.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Floating point (`f64`).
    Float(Vec<f64>),
    /// Unsigned integers (`u64`).
    Unsigned(Vec<u64>),
    /// Signed integers (`i64`).
    Signed(Vec<i64>),
    /// Booleans.
    Bool(Vec<bool>),
    /// Strings (variable-length UTF-8 or ASCII).
    Text(Vec<String>),
}

/// A dataset's or attribute's shape (empty for a scalar) and values.
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    /// The dimensions, slowest first; empty for a scalar.
    pub shape: Vec<usize>,
    /// The values in row-major order.
    pub values: Values,
}

/// Everything a file holds, in the library's traversal order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Contents {
    /// `(path, array)` of every dataset of a readable type.
    pub datasets: Vec<(String, Array)>,
    /// `(path of a group or dataset, its attributes)`; the root is `/`.
    pub attrs: Vec<(String, Vec<(String, Array)>)>,
}

fn array(c: &hdf5::Container) -> hdf5::Result<Option<Array>> {
    let text = |v: Vec<String>| Values::Text(v);
    let values = match c.dtype()?.to_descriptor()? {
        TypeDescriptor::Float(_) => Values::Float(c.read_raw::<f64>()?),
        TypeDescriptor::Unsigned(_) => Values::Unsigned(c.read_raw::<u64>()?),
        TypeDescriptor::Integer(_) => Values::Signed(c.read_raw::<i64>()?),
        TypeDescriptor::Boolean => Values::Bool(c.read_raw::<bool>()?),
        TypeDescriptor::VarLenUnicode => text(
            c.read_raw::<VarLenUnicode>()?
                .iter()
                .map(|s| s.as_str().to_owned())
                .collect(),
        ),
        TypeDescriptor::VarLenAscii => text(
            c.read_raw::<VarLenAscii>()?
                .iter()
                .map(|s| s.as_str().to_owned())
                .collect(),
        ),
        _ => return Ok(None),
    };
    Ok(Some(Array {
        shape: c.shape(),
        values,
    }))
}

fn attributes(loc: &hdf5::Location) -> hdf5::Result<Vec<(String, Array)>> {
    let mut out = Vec::new();
    for name in loc.attr_names()? {
        let attr = loc.attr(&name)?;
        if let Some(a) = array(&attr)? {
            out.push((name, a));
        }
    }
    Ok(out)
}

fn walk(group: &hdf5::Group, out: &mut Contents) -> hdf5::Result<()> {
    out.attrs.push((group.name(), attributes(group)?));
    for ds in group.datasets()? {
        let name = ds.name();
        out.attrs.push((name.clone(), attributes(&ds)?));
        if let Some(a) = array(&ds)? {
            out.datasets.push((name, a));
        }
    }
    for g in group.groups()? {
        walk(&g, out)?;
    }
    Ok(())
}

/// Every dataset and attribute of the HDF5 file `path`.
///
/// # Errors
/// The file cannot be opened or read (the error names it).
pub fn read_contents(path: &Path) -> Result<Contents, ReadError> {
    let hdf5 = |what: &str| {
        let what = what.to_owned();
        move |source| ReadError::Hdf5 {
            path: path.to_path_buf(),
            what,
            source,
        }
    };
    let file = hdf5::File::open(path).map_err(hdf5("opening the file"))?;
    let mut out = Contents::default();
    walk(&file, &mut out).map_err(hdf5("reading every dataset and attribute"))?;
    Ok(out)
}
