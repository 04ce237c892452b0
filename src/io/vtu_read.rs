//! Reading point data from a VTK XML unstructured grid (`.vtu`), so that another code's
//! results can be judged (`contact-patch judge`).
//!
//! The format is Kitware's "VTK XML file formats" (VTK User's Guide, 11th ed., ch. 19, and
//! `vtkXMLWriter`/`vtkXMLDataParser`): `<VTKFile type="UnstructuredGrid"><UnstructuredGrid>
//! <Piece NumberOfPoints=..>` holding `<Points><DataArray NumberOfComponents="3">` (the
//! coordinates, `x y z` per point) and `<PointData>` with named `<DataArray>`s of
//! `NumberOfComponents` values per point. Pieces are concatenated. Cells are not read: results
//! are matched to our nodes by position. Every encoding VTK and its users (DOLFINx, meshio,
//! ParaView, Kratos) write is read:
//!
//! * `format="ascii"`: numbers separated by white space;
//! * `format="binary"`: base64 text of a header and the array's bytes (`type`: `Float32`,
//!   `Float64`, `Int8` to `Int64`, `UInt8` to `UInt64`; the byte order of the root's
//!   `byte_order`, `LittleEndian` by default). The header is one integer of the root's
//!   `header_type` (`UInt32`, the default, or `UInt64`): the array's length in bytes. VTK
//!   encodes the header and the data as two base64 runs, meshio as two, others as one: the
//!   text is decoded run by run, a run ending at its `=` padding;
//! * `format="appended" offset="k"`: the same header and bytes at byte `k` after the `_` that
//!   opens `<AppendedData encoding="raw">` (raw bytes, the file is then not UTF-8 past that
//!   point) or at character `k` of `<AppendedData encoding="base64">`;
//! * `compressor="vtkZLibDataCompressor"` on the root (binary and appended arrays): the header
//!   is `[blocks, block size, last block size (0: a full block), compressed size of each
//!   block]` and the array's bytes are those blocks, each a zlib stream (inflated by the
//!   `flate2` crate).
//!
//! Sizes a file states are checked before anything is allocated for them. An ASCII array's
//! `NumberOfPoints` x `NumberOfComponents` must fit the file: each value takes at least one
//! character and a separator, so a text of `n` bytes holds at most `n / 2 + 1` values (and a
//! file is read up to [`MAX_VTU_BYTES`]). A binary array's header must state exactly
//! `NumberOfPoints` x `NumberOfComponents` x the type's size, within the bytes that follow it;
//! a compressed array's blocks must lie within the file, add up to that size, and expand by at
//! most [`MAX_INFLATE_RATIO`] (deflate's limit), and every block must inflate to its stated
//! size (read no further). A hostile or corrupt file is refused, naming the element or
//! attribute.

use crate::error::{Error, Result};
use base64::Engine as _;
use std::collections::{BTreeMap, HashMap};
use std::io::Read as _;
use std::path::Path;

/// The most bytes read from one results file (a 1M-node grid with a few fields is ~200 MB).
pub const MAX_VTU_BYTES: u64 = 1 << 30;

/// The most a zlib (deflate) stream expands: 258 bytes from 2 bits, 1032:1 (RFC 1951; zlib's
/// technical details). A compressed array stated larger than this times its compressed bytes
/// cannot be what the file holds.
pub const MAX_INFLATE_RATIO: usize = 1032;

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

/// The points of a `.vtu` file and their named fields (pieces concatenated), named as the file
/// names them.
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
    let bytes = std::fs::read(path).map_err(|e| Error::io(&shown, "reading", e))?;
    parse_vtu_bytes(&bytes, &shown.to_string())
}

/// Parse VTU text; `source` names it in errors.
pub fn parse_vtu(text: &str, source: &str) -> Result<PointGrid> {
    parse_vtu_bytes(text.as_bytes(), source)
}

/// The raw or base64 bytes after the `_` of `<AppendedData>`.
struct Appended<'a> {
    raw: bool,
    data: &'a [u8],
    /// Base64: where each appended array's text ends (the next array's offset).
    ends: Vec<usize>,
    /// Base64: the decoded bytes from each offset read so far.
    decoded: std::cell::RefCell<HashMap<usize, std::rc::Rc<[u8]>>>,
}

/// What the root element says about binary data, checked when a binary array is read.
struct Binary<'a> {
    header_type: Option<&'a str>,
    byte_order: Option<&'a str>,
    compressor: Option<&'a str>,
    appended: Option<Appended<'a>>,
}

/// The XML text of a file and its appended data, if any: `<AppendedData ...>_DATA
/// </AppendedData>` becomes `<AppendedData .../>` in the text (raw data need not be UTF-8).
fn split_appended<'a>(bytes: &'a [u8], source: &str) -> Result<(String, Option<&'a [u8]>)> {
    let find = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).position(|w| w == needle);
    let utf8 = |part: &[u8], what: &str| -> Result<String> {
        String::from_utf8(part.to_vec()).map_err(|e| {
            Error::invalid(
                source,
                what,
                format!(
                    "not UTF-8 text (byte {} is not part of a UTF-8 character)",
                    e.utf8_error().valid_up_to()
                ),
                "a .vtu file is XML text in UTF-8; raw binary data belongs after the '_' of \
                 <AppendedData encoding=\"raw\">, or write the arrays as ASCII or base64 \
                 (format=\"binary\")",
            )
        })
    };
    let Some(start) = find(bytes, b"<AppendedData") else {
        return Ok((utf8(bytes, "XML")?, None));
    };
    let bad = |problem: &str| {
        Error::invalid(
            source,
            "<AppendedData>",
            problem,
            "VTK writes <AppendedData encoding=\"raw\">_DATA</AppendedData> (or \
             encoding=\"base64\") after the <UnstructuredGrid> element; write the file again",
        )
    };
    let Some(gt) = bytes[start..]
        .iter()
        .position(|&b| b == b'>')
        .map(|k| start + k)
    else {
        return Err(bad("the element's start tag is not closed"));
    };
    let head = utf8(&bytes[..gt], "XML")?;
    if head.ends_with('/') {
        return Ok((utf8(bytes, "XML")?, None));
    }
    const CLOSE: &[u8] = b"</AppendedData>";
    let close = bytes
        .windows(CLOSE.len())
        .rposition(|w| w == CLOSE)
        .filter(|&c| c > gt)
        .ok_or_else(|| bad("no </AppendedData> after the data"))?;
    let body = &bytes[gt + 1..close];
    let Some(underscore) = body.iter().position(|b| !b.is_ascii_whitespace()) else {
        return Err(bad("no '_' before the data"));
    };
    if body[underscore] != b'_' {
        return Err(bad("the data does not start with '_'"));
    }
    let tail = utf8(&bytes[close + CLOSE.len()..], "XML after </AppendedData>")?;
    let xml = format!("{head}/>{tail}");
    // the encoding is read from the element itself once the XML is parsed
    Ok((xml, Some(&body[underscore + 1..])))
}

/// Parse the bytes of a `.vtu` file; `source` names it in errors.
pub fn parse_vtu_bytes(bytes: &[u8], source: &str) -> Result<PointGrid> {
    let bad = |location: String, problem: String, hint: &str| {
        Error::invalid(source, location, problem, hint)
    };
    let (text, appended) = split_appended(bytes, source)?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| {
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
    let appended = match appended {
        None => None,
        Some(data) => {
            let element = root
                .children()
                .find(|n| n.has_tag_name("AppendedData"))
                .ok_or_else(|| {
                    bad(
                        "<AppendedData>".into(),
                        "the element is not a child of <VTKFile>".into(),
                        "VTK writes <AppendedData> as the last child of <VTKFile>",
                    )
                })?;
            let raw = match element.attribute("encoding").unwrap_or("raw") {
                "raw" => true,
                "base64" => false,
                other => {
                    return Err(bad(
                        "<AppendedData>".into(),
                        format!("encoding=\"{other}\" is not a VTK encoding"),
                        "VTK writes encoding=\"raw\" or encoding=\"base64\"",
                    ))
                }
            };
            let mut ends: Vec<usize> = doc
                .descendants()
                .filter(|n| n.has_tag_name("DataArray"))
                .filter(|n| n.attribute("format") == Some("appended"))
                .filter_map(|n| n.attribute("offset")?.trim().parse().ok())
                .collect();
            ends.sort_unstable();
            ends.dedup();
            Some(Appended {
                raw,
                data,
                ends,
                decoded: Default::default(),
            })
        }
    };
    let binary = Binary {
        header_type: root.attribute("header_type"),
        byte_order: root.attribute("byte_order"),
        compressor: root.attribute("compressor"),
        appended,
    };
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
        let coords = data_array(
            &coords,
            count,
            room,
            &binary,
            source,
            &format!("{at} <Points>"),
        )?;
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
                    &binary,
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

/// The number types of VTK data arrays.
#[derive(Clone, Copy, Debug)]
enum Scalar {
    F32,
    F64,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
}

impl Scalar {
    fn of(name: &str) -> Option<Scalar> {
        Some(match name {
            "Float32" => Scalar::F32,
            "Float64" => Scalar::F64,
            "Int8" => Scalar::I8,
            "UInt8" => Scalar::U8,
            "Int16" => Scalar::I16,
            "UInt16" => Scalar::U16,
            "Int32" => Scalar::I32,
            "UInt32" => Scalar::U32,
            "Int64" => Scalar::I64,
            "UInt64" => Scalar::U64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::F32 | Scalar::I32 | Scalar::U32 => 4,
            Scalar::F64 | Scalar::I64 | Scalar::U64 => 8,
        }
    }

    /// The value of the `size()` bytes `b` in the byte order `little`.
    fn value(self, b: &[u8], little: bool) -> f64 {
        let mut a = [0u8; 8];
        let n = self.size();
        a[..n].copy_from_slice(&b[..n]);
        if !little {
            a[..n].reverse();
        }
        match self {
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::I64 => i64::from_le_bytes(a) as f64,
            Scalar::U64 => u64::from_le_bytes(a) as f64,
        }
    }
}

/// Base64 text decoded run by run, each run ending at its `=` padding (VTK and meshio encode
/// a header and its data as separate runs); white space is skipped.
fn decode_base64(text: &[u8]) -> std::result::Result<Vec<u8>, String> {
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .filter(|b| !b.is_ascii_whitespace())
        .collect();
    let mut out = Vec::with_capacity(clean.len() / 4 * 3 + 3);
    let mut decode = |start: usize, end: usize| {
        base64::engine::general_purpose::STANDARD
            .decode_vec(&clean[start..end], &mut out)
            .map_err(|e| {
                format!(
                    "not base64 (characters {} to {end} of the data: {e})",
                    start + 1
                )
            })
    };
    let mut start = 0;
    for i in 0..clean.len() {
        if clean[i] == b'=' && clean.get(i + 1) != Some(&b'=') {
            decode(start, i + 1)?;
            start = i + 1;
        }
    }
    if start < clean.len() {
        decode(start, clean.len())?;
    }
    Ok(out)
}

/// How a binary array's bytes are laid out (the root's attributes).
#[derive(Clone, Copy)]
struct Layout {
    header: usize,
    little: bool,
    zlib: bool,
}

/// The `header`-byte unsigned integer number `k` of `s`, if `s` holds it.
fn header_int(s: &[u8], k: usize, layout: Layout) -> Option<usize> {
    let at = k.checked_mul(layout.header)?;
    let b = s.get(at..at.checked_add(layout.header)?)?;
    let mut v: u64 = 0;
    let mut push = |x: &u8| v = v << 8 | u64::from(*x);
    if layout.little {
        b.iter().rev().for_each(&mut push);
    } else {
        b.iter().for_each(&mut push);
    }
    Some(usize::try_from(v).unwrap_or(usize::MAX))
}

/// The `want` bytes of a binary array that start at the beginning of `s` (its header, then its
/// data, as the module notes say), or what is wrong and how to fix it.
fn array_bytes(
    s: &[u8],
    layout: Layout,
    want: usize,
) -> std::result::Result<std::borrow::Cow<'_, [u8]>, (String, &'static str)> {
    let h = layout.header;
    let short = |what: String| {
        (
            what,
            "the array's data is cut short or its header is wrong: write the file again",
        )
    };
    let Some(first) = header_int(s, 0, layout) else {
        return Err(short(format!(
            "{} bytes of data, shorter than the {h}-byte header (header_type)",
            s.len()
        )));
    };
    if !layout.zlib {
        if first != want {
            return Err((
                format!(
                    "the header states {first} bytes of data where NumberOfPoints x \
                     NumberOfComponents x the type's size = {want} were expected"
                ),
                "the header is one integer of the file's header_type (UInt32 unless \
                 header_type=\"UInt64\"), the array's length in bytes; check header_type, the \
                 array's type and NumberOfComponents",
            ));
        }
        let data = s.get(h..).unwrap_or(&[]);
        if data.len() < want {
            return Err(short(format!(
                "the header states {want} bytes of data, but {} follow it",
                data.len()
            )));
        }
        return Ok(std::borrow::Cow::Borrowed(&data[..want]));
    }
    let blocks = first;
    let header_len = blocks
        .checked_add(3)
        .and_then(|n| n.checked_mul(h))
        .filter(|&n| n <= s.len())
        .ok_or_else(|| {
            short(format!(
                "the compression header states {blocks} blocks, more than the {} bytes of the \
                 array can describe",
                s.len()
            ))
        })?;
    let block_size = header_int(s, 1, layout).expect("within the header");
    let last = header_int(s, 2, layout).expect("within the header");
    if last > block_size {
        return Err(short(format!(
            "the last block's size {last} is larger than the block size {block_size}"
        )));
    }
    let total = if blocks == 0 {
        Some(0)
    } else {
        (blocks - 1)
            .checked_mul(block_size)
            .and_then(|n| n.checked_add(if last == 0 { block_size } else { last }))
    };
    if total != Some(want) {
        return Err((
            format!(
                "the compression header states {blocks} blocks of {block_size} bytes (the last \
                 {last}), not the {want} bytes NumberOfPoints x NumberOfComponents x the type's \
                 size make"
            ),
            "the header is [blocks, block size, last block size, compressed sizes] in integers \
             of the file's header_type (UInt32 unless header_type=\"UInt64\"); check \
             header_type, the array's type and NumberOfComponents",
        ));
    }
    let mut compressed = Vec::with_capacity(blocks);
    let mut sum = 0usize;
    for b in 0..blocks {
        let c = header_int(s, 3 + b, layout).expect("within the header");
        sum = sum.saturating_add(c);
        compressed.push(c);
    }
    if sum > s.len() - header_len {
        return Err(short(format!(
            "the compressed blocks add up to {sum} bytes, but {} follow the header",
            s.len() - header_len
        )));
    }
    if want > sum.saturating_mul(MAX_INFLATE_RATIO) || want as u64 > MAX_VTU_BYTES {
        return Err((
            format!(
                "{want} bytes from {sum} compressed bytes: more than zlib expands \
                 ({MAX_INFLATE_RATIO}:1), or more than {MAX_VTU_BYTES} bytes"
            ),
            "the file is corrupt or hostile: NumberOfPoints or the compression header is wrong",
        ));
    }
    let mut out = Vec::with_capacity(want);
    let mut at = header_len;
    for (b, &c) in compressed.iter().enumerate() {
        let size = if b + 1 == blocks && last != 0 {
            last
        } else {
            block_size
        };
        let before = out.len();
        flate2::read::ZlibDecoder::new(&s[at..at + c])
            .take(size as u64 + 1)
            .read_to_end(&mut out)
            .map_err(|e| short(format!("block {} is not a zlib stream: {e}", b + 1)))?;
        if out.len() - before != size {
            return Err(short(format!(
                "block {} inflates to {} bytes, not the {size} its header states",
                b + 1,
                out.len() - before
            )));
        }
        at += c;
    }
    Ok(std::borrow::Cow::Owned(out))
}

/// The layout of binary arrays from the root's attributes, or what is wrong with them.
fn layout_of(binary: &Binary) -> std::result::Result<Layout, (String, &'static str)> {
    let header = match binary.header_type.unwrap_or("UInt32") {
        "UInt32" => 4,
        "UInt64" => 8,
        other => {
            return Err((
                format!("header_type=\"{other}\" on <VTKFile> is not UInt32 or UInt64"),
                "VTK writes header_type=\"UInt32\" (the default) or \"UInt64\"",
            ))
        }
    };
    let little = match binary.byte_order.unwrap_or("LittleEndian") {
        "LittleEndian" => true,
        "BigEndian" => false,
        other => {
            return Err((
                format!("byte_order=\"{other}\" on <VTKFile> is not LittleEndian or BigEndian"),
                "VTK writes byte_order=\"LittleEndian\" or \"BigEndian\"",
            ))
        }
    };
    let zlib = match binary.compressor {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(other) => {
            return Err((
                format!(
                    "compressor=\"{other}\" on <VTKFile>: only vtkZLibDataCompressor \
                     compression is read"
                ),
                "write the file with zlib compression or none (VTK: \
                 SetCompressorTypeToZLib() or SetCompressorTypeToNone(); meshio: \
                 compression=\"zlib\" or None)",
            ))
        }
    };
    Ok(Layout {
        header,
        little,
        zlib,
    })
}

/// One `<DataArray>` with `count` tuples (`NumberOfPoints` of its piece), in any of the
/// encodings of the module notes, the sizes checked before anything is allocated for them.
fn data_array(
    node: &roxmltree::Node,
    count: usize,
    room: Room,
    binary: &Binary,
    source: &str,
    location: &str,
) -> Result<PointField> {
    let bad = |problem: String, hint: &str| Error::invalid(source, location, problem, hint);
    let format = node.attribute("format").unwrap_or("ascii");
    let components: usize = match node.attribute("NumberOfComponents") {
        None => 1,
        Some(v) => v.trim().parse().ok().filter(|&c| c > 0).ok_or_else(|| {
            bad(
                format!("NumberOfComponents=\"{v}\" is not a positive integer"),
                "state how many values each point has",
            )
        })?,
    };
    let too_many = |room_words: String| {
        bad(
            format!(
                "NumberOfPoints=\"{count}\" x NumberOfComponents=\"{components}\" values are \
                 more than {room_words}"
            ),
            "correct the NumberOfPoints of the <Piece> or the NumberOfComponents of the \
             array: the file is corrupt or was not written by a VTK writer",
        )
    };
    let expected = count.checked_mul(components);
    if format == "ascii" {
        let expected = expected.filter(|&n| n <= room.values).ok_or_else(|| {
            too_many(format!(
                "a file of {} bytes can hold (at most {}: each value takes a character and a \
                 separator; results files are read up to {MAX_VTU_BYTES} bytes)",
                room.bytes, room.values
            ))
        })?;
        return ascii_values(node, count, components, expected, &bad);
    }
    let scalar = match node.attribute("type") {
        Some(t) => Scalar::of(t).ok_or_else(|| {
            bad(
                format!("type=\"{t}\" is not a VTK number type"),
                "binary arrays state their type: Float32, Float64, Int8 to Int64 or UInt8 to \
                 UInt64",
            )
        })?,
        None => {
            return Err(bad(
                "no type attribute".into(),
                "binary arrays state their type: Float32, Float64, Int8 to Int64 or UInt8 to \
                 UInt64",
            ))
        }
    };
    let layout = layout_of(binary).map_err(|(problem, hint)| bad(problem, hint))?;
    let want = expected
        .and_then(|n| n.checked_mul(scalar.size()))
        .filter(|&n| n as u64 <= MAX_VTU_BYTES)
        .ok_or_else(|| too_many(format!("{MAX_VTU_BYTES} bytes of {scalar:?} can hold")))?;
    let values_of = |bytes: &[u8]| PointField {
        components,
        values: bytes
            .chunks_exact(scalar.size())
            .map(|b| scalar.value(b, layout.little))
            .collect(),
    };
    match format {
        "binary" => {
            let mut text = Vec::new();
            for t in node.descendants().filter(|n| n.is_text()) {
                text.extend_from_slice(t.text().unwrap_or("").as_bytes());
            }
            let decoded = decode_base64(&text).map_err(|why| {
                bad(
                    format!("format=\"binary\": {why}"),
                    "binary arrays hold base64 text (RFC 4648) of a header and the data; for \
                     numbers as text write format=\"ascii\"",
                )
            })?;
            let bytes = array_bytes(&decoded, layout, want)
                .map_err(|(problem, hint)| bad(problem, hint))?;
            Ok(values_of(&bytes))
        }
        "appended" => {
            let Some(appended) = &binary.appended else {
                return Err(bad(
                    "format=\"appended\" but the file has no <AppendedData> element".into(),
                    "appended arrays point into <AppendedData encoding=\"raw\">_DATA\
                     </AppendedData> at the end of the file",
                ));
            };
            let offset: usize = node
                .attribute("offset")
                .and_then(|v| v.trim().parse().ok())
                .ok_or_else(|| {
                    bad(
                        format!(
                            "offset=\"{}\" is not a byte offset",
                            node.attribute("offset").unwrap_or("")
                        ),
                        "an appended array states where its data starts after the '_' of \
                         <AppendedData>: offset=\"K\"",
                    )
                })?;
            if offset > appended.data.len() {
                return Err(bad(
                    format!(
                        "offset=\"{offset}\" is past the end of the {} bytes of <AppendedData>",
                        appended.data.len()
                    ),
                    "the offset counts from the byte after the '_' of <AppendedData>: write the \
                     file again",
                ));
            }
            let bytes = if appended.raw {
                array_bytes(&appended.data[offset..], layout, want)
                    .map_err(|(problem, hint)| bad(problem, hint))?
                    .into_owned()
            } else {
                let stream = appended.base64_from(offset).map_err(|why| {
                    bad(
                        format!("<AppendedData encoding=\"base64\"> at offset {offset}: {why}"),
                        "base64 appended data holds the base64 text of each array's header and \
                         data at its offset",
                    )
                })?;
                array_bytes(&stream, layout, want)
                    .map_err(|(problem, hint)| bad(problem, hint))?
                    .into_owned()
            };
            Ok(values_of(&bytes))
        }
        other => Err(bad(
            format!("format=\"{other}\" is not a VTK data format"),
            "VTK arrays are format=\"ascii\", \"binary\" (base64) or \"appended\"",
        )),
    }
}

impl Appended<'_> {
    /// The bytes decoded from the base64 text at `offset` up to the next array's offset.
    fn base64_from(&self, offset: usize) -> std::result::Result<std::rc::Rc<[u8]>, String> {
        if let Some(d) = self.decoded.borrow().get(&offset) {
            return Ok(d.clone());
        }
        let end = self
            .ends
            .iter()
            .copied()
            .find(|&e| e > offset)
            .unwrap_or(self.data.len())
            .min(self.data.len());
        let d: std::rc::Rc<[u8]> = decode_base64(&self.data[offset..end])?.into();
        self.decoded.borrow_mut().insert(offset, d.clone());
        Ok(d)
    }
}

/// The values of an ASCII array: `expected` numbers (already checked against the file).
fn ascii_values(
    node: &roxmltree::Node,
    count: usize,
    components: usize,
    expected: usize,
    bad: &dyn Fn(String, &str) -> Error,
) -> Result<PointField> {
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
    use base64::engine::general_purpose::STANDARD;
    use std::io::Write as _;

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

    /// `TWO_POINTS` with the array 'p' (values 7, 8) given as `format` and `content`, the root
    /// carrying `root` attributes and the file ending with `appended`.
    fn with_p(root: &str, format: &str, content: &str, appended: &[u8]) -> Vec<u8> {
        let text = TWO_POINTS
            .replace(
                "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">",
                &format!("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" {root}>"),
            )
            .replace(
                "<DataArray type=\"Float64\" Name=\"p\" format=\"ascii\">7 8</DataArray>",
                &format!("<DataArray type=\"Float64\" Name=\"p\" {format}>{content}</DataArray>"),
            );
        let (head, tail) = text.split_at(text.rfind("</VTKFile>").unwrap());
        let mut bytes = head.as_bytes().to_vec();
        bytes.extend_from_slice(appended);
        bytes.extend_from_slice(tail.as_bytes());
        bytes
    }

    fn p_bytes() -> Vec<u8> {
        [7.0f64, 8.0].iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    fn p_of(bytes: &[u8]) -> std::result::Result<Vec<f64>, String> {
        parse_vtu_bytes(bytes, "t.vtu")
            .map(|g| g.fields["p"].values.clone())
            .map_err(|e| e.to_string())
    }

    #[test]
    fn binary_appended_and_compressed_arrays_are_read() {
        let data = p_bytes();
        // base64 of header and data as one run (UInt64 header) and as two runs (UInt32)
        let mut one = 16u64.to_le_bytes().to_vec();
        one.extend_from_slice(&data);
        let one = STANDARD.encode(&one);
        let two = STANDARD.encode(16u32.to_le_bytes()) + &STANDARD.encode(&data);
        assert_eq!(
            p_of(&with_p(
                "header_type=\"UInt64\"",
                "format=\"binary\"",
                &one,
                b""
            )),
            Ok(vec![7.0, 8.0])
        );
        assert_eq!(
            p_of(&with_p("", "format=\"binary\"", &two, b"")),
            Ok(vec![7.0, 8.0])
        );
        // big-endian
        let big: Vec<u8> = 16u32
            .to_be_bytes()
            .into_iter()
            .chain([7.0f64, 8.0].iter().flat_map(|v| v.to_be_bytes()))
            .collect();
        assert_eq!(
            p_of(&with_p(
                "byte_order=\"BigEndian\"",
                "format=\"binary\"",
                &STANDARD.encode(&big),
                b""
            )),
            Ok(vec![7.0, 8.0])
        );
        // appended raw, after another array's 4 bytes
        let mut raw = b"\n<AppendedData encoding=\"raw\">\n _".to_vec();
        raw.extend_from_slice(&[0xff, 0xfe, 0, 0]);
        raw.extend_from_slice(&16u32.to_le_bytes());
        raw.extend_from_slice(&data);
        raw.extend_from_slice(b"\n</AppendedData>\n");
        assert_eq!(
            p_of(&with_p("", "format=\"appended\" offset=\"4\"", "", &raw)),
            Ok(vec![7.0, 8.0])
        );
        // appended base64
        let b64 = format!("<AppendedData encoding=\"base64\">_{two}</AppendedData>");
        assert_eq!(
            p_of(&with_p(
                "",
                "format=\"appended\" offset=\"0\"",
                "",
                b64.as_bytes()
            )),
            Ok(vec![7.0, 8.0])
        );
        // zlib: two blocks of 8 bytes (the last full: its size 0)
        let blocks: Vec<Vec<u8>> = data
            .chunks(8)
            .map(|c| {
                let mut z = flate2::write::ZlibEncoder::new(Vec::new(), Default::default());
                z.write_all(c).unwrap();
                z.finish().unwrap()
            })
            .collect();
        let header: Vec<u8> = [2, 8, 0, blocks[0].len() as u32, blocks[1].len() as u32]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let zipped = STANDARD.encode(&header) + &STANDARD.encode(blocks.concat());
        assert_eq!(
            p_of(&with_p(
                "compressor=\"vtkZLibDataCompressor\"",
                "format=\"binary\"",
                &zipped,
                b""
            )),
            Ok(vec![7.0, 8.0])
        );
    }

    #[test]
    fn hostile_binary_sizes_are_refused_before_allocation() {
        let data = p_bytes();
        let binary = |header: &[u8], data: &[u8], root: &str| {
            p_of(&with_p(
                root,
                "format=\"binary\"",
                &(STANDARD.encode(header) + &STANDARD.encode(data)),
                b"",
            ))
            .unwrap_err()
        };
        // a header that lies, and one that states what NumberOfPoints says but is cut short
        let e = binary(&u32::MAX.to_le_bytes(), &data, "");
        assert!(e.contains("states 4294967295 bytes of data where"), "{e}");
        let many = TWO_POINTS.replace(
            "Name=\"p\" format=\"ascii\">7 8",
            &format!(
                "Name=\"p\" NumberOfComponents=\"1000000000000\" format=\"binary\">{}",
                STANDARD.encode(u32::MAX.to_le_bytes())
            ),
        );
        let e = parse_vtu(&many, "t.vtu").unwrap_err().to_string();
        assert!(
            e.contains("values are more than 1073741824 bytes of F64"),
            "{e}"
        );
        let e = binary(&16u32.to_le_bytes(), &data[..8], "");
        assert!(e.contains("states 16 bytes of data, but 8 follow"), "{e}");
        // compressed: a block count beyond the array, and more than zlib can expand to
        let zlib = "compressor=\"vtkZLibDataCompressor\"";
        let header: Vec<u8> = [u32::MAX, 8, 0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let e = binary(&header, &data, zlib);
        assert!(e.contains("states 4294967295 blocks"), "{e}");
        // 2 points x 10^7 components x 8 bytes from 4 compressed bytes
        let header: Vec<u8> = [1u32, 160_000_000, 0, 4]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let bomb = TWO_POINTS
            .replace(
                "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">",
                &format!("<VTKFile type=\"UnstructuredGrid\" {zlib}>"),
            )
            .replace(
                "Name=\"p\" format=\"ascii\">7 8",
                &format!(
                    "Name=\"p\" NumberOfComponents=\"10000000\" format=\"binary\">{}{}",
                    STANDARD.encode(&header),
                    STANDARD.encode([0u8; 4])
                ),
            );
        let e = parse_vtu(&bomb, "t.vtu").unwrap_err().to_string();
        assert!(e.contains("more than zlib expands"), "{e}");
        // a block that is not zlib, and not base64 at all
        let header: Vec<u8> = [1u32, 16, 0, 16]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let e = binary(&header, &data, zlib);
        assert!(e.contains("block 1 is not a zlib stream"), "{e}");
        let e = p_of(&with_p("", "format=\"binary\"", "7 8", b"")).unwrap_err();
        assert!(e.contains("not base64"), "{e}");
        // appended data without its element, past its end, and raw bytes outside it
        let e = p_of(&with_p("", "format=\"appended\" offset=\"0\"", "", b"")).unwrap_err();
        assert!(e.contains("no <AppendedData> element"), "{e}");
        let raw = b"<AppendedData encoding=\"raw\">_\x10\x00\x00\x00</AppendedData>";
        let e = p_of(&with_p("", "format=\"appended\" offset=\"99\"", "", raw)).unwrap_err();
        assert!(e.contains("past the end of the 4 bytes"), "{e}");
        let e = p_of(&with_p("", "format=\"binary\"", "AAAA", b"\xff")).unwrap_err();
        assert!(e.contains("not UTF-8"), "{e}");
        let e = p_of(&with_p(
            "header_type=\"UInt16\"",
            "format=\"binary\"",
            "AAAA",
            b"",
        ))
        .unwrap_err();
        assert!(e.contains("header_type=\"UInt16\""), "{e}");
    }

    #[test]
    fn refusals_say_what_and_how_to_fix() {
        let short = TWO_POINTS.replace("-4 5.25 0", "-4 5.25");
        let e = parse_vtu(&short, "t.vtu").unwrap_err().to_string();
        assert!(
            e.contains("5 values where 2 points x 3 components = 6"),
            "{e}"
        );
        let word = TWO_POINTS.replace("7 8", "7 x");
        let e = parse_vtu(&word, "t.vtu").unwrap_err().to_string();
        assert!(e.contains("'x' (value 2) is not a number"), "{e}");
        let e = parse_vtu(&TWO_POINTS.replace("ascii\">7", "raw\">7"), "t.vtu")
            .unwrap_err()
            .to_string();
        assert!(e.contains("format=\"raw\" is not a VTK data format"), "{e}");
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
