//! Meshes: nodes, cells of one element kind, boundary facets, and named node and facet sets.
//!
//! The structured block generator takes the vertex coordinates along x and y as arbitrary lists
//! of breaks (the contact patch meshes need uneven, non-nested breaks), optionally moves some
//! vertices to distort the grid, and derives the higher-order nodes from the (moved) vertices:
//! mid-side nodes at edge midpoints, the Q9 centre at the mean of its corners, so every element
//! keeps straight sides. A move may also start at a mid-side or centre node (where the vertex
//! moves left it) and then moves that node alone, which curves a side. Triangles split each quadrilateral cell along the diagonal from its
//! lower-left to its upper-right vertex.
//!
//! A facet is `(cell, local edge)`; only boundary facets (edges owned by one cell) enter facet
//! sets. Every body gets the sets `left`, `right`, `bottom`, `top` (nodes and boundary facets on
//! the sides of its bounding box), the corner node sets `bottom_left`, `bottom_right`,
//! `top_left`, `top_right`, and `all` (nodes). The 3D block takes these sets on its unmoved
//! grid, so they are the block's sides whatever its moves do to the coordinates.

use crate::fe::{ElementKind, ReferenceCell};
use crate::fe3d::SolidKind;
use std::collections::BTreeMap;

/// A facet: a cell and one of its local facets (an edge in 2D, a face in 3D; the field keeps
/// the 2D name `edge`), numbered as in [`ReferenceCell::facets`].
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Facet {
    pub cell: usize,
    pub edge: usize,
}

/// A mesh in `D` dimensions of cells of one kind `K`; `Mesh` alone is the 2D mesh of
/// [`ElementKind`] cells, [`Mesh3`] the 3D mesh of [`SolidKind`] cells.
#[derive(Clone, Debug)]
pub struct Mesh<const D: usize = 2, K = ElementKind> {
    pub kind: K,
    pub nodes: Vec<[f64; D]>,
    /// Flat connectivity, `kind.node_count()` entries per cell.
    pub connectivity: Vec<usize>,
    pub node_sets: BTreeMap<String, Vec<usize>>,
    pub facet_sets: BTreeMap<String, Vec<Facet>>,
}

/// A 3D mesh of solid cells.
pub type Mesh3 = Mesh<3, SolidKind>;

/// Names of the two sides of the bounding box along each axis, `[low, high]`: x left/right and
/// y bottom/top in 2D; x left/right, y front/back and z bottom/top in 3D.
fn side_names(dim: usize) -> &'static [[&'static str; 2]] {
    const PLANE: [[&str; 2]; 2] = [["left", "right"], ["bottom", "top"]];
    const SOLID: [[&str; 2]; 3] = [["left", "right"], ["front", "back"], ["bottom", "top"]];
    if dim == 2 {
        &PLANE
    } else {
        &SOLID
    }
}

impl<const D: usize, K: ReferenceCell<D>> Mesh<D, K> {
    /// Build a mesh from explicit data and add the automatic sets.
    pub fn new(kind: K, nodes: Vec<[f64; D]>, connectivity: Vec<usize>) -> Self {
        let mut mesh = Mesh {
            kind,
            nodes,
            connectivity,
            node_sets: BTreeMap::new(),
            facet_sets: BTreeMap::new(),
        };
        mesh.add_automatic_sets();
        mesh
    }

    pub fn cell_count(&self) -> usize {
        self.connectivity.len() / self.kind.node_count()
    }

    pub fn cell(&self, c: usize) -> &[usize] {
        let nn = self.kind.node_count();
        &self.connectivity[c * nn..(c + 1) * nn]
    }

    /// Coordinates of the nodes of cell `c`, in element order.
    pub fn cell_coords(&self, c: usize) -> Vec<[f64; D]> {
        self.cell(c).iter().map(|&n| self.nodes[n]).collect()
    }

    /// Global node ids of a facet, in facet order (2D: `[start, end(, mid)]`).
    pub fn facet_nodes(&self, f: Facet) -> Vec<usize> {
        let cell = self.cell(f.cell);
        self.kind.facets()[f.edge]
            .iter()
            .map(|&l| cell[l])
            .collect()
    }

    /// Axis-aligned bounding box `[min, max]`.
    pub fn bounding_box(&self) -> [[f64; D]; 2] {
        let mut lo = [f64::INFINITY; D];
        let mut hi = [f64::NEG_INFINITY; D];
        let used = self.used_nodes();
        for p in self
            .nodes
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|(p, _)| p)
        {
            for i in 0..D {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        [lo, hi]
    }

    /// A length scale for geometric tolerances: the largest side of the bounding box.
    pub fn size(&self) -> f64 {
        let [lo, hi] = self.bounding_box();
        (0..D)
            .map(|i| hi[i] - lo[i])
            .fold(f64::NEG_INFINITY, f64::max)
            .max(f64::MIN_POSITIVE)
    }

    /// The sorted corner nodes of facet `k` of cell `c` (unused entries `usize::MAX`): a key
    /// that two cells sharing the facet give alike.
    fn facet_key(&self, c: usize, k: usize) -> [usize; 4] {
        let cell = self.cell(c);
        let local = self.kind.facets()[k];
        let mut key = [usize::MAX; 4];
        for (slot, &l) in key
            .iter_mut()
            .zip(&local[..self.kind.facet_corner_count(k)])
        {
            *slot = cell[l];
        }
        key.sort_unstable();
        key
    }

    /// Facets that belong to exactly one cell, in cell order. The facets are bucketed by their
    /// smallest node (a counting sort, linear in the facets), and a facet is on the boundary
    /// when no other facet of its bucket has the same corner nodes.
    pub fn boundary_facets(&self) -> Vec<Facet> {
        let facet_count = self.kind.facets().len();
        let total = self.cell_count() * facet_count;
        let keys: Vec<[usize; 4]> = (0..total)
            .map(|f| self.facet_key(f / facet_count, f % facet_count))
            .collect();
        let mut start = vec![0usize; self.nodes.len() + 1];
        for key in &keys {
            start[key[0] + 1] += 1;
        }
        for v in 0..self.nodes.len() {
            start[v + 1] += start[v];
        }
        let mut next = start.clone();
        let mut bucketed = vec![0usize; total];
        for (f, key) in keys.iter().enumerate() {
            bucketed[next[key[0]]] = f;
            next[key[0]] += 1;
        }
        let mut shared = vec![false; total];
        for v in 0..self.nodes.len() {
            let bucket = &bucketed[start[v]..start[v + 1]];
            for (a, &f) in bucket.iter().enumerate() {
                for &g in &bucket[a + 1..] {
                    if keys[f] == keys[g] {
                        shared[f] = true;
                        shared[g] = true;
                    }
                }
            }
        }
        (0..total)
            .filter(|&f| !shared[f])
            .map(|f| Facet {
                cell: f / facet_count,
                edge: f % facet_count,
            })
            .collect()
    }

    /// Nodes inside the closed box `[lo, hi]` (with tolerance `tol`).
    pub fn nodes_in_box(&self, lo: [f64; D], hi: [f64; D], tol: f64) -> Vec<usize> {
        let used = self.used_nodes();
        (0..self.nodes.len())
            .filter(|&n| used[n] && inside(self.nodes[n], lo, hi, tol))
            .collect()
    }

    /// Whether each node is a node of some cell. The bounding box and every set chosen by
    /// position ignore the others: a stray node far away (a point of a Gmsh geometry, a typo
    /// in an explicit list) neither moves `top` onto itself nor lands in a box.
    pub fn used_nodes(&self) -> Vec<bool> {
        let mut used = vec![false; self.nodes.len()];
        for &n in &self.connectivity {
            if let Some(u) = used.get_mut(n) {
                *u = true;
            }
        }
        used
    }

    /// Boundary facets whose nodes all lie in the closed box `[lo, hi]`.
    pub fn facets_in_box(&self, lo: [f64; D], hi: [f64; D], tol: f64) -> Vec<Facet> {
        self.select_facets(&self.boundary_facets(), lo, hi, tol)
    }

    /// The facets of `candidates` whose nodes all lie in the closed box `[lo, hi]`.
    fn select_facets(
        &self,
        candidates: &[Facet],
        lo: [f64; D],
        hi: [f64; D],
        tol: f64,
    ) -> Vec<Facet> {
        let facets = self.kind.facets();
        candidates
            .iter()
            .copied()
            .filter(|f| {
                let cell = self.cell(f.cell);
                facets[f.edge]
                    .iter()
                    .all(|&l| inside(self.nodes[cell[l]], lo, hi, tol))
            })
            .collect()
    }

    /// The node closest to `p`, with its distance.
    pub fn nearest_node(&self, p: [f64; D]) -> Option<(usize, f64)> {
        self.nodes
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let d2 = (1..D).fold((q[0] - p[0]).powi(2), |s, k| s + (q[k] - p[k]).powi(2));
                (i, d2.sqrt())
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// A geometric tolerance relative to the mesh size.
    pub fn tolerance(&self) -> f64 {
        1e-9 * self.size()
    }

    /// The sides of the bounding box as node and facet sets (names from [`side_names`]), the
    /// corners as node sets (side names from the last axis to the first joined by `_`, e.g.
    /// `bottom_left` in 2D, `bottom_front_left` in 3D), and `all`.
    fn add_automatic_sets(&mut self) {
        if self.nodes.is_empty() {
            return;
        }
        let [lo, hi] = self.bounding_box();
        let tol = self.tolerance();
        let boundary = self.boundary_facets();
        let names = side_names(D);
        for axis in 0..D {
            for (side, name) in names[axis].iter().enumerate() {
                let mut a = [f64::NEG_INFINITY; D];
                let mut b = [f64::INFINITY; D];
                let at = if side == 0 { lo[axis] } else { hi[axis] };
                a[axis] = at;
                b[axis] = at;
                let nodes = self.nodes_in_box(a, b, tol);
                let facets = self.select_facets(&boundary, a, b, tol);
                self.node_sets.insert(name.to_string(), nodes);
                self.facet_sets.insert(name.to_string(), facets);
            }
        }
        for corner in 0..(1usize << D) {
            let mut p = [0.0; D];
            let mut parts = Vec::with_capacity(D);
            for axis in (0..D).rev() {
                let side = (corner >> axis) & 1;
                p[axis] = if side == 0 { lo[axis] } else { hi[axis] };
                parts.push(names[axis][side]);
            }
            let nodes = self.nodes_in_box(p, p, tol);
            self.node_sets.insert(parts.join("_"), nodes);
        }
        self.node_sets
            .insert("all".to_string(), (0..self.nodes.len()).collect());
    }
}

fn inside<const D: usize>(p: [f64; D], lo: [f64; D], hi: [f64; D], tol: f64) -> bool {
    (0..D).all(|i| p[i] >= lo[i] - tol && p[i] <= hi[i] + tol)
}

/// Problems found while generating a block mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum BlockError {
    TooFewBreaks {
        axis: char,
        count: usize,
    },
    NotIncreasing {
        axis: char,
        index: usize,
        value: f64,
        previous: f64,
    },
    NoNodeAt {
        from: [f64; 2],
    },
}

impl std::fmt::Display for BlockError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BlockError::TooFewBreaks { axis, count } => write!(
                f,
                "the {axis} breaks need at least two values (got {count}); list the element boundaries, e.g. [0, 1, 2]"
            ),
            BlockError::NotIncreasing { axis, index, value, previous } => write!(
                f,
                "the {axis} breaks must increase strictly, but entry {index} ({value}) is not greater than the one before ({previous})"
            ),
            BlockError::NoNodeAt { from } => write!(
                f,
                "a move starts at ({}, {}), where the block has no node; use the coordinates of a grid vertex, or of a mid-side or centre node as the vertex moves leave it",
                from[0], from[1]
            ),
        }
    }
}

/// Generate a structured block mesh (see the module docs).
pub fn block(
    kind: ElementKind,
    xs: &[f64],
    ys: &[f64],
    moves: &[([f64; 2], [f64; 2])],
) -> Result<Mesh, BlockError> {
    for (axis, b) in [('x', xs), ('y', ys)] {
        if b.len() < 2 {
            return Err(BlockError::TooFewBreaks {
                axis,
                count: b.len(),
            });
        }
        for i in 1..b.len() {
            if b[i].partial_cmp(&b[i - 1]) != Some(std::cmp::Ordering::Greater) {
                return Err(BlockError::NotIncreasing {
                    axis,
                    index: i,
                    value: b[i],
                    previous: b[i - 1],
                });
            }
        }
    }
    let (nx, ny) = (xs.len() - 1, ys.len() - 1);
    // vertex grid, then moves
    let mut vertex = vec![[0.0; 2]; (nx + 1) * (ny + 1)];
    for j in 0..=ny {
        for i in 0..=nx {
            vertex[j * (nx + 1) + i] = [xs[i], ys[j]];
        }
    }
    let size = (xs[nx] - xs[0]).max(ys[ny] - ys[0]);
    let at = |p: [f64; 2], from: [f64; 2]| {
        (p[0] - from[0]).abs() <= 1e-9 * size && (p[1] - from[1]).abs() <= 1e-9 * size
    };
    // a move from a vertex of the grid moves the vertex (the higher-order nodes follow it);
    // any other move is of a mid-side or centre node, applied once they are placed
    let mut node_moves = Vec::new();
    for &(from, to) in moves {
        match vertex.iter().position(|&v| at(v, from)) {
            Some(k) => vertex[k] = to,
            None => node_moves.push((from, to)),
        }
    }
    let v = |i: usize, j: usize| vertex[j * (nx + 1) + i];
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];

    // Node lattice: step 1 (linear) or 2 (quadratic) per cell; only lattice points in use get ids.
    let q = if kind.is_quadratic() { 2 } else { 1 };
    let (lx, ly) = (q * nx + 1, q * ny + 1);
    let mut id = vec![usize::MAX; lx * ly];
    let mut nodes = Vec::new();
    let mut node_at = |li: usize, lj: usize, nodes: &mut Vec<[f64; 2]>| -> usize {
        let k = lj * lx + li;
        if id[k] == usize::MAX {
            let p = if q == 1 {
                v(li, lj)
            } else {
                let (i, j) = (li / 2, lj / 2);
                match (li % 2, lj % 2) {
                    (0, 0) => v(i, j),
                    (1, 0) => mid(v(i, j), v(i + 1, j)),
                    (0, 1) => mid(v(i, j), v(i, j + 1)),
                    _ => {
                        if kind == ElementKind::Q9 {
                            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                            [
                                0.25 * (a[0] + b[0] + c[0] + d[0]),
                                0.25 * (a[1] + b[1] + c[1] + d[1]),
                            ]
                        } else {
                            mid(v(i, j), v(i + 1, j + 1))
                        }
                    }
                }
            };
            id[k] = nodes.len();
            nodes.push(p);
        }
        id[k]
    };
    let mut conn = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b) = (q * i, q * j);
            match kind {
                ElementKind::Q4 => {
                    for (di, dj) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                        conn.push(node_at(a + di, b + dj, &mut nodes));
                    }
                }
                ElementKind::Q9 => {
                    for (di, dj) in [
                        (0, 0),
                        (2, 0),
                        (2, 2),
                        (0, 2),
                        (1, 0),
                        (2, 1),
                        (1, 2),
                        (0, 1),
                        (1, 1),
                    ] {
                        conn.push(node_at(a + di, b + dj, &mut nodes));
                    }
                }
                ElementKind::T3 => {
                    for tri in [[(0, 0), (1, 0), (1, 1)], [(0, 0), (1, 1), (0, 1)]] {
                        for (di, dj) in tri {
                            conn.push(node_at(a + di, b + dj, &mut nodes));
                        }
                    }
                }
                ElementKind::T6 => {
                    let tris = [
                        [(0, 0), (2, 0), (2, 2), (1, 0), (2, 1), (1, 1)],
                        [(0, 0), (2, 2), (0, 2), (1, 1), (1, 2), (0, 1)],
                    ];
                    for tri in tris {
                        for (di, dj) in tri {
                            conn.push(node_at(a + di, b + dj, &mut nodes));
                        }
                    }
                }
            }
        }
    }
    // moves of single higher-order nodes (curving a side, shifting a centre), from where the
    // vertex moves left them; vertices were taken above, so only lattice nodes remain
    for (from, to) in node_moves {
        let k = nodes
            .iter()
            .position(|&p| at(p, from))
            .ok_or(BlockError::NoNodeAt { from })?;
        nodes[k] = to;
    }
    Ok(Mesh::new(kind, nodes, conn))
}

/// Problems found while generating a 3D block mesh: those of the 2D block, or a move from
/// a point where the block has no node.
#[derive(Debug, Clone, PartialEq)]
pub enum Block3Error {
    Breaks(BlockError),
    NoNodeAt { from: [f64; 3] },
}

impl std::fmt::Display for Block3Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Block3Error::Breaks(e) => e.fmt(f),
            Block3Error::NoNodeAt { from } => write!(
                f,
                "a move starts at ({}, {}, {}), where the block has no node; use the coordinates of a grid vertex, or of a mid-edge, face or centre node as the vertex moves leave it",
                from[0], from[1], from[2]
            ),
        }
    }
}

/// The breaks of one axis checked: at least two, strictly increasing.
fn check_breaks(axis: char, b: &[f64]) -> Result<(), BlockError> {
    if b.len() < 2 {
        return Err(BlockError::TooFewBreaks {
            axis,
            count: b.len(),
        });
    }
    for i in 1..b.len() {
        if b[i].partial_cmp(&b[i - 1]) != Some(std::cmp::Ordering::Greater) {
            return Err(BlockError::NotIncreasing {
                axis,
                index: i,
                value: b[i],
                previous: b[i - 1],
            });
        }
    }
    Ok(())
}

/// The six tetrahedra of the Kuhn (Freudenthal) split of the unit cube, as vertex offsets:
/// one tetrahedron per order of the axes, along the path `(0,0,0) -> e_p -> e_p + e_q ->
/// (1,1,1)`. Every cube is split alike, so each cube face is cut along the same diagonal
/// from both sides and the split is conforming. The vertices of each are ordered for a
/// positive volume.
const KUHN_TETRAHEDRA: [[[usize; 3]; 4]; 6] = [
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1]],
    [[0, 0, 0], [1, 0, 1], [1, 0, 0], [1, 1, 1]],
    [[0, 0, 0], [1, 1, 0], [0, 1, 0], [1, 1, 1]],
    [[0, 0, 0], [0, 1, 0], [0, 1, 1], [1, 1, 1]],
    [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1]],
    [[0, 0, 0], [0, 1, 1], [0, 0, 1], [1, 1, 1]],
];

/// Generate a structured 3D block mesh: vertices at the breaks `xs x ys x zs`, moved by the
/// vertex moves, the higher-order nodes placed from the moved vertices (mid-edge nodes at
/// edge midpoints, Hex27 face and body centres at the mean of their corners, so every element
/// keeps straight edges), then moves of single higher-order nodes as in [`block`].
/// The automatic sets (sides, corners, `all`) are those of the unmoved grid: `top` is the
/// nodes and boundary facets of the last layer of cells in z, also where a move lifts a node
/// off the plane of the face, or rotates the whole block (a block's sides are its topology).
/// Hexahedra are the grid cells; tetrahedra split each cell into six (see
/// `KUHN_TETRAHEDRA`), conformingly.
pub fn block3(
    kind: SolidKind,
    xs: &[f64],
    ys: &[f64],
    zs: &[f64],
    moves: &[([f64; 3], [f64; 3])],
) -> Result<Mesh3, Block3Error> {
    for (axis, b) in [('x', xs), ('y', ys), ('z', zs)] {
        check_breaks(axis, b).map_err(Block3Error::Breaks)?;
    }
    let cells = [xs.len() - 1, ys.len() - 1, zs.len() - 1];
    let vertex_index = |i: usize, j: usize, k: usize| (k * (cells[1] + 1) + j) * (cells[0] + 1) + i;
    let mut vertex = vec![[0.0; 3]; (cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1)];
    for k in 0..=cells[2] {
        for j in 0..=cells[1] {
            for i in 0..=cells[0] {
                vertex[vertex_index(i, j, k)] = [xs[i], ys[j], zs[k]];
            }
        }
    }
    let size = (xs[cells[0]] - xs[0])
        .max(ys[cells[1]] - ys[0])
        .max(zs[cells[2]] - zs[0]);
    let at = |p: [f64; 3], from: [f64; 3]| (0..3).all(|i| (p[i] - from[i]).abs() <= 1e-9 * size);
    let mut node_moves = Vec::new();
    for &(from, to) in moves {
        match vertex.iter().position(|&v| at(v, from)) {
            Some(k) => vertex[k] = to,
            None => node_moves.push((from, to)),
        }
    }
    // Node lattice: step 1 (linear) or 2 (quadratic) per cell. A lattice point is placed at
    // the mean of the vertices around it (over each odd coordinate, both neighbours), which
    // is the edge midpoint, face centre or body centre; the Tet10 mid-edge nodes on a face or
    // body diagonal are placed at that diagonal's midpoint instead.
    let q = if kind.is_quadratic() { 2 } else { 1 };
    let lattice = [q * cells[0] + 1, q * cells[1] + 1, q * cells[2] + 1];
    let mut id = vec![usize::MAX; lattice[0] * lattice[1] * lattice[2]];
    let mut nodes: Vec<[f64; 3]> = Vec::new();
    // where each node lies on the unmoved grid: the automatic sets are taken there
    let mut unmoved: Vec<[f64; 3]> = Vec::new();
    let breaks = [xs, ys, zs];
    let unmoved_point = |l: [usize; 3]| -> [f64; 3] {
        [0, 1, 2].map(|a| {
            let b = breaks[a];
            if q == 1 || l[a].is_multiple_of(2) {
                b[l[a] / q]
            } else {
                0.5 * (b[l[a] / 2] + b[l[a] / 2 + 1])
            }
        })
    };
    let v = |p: [usize; 3]| vertex[vertex_index(p[0], p[1], p[2])];
    let mut node_at = |l: [usize; 3], place: &dyn Fn() -> [f64; 3], nodes: &mut Vec<[f64; 3]>| {
        let k = (l[2] * lattice[1] + l[1]) * lattice[0] + l[0];
        if id[k] == usize::MAX {
            id[k] = nodes.len();
            nodes.push(place());
            unmoved.push(unmoved_point(l));
        }
        id[k]
    };
    let mean_around = |l: [usize; 3]| -> [f64; 3] {
        if q == 1 {
            return v(l);
        }
        let mut sum = [0.0; 3];
        let mut count = 0.0;
        for corner in 0..8usize {
            let mut p = [0; 3];
            let mut skip = false;
            for axis in 0..3 {
                let bit = (corner >> axis) & 1;
                if l[axis].is_multiple_of(2) {
                    if bit == 1 {
                        skip = true;
                    }
                    p[axis] = l[axis] / 2;
                } else {
                    p[axis] = l[axis] / 2 + bit;
                }
            }
            if skip {
                continue;
            }
            let x = v(p);
            for i in 0..3 {
                sum[i] += x[i];
            }
            count += 1.0;
        }
        sum.map(|s| s / count)
    };
    let mut conn = Vec::new();
    for k in 0..cells[2] {
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                let base = [q * i, q * j, q * k];
                match kind {
                    SolidKind::Hex8 | SolidKind::Hex27 => {
                        for xi in kind.node_coordinates() {
                            // natural -1, 0, 1 to lattice offsets 0, q/2, q
                            let l = [0, 1, 2]
                                .map(|a| base[a] + ((xi[a] + 1.0) * 0.5 * q as f64) as usize);
                            conn.push(node_at(l, &|| mean_around(l), &mut nodes));
                        }
                    }
                    SolidKind::Tet4 | SolidKind::Tet10 => {
                        for tet in KUHN_TETRAHEDRA {
                            let corner = |c: usize| [0, 1, 2].map(|a| base[a] + q * tet[c][a]);
                            for c in 0..4 {
                                let l = corner(c);
                                conn.push(node_at(l, &|| v(l.map(|x| x / q)), &mut nodes));
                            }
                            if kind == SolidKind::Tet10 {
                                for [a, b] in [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]] {
                                    let (la, lb) = (corner(a), corner(b));
                                    let l = [0, 1, 2].map(|x| (la[x] + lb[x]) / 2);
                                    let place = || {
                                        let (pa, pb) = (v(la.map(|x| x / 2)), v(lb.map(|x| x / 2)));
                                        [0, 1, 2].map(|x| 0.5 * (pa[x] + pb[x]))
                                    };
                                    conn.push(node_at(l, &place, &mut nodes));
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    for (from, to) in node_moves {
        let k = nodes
            .iter()
            .position(|&p| at(p, from))
            .ok_or(Block3Error::NoNodeAt { from })?;
        nodes[k] = to;
    }
    // the sides and corners of the block's topology (its first and last layers of cells),
    // whatever the moves did to the coordinates
    let mut mesh = Mesh::new(kind, unmoved, conn);
    mesh.nodes = nodes;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block3_counts_sets_and_positive_volumes() {
        let (xs, ys, zs) = ([0.0, 1.0, 3.0], [0.0, 2.0], [0.0, 0.5, 1.0]);
        for (kind, nodes, cells) in [
            (SolidKind::Hex8, 3 * 2 * 3, 4),
            (SolidKind::Hex27, 5 * 3 * 5, 4),
            (SolidKind::Tet4, 3 * 2 * 3, 24),
            (SolidKind::Tet10, 5 * 3 * 5, 24),
        ] {
            let m = block3(kind, &xs, &ys, &zs, &[([1.0, 2.0, 0.5], [1.1, 2.0, 0.45])]).unwrap();
            assert_eq!((m.nodes.len(), m.cell_count()), (nodes, cells), "{kind:?}");
            // boundary faces: 2 (x sides) * 1*2 + 2 (y) * 2*2 + 2 (z) * 2*1 cell faces = 16,
            // two triangles each for tetrahedra
            let per_face = if kind.is_hexahedron() { 1 } else { 2 };
            assert_eq!(m.boundary_facets().len(), 16 * per_face, "{kind:?}");
            assert_eq!(m.facet_sets["left"].len(), 2 * per_face);
            assert_eq!(m.facet_sets["front"].len(), 4 * per_face);
            assert_eq!(m.facet_sets["top"].len(), 2 * per_face);
            assert_eq!(m.node_sets["bottom_front_left"], vec![0]);
            assert_eq!(m.node_sets["top_back_right"].len(), 1);
            // every cell has a positive volume
            for c in 0..m.cell_count() {
                let pv = kind.point_values(&m.cell_coords(c), kind.centre());
                assert!(pv.det_j > 0.0, "{kind:?} cell {c}: det J = {}", pv.det_j);
            }
        }
        assert!(matches!(
            block3(SolidKind::Hex8, &[0.0, 1.0], &[0.0], &[0.0, 1.0], &[]),
            Err(Block3Error::Breaks(BlockError::TooFewBreaks {
                axis: 'y',
                ..
            }))
        ));
        assert!(matches!(
            block3(
                SolidKind::Hex8,
                &[0.0, 1.0],
                &[0.0, 1.0],
                &[0.0, 1.0],
                &[([0.5, 0.5, 0.5], [0.0; 3])]
            ),
            Err(Block3Error::NoNodeAt { .. })
        ));
    }

    /// The automatic sets of a 3D block are its topology's: a move that lifts a top-face
    /// vertex off the face (above the rest of the block, so the bounding box's top is that
    /// node alone) or lowers it into the block leaves `top` and every other set as on the
    /// unmoved grid, and the moved node is where the move put it.
    #[test]
    fn block3_sets_survive_moves_off_the_faces() {
        let (xs, ys, zs) = ([0.0, 0.5, 1.0], [0.0, 0.5, 1.0], [0.0, 0.4, 1.0]);
        for kind in [
            SolidKind::Hex8,
            SolidKind::Hex27,
            SolidKind::Tet4,
            SolidKind::Tet10,
        ] {
            let plain = block3(kind, &xs, &ys, &zs, &[]).unwrap();
            for to in [[0.5, 0.5, 1.1], [0.45, 0.55, 0.9]] {
                let moved = block3(kind, &xs, &ys, &zs, &[([0.5, 0.5, 1.0], to)]).unwrap();
                assert_eq!(moved.facet_sets, plain.facet_sets, "{kind:?} to {to:?}");
                assert_eq!(moved.node_sets, plain.node_sets, "{kind:?} to {to:?}");
                let per_face = if kind.is_hexahedron() { 1 } else { 2 };
                assert_eq!(moved.facet_sets["top"].len(), 4 * per_face, "{kind:?}");
                let lifted = moved.nearest_node(to).unwrap();
                assert!(lifted.1 < 1e-14, "{kind:?}: no node at {to:?}");
                assert!(moved.node_sets["top"].contains(&lifted.0), "{kind:?}");
            }
        }
    }

    #[test]
    fn block_counts_and_automatic_sets() {
        let m = block(ElementKind::Q4, &[0.0, 1.0, 3.0], &[0.0, 2.0], &[]).unwrap();
        assert_eq!(m.nodes.len(), 6);
        assert_eq!(m.cell_count(), 2);
        assert_eq!(m.node_sets["left"].len(), 2);
        assert_eq!(m.facet_sets["top"].len(), 2);
        assert_eq!(
            m.node_sets["top_right"],
            vec![m.nearest_node([3.0, 2.0]).unwrap().0]
        );
        assert_eq!(m.boundary_facets().len(), 6);

        let q9 = block(ElementKind::Q9, &[0.0, 1.0, 3.0], &[0.0, 2.0], &[]).unwrap();
        assert_eq!(q9.nodes.len(), 15);
        assert_eq!(q9.cell_count(), 2);
        let t6 = block(ElementKind::T6, &[0.0, 1.0, 3.0], &[0.0, 2.0], &[]).unwrap();
        assert_eq!(t6.nodes.len(), 15);
        assert_eq!(t6.cell_count(), 4);
        let t3 = block(ElementKind::T3, &[0.0, 1.0, 3.0], &[0.0, 2.0], &[]).unwrap();
        assert_eq!((t3.nodes.len(), t3.cell_count()), (6, 4));
    }

    /// Defect W04 (second report): a node of no cell at (1000, 1000) made itself the whole
    /// `top` set (and every set of the bounding box's upper and right sides).
    #[test]
    fn a_node_of_no_cell_is_in_no_set_chosen_by_position() {
        let nodes = vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [1000.0, 1000.0],
        ];
        let m = Mesh::new(ElementKind::Q4, nodes, vec![0, 1, 2, 3]);
        assert_eq!(m.used_nodes(), vec![true, true, true, true, false]);
        assert_eq!(m.bounding_box(), [[0.0, 0.0], [1.0, 1.0]]);
        assert_eq!(m.node_sets["top"], vec![2, 3]);
        assert_eq!(m.node_sets["right"], vec![1, 2]);
        assert_eq!(m.node_sets["top_right"], vec![2]);
        assert_eq!(m.facet_sets["top"].len(), 1);
        assert!(m.nodes_in_box([-1.0; 2], [2000.0; 2], 0.0).len() == 4);
    }

    #[test]
    fn moved_vertex_keeps_quadratic_nodes_on_straight_sides() {
        let m = block(
            ElementKind::Q9,
            &[0.0, 1.0, 2.0],
            &[0.0, 1.0, 2.0],
            &[([1.0, 1.0], [1.2, 0.7])],
        )
        .unwrap();
        let (moved, d) = m.nearest_node([1.2, 0.7]).unwrap();
        assert!(d < 1e-14);
        // the mid-side node between (1,0) and the moved vertex sits at their midpoint
        let (_, d) = m.nearest_node([1.1, 0.35]).unwrap();
        assert!(d < 1e-14, "mid-side node not at the midpoint");
        assert!(m.node_sets["all"].contains(&moved));
    }

    #[test]
    fn bad_breaks_and_moves_are_reported() {
        assert_eq!(
            block(ElementKind::Q4, &[0.0], &[0.0, 1.0], &[]).unwrap_err(),
            BlockError::TooFewBreaks {
                axis: 'x',
                count: 1
            }
        );
        assert!(matches!(
            block(ElementKind::Q4, &[0.0, 1.0], &[0.0, 1.0, 1.0], &[]),
            Err(BlockError::NotIncreasing {
                axis: 'y',
                index: 2,
                ..
            })
        ));
        assert!(matches!(
            block(
                ElementKind::Q4,
                &[0.0, 1.0],
                &[0.0, 1.0],
                &[([0.5, 0.5], [0.4, 0.4])]
            ),
            Err(BlockError::NoNodeAt { .. })
        ));
    }

    #[test]
    fn a_move_from_a_mid_side_or_centre_node_moves_that_node_alone() {
        // Q9 on [0,2]x[0,1]: curve the top side of the first cell (its mid-side node at
        // (0.5, 1)) and shift the centre of the second ((1.5, 0.5))
        let plain = block(ElementKind::Q9, &[0.0, 1.0, 2.0], &[0.0, 1.0], &[]).unwrap();
        let moved = block(
            ElementKind::Q9,
            &[0.0, 1.0, 2.0],
            &[0.0, 1.0],
            &[([0.5, 1.0], [0.5, 1.1]), ([1.5, 0.5], [1.55, 0.45])],
        )
        .unwrap();
        assert_eq!(plain.nodes.len(), moved.nodes.len());
        let changed: Vec<usize> = (0..plain.nodes.len())
            .filter(|&k| plain.nodes[k] != moved.nodes[k])
            .collect();
        assert_eq!(changed.len(), 2, "{changed:?}");
        let top_mid = plain.nearest_node([0.5, 1.0]).unwrap().0;
        let centre = plain.nearest_node([1.5, 0.5]).unwrap().0;
        assert_eq!(moved.nodes[top_mid], [0.5, 1.1]);
        assert_eq!(moved.nodes[centre], [1.55, 0.45]);
        // after a vertex move, a mid-side node is found where the move left it
        let both = block(
            ElementKind::T6,
            &[0.0, 1.0],
            &[0.0, 1.0],
            &[([1.0, 1.0], [1.2, 1.0]), ([0.6, 1.0], [0.6, 1.05])],
        )
        .unwrap();
        assert!(both.nodes.contains(&[0.6, 1.05]));
        assert!(both.nodes.contains(&[1.2, 1.0]));
        // a linear element has no such nodes: the move is refused
        assert!(matches!(
            block(
                ElementKind::Q4,
                &[0.0, 1.0],
                &[0.0, 1.0],
                &[([0.5, 1.0], [0.5, 1.1])]
            ),
            Err(BlockError::NoNodeAt { .. })
        ));
    }
}
