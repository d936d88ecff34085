//! The VTK XML PolyData format (`.vtp`), written by hand: the XML head lists the arrays, and
//! their bytes follow in one raw appended block, each array zlib-compressed in blocks the way
//! VTK's `vtkZLibDataCompressor` reads them (a UInt64 header of block count, block size, last
//! block size and the compressed size of each block, then the blocks).
//!
//! No crate did this well: `vtkio` writes VTK XML, but its last release is a 2022 release
//! candidate; this is one format's writer, a page long, checked against VTK's own reader by
//! the tests.

use anyhow::Context;
use flate2::write::ZlibEncoder;
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

/// Uncompressed bytes per compressed block (VTK's readers take any size).
const BLOCK: usize = 1 << 16;

/// The values of one array, in the type the file stores.
pub enum Values {
    /// 32-bit floats (`Float32`).
    F32(Vec<f32>),
    /// 32-bit signed integers (`Int32`).
    I32(Vec<i32>),
}

impl Values {
    fn type_name(&self) -> &'static str {
        match self {
            Values::F32(_) => "Float32",
            Values::I32(_) => "Int32",
        }
    }
    fn bytes(&self) -> &[u8] {
        match self {
            Values::F32(v) => bytemuck::cast_slice(v),
            Values::I32(v) => bytemuck::cast_slice(v),
        }
    }
}

/// A named array of `components` values per point or cell.
pub struct Array {
    /// Name ParaView shows.
    pub name: &'static str,
    /// Values per tuple (1 for scalars, 3 for vectors).
    pub components: usize,
    /// The tuples' values, one after another.
    pub values: Values,
}

impl Array {
    /// A scalar float array.
    pub fn scalars(name: &'static str, v: impl IntoIterator<Item = f64>) -> Self {
        Array { name, components: 1, values: Values::F32(v.into_iter().map(|x| x as f32).collect()) }
    }
    /// A vector float array of `N` components.
    pub fn vectors<const N: usize>(name: &'static str, v: impl IntoIterator<Item = [f64; N]>) -> Self {
        Array { name, components: N, values: Values::F32(v.into_iter().flat_map(|x| x.map(|c| c as f32)).collect()) }
    }
    /// A scalar integer array.
    pub fn integers(name: &'static str, v: impl IntoIterator<Item = i64>) -> Self {
        Array { name, components: 1, values: Values::I32(v.into_iter().map(|x| x as i32).collect()) }
    }
}

/// Cells of one kind, each a run of point indices.
#[derive(Default)]
pub struct Cells {
    /// Point indices of every cell, one cell after another.
    pub connectivity: Vec<i32>,
    /// Where each cell's indices end in `connectivity`.
    pub offsets: Vec<i32>,
}

impl Cells {
    /// Adds a cell of the given points.
    pub fn push(&mut self, points: impl IntoIterator<Item = usize>) {
        self.connectivity.extend(points.into_iter().map(|p| p as i32));
        self.offsets.push(self.connectivity.len() as i32);
    }
    fn len(&self) -> usize {
        self.offsets.len()
    }
}

/// One PolyData piece: points, their cells (vertices, lines or polygons), and arrays on the
/// points and on the cells (in VTK's cell order: vertices, then lines, then polygons).
#[derive(Default)]
pub struct PolyData {
    /// Point coordinates (m).
    pub points: Vec<[f64; 3]>,
    /// Vertex cells.
    pub verts: Cells,
    /// Line cells.
    pub lines: Cells,
    /// Polygon cells.
    pub polys: Cells,
    /// Arrays with a tuple per point.
    pub point_data: Vec<Array>,
    /// Arrays with a tuple per cell.
    pub cell_data: Vec<Array>,
}

/// The appended block being built: the compressed arrays and the XML that points at them.
struct Appended {
    xml: String,
    data: Vec<u8>,
}

impl Appended {
    fn array(&mut self, name: &str, components: usize, values: &Values) -> anyhow::Result<()> {
        self.raw_array(name, components, values.type_name(), values.bytes())
    }

    /// An array of `raw` bytes of VTK type `type_name`.
    fn raw_array(&mut self, name: &str, components: usize, type_name: &str, raw: &[u8]) -> anyhow::Result<()> {
        writeln!(self.xml, r#"        <DataArray type="{type_name}" Name="{name}" NumberOfComponents="{components}" format="appended" offset="{}"/>"#, self.data.len())?;
        let blocks: Vec<&[u8]> = if raw.is_empty() { Vec::new() } else { raw.chunks(BLOCK).collect() };
        let mut compressed = Vec::with_capacity(blocks.len());
        for b in &blocks {
            let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            z.write_all(b)?;
            compressed.push(z.finish()?);
        }
        let last = raw.len() % BLOCK;
        let header = [blocks.len() as u64, BLOCK as u64, last as u64].into_iter().chain(compressed.iter().map(|c| c.len() as u64));
        for h in header {
            self.data.extend_from_slice(&h.to_le_bytes());
        }
        for c in &compressed {
            self.data.extend_from_slice(c);
        }
        Ok(())
    }

    fn arrays(&mut self, tag: &str, arrays: &[Array]) -> anyhow::Result<()> {
        writeln!(self.xml, "      <{tag}>")?;
        for a in arrays {
            self.array(a.name, a.components, &a.values)?;
        }
        writeln!(self.xml, "      </{tag}>")?;
        Ok(())
    }

    fn cells(&mut self, tag: &str, c: &Cells) -> anyhow::Result<()> {
        if c.len() == 0 {
            return Ok(());
        }
        writeln!(self.xml, "      <{tag}>")?;
        self.raw_array("connectivity", 1, "Int32", bytemuck::cast_slice(&c.connectivity))?;
        self.raw_array("offsets", 1, "Int32", bytemuck::cast_slice(&c.offsets))?;
        writeln!(self.xml, "      </{tag}>")?;
        Ok(())
    }
}

/// Writes `piece` to `path` and returns the file's length (bytes).
pub fn write(path: &Path, piece: &PolyData) -> anyhow::Result<u64> {
    let mut a = Appended { xml: String::new(), data: Vec::new() };
    writeln!(a.xml, r#"<?xml version="1.0"?>"#)?;
    writeln!(a.xml, r#"<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64" compressor="vtkZLibDataCompressor">"#)?;
    writeln!(a.xml, "  <PolyData>")?;
    writeln!(
        a.xml,
        r#"    <Piece NumberOfPoints="{}" NumberOfVerts="{}" NumberOfLines="{}" NumberOfStrips="0" NumberOfPolys="{}">"#,
        piece.points.len(),
        piece.verts.len(),
        piece.lines.len(),
        piece.polys.len()
    )?;
    a.arrays("PointData", &piece.point_data)?;
    a.arrays("CellData", &piece.cell_data)?;
    writeln!(a.xml, "      <Points>")?;
    a.array("Points", 3, &Values::F32(piece.points.iter().flat_map(|p| p.map(|c| c as f32)).collect()))?;
    writeln!(a.xml, "      </Points>")?;
    a.cells("Verts", &piece.verts)?;
    a.cells("Lines", &piece.lines)?;
    a.cells("Polys", &piece.polys)?;
    writeln!(a.xml, "    </Piece>")?;
    writeln!(a.xml, "  </PolyData>")?;
    write!(a.xml, "  <AppendedData encoding=\"raw\">\n   _")?;
    let mut bytes = a.xml.into_bytes();
    bytes.extend_from_slice(&a.data);
    bytes.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    std::fs::write(path, &bytes).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(bytes.len() as u64)
}
