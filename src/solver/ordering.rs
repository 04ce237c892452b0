//! Nested-dissection orderings of a symmetric sparsity pattern, from the graph alone or, in
//! [`coordinate_dissection`], from the graph and the points of its equations.
//!
//! [`dissection_order`] is METIS's multilevel nested dissection ([`metis_nested_dissection`],
//! Karypis and Kumar 1998) on the quotient graph of supervariables (step 1 below), and the
//! level-structure dissection below ([`nested_dissection`]; George 1973, "Nested dissection of a
//! regular finite element mesh"; George and Liu, *Computer Solution of Large Sparse Positive
//! Definite Systems*, 1981, chapter 8) where METIS cannot take the graph. Their factors'
//! multiply-adds, against AMD's (`contact-patch run` with `limits.factor_operations` set to 1
//! prints the kept one): the contact block of `crosscheck/performance.py` (1,002,830 dofs, Q4)
//! AMD 8.74e10, level structures 9.61e10, METIS 5.25e10, the geometric dissection
//! ([`coordinate_dissection`]) 5.13e10; the 3D slab
//! `cases/large/slab-3d-1m.json` (1,090,824 equations, Hex8) AMD 1.03e13, level structures
//! 5.35e12, METIS 3.07e12, geometric 2.85e12.
//!
//! The level-structure dissection:
//!
//! 1. **Supervariables.** Consecutive equations with the same neighbours (the `D` dofs of a
//!    node, coupled to the same nodes) are one vertex of the quotient graph, ordered together.
//! 2. **Dissection.** For a connected set of vertices: a pseudo-peripheral vertex `r` (the end of
//!    a breadth-first search repeated from the farthest vertex until the depth stops growing),
//!    the level structure from `r`, and the level `m` where the levels' cumulative size passes
//!    half the set; the vertices of level `m` that touch level `m + 1` separate the levels
//!    before `m` from those after it. Each remaining connected part is dissected in turn, and
//!    the separator is ordered after the parts (the last eliminated).
//! 3. **Leaves.** A set of at most [`LEAF`] vertices, or one whose level structure has fewer
//!    than three levels, is ordered as found (its fill is bounded by its size).
//!
//! Eliminating the separators last confines the fill of each part to the part and its
//! separator: on a 3D grid of `n` vertices the factor holds `O(n^(4/3))` entries and takes
//! `O(n^2)` operations, against far more for minimum degree on the same grids (which orders
//! the interior of large slabs poorly). The caller compares the factor's work with that of
//! AMD and keeps the cheaper (`Cholesky::analyse` in `crate::solver::sparse`).

/// The upper-triangular CSC pattern of a symmetric `n x n` matrix, as the ordering reads it.
#[derive(Clone, Copy, Debug)]
pub struct Pattern<'a> {
    pub n: usize,
    pub col_ptr: &'a [usize],
    pub row_idx: &'a [usize],
}

/// Sets of at most this many vertices are not dissected further.
pub const LEAF: usize = 64;

/// The quotient graph of supervariables: `groups[g]` are the equations of vertex `g`
/// (consecutive), `adjacency[start[g]..start[g + 1]]` its neighbours.
struct Quotient {
    groups: Vec<std::ops::Range<usize>>,
    start: Vec<usize>,
    adjacency: Vec<usize>,
}

/// Full (both triangles) adjacency of the pattern, without the diagonal, as CSR.
fn full_adjacency(pattern: &Pattern) -> (Vec<usize>, Vec<usize>) {
    let n = pattern.n;
    let mut degree = vec![0usize; n];
    for j in 0..n {
        for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
            if i != j {
                degree[i] += 1;
                degree[j] += 1;
            }
        }
    }
    let mut start = vec![0usize; n + 1];
    for i in 0..n {
        start[i + 1] = start[i] + degree[i];
    }
    let mut fill = start[..n].to_vec();
    let mut adjacency = vec![0usize; start[n]];
    for j in 0..n {
        for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
            if i != j {
                adjacency[fill[i]] = j;
                fill[i] += 1;
                adjacency[fill[j]] = i;
                fill[j] += 1;
            }
        }
    }
    for i in 0..n {
        adjacency[start[i]..start[i + 1]].sort_unstable();
    }
    (start, adjacency)
}

/// Group consecutive equations whose closed neighbourhoods (neighbours and the equation
/// itself) are equal.
fn quotient(pattern: &Pattern) -> Quotient {
    let n = pattern.n;
    let (start, adjacency) = full_adjacency(pattern);
    // the closed neighbourhood of `i` in increasing order (the adjacency lists are sorted)
    let closed = |i: usize| {
        let list = &adjacency[start[i]..start[i + 1]];
        let k = list.partition_point(|&w| w < i);
        list[..k]
            .iter()
            .copied()
            .chain(std::iter::once(i))
            .chain(list[k..].iter().copied())
    };
    let degree = |i: usize| start[i + 1] - start[i];
    let mut groups: Vec<std::ops::Range<usize>> = Vec::new();
    let mut group_of = vec![0usize; n];
    let mut i = 0;
    while i < n {
        let mut j = i + 1;
        while j < n && degree(j) == degree(i) && closed(j).eq(closed(i)) {
            j += 1;
        }
        for g in group_of.iter_mut().take(j).skip(i) {
            *g = groups.len();
        }
        groups.push(i..j);
        i = j;
    }
    let mut q_start = vec![0usize; groups.len() + 1];
    let mut q_adjacency = Vec::new();
    let mut seen = vec![usize::MAX; groups.len()];
    for (g, range) in groups.iter().enumerate() {
        let first = range.start;
        for &k in &adjacency[start[first]..start[first + 1]] {
            let h = group_of[k];
            if h != g && seen[h] != g {
                seen[h] = g;
                q_adjacency.push(h);
            }
        }
        q_start[g + 1] = q_adjacency.len();
    }
    Quotient {
        groups,
        start: q_start,
        adjacency: q_adjacency,
    }
}

impl Quotient {
    fn neighbours(&self, v: usize) -> &[usize] {
        &self.adjacency[self.start[v]..self.start[v + 1]]
    }
}

/// Scratch marks shared by the searches: `mark[v] == stamp` means "in the current set".
struct Marks {
    set: Vec<u32>,
    level: Vec<u32>,
    stamp: u32,
}

/// The level structure from `root` within the marked set: the vertices by level.
fn levels(q: &Quotient, marks: &mut Marks, root: usize, members: usize) -> Vec<Vec<usize>> {
    let stamp = marks.stamp;
    let mut out: Vec<Vec<usize>> = vec![vec![root]];
    marks.level[root] = stamp;
    let mut count = 1;
    while count < members {
        let mut next = Vec::new();
        for &v in out.last().expect("a level") {
            for &w in q.neighbours(v) {
                if marks.set[w] == stamp && marks.level[w] != stamp {
                    marks.level[w] = stamp;
                    next.push(w);
                }
            }
        }
        if next.is_empty() {
            break;
        }
        count += next.len();
        out.push(next);
    }
    out
}

/// Order the connected or not set `set` into `order` (parts first, separators last).
fn dissect(q: &Quotient, marks: &mut Marks, set: Vec<usize>, order: &mut Vec<usize>) {
    let mut stack: Vec<(Vec<usize>, bool)> = vec![(set, false)];
    // (set, is_separator): separators are emitted when popped after their parts
    while let Some((set, separator)) = stack.pop() {
        if separator || set.len() <= LEAF {
            order.extend_from_slice(&set);
            continue;
        }
        marks.stamp += 1;
        let stamp = marks.stamp;
        for &v in &set {
            marks.set[v] = stamp;
        }
        // the component of the first vertex, its pseudo-peripheral vertex and levels
        let mut structure = levels(q, marks, set[0], set.len());
        let reached: usize = structure.iter().map(Vec::len).sum();
        if reached < set.len() {
            // several components: dissect each on its own
            let component: Vec<usize> = structure.concat();
            let rest: Vec<usize> = set
                .iter()
                .copied()
                .filter(|&v| marks.level[v] != stamp)
                .collect();
            stack.push((rest, false));
            stack.push((component, false));
            continue;
        }
        for _ in 0..8 {
            let last = structure.last().expect("a level");
            // the farthest vertex of least degree starts the next search
            let far = *last
                .iter()
                .min_by_key(|&&v| q.neighbours(v).len())
                .expect("a vertex");
            marks.stamp += 1;
            let again = marks.stamp;
            for &v in &set {
                marks.set[v] = again;
            }
            let candidate = levels(q, marks, far, set.len());
            if candidate.len() > structure.len() {
                structure = candidate;
            } else {
                break;
            }
        }
        if structure.len() < 3 {
            order.extend_from_slice(&set);
            continue;
        }
        // the middle level by size, not the first or the last
        let half = set.len() / 2;
        let mut cumulative = 0;
        let mut middle = 1;
        for (k, level) in structure.iter().enumerate() {
            cumulative += level.len();
            if cumulative >= half {
                middle = k.clamp(1, structure.len() - 2);
                break;
            }
        }
        // thin the separator: the vertices of the middle level that touch the next one
        let next_level: std::collections::HashSet<usize> =
            structure[middle + 1].iter().copied().collect();
        let (separator, moved): (Vec<usize>, Vec<usize>) = structure[middle]
            .iter()
            .copied()
            .partition(|&v| q.neighbours(v).iter().any(|w| next_level.contains(w)));
        let mut before: Vec<usize> = structure[..middle].concat();
        before.extend(moved);
        let after: Vec<usize> = structure[middle + 1..].concat();
        stack.push((separator, true));
        stack.push((after, false));
        stack.push((before, false));
    }
}

/// The nested-dissection order of the equations of `pattern`: `order[k]` is the equation
/// eliminated `k`-th.
pub fn nested_dissection(pattern: &Pattern) -> Vec<usize> {
    let q = quotient(pattern);
    let nv = q.groups.len();
    let mut marks = Marks {
        set: vec![0; nv],
        level: vec![0; nv],
        stamp: 0,
    };
    let mut vertex_order = Vec::with_capacity(nv);
    dissect(&q, &mut marks, (0..nv).collect(), &mut vertex_order);
    let mut order = Vec::with_capacity(pattern.n);
    for v in vertex_order {
        order.extend(q.groups[v].clone());
    }
    order
}

/// Held for the duration of every METIS call (see [`metis_nested_dissection`]).
static METIS_CALL: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// METIS's multilevel nested dissection of the quotient graph (Karypis and Kumar, "A fast and
/// high quality multilevel scheme for partitioning irregular graphs", SIAM J. Sci. Comput. 20
/// (1998) 359-392; METIS 5 `METIS_NodeND`, default options): each supervariable is one vertex
/// weighted by its number of equations, its equations kept together in the order. The
/// separators come from coarsened graphs refined on the way back (Fiduccia-Mattheyses), so on
/// meshes they are near the shortest cuts, where the level structures of
/// [`nested_dissection`] cut along the fronts of a breadth-first search from a corner. `None`
/// when the graph does not fit METIS's 32-bit indices or METIS reports an error; the caller then
/// uses [`nested_dissection`].
pub fn metis_nested_dissection(pattern: &Pattern) -> Option<Vec<usize>> {
    let q = quotient(pattern);
    let nv = q.groups.len();
    let index = |v: usize| metis_sys::idx_t::try_from(v).ok();
    let mut nvtxs = index(nv)?;
    index(q.adjacency.len())?;
    if nv == 0 {
        return Some(Vec::new());
    }
    let mut xadj: Vec<metis_sys::idx_t> = q.start.iter().map(|&v| v as metis_sys::idx_t).collect();
    let mut adjncy: Vec<metis_sys::idx_t> =
        q.adjacency.iter().map(|&v| v as metis_sys::idx_t).collect();
    let mut vwgt: Vec<metis_sys::idx_t> = q
        .groups
        .iter()
        .map(|g| index(g.len()))
        .collect::<Option<_>>()?;
    let mut perm: Vec<metis_sys::idx_t> = vec![0; nv];
    let mut iperm: Vec<metis_sys::idx_t> = vec![0; nv];
    // METIS reseeds one process-wide random generator at the start of every call and draws
    // from it throughout: calls on two threads at once would interleave their draws, and the
    // order would depend on the timing. One call at a time keeps it a function of the graph.
    let _one_at_a_time = METIS_CALL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    // SAFETY: every array has the length METIS_NodeND reads or writes for a graph of `nvtxs`
    // vertices (xadj nv + 1, adjncy xadj[nv], vwgt, perm and iperm nv); the adjacency is
    // symmetric without self-loops (the quotient graph); a null options pointer means METIS's
    // defaults. METIS keeps no pointer past the call.
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            vwgt.as_mut_ptr(),
            std::ptr::null_mut(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return None;
    }
    // perm[k] is the vertex eliminated k-th; check it is a permutation before trusting it
    let mut seen = vec![false; nv];
    let mut order = Vec::with_capacity(pattern.n);
    for &v in &perm {
        let v = usize::try_from(v).ok().filter(|&v| v < nv && !seen[v])?;
        seen[v] = true;
        order.extend(q.groups[v].clone());
    }
    Some(order)
}

/// The nested-dissection order of the equations of `pattern`: METIS's
/// ([`metis_nested_dissection`]), or the level-structure dissection ([`nested_dissection`])
/// where METIS cannot take the graph.
pub fn dissection_order(pattern: &Pattern) -> Vec<usize> {
    metis_nested_dissection(pattern).unwrap_or_else(|| nested_dissection(pattern))
}

/// Sets of at most this many vertices end [`coordinate_dissection`]'s bisection; each is
/// ordered along its longest extent (a band).
pub const COORDINATE_LEAF: usize = 32;

/// Vertices sorted along the longest extent of their bounding box (then the other axes, then
/// the vertex number): a band order for a leaf or a separator.
fn banded(set: &mut [usize], point: &[[f64; 3]]) {
    let axes = extents_by_length(set, point);
    set.sort_unstable_by(|&a, &b| {
        axes.iter()
            .map(|&x| point[a][x].total_cmp(&point[b][x]))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.cmp(&b))
    });
}

/// The axes of `set`'s bounding box, longest extent first.
fn extents_by_length(set: &[usize], point: &[[f64; 3]]) -> [usize; 3] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &v in set {
        for x in 0..3 {
            lo[x] = lo[x].min(point[v][x]);
            hi[x] = hi[x].max(point[v][x]);
        }
    }
    let mut axes = [0, 1, 2];
    axes.sort_by(|&a, &b| (hi[b] - lo[b]).total_cmp(&(hi[a] - lo[a])).then(a.cmp(&b)));
    axes
}

/// Split `set` at the median of coordinate `axis`: the vertices below the median value and
/// those at or above it (or, when one side would be empty because many vertices share the
/// median value, at or below it and above it; or, when every vertex shares it, by position).
fn bisect(mut set: Vec<usize>, point: &[[f64; 3]], axis: usize) -> (Vec<usize>, Vec<usize>) {
    let key = |v: usize| point[v][axis];
    let half = set.len() / 2;
    set.select_nth_unstable_by(half, |&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    let median = key(set[half]);
    let (lower, upper): (Vec<usize>, Vec<usize>) = set.iter().partition(|&&v| key(v) < median);
    if !lower.is_empty() {
        return (lower, upper);
    }
    let (lower, upper): (Vec<usize>, Vec<usize>) = set.iter().partition(|&&v| key(v) <= median);
    if !upper.is_empty() {
        return (lower, upper);
    }
    let upper = set.split_off(half);
    (set, upper)
}

/// Geometric nested dissection: the recursive coordinate bisection of the quotient graph's
/// vertices by their points (Heath and Raghavan, "A Cartesian parallel nested dissection
/// algorithm", SIAM J. Matrix Anal. Appl. 16 (1995) 235-253; on a regular grid the separators
/// are George's (1973) grid lines). A set of more than [`COORDINATE_LEAF`] vertices is split at
/// the median of the longest extent of its bounding box; of the two sides, the vertices of the
/// one that touch the other form the separator (the smaller such set), ordered after both
/// sides. Every edge between the two sides ends in the separator, so the order is a nested
/// dissection of the graph whatever the geometry; the points decide only how short the
/// separators are. It costs a median selection and one sweep of the edges per level, far less
/// than a minimum-degree or multilevel ordering.
///
/// `points[e]` is the point of equation `e` (its node); a supervariable takes its first
/// equation's point. `None` when a point is missing (not finite) or the lengths differ: the
/// caller then orders without geometry.
pub fn coordinate_dissection(pattern: &Pattern, points: &[[f64; 3]]) -> Option<Vec<usize>> {
    if points.len() != pattern.n || points.iter().flatten().any(|c| !c.is_finite()) {
        return None;
    }
    let q = quotient(pattern);
    let nv = q.groups.len();
    let point: Vec<[f64; 3]> = q.groups.iter().map(|g| points[g.start]).collect();
    let mut mark = vec![0u32; nv];
    let mut stamp = 0u32;
    let mut vertex_order = Vec::with_capacity(nv);
    // (set, is_separator): a separator is emitted when popped, after the sides pushed above it
    let mut stack: Vec<(Vec<usize>, bool)> = vec![((0..nv).collect(), false)];
    while let Some((mut set, separator)) = stack.pop() {
        if separator || set.len() <= COORDINATE_LEAF {
            banded(&mut set, &point);
            vertex_order.extend_from_slice(&set);
            continue;
        }
        let axis = extents_by_length(&set, &point)[0];
        let (lower, upper) = bisect(set, &point, axis);
        stamp += 2;
        let (in_lower, in_upper) = (stamp - 1, stamp);
        for &v in &lower {
            mark[v] = in_lower;
        }
        for &v in &upper {
            mark[v] = in_upper;
        }
        let touches = |v: usize, other: u32| q.neighbours(v).iter().any(|&w| mark[w] == other);
        let lower_cut = lower.iter().filter(|&&v| touches(v, in_upper)).count();
        let upper_cut = upper.iter().filter(|&&v| touches(v, in_lower)).count();
        let (cut, other, other_stamp) = if lower_cut <= upper_cut {
            (lower, upper, in_upper)
        } else {
            (upper, lower, in_lower)
        };
        let (separator, rest): (Vec<usize>, Vec<usize>) =
            cut.into_iter().partition(|&v| touches(v, other_stamp));
        stack.push((separator, true));
        stack.push((other, false));
        stack.push((rest, false));
    }
    let mut order = Vec::with_capacity(pattern.n);
    for v in vertex_order {
        order.extend(q.groups[v].clone());
    }
    Some(order)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An upper-triangular CSC pattern built from dense blocks.
    struct Owned {
        n: usize,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
    }

    impl Owned {
        fn view(&self) -> Pattern<'_> {
            Pattern {
                n: self.n,
                col_ptr: &self.col_ptr,
                row_idx: &self.row_idx,
            }
        }
    }

    struct Builder {
        columns: Vec<std::collections::BTreeSet<usize>>,
    }

    impl Builder {
        fn new(n: usize) -> Self {
            Builder {
                columns: vec![Default::default(); n],
            }
        }
        fn add_block(&mut self, eqs: &[usize]) {
            for &i in eqs {
                for &j in eqs {
                    if i <= j {
                        self.columns[j].insert(i);
                    }
                }
            }
        }
        fn build(self) -> Owned {
            let mut col_ptr = vec![0];
            let mut row_idx = Vec::new();
            for c in &self.columns {
                row_idx.extend(c.iter().copied());
                col_ptr.push(row_idx.len());
            }
            Owned {
                n: self.columns.len(),
                col_ptr,
                row_idx,
            }
        }
    }

    /// The pattern of the 5-point Laplacian on an `n x n` grid with `dofs` unknowns per node.
    fn grid(n: usize, dofs: usize) -> Owned {
        let node = |i: usize, j: usize| i * n + j;
        let mut b = Builder::new(n * n * dofs);
        for i in 0..n {
            for j in 0..n {
                let mut block = vec![node(i, j)];
                if i + 1 < n {
                    block.push(node(i + 1, j));
                }
                if j + 1 < n {
                    block.push(node(i, j + 1));
                }
                for &a in &block {
                    for &c in &block {
                        let eqs: Vec<usize> = [a, c]
                            .iter()
                            .flat_map(|&v| (0..dofs).map(move |d| dofs * v + d))
                            .collect();
                        b.add_block(&eqs);
                    }
                }
            }
        }
        b.build()
    }

    /// `order` holds each of the `n` equations once and each node's `dofs` equations together,
    /// in turn.
    fn assert_node_order(order: &[usize], n: usize, dofs: usize) {
        let mut sorted = order.to_vec();
        sorted.sort_unstable();
        assert_eq!(
            sorted,
            (0..n).collect::<Vec<_>>(),
            "not a permutation of {n}"
        );
        for chunk in order.chunks(dofs) {
            assert_eq!(chunk[0] % dofs, 0);
            assert!(chunk.windows(2).all(|w| w[1] == w[0] + 1));
        }
    }

    #[test]
    fn the_order_is_a_permutation_keeping_each_node_s_dofs_together() {
        for (n, dofs) in [(1, 1), (7, 1), (20, 2), (33, 3)] {
            let p = grid(n, dofs);
            let order = nested_dissection(&p.view());
            assert_node_order(&order, p.n, dofs);
        }
    }

    #[test]
    fn metis_orders_every_equation_once_keeping_each_node_s_dofs_together() {
        for (n, dofs) in [(1, 1), (7, 1), (20, 2), (33, 3)] {
            let p = grid(n, dofs);
            let order = metis_nested_dissection(&p.view()).expect("METIS orders a grid");
            assert_node_order(&order, p.n, dofs);
        }
        let empty = Owned {
            n: 0,
            col_ptr: vec![0],
            row_idx: Vec::new(),
        };
        assert_eq!(metis_nested_dissection(&empty.view()), Some(Vec::new()));
    }

    /// The number of connected parts of the pattern's graph without the last `tail`
    /// vertices of `order`.
    fn parts_without_tail(p: &Owned, order: &[usize], tail: usize) -> usize {
        let (start, adjacency) = full_adjacency(&p.view());
        let top: std::collections::HashSet<usize> =
            order[order.len() - tail..].iter().copied().collect();
        let mut component = vec![usize::MAX; p.n];
        let mut count = 0;
        for s in 0..p.n {
            if top.contains(&s) || component[s] != usize::MAX {
                continue;
            }
            let mut stack = vec![s];
            component[s] = count;
            while let Some(v) = stack.pop() {
                for &w in &adjacency[start[v]..start[v + 1]] {
                    if !top.contains(&w) && component[w] == usize::MAX {
                        component[w] = count;
                        stack.push(w);
                    }
                }
            }
            count += 1;
        }
        count
    }

    #[test]
    fn metis_s_last_equations_separate_the_grid() {
        // the top separator of a 41 x 41 grid: at most about two grid lines of vertices
        // (METIS's vertex separator from a refined edge cut), whose removal leaves two parts;
        // the separator is the shortest tail of the order whose removal disconnects the rest
        let n = 41;
        let p = grid(n, 1);
        let order = metis_nested_dissection(&p.view()).unwrap();
        let tail = (1..p.n)
            .find(|&t| parts_without_tail(&p, &order, t) >= 2)
            .unwrap();
        assert!(
            tail <= 2 * n,
            "the top separator has {tail} vertices on a {n} x {n} grid"
        );
    }

    /// The point of each equation of [`grid`]`(n, dofs)` (node `i n + j` at `(i, j)`).
    fn grid_points(n: usize, dofs: usize) -> Vec<[f64; 3]> {
        (0..n * n * dofs)
            .map(|e| {
                let v = e / dofs;
                [(v / n) as f64, (v % n) as f64, 0.0]
            })
            .collect()
    }

    #[test]
    fn the_coordinate_dissection_orders_every_equation_once_keeping_each_node_s_dofs_together() {
        for (n, dofs) in [(1, 1), (7, 1), (20, 2), (33, 3)] {
            let p = grid(n, dofs);
            let order = coordinate_dissection(&p.view(), &grid_points(n, dofs)).unwrap();
            assert_node_order(&order, p.n, dofs);
        }
    }

    #[test]
    fn the_coordinate_dissection_s_top_separator_is_one_grid_line() {
        // on a 41 x 41 grid the last 41 vertices (a grid line) disconnect the rest, and no
        // shorter tail does
        let n = 41;
        let p = grid(n, 1);
        let order = coordinate_dissection(&p.view(), &grid_points(n, 1)).unwrap();
        assert_eq!(parts_without_tail(&p, &order, n), 2);
        assert_eq!(parts_without_tail(&p, &order, n - 1), 1);
    }

    #[test]
    fn any_points_give_a_dissection_of_the_graph() {
        // the points decide only the separators' lengths: with every point equal, or points
        // unrelated to the graph, the order is still a permutation whose top separator
        // disconnects the rest
        let n = 20;
        let p = grid(n, 1);
        let scrambled: Vec<[f64; 3]> = (0..n * n)
            .map(|e| [((e * 7919) % 101) as f64, ((e * 104_729) % 37) as f64, 0.0])
            .collect();
        for points in [vec![[1.0, 2.0, 3.0]; n * n], scrambled] {
            let order = coordinate_dissection(&p.view(), &points).unwrap();
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..p.n).collect::<Vec<_>>());
            let tail = (1..p.n).find(|&t| parts_without_tail(&p, &order, t) >= 2);
            assert!(tail.is_some(), "no tail of the order separates the grid");
        }
    }

    #[test]
    fn missing_points_leave_the_geometric_dissection_out() {
        let p = grid(5, 2);
        let mut points = grid_points(5, 2);
        assert!(coordinate_dissection(&p.view(), &points[1..]).is_none());
        points[7][1] = f64::NAN;
        assert!(coordinate_dissection(&p.view(), &points).is_none());
    }

    #[test]
    fn the_last_equations_separate_the_grid() {
        // on a 41 x 41 grid the top separator is a line of about 41 nodes whose removal
        // leaves two parts with no edge between them
        let n = 41;
        let p = grid(n, 1);
        let order = nested_dissection(&p.view());
        let count = parts_without_tail(&p, &order, n);
        assert!(
            count >= 2,
            "the last {n} vertices separate the grid ({count} part)"
        );
    }
}
