//! Reading point data from a VTK XML unstructured grid (`.vtu`), so that another code's
//! results can be judged (`contact-patch judge`).
//!
//! The format is Kitware's "VTK XML file formats" (VTK User's Guide, 11th ed., ch. 19):
//! `<VTKFile type="UnstructuredGrid"><UnstructuredGrid><Piece NumberOfPoints=..>` holding
//! `<Points><DataArray NumberOfComponents="3">` (the coordinates, `x y z` per point) and
//! `<PointData>` with named `<DataArray>`s of `NumberOfComponents` values per point. Pieces are
//! concatenated. Only `format="ascii"` arrays are read (what this tool, DOLFINx's `VTKFile` and
//! meshio with `binary=False` write); binary and appended arrays are refused with that hint.
//! Cells are not read: results are matched to our nodes by position.
//!
//! The sizes a file states (`NumberOfPoints`, `NumberOfComponents`) are checked against the
//! file's length before anything is allocated: each value takes at least one character and a
//! separator, so a text of `n` bytes holds at most `n / 2 + 1` values (and a file is read up to
//! [`MAX_VTU_BYTES`]). A hostile or corrupt header is refused, naming the attribute.

use crate::error::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// The most bytes read from one results file (a 1M-node grid with a few fields is ~200 MB).
pub const MAX_VTU_BYTES: u64 = 1 << 30;

/// One named point field: `components` values per point, point after point.
#[derive(Clone, Debug, PartialEq)]
pub struct PointField {
    pub components: usize,
    pub values: Vec<f64>,
}

impl PointField {
    /// The values of point `p`.
    pub fn at(&self, p: usize) -> &[f64] {
        &self.values[p * self.components..(p + 1) * self.components]
    }
}

/// The points of a `.vtu` file and their named fields (pieces concatenated).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointGrid {
    pub points: Vec<[f64; 3]>,
    pub fields: BTreeMap<String, PointField>,
}

/// Read the points and point data of the `.vtu` file at `path`.
pub fn read_vtu(path: &Path) -> Result<PointGrid> {
    let shown = path.display();
    let size = std::fs::metadata(path)
        .map_err(|e| Error::io(&shown, "reading", e))?
        .len();
    if size > MAX_VTU_BYTES {
        return Err(Error::invalid(
            &shown,
            "file",
            format!("{size} bytes; results files are read up to {MAX_VTU_BYTES} bytes"),
            "split the results into one .vtu per body, or write fewer fields",
        ));
    }
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(&shown, "reading", e))?;
    parse_vtu(&text, &shown.to_string())
}

/// Parse VTU text; `source` names it in errors.
pub fn parse_vtu(text: &str, source: &str) -> Result<PointGrid> {
    let bad = |location: String, problem: String, hint: &str| {
        Error::invalid(source, location, problem, hint)
    };
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        bad(
            "XML".into(),
            format!("not well-formed XML: {e}"),
            "give a VTK XML unstructured grid (.vtu) file",
        )
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "VTKFile" || root.attribute("type") != Some("UnstructuredGrid") {
        return Err(bad(
            "root element".into(),
            format!(
                "<{} type={:?}> is not a VTK unstructured grid",
                root.tag_name().name(),
                root.attribute("type").unwrap_or("")
            ),
            "give a .vtu file (<VTKFile type=\"UnstructuredGrid\">); for a .pvd collection give \
             the .vtu file it names",
        ));
    }
    let grid = root
        .children()
        .find(|n| n.has_tag_name("UnstructuredGrid"))
        .ok_or_else(|| {
            bad(
                "<VTKFile>".into(),
                "no <UnstructuredGrid> element".into(),
                "give a .vtu file written by a VTK XML writer",
            )
        })?;
    let mut out = PointGrid::default();
    let pieces: Vec<_> = grid
        .children()
        .filter(|n| n.has_tag_name("Piece"))
        .collect();
    if pieces.is_empty() {
        return Err(bad(
            "<UnstructuredGrid>".into(),
            "no <Piece> element".into(),
            "the file holds no points",
        ));
    }
    let room = Room {
        bytes: text.len(),
        values: text.len() / 2 + 1,
    };
    let mut piece_fields: Vec<BTreeMap<String, PointField>> = Vec::new();
    for (k, piece) in pieces.iter().enumerate() {
        let at = format!("<Piece> {}", k + 1);
        let count: usize = piece
            .attribute("NumberOfPoints")
            .and_then(|v| v.trim().parse().ok())
            .ok_or_else(|| {
                bad(
                    at.clone(),
                    "no readable NumberOfPoints attribute".into(),
                    "a <Piece> states NumberOfPoints=\"N\"",
                )
            })?;
        let coords = piece
            .children()
            .find(|n| n.has_tag_name("Points"))
            .and_then(|p| p.children().find(|n| n.has_tag_name("DataArray")))
            .ok_or_else(|| {
                bad(
                    at.clone(),
                    "no <Points><DataArray> (the point coordinates)".into(),
                    "a .vtu piece lists its points' coordinates under <Points>",
                )
            })?;
        let coords = data_array(&coords, count, room, source, &format!("{at} <Points>"))?;
        if coords.components != 3 {
            return Err(bad(
                format!("{at} <Points>"),
                format!("{} components per point", coords.components),
                "VTK points have 3 coordinates (z = 0 in 2D)",
            ));
        }
        out.points
            .extend((0..count).map(|p| [coords.at(p)[0], coords.at(p)[1], coords.at(p)[2]]));
        let mut fields = BTreeMap::new();
        if let Some(data) = piece.children().find(|n| n.has_tag_name("PointData")) {
            for array in data.children().filter(|n| n.has_tag_name("DataArray")) {
                let name = array.attribute("Name").unwrap_or("").to_string();
                let field = data_array(
                    &array,
                    count,
                    room,
                    source,
                    &format!("{at} <PointData> '{name}'"),
                )?;
                fields.insert(name, field);
            }
        }
        piece_fields.push(fields);
    }
    // a field is kept when every piece has it with the same number of components
    let first = piece_fields[0].clone();
    for (name, field) in first {
        let parts: Option<Vec<&PointField>> = piece_fields
            .iter()
            .map(|f| f.get(&name).filter(|g| g.components == field.components))
            .collect();
        if let Some(parts) = parts {
            let values = parts
                .iter()
                .flat_map(|p| p.values.iter().copied())
                .collect();
            out.fields.insert(
                name,
                PointField {
                    components: field.components,
                    values,
                },
            );
        }
    }
    Ok(out)
}

/// How many values a text can hold: `bytes` long, at most `values` (module notes).
#[derive(Clone, Copy)]
struct Room {
    bytes: usize,
    values: usize,
}

/// One ASCII `<DataArray>` with `count` tuples (`NumberOfPoints` of its piece), the sizes
/// checked against the `room` of the file before anything is allocated.
fn data_array(
    node: &roxmltree::Node,
    count: usize,
    room: Room,
    source: &str,
    location: &str,
) -> Result<PointField> {
    let bad = |problem: String, hint: &str| Error::invalid(source, location, problem, hint);
    let format = node.attribute("format").unwrap_or("ascii");
    if format != "ascii" {
        return Err(bad(
            format!("format=\"{format}\": only ASCII data arrays are read"),
            "write the .vtu as ASCII (DOLFINx: dolfinx.io.VTKFile; meshio: \
             meshio.write(path, mesh, binary=False); VTK: SetDataModeToAscii())",
        ));
    }
    let components: usize = match node.attribute("NumberOfComponents") {
        None => 1,
        Some(v) => v.trim().parse().ok().filter(|&c| c > 0).ok_or_else(|| {
            bad(
                format!("NumberOfComponents=\"{v}\" is not a positive integer"),
                "state how many values each point has",
            )
        })?,
    };
    let expected = count
        .checked_mul(components)
        .filter(|&n| n <= room.values)
        .ok_or_else(|| {
            bad(
                format!(
                    "NumberOfPoints=\"{count}\" x NumberOfComponents=\"{components}\" values are \
                     more than a file of {} bytes can hold (at most {}: each value takes a \
                     character and a separator; results files are read up to {MAX_VTU_BYTES} \
                     bytes)",
                    room.bytes, room.values
                ),
                "correct the NumberOfPoints of the <Piece> or the NumberOfComponents of the \
                 array: the file is corrupt or was not written by a VTK writer",
            )
        })?;
    let mut values = Vec::with_capacity(expected);
    for text in node.descendants().filter(|n| n.is_text()) {
        for word in text.text().unwrap_or("").split_ascii_whitespace() {
            let v: f64 = word.parse().map_err(|_| {
                bad(
                    format!("'{word}' (value {}) is not a number", values.len() + 1),
                    "ASCII data arrays hold numbers separated by white space",
                )
            })?;
            values.push(v);
        }
    }
    if values.len() != expected {
        return Err(bad(
            format!(
                "{} values where {count} points x {components} components = {expected} were \
                 expected",
                values.len(),
            ),
            "the array must hold NumberOfComponents values for each of the piece's points",
        ));
    }
    Ok(PointField { components, values })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_POINTS: &str = r#"<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1">
<UnstructuredGrid><Piece NumberOfPoints="2" NumberOfCells="0">
<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1.5 -2 0</DataArray></Points>
<PointData><DataArray type="Float64" Name="displacement" NumberOfComponents="3" format="ascii">
1e-3 2 0
-4 5.25 0
</DataArray><DataArray type="Float64" Name="p" format="ascii">7 8</DataArray></PointData>
</Piece></UnstructuredGrid></VTKFile>"#;

    #[test]
    fn reads_points_and_named_fields() {
        let g = parse_vtu(TWO_POINTS, "t.vtu").unwrap();
        assert_eq!(g.points, vec![[0.0, 0.0, 0.0], [1.5, -2.0, 0.0]]);
        assert_eq!(g.fields["displacement"].components, 3);
        assert_eq!(g.fields["displacement"].at(1), &[-4.0, 5.25, 0.0]);
        assert_eq!(g.fields["p"].values, vec![7.0, 8.0]);
    }

    #[test]
    fn pieces_are_concatenated() {
        let body = TWO_POINTS
            .split("<UnstructuredGrid>")
            .nth(1)
            .unwrap()
            .split("</UnstructuredGrid>")
            .next()
            .unwrap();
        let text = format!(
            "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>{body}{body}</UnstructuredGrid></VTKFile>"
        );
        let g = parse_vtu(&text, "t.vtu").unwrap();
        assert_eq!(g.points.len(), 4);
        assert_eq!(g.fields["p"].values, vec![7.0, 8.0, 7.0, 8.0]);
    }

    #[test]
    fn refusals_say_what_and_how_to_fix() {
        let binary = TWO_POINTS.replace("format=\"ascii\">\n1e-3", "format=\"binary\">\n1e-3");
        let e = parse_vtu(&binary, "t.vtu").unwrap_err().to_string();
        assert!(
            e.contains("only ASCII") && e.contains("binary=False"),
            "{e}"
        );
        let short = TWO_POINTS.replace("-4 5.25 0", "-4 5.25");
        let e = parse_vtu(&short, "t.vtu").unwrap_err().to_string();
        assert!(
            e.contains("5 values where 2 points x 3 components = 6"),
            "{e}"
        );
        let word = TWO_POINTS.replace("7 8", "7 x");
        let e = parse_vtu(&word, "t.vtu").unwrap_err().to_string();
        assert!(e.contains("'x' (value 2) is not a number"), "{e}");
        // sizes beyond what the text holds are refused before anything is allocated
        for (attribute, hostile) in [
            (
                "NumberOfPoints=\"2\"",
                "NumberOfPoints=\"4611686018427387904\"",
            ),
            (
                "Name=\"p\"",
                "Name=\"p\" NumberOfComponents=\"1000000000000\"",
            ),
        ] {
            let e = parse_vtu(&TWO_POINTS.replace(attribute, hostile), "t.vtu")
                .unwrap_err()
                .to_string();
            assert!(e.contains("more than a file of"), "{e}");
        }
        let e = parse_vtu("<VTKFile type=\"PolyData\"/>", "t.vtu")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a VTK unstructured grid"), "{e}");
        let e = parse_vtu("<VTKFile", "t.vtu").unwrap_err().to_string();
        assert!(e.contains("not well-formed XML"), "{e}");
    }
}
