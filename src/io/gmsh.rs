//! Writing meshes as Gmsh MSH 4.1 ASCII files, with a physical group for every body, every named
//! node set and every named facet set, so that other codes can read the catalogue's meshes.
//!
//! Format: "MSH file format version 4.1", Gmsh reference manual (C. Geuzaine, J.-F. Remacle,
//! gmsh.info/doc/texinfo/gmsh.html, sec. 10.1). Sections `$MeshFormat` (`4.1 0 8`),
//! `$PhysicalNames`, `$Entities`, `$Nodes`, `$Elements`. The layout chosen here:
//!
//! * body `b`: surface entity `b + 1` in the physical surface (dim 2) named after the body; all
//!   its nodes are classified on that surface, node tags `offset_b + local + 1` (bodies do not
//!   share nodes, so two bodies touching at an interface have distinct coincident nodes);
//!   its cells are Gmsh elements 3 (4-node quadrangle), 10 (9-node quadrangle), 2 (3-node
//!   triangle) or 9 (6-node triangle), whose node orders are ours (corners counter-clockwise,
//!   then edge midpoints from edge 0-1, then the centre);
//! * facet set `s` of body `b`: a curve entity of its own in the physical curve (dim 1) named
//!   `b/s`, holding the set's facets as elements 1 (2-node line) or 8 (3-node line: ends, then
//!   midpoint);
//! * node set `s` of body `b`: the physical point group (dim 0) named `b/s/nodes`; each node in
//!   a node set is a point entity (one element 15, a 1-node point) carrying the groups of every
//!   set that holds it. The automatic set `all` is the body's surface group and is not
//!   repeated. The suffix keeps every physical name unique: a facet set and the node set of its
//!   nodes usually share a name, and readers that key groups by name alone (meshio) would keep
//!   only one of two groups named alike.

use crate::fe::ElementKind;
use crate::mesh::Mesh;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The set every body has that equals its surface group (not written as a point group).
pub const ALL_NODES_SET: &str = "all";

/// The name of the physical group (dim 1) of facet set `set` of body `body`.
pub fn group_name(body: &str, set: &str) -> String {
    format!("{body}/{set}")
}

/// The name of the physical group (dim 0) of node set `set` of body `body`: distinct from the
/// facet set of the same name.
pub fn node_group_name(body: &str, set: &str) -> String {
    format!("{body}/{set}/nodes")
}

/// Gmsh element type of a cell kind, and of its facets.
pub fn element_types(kind: ElementKind) -> (u8, u8) {
    match kind {
        ElementKind::Q4 => (3, 1),
        ElementKind::Q9 => (10, 8),
        ElementKind::T3 => (2, 1),
        ElementKind::T6 => (9, 8),
    }
}

/// Bounding box `min x, min y, 0, max x, max y, 0` of some nodes.
fn bounds(mesh: &Mesh, nodes: impl Iterator<Item = usize>) -> String {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for n in nodes {
        for i in 0..2 {
            lo[i] = lo[i].min(mesh.nodes[n][i]);
            hi[i] = hi[i].max(mesh.nodes[n][i]);
        }
    }
    if lo[0] > hi[0] {
        return "0 0 0 0 0 0".into();
    }
    format!("{} {} 0 {} {} 0", lo[0], lo[1], hi[0], hi[1])
}

/// The MSH 4.1 text of the named meshes (in order; names are the bodies' names).
pub fn msh(bodies: &[(&str, &Mesh)]) -> String {
    // physical groups: (dim, tag, name)
    let mut groups: Vec<(u8, usize, String)> = Vec::new();
    let mut next_group = [1usize; 3];
    let mut group = |dim: u8, name: String, groups: &mut Vec<(u8, usize, String)>| {
        let tag = next_group[dim as usize];
        next_group[dim as usize] += 1;
        groups.push((dim, tag, name));
        tag
    };
    let mut offsets = Vec::new();
    let mut offset = 0usize;
    for (_, mesh) in bodies {
        offsets.push(offset);
        offset += mesh.nodes.len();
    }
    let node_count = offset;
    // point entities: (body, node, physical tags); curve entities: (body, set, physical tag)
    let mut points: Vec<(usize, usize, Vec<usize>)> = Vec::new();
    let mut curves: Vec<(usize, &str, usize)> = Vec::new();
    let mut surfaces: Vec<usize> = Vec::new();
    for (b, (name, mesh)) in bodies.iter().enumerate() {
        surfaces.push(group(2, name.to_string(), &mut groups));
        let mut of_node: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (set, nodes) in &mesh.node_sets {
            if set == ALL_NODES_SET {
                continue;
            }
            let tag = group(0, node_group_name(name, set), &mut groups);
            for &n in nodes {
                of_node.entry(n).or_default().push(tag);
            }
        }
        points.extend(of_node.into_iter().map(|(n, tags)| (b, n, tags)));
        for set in mesh.facet_sets.keys() {
            let tag = group(1, group_name(name, set), &mut groups);
            curves.push((b, set.as_str(), tag));
        }
    }
    let tags = |t: &[usize]| {
        let mut s = t.len().to_string();
        for x in t {
            let _ = write!(s, " {x}");
        }
        s
    };
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    let _ = writeln!(s, "{}", groups.len());
    for (dim, tag, name) in &groups {
        let _ = writeln!(s, "{dim} {tag} \"{}\"", name.replace('"', "'"));
    }
    s += "$EndPhysicalNames\n$Entities\n";
    let _ = writeln!(s, "{} {} {} 0", points.len(), curves.len(), surfaces.len());
    for (k, (b, n, t)) in points.iter().enumerate() {
        let p = bodies[*b].1.nodes[*n];
        let _ = writeln!(s, "{} {} {} 0 {}", k + 1, p[0], p[1], tags(t));
    }
    for (k, (b, set, tag)) in curves.iter().enumerate() {
        let mesh = bodies[*b].1;
        let nodes = mesh.facet_sets[*set]
            .iter()
            .flat_map(|&f| mesh.facet_nodes(f));
        let _ = writeln!(s, "{} {} {} 0", k + 1, bounds(mesh, nodes), tags(&[*tag]));
    }
    for (b, tag) in surfaces.iter().enumerate() {
        let mesh = bodies[b].1;
        let _ = writeln!(
            s,
            "{} {} {} 0",
            b + 1,
            bounds(mesh, 0..mesh.nodes.len()),
            tags(&[*tag])
        );
    }
    s += "$EndEntities\n$Nodes\n";
    let _ = writeln!(
        s,
        "{} {node_count} {} {node_count}",
        bodies.len(),
        node_count.min(1)
    );
    for (b, (_, mesh)) in bodies.iter().enumerate() {
        let _ = writeln!(s, "2 {} 0 {}", b + 1, mesh.nodes.len());
        for n in 0..mesh.nodes.len() {
            let _ = writeln!(s, "{}", offsets[b] + n + 1);
        }
        for p in &mesh.nodes {
            let _ = writeln!(s, "{} {} 0", p[0], p[1]);
        }
    }
    s += "$EndNodes\n$Elements\n";
    let element_count: usize = points.len()
        + curves
            .iter()
            .map(|(b, set, _)| bodies[*b].1.facet_sets[*set].len())
            .sum::<usize>()
        + bodies.iter().map(|(_, m)| m.cell_count()).sum::<usize>();
    let _ = writeln!(
        s,
        "{} {element_count} {} {element_count}",
        points.len() + curves.len() + bodies.len(),
        element_count.min(1)
    );
    let mut next = 1usize;
    for (k, (b, n, _)) in points.iter().enumerate() {
        let _ = writeln!(s, "0 {} 15 1\n{next} {}", k + 1, offsets[*b] + n + 1);
        next += 1;
    }
    for (k, (b, set, _)) in curves.iter().enumerate() {
        let mesh = bodies[*b].1;
        let facets = &mesh.facet_sets[*set];
        let _ = writeln!(
            s,
            "1 {} {} {}",
            k + 1,
            element_types(mesh.kind).1,
            facets.len()
        );
        for &f in facets {
            let ids: Vec<String> = mesh
                .facet_nodes(f)
                .iter()
                .map(|n| (offsets[*b] + n + 1).to_string())
                .collect();
            let _ = writeln!(s, "{next} {}", ids.join(" "));
            next += 1;
        }
    }
    for (b, (_, mesh)) in bodies.iter().enumerate() {
        let _ = writeln!(
            s,
            "2 {} {} {}",
            b + 1,
            element_types(mesh.kind).0,
            mesh.cell_count()
        );
        for c in 0..mesh.cell_count() {
            let ids: Vec<String> = mesh
                .cell(c)
                .iter()
                .map(|n| (offsets[b] + n + 1).to_string())
                .collect();
            let _ = writeln!(s, "{next} {}", ids.join(" "));
            next += 1;
        }
    }
    s += "$EndElements\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Facet;

    /// Two Q4 cells side by side: nodes 0-1-2 along y = 0, 3-4-5 along y = 1.
    fn strip() -> Mesh {
        let nodes = vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [0.0, 1.0],
            [1.0, 1.0],
            [2.0, 1.0],
        ];
        let mut m = Mesh::new(ElementKind::Q4, nodes, vec![0, 1, 4, 3, 1, 2, 5, 4]);
        m.node_sets.clear();
        m.facet_sets.clear();
        m.node_sets.insert("corner".into(), vec![0]);
        m.node_sets.insert("base".into(), vec![0, 1, 2]);
        m.node_sets.insert(ALL_NODES_SET.into(), (0..6).collect());
        m.facet_sets.insert(
            "base".into(),
            vec![Facet { cell: 0, edge: 0 }, Facet { cell: 1, edge: 0 }],
        );
        m
    }

    #[test]
    fn sections_counts_and_groups() {
        let m = strip();
        let text = msh(&[("a", &m), ("b", &m)]);
        assert!(text.starts_with("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"));
        // per body: the surface, 2 point groups, 1 curve group
        assert!(
            text.contains(
                "$PhysicalNames\n8\n2 1 \"a\"\n0 1 \"a/base/nodes\"\n0 2 \"a/corner/nodes\"\n1 1 \"a/base\"\n"
            ),
            "{text}"
        );
        // node 0 is in 'base' and 'corner': one point entity with both groups
        assert!(text.contains("\n1 0 0 0 2 1 2\n"), "{text}");
        // 3 point entities, 1 curve, 1 surface per body; 12 nodes tagged 1..12
        assert!(text.contains("$Entities\n6 2 2 0\n"), "{text}");
        assert!(text.contains("$Nodes\n2 12 1 12\n"), "{text}");
        // 10 blocks (6 points, 2 curves, 2 surfaces): 6 points + 4 lines + 4 quads
        assert!(text.contains("$Elements\n10 14 1 14\n"), "{text}");
        // body b's first quad uses its own node tags 7, 8, 11, 10
        assert!(text.contains("\n2 2 3 2\n13 7 8 11 10\n"), "{text}");
    }
}
