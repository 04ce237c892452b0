//! VTK XML unstructured grids (`.vtu`, version 0.1, ASCII) built from points, cells and named
//! point-data arrays: the contact-surface files, and the extra point data of the body files.
//!
//! Format: *VTK File Formats*, Kitware (VTK User's Guide, "XML File Formats"): `<Points>` with
//! three components per point, `<Cells>` with `connectivity`, `offsets` and `types`, then
//! `<PointData>` with one `<DataArray>` per field. Numbers are written in Rust's shortest
//! round-trip form, so a reader gets back the very `f64` the solver computed. Cell types used:
//! 3 (`VTK_LINE`) for Line2 facets and 21 (`VTK_QUADRATIC_EDGE`, end, end, middle) for Line3
//! facets, whose node order is ours; for 3D bodies 12 (`VTK_HEXAHEDRON`), 29
//! (`VTK_TRIQUADRATIC_HEXAHEDRON`), 10 (`VTK_TETRA`) and 24 (`VTK_QUADRATIC_TETRA`), in the
//! node order of [`crate::fe3d`], which is VTK's.

use crate::error::Result;
use std::fmt::Write as _;
use std::path::Path;

/// `x` in the shortest form that reads back as the same `f64`, with an exponent for very small
/// and very large magnitudes (`1e-18`, not eighteen zeros).
pub fn number(x: f64) -> String {
    format!("{x:?}")
}

/// The values of one point-data array, `components` per point.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Float(Vec<f64>),
    Int(Vec<i32>),
}

/// One named point-data array.
#[derive(Clone, Debug, PartialEq)]
pub struct PointArray {
    pub name: String,
    pub components: usize,
    pub values: Values,
}

impl PointArray {
    pub fn float(name: &str, components: usize, values: Vec<f64>) -> PointArray {
        PointArray {
            name: name.into(),
            components,
            values: Values::Float(values),
        }
    }

    pub fn int(name: &str, values: Vec<i32>) -> PointArray {
        PointArray {
            name: name.into(),
            components: 1,
            values: Values::Int(values),
        }
    }

    /// The `<DataArray>` element, one point per line.
    pub fn xml(&self) -> String {
        let c = self.components.max(1);
        let (kind, len) = match &self.values {
            Values::Float(v) => ("Float64", v.len()),
            Values::Int(v) => ("Int32", v.len()),
        };
        let mut s = format!(
            "<DataArray type=\"{kind}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
            self.name, self.components
        );
        s += &lines_in_parallel(len.div_ceil(c), |point, t| {
            let range = point * c..((point + 1) * c).min(len);
            for (k, i) in range.enumerate() {
                if k > 0 {
                    t.push(' ');
                }
                let _ = match &self.values {
                    Values::Float(v) => write!(t, "{:?}", v[i]),
                    Values::Int(v) => write!(t, "{}", v[i]),
                };
            }
            t.push('\n');
        });
        s += "</DataArray>\n";
        s
    }
}

/// Write an unstructured grid of `points` (2D with z = 0, or 3D) and `cells` (VTK cell type,
/// point indices) with `arrays` as point data.
pub fn write_grid<const D: usize>(
    path: &Path,
    points: &[[f64; D]],
    cells: &[(u8, Vec<usize>)],
    arrays: &[PointArray],
) -> Result<()> {
    let mut text = String::new();
    let _ = writeln!(text, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        text,
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">"
    );
    let _ = writeln!(text, "<UnstructuredGrid>");
    let _ = writeln!(
        text,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        points.len(),
        cells.len()
    );
    let _ = writeln!(
        text,
        "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    for p in points {
        let z = if D > 2 { number(p[2]) } else { "0".to_string() };
        let _ = writeln!(text, "{} {} {z}", number(p[0]), number(p[1]));
    }
    let _ = writeln!(text, "</DataArray></Points>");
    let _ = writeln!(
        text,
        "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    );
    for (_, ids) in cells {
        let ids: Vec<String> = ids.iter().map(|n| n.to_string()).collect();
        let _ = writeln!(text, "{}", ids.join(" "));
    }
    let _ = writeln!(
        text,
        "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    );
    let mut offset = 0;
    for (_, ids) in cells {
        offset += ids.len();
        let _ = writeln!(text, "{offset}");
    }
    let _ = writeln!(
        text,
        "</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    );
    for (kind, _) in cells {
        let _ = writeln!(text, "{kind}");
    }
    let _ = writeln!(text, "</DataArray></Cells>");
    let _ = writeln!(text, "<PointData>");
    for a in arrays {
        text += &a.xml();
    }
    let _ = writeln!(text, "</PointData>");
    let _ = writeln!(text, "</Piece></UnstructuredGrid></VTKFile>");
    crate::io::paths::write_new_file(path, &text)
}

/// The text `line(0, ..) + line(1, ..) + .. + line(count - 1, ..)`, formatted in as many
/// consecutive chunks as the machine has threads, each on its own thread (formatting numbers
/// is most of the cost of writing a large mesh's `.vtu`); the text is the same whatever the
/// number of threads.
pub fn lines_in_parallel(count: usize, line: impl Fn(usize, &mut String) + Sync) -> String {
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(count / PARALLEL_LINES_MIN + 1);
    let chunk = count.div_ceil(threads.max(1)).max(1);
    let format = |range: std::ops::Range<usize>| {
        let mut t = String::new();
        for k in range {
            line(k, &mut t);
        }
        t
    };
    if threads <= 1 {
        return format(0..count);
    }
    std::thread::scope(|scope| {
        let parts: Vec<_> = (0..count)
            .step_by(chunk)
            .map(|start| {
                let format = &format;
                scope.spawn(move || format(start..(start + chunk).min(count)))
            })
            .collect();
        parts
            .into_iter()
            .map(|p| p.join().expect("formatting thread"))
            .collect()
    })
}

/// Below this many lines per thread, [`lines_in_parallel`] formats on one thread.
const PARALLEL_LINES_MIN: usize = 20_000;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrays_write_one_point_per_line_in_round_trip_form() {
        let a = PointArray::float("f", 2, vec![0.1 + 0.2, 1.4000000000000001, -3.0, 5e-324]);
        let xml = a.xml();
        let lines: Vec<&str> = xml.lines().collect();
        assert_eq!(
            lines[0],
            "<DataArray type=\"Float64\" Name=\"f\" NumberOfComponents=\"2\" format=\"ascii\">"
        );
        assert_eq!(lines[1], "0.30000000000000004 1.4000000000000001");
        let back: Vec<f64> = lines[2]
            .split(' ')
            .map(|t| t.parse().expect("a number"))
            .collect();
        assert_eq!(back, vec![-3.0, 5e-324]);
        assert_eq!(lines[2], "-3.0 5e-324");
        assert_eq!(
            PointArray::int("s", vec![0, 4]).xml().lines().nth(2),
            Some("4")
        );
    }

    /// An array long enough to be formatted on several threads has the text of the
    /// one-thread loop: every point on its own line, in order.
    #[test]
    fn a_long_array_is_formatted_in_parallel_as_in_sequence() {
        let n = 3 * PARALLEL_LINES_MIN + 17;
        let values: Vec<f64> = (0..3 * n).map(|i| (i as f64 * 0.37).sin() * 1e3).collect();
        let xml = PointArray::float("v", 3, values.clone()).xml();
        let mut expected = String::new();
        for point in values.chunks(3) {
            let _ = writeln!(expected, "{:?} {:?} {:?}", point[0], point[1], point[2]);
        }
        let body: Vec<&str> = xml.lines().skip(1).take(n).collect();
        assert_eq!(body.join("\n") + "\n", expected);
        assert_eq!(xml.lines().count(), n + 2);
    }
}
