//! The VTK XML unstructured-grid file (`.vtu`) and its time collection
//! (`.pvd`), as ParaView and the VTK library read them: arrays in one
//! appended raw block (little-endian, a `UInt64` byte count before each), so
//! files stay small and every value, NaN included, is exact.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

/// VTK cell type of a point (`VTK_VERTEX`).
pub const VTK_VERTEX: u8 = 1;
/// VTK cell type of a bilinear quadrilateral (`VTK_QUAD`).
pub const VTK_QUAD: u8 = 9;
/// VTK cell type of a quadrilateral quadratic along its first pair of
/// edges and linear across (`VTK_QUADRATIC_LINEAR_QUAD`): corners 0–3, then
/// the mid-points of edges 0–1 and 2–3.
pub const VTK_QUADRATIC_LINEAR_QUAD: u8 = 26;

/// The values of one data array.
#[derive(Debug, Clone)]
pub enum Values {
    /// `Float64`.
    F64(Vec<f64>),
    /// `Int64`.
    I64(Vec<i64>),
    /// `UInt8`.
    U8(Vec<u8>),
}

impl Values {
    fn vtk_type(&self) -> &'static str {
        match self {
            Values::F64(_) => "Float64",
            Values::I64(_) => "Int64",
            Values::U8(_) => "UInt8",
        }
    }

    fn bytes(&self) -> Vec<u8> {
        match self {
            Values::F64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Values::I64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
            Values::U8(v) => v.clone(),
        }
    }
}

/// A named array of `components` values per point or cell.
#[derive(Debug, Clone)]
pub struct Array {
    /// The array's name in ParaView.
    pub name: String,
    /// Values per point or cell (1 or 3).
    pub components: usize,
    /// The values, point after point.
    pub values: Values,
}

impl Array {
    /// A `Float64` array.
    pub fn f64(name: &str, components: usize, values: Vec<f64>) -> Self {
        Self {
            name: name.to_owned(),
            components,
            values: Values::F64(values),
        }
    }

    /// An `Int64` array of one component.
    pub fn i64(name: &str, values: Vec<i64>) -> Self {
        Self {
            name: name.to_owned(),
            components: 1,
            values: Values::I64(values),
        }
    }
}

/// An unstructured grid: points, cells and their data.
#[derive(Debug, Clone, Default)]
pub struct Grid {
    /// Point coordinates, three per point.
    pub points: Vec<f64>,
    /// The cells' point indices, cell after cell.
    pub connectivity: Vec<i64>,
    /// The end of each cell in `connectivity`.
    pub offsets: Vec<i64>,
    /// Each cell's VTK type.
    pub types: Vec<u8>,
    /// Arrays with a value per point.
    pub point_data: Vec<Array>,
    /// Arrays with a value per cell.
    pub cell_data: Vec<Array>,
}

impl Grid {
    /// Appends a cell of `kind` through `points`.
    pub fn add_cell(&mut self, kind: u8, points: &[i64]) {
        self.connectivity.extend_from_slice(points);
        self.offsets.push(self.connectivity.len() as i64);
        self.types.push(kind);
    }

    /// Writes the grid as a `.vtu` file.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let mut xml = String::new();
        let mut blocks: Vec<Vec<u8>> = Vec::new();
        let mut offset = 0usize;
        let mut array = |xml: &mut String, a: &Array| {
            let bytes = a.values.bytes();
            let _ = writeln!(
                xml,
                r#"<DataArray type="{}" Name="{}" NumberOfComponents="{}" format="appended" offset="{offset}"/>"#,
                a.values.vtk_type(),
                a.name,
                a.components
            );
            offset += 8 + bytes.len();
            blocks.push(bytes);
        };
        let _ = writeln!(
            xml,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
             byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n\
             <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.points.len() / 3,
            self.types.len()
        );
        xml.push_str("<PointData>\n");
        self.point_data.iter().for_each(|a| array(&mut xml, a));
        xml.push_str("</PointData>\n<CellData>\n");
        self.cell_data.iter().for_each(|a| array(&mut xml, a));
        xml.push_str("</CellData>\n<Points>\n");
        array(&mut xml, &Array::f64("points", 3, self.points.clone()));
        xml.push_str("</Points>\n<Cells>\n");
        array(
            &mut xml,
            &Array::i64("connectivity", self.connectivity.clone()),
        );
        array(&mut xml, &Array::i64("offsets", self.offsets.clone()));
        array(
            &mut xml,
            &Array {
                name: "types".to_owned(),
                components: 1,
                values: Values::U8(self.types.clone()),
            },
        );
        xml.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_");
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        out.write_all(xml.as_bytes())?;
        for b in &blocks {
            out.write_all(&(b.len() as u64).to_le_bytes())?;
            out.write_all(b)?;
        }
        out.write_all(b"\n</AppendedData>\n</VTKFile>\n")?;
        out.flush()
    }
}

/// One entry of a `.pvd` collection: a file, its time and its part.
#[derive(Debug, Clone)]
pub struct Entry {
    /// Time of the data set.
    pub time: f64,
    /// Part (block) number: one per kind of data set at a time.
    pub part: usize,
    /// File name relative to the collection's directory.
    pub file: String,
}

/// `text` with XML's special characters as entities (file names).
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Writes a `.pvd` collection: ParaView opens the whole time series from it.
pub fn write_collection(path: &Path, entries: &[Entry]) -> std::io::Result<()> {
    let mut xml = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" \
         byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for e in entries {
        let _ = writeln!(
            xml,
            r#"<DataSet timestep="{:e}" group="" part="{}" file="{}"/>"#,
            e.time,
            e.part,
            escape(&e.file)
        );
    }
    xml.push_str("</Collection>\n</VTKFile>\n");
    std::fs::write(path, xml)
}
