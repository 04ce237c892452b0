//! Reading Gmsh `.msh` meshes into a body's mesh (`crate::mesh::Mesh`), with physical groups as named sets.
//!
//! Formats (Gmsh reference manual, C. Geuzaine, J.-F. Remacle, gmsh.info/doc/texinfo, sec. 10.1
//! "MSH file format" and 10.2 "Legacy formats"):
//!
//! * MSH 4.1, ASCII and binary, read by the `mshio` crate (sections `$Entities`, `$Nodes`,
//!   `$Elements`); an element's physical groups are those of its entity. `mshio` skips
//!   `$PhysicalNames`, which is plain text in both encodings, so that section is read here.
//!   Where the node tags of the file are contiguous `mshio` keeps no tags and the nodes are
//!   numbered in file order from the smallest tag, as Gmsh writes them. When `mshio` fails,
//!   a section that opens without its `$End` line is named (`mshio` says only "Unknown error
//!   occurred").
//! * MSH 2.2 ASCII, read here line by line: `$Nodes` (`tag x y z`), `$Elements`
//!   (`tag type ntags physical elementary ... nodes`), `$PhysicalNames` (`dim tag "name"`).
//!
//! Elements taken: 2-node line (Gmsh type 1), 3-node line (8), 1-node point (15), 3-node
//! triangle (2), 6-node triangle (9), 4-node quadrangle (3), 9-node quadrangle (10). Gmsh
//! numbers their nodes as `crate::fe` does (corners, then the mid-side nodes of edges 0-1, 1-2,
//! ..., then the Q9 centre), so a cell's node list is taken as it is, except that a cell whose
//! corners run clockwise (negative signed area `A = 1/2 sum (x_i y_{i+1} - x_{i+1} y_i)`, which
//! Gmsh writes for a surface whose normal points along -z) is mirrored to counter-clockwise:
//! corners `0, 3, 2, 1` (triangles `0, 2, 1`) and the mid-side nodes with their edges.
//!
//! A body takes the 2D elements of one physical surface (`physical`), or every 2D element when
//! the file has one kind and the case names none. Its nodes are the nodes of those cells, in
//! ascending Gmsh tag. Every other physical group becomes a set of the body where it lies on
//! the body: a 1D group a facet set (each line must be a boundary facet of the body) and a node
//! set of its nodes, a 0D group a node set, a 2D group a node set. A group that touches no node
//! of the body belongs to another body and is left out; one that lies partly on the body is
//! refused with the element that does not fit.

use crate::fe::{ElementKind, ReferenceCell};
use crate::fe3d::SolidKind;
use crate::mesh::{Facet, Mesh};
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// A problem in a `.msh` file: where (a line, an element, a group), what, and how to fix it.
#[derive(Clone, Debug, PartialEq)]
pub struct MshError {
    pub place: String,
    pub problem: String,
    pub hint: String,
}

impl MshError {
    fn new(place: impl Into<String>, problem: impl Into<String>, hint: impl Into<String>) -> Self {
        MshError {
            place: place.into(),
            problem: problem.into(),
            hint: hint.into(),
        }
    }
}

type Read<T> = std::result::Result<T, MshError>;

/// One element of the file, with the physical tags of its group(s).
#[derive(Clone, Debug, PartialEq)]
pub struct MshElement {
    pub tag: u64,
    pub gmsh_type: i32,
    pub nodes: Vec<u64>,
    pub physical: Vec<i32>,
}

/// The parts of a `.msh` file a mesh needs, in either version.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MshContent {
    /// `"4.1"` or `"2.2"`.
    pub version: String,
    pub nodes: HashMap<u64, [f64; 3]>,
    pub elements: Vec<MshElement>,
    /// `(dimension, tag) -> name`.
    pub names: BTreeMap<(i32, i32), String>,
}

const RESAVE: &str = "save the mesh from Gmsh as MSH 4.1 (ASCII or binary) or MSH 2.2 ASCII, e.g. `gmsh -2 file.geo -format msh41`, or File > Export";

/// Dimension of a Gmsh element type this reader takes, `None` for any other type.
fn element_dimension(gmsh_type: i32) -> Option<i32> {
    match gmsh_type {
        15 => Some(0),
        1 | 8 => Some(1),
        2 | 3 | 9 | 10 => Some(2),
        4 | 5 | 11 | 12 => Some(3),
        _ => None,
    }
}

/// The node count of a Gmsh element type this reader takes.
fn element_node_count(gmsh_type: i32) -> Option<usize> {
    match gmsh_type {
        15 => Some(1),
        1 => Some(2),
        8 | 2 => Some(3),
        3 | 4 => Some(4),
        9 => Some(6),
        5 => Some(8),
        10 => Some(9),
        11 => Some(10),
        12 => Some(27),
        _ => None,
    }
}

/// The corner count of a Gmsh element type this reader takes (its first nodes are corners).
fn corner_count(gmsh_type: i32) -> usize {
    match gmsh_type {
        15 => 1,
        1 | 8 => 2,
        2 | 9 => 3,
        3 | 10 | 4 | 11 => 4,
        _ => 8,
    }
}

/// Read a `.msh` file's bytes (MSH 4.1 ASCII or binary, MSH 2.2 ASCII).
pub fn read_msh(bytes: &[u8]) -> Read<MshContent> {
    let (version, file_type, data_size, header_line) = header(bytes)?;
    match (version.as_str(), file_type) {
        ("4.1", 0 | 1) => {
            if data_size != 8 && data_size != 4 {
                return Err(MshError::new(
                    format!("line {header_line}"),
                    format!("data size {data_size} is not 4 or 8"),
                    RESAVE,
                ));
            }
            read_v41(bytes)
        }
        ("2.2", 0) => read_v22(bytes),
        ("2.2", _) => Err(MshError::new(
            format!("line {header_line}"),
            "binary MSH 2.2 is not read",
            RESAVE,
        )),
        (v, _) => Err(MshError::new(
            format!("line {header_line}"),
            format!("MSH version {v} is not read (only 4.1 and 2.2)"),
            RESAVE,
        )),
    }
}

/// `(version, file type, data size, line)` from `$MeshFormat`.
fn header(bytes: &[u8]) -> Read<(String, i64, i64, usize)> {
    let mut lines = bytes.split(|&b| b == b'\n').map(trim_line);
    let first = lines.next().unwrap_or_default();
    if first != b"$MeshFormat" {
        return Err(MshError::new(
            "line 1",
            "the file does not start with $MeshFormat: not a Gmsh .msh file",
            RESAVE,
        ));
    }
    let second = lines.next().unwrap_or_default();
    let text = String::from_utf8_lossy(second);
    let words: Vec<&str> = text.split_whitespace().collect();
    let number = |i: usize| words.get(i).and_then(|w| w.parse::<i64>().ok());
    match (words.first(), number(1), number(2)) {
        (Some(v), Some(t), Some(d)) => Ok((v.to_string(), t, d, 2)),
        _ => Err(MshError::new(
            "line 2",
            format!("expected `version file-type data-size`, found `{text}`"),
            RESAVE,
        )),
    }
}

fn trim_line(line: &[u8]) -> &[u8] {
    let mut l = line;
    while let [rest @ .., b'\r' | b' ' | b'\t'] = l {
        l = rest;
    }
    while let [b' ' | b'\t', rest @ ..] = l {
        l = rest;
    }
    l
}

/// `$PhysicalNames` (plain text in every version and encoding): `(dim, tag) -> name`.
fn physical_names(bytes: &[u8]) -> Read<BTreeMap<(i32, i32), String>> {
    let mut names = BTreeMap::new();
    let mut lines = bytes
        .split(|&b| b == b'\n')
        .map(trim_line)
        .enumerate()
        .map(|(i, l)| (i + 1, l));
    let Some(_) = lines.by_ref().find(|(_, l)| *l == b"$PhysicalNames") else {
        return Ok(names);
    };
    let truncated = || {
        MshError::new(
            "$PhysicalNames",
            "the file ends inside $PhysicalNames (truncated?)",
            "write the file again from Gmsh",
        )
    };
    let (line, count) = lines.next().ok_or_else(truncated)?;
    let count: usize = std::str::from_utf8(count)
        .ok()
        .and_then(|t| t.parse().ok())
        .ok_or_else(|| {
            MshError::new(
                format!("line {line}"),
                "expected the number of physical names",
                "write the file again from Gmsh",
            )
        })?;
    for _ in 0..count {
        let (line, text) = lines.next().ok_or_else(truncated)?;
        let text = String::from_utf8_lossy(text);
        let bad = || {
            MshError::new(
                format!("line {line}"),
                format!("expected `dimension tag \"name\"`, found `{text}`"),
                "write the file again from Gmsh",
            )
        };
        let mut words = text.splitn(3, char::is_whitespace);
        let dim: i32 = words.next().and_then(|w| w.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = words.next().and_then(|w| w.parse().ok()).ok_or_else(bad)?;
        let name = words.next().unwrap_or("").trim();
        let name = name
            .strip_prefix('"')
            .and_then(|n| n.strip_suffix('"'))
            .ok_or_else(bad)?;
        names.insert((dim, tag), name.to_string());
    }
    match lines.next() {
        Some((_, b"$EndPhysicalNames")) => Ok(names),
        Some((line, _)) => Err(MshError::new(
            format!("line {line}"),
            format!("expected $EndPhysicalNames after {count} names"),
            "the count on the line after $PhysicalNames must match the names listed",
        )),
        None => Err(truncated()),
    }
}

/// The sections of an MSH 4.1 file, by the name between `$` and `$End`.
const V41_SECTIONS: [&str; 13] = [
    "MeshFormat",
    "PhysicalNames",
    "Entities",
    "PartitionedEntities",
    "Nodes",
    "Elements",
    "Periodic",
    "GhostElements",
    "Parametrizations",
    "NodeData",
    "ElementData",
    "ElementNodeData",
    "InterpolationScheme",
];

/// The first section of an MSH 4.1 file that opens without its `$End` line (a truncated or
/// cut file), as [`section`] names it; `None` when every section that opens is closed.
fn unclosed_v41_section(bytes: &[u8]) -> Option<MshError> {
    let text = String::from_utf8_lossy(bytes);
    let lines: Vec<(usize, &str)> = text
        .split('\n')
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .collect();
    V41_SECTIONS
        .iter()
        .filter_map(|name| section(&lines, name).err())
        .min_by(|a, b| {
            a.place
                .len()
                .cmp(&b.place.len())
                .then(a.place.cmp(&b.place))
        })
}

fn read_v41(bytes: &[u8]) -> Read<MshContent> {
    let names = physical_names(bytes)?;
    let file = mshio::parse_msh_bytes(bytes).map_err(|e| {
        // mshio says "Unknown error occurred" for a section cut short: name it when that is so
        if let Some(unclosed) = unclosed_v41_section(bytes) {
            return unclosed;
        }
        MshError::new(
            "MSH 4.1 sections",
            format!(
                "the file could not be read: {}",
                mshio_message(&e.to_string())
            ),
            "check that the file is complete (not truncated) and written by Gmsh",
        )
    })?;
    let mut content = MshContent {
        version: "4.1".into(),
        names,
        ..Default::default()
    };
    let data = file.data;
    let nodes = data.nodes.ok_or_else(|| {
        MshError::new(
            "$Nodes",
            "the file has no $Nodes section",
            "mesh the model (gmsh -2) before saving",
        )
    })?;
    let mut next_tag = nodes.min_node_tag;
    for block in &nodes.node_blocks {
        let mut tags: Vec<u64> = match &block.node_tags {
            Some(map) => {
                let mut t = vec![0; block.nodes.len()];
                for (&tag, &i) in map {
                    t[i] = tag;
                }
                t
            }
            None => (0..block.nodes.len() as u64)
                .map(|i| next_tag + i)
                .collect(),
        };
        next_tag += block.nodes.len() as u64;
        for (tag, node) in tags.drain(..).zip(&block.nodes) {
            content.nodes.insert(tag, [node.x, node.y, node.z]);
        }
    }
    let entity_groups: HashMap<(i32, i32), Vec<i32>> = match &data.entities {
        Some(e) => e
            .points
            .iter()
            .map(|p| ((0, p.tag), p.physical_tags.clone()))
            .chain(
                e.curves
                    .iter()
                    .map(|c| ((1, c.tag), c.physical_tags.clone())),
            )
            .chain(
                e.surfaces
                    .iter()
                    .map(|s| ((2, s.tag), s.physical_tags.clone())),
            )
            .chain(
                e.volumes
                    .iter()
                    .map(|v| ((3, v.tag), v.physical_tags.clone())),
            )
            .collect(),
        None => HashMap::new(),
    };
    let elements = data.elements.ok_or_else(|| {
        MshError::new(
            "$Elements",
            "the file has no $Elements section",
            "mesh the model (gmsh -2) before saving",
        )
    })?;
    for block in &elements.element_blocks {
        let physical = entity_groups
            .get(&(block.entity_dim, block.entity_tag))
            .cloned()
            .unwrap_or_default();
        let gmsh_type = block.element_type as i32;
        for e in &block.elements {
            content.elements.push(MshElement {
                tag: e.element_tag,
                gmsh_type,
                nodes: e.nodes.clone(),
                physical: physical.clone(),
            });
        }
    }
    Ok(content)
}

/// `mshio`'s message without the hex dump it appends, its context lines joined into one.
fn mshio_message(full: &str) -> String {
    let text = full.split("Hex dump").next().unwrap_or(full);
    text.lines()
        .map(|l| l.trim().trim_end_matches(','))
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("; ")
}

/// Lines of a section, numbered from 1, between `$Name` and `$EndName`.
fn section<'a>(lines: &'a [(usize, &'a str)], name: &str) -> Read<Option<&'a [(usize, &'a str)]>> {
    let open = format!("${name}");
    let close = format!("$End{name}");
    let Some(start) = lines.iter().position(|(_, l)| *l == open) else {
        return Ok(None);
    };
    let Some(len) = lines[start + 1..].iter().position(|(_, l)| *l == close) else {
        return Err(MshError::new(
            format!("line {}", lines[start].0),
            format!("{open} has no {close}: the file is truncated"),
            "write the file again from Gmsh",
        ));
    };
    Ok(Some(&lines[start + 1..start + 1 + len]))
}

fn read_v22(bytes: &[u8]) -> Read<MshContent> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        MshError::new(
            format!("byte {}", e.valid_up_to()),
            "an ASCII MSH 2.2 file holds a byte that is not text",
            RESAVE,
        )
    })?;
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .collect();
    let names = physical_names(bytes)?;
    let mut content = MshContent {
        version: "2.2".into(),
        names,
        ..Default::default()
    };
    let counted = |body: &[(usize, &str)], name: &str| -> Read<usize> {
        let (line, first) = body.first().copied().ok_or_else(|| {
            MshError::new(
                format!("${name}"),
                format!("${name} is empty"),
                "write the file again from Gmsh",
            )
        })?;
        let count: usize = first.parse().map_err(|_| {
            MshError::new(
                format!("line {line}"),
                format!("expected the number of entries of ${name}, found `{first}`"),
                "write the file again from Gmsh",
            )
        })?;
        if body.len() - 1 != count {
            return Err(MshError::new(
                format!("line {line}"),
                format!(
                    "${name} announces {count} entries but lists {}",
                    body.len() - 1
                ),
                "the file is truncated or edited; write it again from Gmsh",
            ));
        }
        Ok(count)
    };
    let nodes = section(&lines, "Nodes")?.ok_or_else(|| {
        MshError::new(
            "$Nodes",
            "the file has no $Nodes section",
            "mesh the model before saving",
        )
    })?;
    counted(nodes, "Nodes")?;
    for &(line, l) in &nodes[1..] {
        let words: Vec<&str> = l.split_whitespace().collect();
        let bad = || {
            MshError::new(
                format!("line {line}"),
                format!("expected `tag x y z`, found `{l}`"),
                "write the file again from Gmsh",
            )
        };
        if words.len() != 4 {
            return Err(bad());
        }
        let tag: u64 = words[0].parse().map_err(|_| bad())?;
        let mut p = [0.0; 3];
        for i in 0..3 {
            p[i] = words[i + 1].parse().map_err(|_| bad())?;
        }
        if content.nodes.insert(tag, p).is_some() {
            return Err(MshError::new(
                format!("line {line}"),
                format!("node tag {tag} appears twice"),
                "write the file again from Gmsh",
            ));
        }
    }
    let elements = section(&lines, "Elements")?.ok_or_else(|| {
        MshError::new(
            "$Elements",
            "the file has no $Elements section",
            "mesh the model before saving",
        )
    })?;
    counted(elements, "Elements")?;
    for &(line, l) in &elements[1..] {
        let bad = |what: String| {
            MshError::new(
                format!("line {line}"),
                format!("{what} in `{l}`"),
                "expected `tag type ntags tags... nodes...`; write the file again from Gmsh",
            )
        };
        let words: Vec<i64> = l
            .split_whitespace()
            .map(|w| w.parse::<i64>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| bad("a field is not an integer".into()))?;
        if words.len() < 3 || words[0] < 0 || words[2] < 0 {
            return Err(bad("too few fields".into()));
        }
        let gmsh_type = words[1] as i32;
        let ntags = words[2] as usize;
        let node_count = match element_node_count(gmsh_type) {
            Some(n) => n,
            None => {
                return Err(MshError::new(
                    format!("line {line} (element {})", words[0]),
                    format!("Gmsh element type {gmsh_type} is not read"),
                    SUPPORTED,
                ))
            }
        };
        if words.len() != 3 + ntags + node_count {
            return Err(bad(format!(
                "a type {gmsh_type} element with {ntags} tags needs {} fields, found {}",
                3 + ntags + node_count,
                words.len()
            )));
        }
        let physical = if ntags >= 1 && words[3] != 0 {
            vec![words[3] as i32]
        } else {
            Vec::new()
        };
        let nodes = words[3 + ntags..]
            .iter()
            .map(|&n| u64::try_from(n).map_err(|_| bad(format!("node tag {n}"))))
            .collect::<Read<Vec<u64>>>()?;
        content.elements.push(MshElement {
            tag: words[0] as u64,
            gmsh_type,
            nodes,
            physical,
        });
    }
    Ok(content)
}

/// A cell kind that a body's Gmsh elements are read into, in `D` dimensions: which Gmsh element
/// types it takes, how their nodes map onto [`ReferenceCell`]'s numbering, and what the reader
/// says of the meshes it takes.
pub trait GmshCell<const D: usize>: ReferenceCell<D> + PartialEq + std::fmt::Debug {
    /// The kind of Gmsh element type `gmsh_type`, `None` for a type that is not a cell here.
    fn from_gmsh(gmsh_type: i32) -> Option<Self>;
    /// Node `i` of the cell in this crate's numbering is node `order[i]` of the Gmsh element.
    fn gmsh_order(self) -> &'static [usize];
    /// The renumbering that turns a cell with these corners inside out to a positive one
    /// (2D: a cell whose corners run clockwise; 3D: none, an inverted cell is refused by the
    /// model's geometry check with its Jacobian), `None` when the cell is already positive.
    fn mirrored(self, corners: &[[f64; D]]) -> Option<&'static [usize]>;
    /// The meshes this dimension reads, for the messages.
    const SUPPORTED: &'static str;
}

const SUPPORTED_2D: &str = "mesh with 3- or 6-node triangles or 4- or 9-node quadrangles (Gmsh: Mesh.RecombineAll = 1 for quadrangles, Mesh.ElementOrder = 2 and Mesh.SecondOrderIncomplete = 0 for 9-node ones), lines and points on the boundary";
const SUPPORTED_3D: &str = "mesh with 4- or 10-node tetrahedra or 8- or 27-node hexahedra (Gmsh: Mesh.RecombineAll = 1 with transfinite volumes for hexahedra, Mesh.ElementOrder = 2 and Mesh.SecondOrderIncomplete = 0 for 27-node ones), surfaces, lines and points on the boundary";
/// Every element type the reader takes.
const SUPPORTED: &str = "mesh with triangles or quadrangles (2D bodies) or tetrahedra or hexahedra (3D bodies), linear or quadratic (9-node quadrangles, 27-node hexahedra), and lines, points and surfaces on the boundary";

impl GmshCell<2> for ElementKind {
    fn from_gmsh(gmsh_type: i32) -> Option<Self> {
        match gmsh_type {
            2 => Some(ElementKind::T3),
            9 => Some(ElementKind::T6),
            3 => Some(ElementKind::Q4),
            10 => Some(ElementKind::Q9),
            _ => None,
        }
    }
    fn gmsh_order(self) -> &'static [usize] {
        // Gmsh numbers these as crate::fe does (corners, mid-sides, the Q9 centre)
        &[0, 1, 2, 3, 4, 5, 6, 7, 8][..self.node_count()]
    }
    fn mirrored(self, corners: &[[f64; 2]]) -> Option<&'static [usize]> {
        (signed_area(corners) < 0.0).then(|| mirrored_order(self))
    }
    const SUPPORTED: &'static str = SUPPORTED_2D;
}

/// Gmsh's Tet10 has the mid-edge nodes 8 on edge 2-3 and 9 on edge 1-3, VTK's the other way
/// round; Gmsh's Hex27 numbers the mid-edge nodes edge by edge from corner 0 (0-1, 0-3, 0-4,
/// 1-2, 1-5, 2-3, 2-6, 3-7, 4-5, 4-7, 5-6, 6-7) and the face centres bottom, front, left,
/// right, back, top (Gmsh reference manual, "Node ordering"; checked against Gmsh's own
/// reference coordinates in the tests).
const TET10_FROM_GMSH: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];
const HEX27_FROM_GMSH: [usize; 27] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20, 25,
    26,
];

impl GmshCell<3> for SolidKind {
    fn from_gmsh(gmsh_type: i32) -> Option<Self> {
        match gmsh_type {
            4 => Some(SolidKind::Tet4),
            11 => Some(SolidKind::Tet10),
            5 => Some(SolidKind::Hex8),
            12 => Some(SolidKind::Hex27),
            _ => None,
        }
    }
    fn gmsh_order(self) -> &'static [usize] {
        match self {
            SolidKind::Tet4 => &[0, 1, 2, 3],
            SolidKind::Tet10 => &TET10_FROM_GMSH,
            SolidKind::Hex8 => &[0, 1, 2, 3, 4, 5, 6, 7],
            SolidKind::Hex27 => &HEX27_FROM_GMSH,
        }
    }
    fn mirrored(self, _corners: &[[f64; 3]]) -> Option<&'static [usize]> {
        None
    }
    const SUPPORTED: &'static str = SUPPORTED_3D;
}

/// The highest dimension of the cells in `content` (3 for a file with tetrahedra or
/// hexahedra): the dimension of a body read from it.
pub fn cell_dimension(content: &MshContent) -> i32 {
    content
        .elements
        .iter()
        .filter_map(|e| element_dimension(e.gmsh_type))
        .max()
        .unwrap_or(0)
}

/// The signed area of the polygon through `corners`.
fn signed_area(corners: &[[f64; 2]]) -> f64 {
    let n = corners.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (corners[i], corners[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
}

/// The local node order that mirrors a cell of `kind` (clockwise <-> counter-clockwise),
/// keeping corner 0 first: new node `i` is old node `order[i]`.
pub fn mirrored_order(kind: ElementKind) -> &'static [usize] {
    match kind {
        ElementKind::T3 => &[0, 2, 1],
        // edges 0-2, 2-1, 1-0 have mid-nodes 5, 4, 3
        ElementKind::T6 => &[0, 2, 1, 5, 4, 3],
        ElementKind::Q4 => &[0, 3, 2, 1],
        // edges 0-3, 3-2, 2-1, 1-0 have mid-nodes 7, 6, 5, 4; the centre stays
        ElementKind::Q9 => &[0, 3, 2, 1, 7, 6, 5, 4, 8],
    }
}

/// The Gmsh name of the groups of dimension `dim`, for the messages.
fn group_word(dim: usize) -> &'static str {
    match dim {
        3 => "volume",
        2 => "surface",
        1 => "curve",
        _ => "point",
    }
}

/// A body's mesh and sets from `content`, in `D` dimensions: the `D`-dimensional elements of
/// physical group `physical` (every one if `None`), the other groups as sets (see the module
/// text). Also returns the number of cells mirrored to a positive orientation.
pub fn body_mesh<const D: usize, K: GmshCell<D>>(
    content: &MshContent,
    physical: Option<&str>,
) -> Read<(Mesh<D, K>, usize)> {
    let dim = D as i32;
    let word = group_word(D);
    let group_name = |dim: i32, tag: i32| -> String {
        content
            .names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical_{dim}d_{tag}"))
    };
    for e in &content.elements {
        if element_dimension(e.gmsh_type).is_none() {
            return Err(MshError::new(
                format!("element {}", e.tag),
                format!("Gmsh element type {} is not read", e.gmsh_type),
                SUPPORTED,
            ));
        }
    }
    // the cells of the body
    let body_tag = match physical {
        Some(name) => {
            let found = content
                .names
                .iter()
                .find(|((d, _), n)| *d == dim && n.as_str() == name)
                .map(|((_, t), _)| *t);
            match found {
                Some(t) => Some(t),
                None => {
                    let known: Vec<&String> = content
                        .names
                        .iter()
                        .filter(|((d, _), _)| *d == dim)
                        .map(|(_, n)| n)
                        .collect();
                    let gmsh_word = if D == 3 { "Volume" } else { "Surface" };
                    return Err(MshError::new(
                        "$PhysicalNames",
                        format!("the file has no physical {word} named '{name}'"),
                        format!("name one of its physical {word}s {known:?}, or add Physical {gmsh_word}(\"{name}\") in Gmsh"),
                    ));
                }
            }
        }
        None => None,
    };
    let cells: Vec<&MshElement> = content
        .elements
        .iter()
        .filter(|e| element_dimension(e.gmsh_type) == Some(dim))
        .filter(|e| body_tag.is_none_or(|t| e.physical.contains(&t)))
        .collect();
    let Some(first) = cells.first() else {
        return Err(MshError::new(
            "$Elements",
            match physical {
                Some(name) => format!("the physical {word} '{name}' has no {D}D elements"),
                None => format!("the file has no {D}D elements"),
            },
            format!(
                "mesh the {word} in {D}D (gmsh -{D}) and save every element of the physical {word}"
            ),
        ));
    };
    let Some(kind) = K::from_gmsh(first.gmsh_type) else {
        return Err(MshError::new(
            format!("element {}", first.tag),
            format!("Gmsh element type {} is not a {D}D cell", first.gmsh_type),
            K::SUPPORTED,
        ));
    };
    if let Some(other) = cells.iter().find(|e| e.gmsh_type != first.gmsh_type) {
        return Err(MshError::new(
            format!("element {}", other.tag),
            format!(
                "the body mixes Gmsh element types {} and {}; a body has one element kind",
                first.gmsh_type, other.gmsh_type
            ),
            if D == 3 {
                "mesh the body with tetrahedra only or hexahedra only (Mesh.RecombineAll and transfinite volumes everywhere or nowhere), or split the body in two"
            } else {
                "recombine every triangle (Mesh.RecombineAll = 1) or none, or split the body in two"
            },
        ));
    }
    // nodes: those of the cells, in ascending tag
    let node_of = |e: &MshElement, tag: u64| -> Read<[f64; 3]> {
        content.nodes.get(&tag).copied().ok_or_else(|| {
            MshError::new(
                format!("element {}", e.tag),
                format!("node {tag} is not in $Nodes"),
                "write the file again from Gmsh (the file is truncated or edited)",
            )
        })
    };
    let mut tags = BTreeSet::new();
    for e in &cells {
        for &n in &e.nodes {
            node_of(e, n)?;
            tags.insert(n);
        }
    }
    let local: HashMap<u64, usize> = tags.iter().enumerate().map(|(i, &t)| (t, i)).collect();
    let mut nodes = Vec::with_capacity(tags.len());
    for &t in &tags {
        let p = content.nodes[&t];
        if !p.iter().all(|x| x.is_finite()) {
            return Err(MshError::new(
                format!("node {t}"),
                "the coordinates are not finite",
                "fix the geometry",
            ));
        }
        if D == 2 && p[2] != 0.0 {
            return Err(MshError::new(
                format!("node {t}"),
                format!(
                    "z = {} is not 0; the mesh must lie in the plane z = 0",
                    p[2]
                ),
                "draw the geometry in the x-y plane",
            ));
        }
        nodes.push(std::array::from_fn::<f64, D, _>(|i| p[i]));
    }
    let corners = kind.corner_count();
    let order = kind.gmsh_order();
    let mut mirrored = 0;
    let mut connectivity = Vec::with_capacity(cells.len() * kind.node_count());
    for e in &cells {
        let ids: Vec<usize> = order.iter().map(|&i| local[&e.nodes[i]]).collect();
        let pts: Vec<[f64; D]> = ids[..corners].iter().map(|&i| nodes[i]).collect();
        match kind.mirrored(&pts) {
            Some(mirror) => {
                mirrored += 1;
                connectivity.extend(mirror.iter().map(|&i| ids[i]));
            }
            None => connectivity.extend_from_slice(&ids),
        }
    }
    let mut mesh = Mesh::new(kind, nodes, connectivity);
    // boundary facets by their sorted corner nodes
    let boundary: HashMap<Vec<usize>, Facet> = mesh
        .boundary_facets()
        .into_iter()
        .map(|f| {
            let n = mesh.facet_nodes(f);
            let mut key = n[..kind.facet_corner_count(f.edge)].to_vec();
            key.sort_unstable();
            (key, f)
        })
        .collect();
    let mut node_sets: BTreeMap<String, BTreeSet<usize>> = BTreeMap::new();
    let mut facet_sets: BTreeMap<String, Vec<Facet>> = BTreeMap::new();
    // every physical group other than the body's own, with its elements
    let mut groups: BTreeMap<(i32, i32), Vec<&MshElement>> = BTreeMap::new();
    for e in &content.elements {
        let element_dim = element_dimension(e.gmsh_type).expect("checked above");
        for &p in &e.physical {
            if element_dim == dim && body_tag == Some(p) {
                continue;
            }
            groups.entry((element_dim, p)).or_default().push(e);
        }
    }
    for (&(group_dim, tag), elements) in &groups {
        let name = group_name(group_dim, tag);
        let on_body = |e: &MshElement| e.nodes.iter().filter(|t| local.contains_key(t)).count();
        let touching = elements.iter().filter(|e| on_body(e) > 0).count();
        if touching == 0 {
            continue; // another body's group
        }
        if let Some(off) = elements.iter().find(|e| on_body(e) < e.nodes.len()) {
            return Err(MshError::new(
                format!("element {} of physical group '{name}'", off.tag),
                "the group lies partly on this body: the element has nodes that are not nodes of the body's cells",
                "give each body its own physical groups (a group on two bodies cannot become one set)",
            ));
        }
        let set = node_sets.entry(name.clone()).or_default();
        for e in elements {
            set.extend(e.nodes.iter().map(|t| local[t]));
        }
        if group_dim == dim - 1 {
            let mut facets = Vec::with_capacity(elements.len());
            for e in elements {
                let element_nodes: BTreeSet<usize> = e.nodes.iter().map(|t| local[t]).collect();
                let mut key: Vec<usize> = e.nodes[..corner_count(e.gmsh_type)]
                    .iter()
                    .map(|t| local[t])
                    .collect();
                key.sort_unstable();
                // the element's nodes must be the facet's, mid-side nodes too
                let facet = boundary.get(&key).copied().filter(|f| {
                    mesh.facet_nodes(*f).into_iter().collect::<BTreeSet<_>>() == element_nodes
                });
                match facet {
                    Some(f) => facets.push(f),
                    None => {
                        let (what, fix) = if D == 3 {
                            ("the face is not a boundary face of the body's cells", "put only boundary surfaces in a 2D physical group of a body (faces of the same order as the cells)")
                        } else {
                            ("the line is not a boundary edge of the body's cells", "put only boundary curves in a 1D physical group of a body (lines of the same order as the cells)")
                        };
                        return Err(MshError::new(
                            format!("element {} of physical group '{name}'", e.tag),
                            what,
                            fix,
                        ));
                    }
                }
            }
            facets.sort_unstable();
            facets.dedup();
            facet_sets.insert(name.clone(), facets);
        }
    }
    for (name, nodes) in node_sets {
        if mesh.node_sets.contains_key(&name) {
            return Err(MshError::new(
                format!("physical group '{name}'"),
                format!("'{name}' is a built-in set name"),
                if D == 3 {
                    "rename the physical group; the built-in sets are left, right, front, back, bottom, top, the corners and all"
                } else {
                    "rename the physical group; the built-in sets are left, right, bottom, top, the corners and all"
                },
            ));
        }
        mesh.node_sets.insert(name, nodes.into_iter().collect());
    }
    mesh.facet_sets.extend(facet_sets);
    Ok((mesh, mirrored))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two Q4 cells on [0,2] x [0,1] in MSH 2.2, the second clockwise, with a bottom curve,
    /// a corner point and the surface as physical groups.
    const TWO_QUADS_V22: &str = "$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
3
0 1 \"corner\"
1 2 \"base\"
2 3 \"plate\"
$EndPhysicalNames
$Nodes
6
10 0 0 0
11 1 0 0
12 2 0 0
13 0 1 0
14 1 1 0
15 2 1 0
$EndNodes
$Elements
5
1 15 2 1 1 10
2 1 2 2 1 10 11
3 1 2 2 1 11 12
4 3 2 3 1 10 11 14 13
5 3 2 3 1 11 14 15 12
$EndElements
";

    #[test]
    fn a_v22_file_becomes_cells_and_sets_with_a_clockwise_cell_mirrored() {
        let content = read_msh(TWO_QUADS_V22.as_bytes()).unwrap();
        assert_eq!(content.version, "2.2");
        let (mesh, mirrored) = body_mesh::<2, ElementKind>(&content, Some("plate")).unwrap();
        assert_eq!(mirrored, 1);
        assert_eq!(mesh.kind, ElementKind::Q4);
        // nodes in ascending tag: 10..15 -> 0..5
        assert_eq!(mesh.nodes[4], [1.0, 1.0]);
        assert_eq!(mesh.cell(0), &[0, 1, 4, 3]);
        // 11 14 15 12 (clockwise) -> 11 12 15 14
        assert_eq!(mesh.cell(1), &[1, 2, 5, 4]);
        for c in 0..2 {
            assert!(signed_area(&mesh.cell_coords(c)) > 0.0);
        }
        assert_eq!(mesh.node_sets["corner"], vec![0]);
        assert_eq!(mesh.node_sets["base"], vec![0, 1, 2]);
        assert_eq!(
            mesh.facet_sets["base"],
            vec![Facet { cell: 0, edge: 0 }, Facet { cell: 1, edge: 0 }]
        );
        // the body's own surface is not a set
        assert!(!mesh.node_sets.contains_key("plate"));
    }

    #[test]
    fn mirroring_keeps_every_edge_with_its_mid_node() {
        for kind in [ElementKind::T6, ElementKind::Q9] {
            let order = mirrored_order(kind);
            let edges = kind.edges();
            // the mirrored cell's edge k runs between old corners and holds the old mid-node
            // of the same (reversed) edge
            for e in edges {
                let (a, b, m) = (order[e[0]], order[e[1]], order[e[2]]);
                let old = edges
                    .iter()
                    .find(|f| f[0] == b && f[1] == a)
                    .expect("the reversed edge is an edge of the old cell");
                assert_eq!(old[2], m, "{kind:?}");
            }
        }
    }

    #[test]
    fn q9_and_t6_node_order_is_taken_as_written() {
        // one counter-clockwise Q9 on [0,2]^2 in MSH 2.2: corners, mid-sides 0-1 .. 3-0, centre
        let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n9\n\
            1 0 0 0\n2 2 0 0\n3 2 2 0\n4 0 2 0\n5 1 0 0\n6 2 1 0\n7 1 2 0\n8 0 1 0\n9 1 1 0\n$EndNodes\n\
            $Elements\n1\n1 10 2 0 1 1 2 3 4 5 6 7 8 9\n$EndElements\n";
        let (mesh, mirrored) =
            body_mesh::<2, ElementKind>(&read_msh(text.as_bytes()).unwrap(), None).unwrap();
        assert_eq!((mesh.kind, mirrored), (ElementKind::Q9, 0));
        assert_eq!(mesh.cell(0), &[0, 1, 2, 3, 4, 5, 6, 7, 8]);
        // edge 1 = corners 1-2 with mid-node 5 at (2, 1)
        let f = mesh.facet_nodes(Facet { cell: 0, edge: 1 });
        assert_eq!(mesh.nodes[f[2]], [2.0, 1.0]);
    }

    fn error_of(text: &str, physical: Option<&str>) -> MshError {
        read_msh(text.as_bytes())
            .and_then(|c| body_mesh::<2, ElementKind>(&c, physical))
            .map(|_| ())
            .unwrap_err()
    }

    #[test]
    fn a_truncated_file_is_refused_with_the_section() {
        let cut = &TWO_QUADS_V22[..TWO_QUADS_V22.find("$EndElements").unwrap()];
        let e = error_of(cut, Some("plate"));
        assert!(e.problem.contains("$Elements has no $EndElements"), "{e:?}");
        let cut = TWO_QUADS_V22.replace("5 3 2 3 1 11 14 15 12\n", "");
        let e = error_of(&cut, Some("plate"));
        assert!(
            e.problem.contains("announces 5 entries but lists 4"),
            "{e:?}"
        );
    }

    #[test]
    fn an_unknown_element_type_is_named_with_its_line() {
        let text = TWO_QUADS_V22.replace("5 3 2 3 1 11 14 15 12", "5 6 2 3 1 11 14 15 12 10 13");
        let e = error_of(&text, Some("plate"));
        assert_eq!(e.place, "line 25 (element 5)");
        assert!(e.problem.contains("element type 6 is not read"), "{e:?}");
    }

    #[test]
    fn a_missing_physical_group_is_named_with_those_there_are() {
        let e = error_of(TWO_QUADS_V22, Some("plates"));
        assert!(
            e.problem.contains("no physical surface named 'plates'"),
            "{e:?}"
        );
        assert!(e.hint.contains("[\"plate\"]"), "{e:?}");
    }

    #[test]
    fn other_versions_and_non_msh_files_are_refused() {
        let e = error_of("$MeshFormat\n4.0 0 8\n$EndMeshFormat\n", None);
        assert!(e.problem.contains("version 4.0 is not read"), "{e:?}");
        let e = error_of("{\"name\": 1}", None);
        assert!(e.problem.contains("not a Gmsh .msh file"), "{e:?}");
        let e = error_of("$MeshFormat\n2.2 1 8\n$EndMeshFormat\n", None);
        assert!(e.problem.contains("binary MSH 2.2"), "{e:?}");
    }

    #[test]
    fn an_interior_line_in_a_group_is_refused() {
        // the line 11-14 is the edge the two cells share
        let text = TWO_QUADS_V22.replace("3 1 2 2 1 11 12", "3 1 2 2 1 11 14");
        let e = error_of(&text, Some("plate"));
        assert_eq!(e.place, "element 3 of physical group 'base'");
        assert!(e.problem.contains("not a boundary edge"), "{e:?}");
    }

    /// The same two cells written by our MSH 4.1 writer read back the same (ASCII, via mshio).
    #[test]
    fn our_v41_writer_reads_back() {
        let mesh = crate::mesh::block(ElementKind::Q9, &[0.0, 1.0, 3.0], &[0.0, 2.0], &[]).unwrap();
        let text = crate::io::gmsh::msh(&[("slab", &mesh)]);
        let content = read_msh(text.as_bytes()).unwrap();
        assert_eq!(content.version, "4.1");
        let (back, mirrored) = body_mesh::<2, ElementKind>(&content, Some("slab")).unwrap();
        assert_eq!(mirrored, 0);
        assert_eq!(back.nodes, mesh.nodes);
        assert_eq!(back.connectivity, mesh.connectivity);
        assert_eq!(back.facet_sets["slab/top"], mesh.facet_sets["top"]);
        assert_eq!(back.node_sets["slab/top"], mesh.node_sets["top"]);
    }

    /// Gmsh's reference coordinates of its Tet10 (on the unit tetrahedron) and Hex27 (on
    /// [-1, 1]^3) nodes, in Gmsh's order (gmsh 4.15.2, `gmsh.model.mesh.getElementProperties`):
    /// read through `gmsh_order`, they are our cells' reference nodes one for one.
    #[test]
    fn gmsh_node_orders_give_our_reference_nodes() {
        use crate::fe::ReferenceCell;
        const GMSH_TET10: [[f64; 3]; 10] = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.5, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.0, 0.5, 0.0],
            [0.0, 0.0, 0.5],
            [0.0, 0.5, 0.5],
            [0.5, 0.0, 0.5],
        ];
        const GMSH_HEX27: [[f64; 3]; 27] = [
            [-1.0, -1.0, -1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, 1.0],
            [0.0, -1.0, -1.0],
            [-1.0, 0.0, -1.0],
            [-1.0, -1.0, 0.0],
            [1.0, 0.0, -1.0],
            [1.0, -1.0, 0.0],
            [0.0, 1.0, -1.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [0.0, -1.0, 1.0],
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.0, -1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0],
        ];
        for (kind, gmsh) in [
            (SolidKind::Tet10, &GMSH_TET10[..]),
            (SolidKind::Hex27, &GMSH_HEX27[..]),
        ] {
            let ours = kind.node_coordinates();
            let order = kind.gmsh_order();
            assert_eq!(order.len(), ours.len());
            for (i, &g) in order.iter().enumerate() {
                assert_eq!(
                    ours[i], gmsh[g],
                    "{kind:?}: our node {i} is Gmsh's node {g}"
                );
            }
        }
        // the corners of the linear cells are in the same order
        for kind in [SolidKind::Tet4, SolidKind::Hex8] {
            assert_eq!(
                kind.gmsh_order(),
                (0..kind.node_count()).collect::<Vec<_>>()
            );
        }
    }

    /// Two Hex8 cells on [0, 2] x [0, 1] x [0, 1] in MSH 2.2 with the bottom face of the first
    /// as the physical surface "floor", the edge x = 0, y = 0 as the curve "post" and the
    /// volume "solid".
    const TWO_HEXES_V22: &str = "$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
3
1 1 \"post\"
2 2 \"floor\"
3 3 \"solid\"
$EndPhysicalNames
$Nodes
12
1 0 0 0
2 1 0 0
3 2 0 0
4 0 1 0
5 1 1 0
6 2 1 0
7 0 0 1
8 1 0 1
9 2 0 1
10 0 1 1
11 1 1 1
12 2 1 1
$EndNodes
$Elements
4
1 1 2 1 1 1 7
2 3 2 2 2 1 2 5 4
3 5 2 3 3 1 2 5 4 7 8 11 10
4 5 2 3 3 2 3 6 5 8 9 12 11
$EndElements
";

    fn error_of_3d(text: &str, physical: Option<&str>) -> MshError {
        read_msh(text.as_bytes())
            .and_then(|c| body_mesh::<3, SolidKind>(&c, physical))
            .map(|_| ())
            .unwrap_err()
    }

    #[test]
    fn a_3d_body_reads_its_surfaces_as_facet_sets_and_curves_as_node_sets() {
        let content = read_msh(TWO_HEXES_V22.as_bytes()).unwrap();
        assert_eq!(cell_dimension(&content), 3);
        let (mesh, mirrored) = body_mesh::<3, SolidKind>(&content, Some("solid")).unwrap();
        assert_eq!(mirrored, 0);
        assert_eq!(
            (mesh.kind, mesh.cell_count(), mesh.nodes.len()),
            (SolidKind::Hex8, 2, 12)
        );
        assert_eq!(mesh.facet_sets["floor"].len(), 1);
        let floor: BTreeSet<usize> = mesh
            .facet_nodes(mesh.facet_sets["floor"][0])
            .into_iter()
            .collect();
        let expected: BTreeSet<usize> = [0, 1, 3, 4].into_iter().collect();
        assert_eq!(floor, expected, "the face 1 2 5 4 (tags) is nodes 0 1 4 3");
        assert_eq!(mesh.node_sets["floor"], vec![0, 1, 3, 4]);
        assert_eq!(mesh.node_sets["post"], vec![0, 6]);
        assert!(
            !mesh.facet_sets.contains_key("post"),
            "a curve is no facet set in 3D"
        );
        // the built-in sets of a 3D mesh are there too
        assert_eq!(mesh.node_sets["bottom"].len(), 6);
    }

    #[test]
    fn a_3d_group_inside_the_body_or_across_kinds_is_refused() {
        // the face x = 1 between the two cells
        let inner = TWO_HEXES_V22.replace("2 3 2 2 2 1 2 5 4", "2 3 2 2 2 2 5 11 8");
        let e = error_of_3d(&inner, Some("solid"));
        assert_eq!(e.place, "element 2 of physical group 'floor'");
        assert!(e.problem.contains("not a boundary face"), "{e:?}");
        // a tetrahedron in the hexahedra's volume
        let mixed = TWO_HEXES_V22
            .replace("$Elements\n4\n", "$Elements\n5\n")
            .replace("$EndElements", "5 4 2 3 3 3 6 9 12\n$EndElements");
        let e = error_of_3d(&mixed, Some("solid"));
        assert!(
            e.problem.contains("mixes Gmsh element types 5 and 4"),
            "{e:?}"
        );
        assert!(
            e.hint.contains("tetrahedra only or hexahedra only"),
            "{e:?}"
        );
        // a name that is no physical volume: the volumes there are are listed
        let e = error_of_3d(TWO_HEXES_V22, Some("floor"));
        assert!(
            e.problem.contains("no physical volume named 'floor'"),
            "{e:?}"
        );
        assert!(e.hint.contains("[\"solid\"]"), "{e:?}");
        // a curve that leaves the body (node 13 is no node of its cells)
        let partly = TWO_HEXES_V22
            .replace("$Nodes\n12\n", "$Nodes\n13\n")
            .replace("$EndNodes", "13 0 0 2\n$EndNodes")
            .replace("1 1 2 1 1 1 7", "1 1 2 1 1 7 13");
        let e = error_of_3d(&partly, Some("solid"));
        assert_eq!(e.place, "element 1 of physical group 'post'");
        assert!(e.problem.contains("lies partly on this body"), "{e:?}");
    }
}
