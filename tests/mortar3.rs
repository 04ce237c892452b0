//! The 3D segment-based mortar (`contact::discretization::mortar3`) against closed forms and
//! independent integrations: clip polygons that tile the covered slave facets (matching,
//! nested, rotated by 30 degrees, skewed and distorted grids, Quad4, Tri3, Quad9 and Tri6 on
//! either side),
//! linear and angular momentum of `D` and `M`, the weighted gap of a uniform separation,
//! standard `D` equal to the closed-form consistent mass of parallelogram facets, the dual
//! basis (closed-form coefficients, biorthogonality, diagonal `D`), Tri6's modified basis
//! (standard and dual `D` and the multiplier mass against closed forms, biorthogonality to the
//! modified basis, constants reproduced), nested `M` against an
//! integration over the finer side's facets, finite-difference checks of every row's
//! coefficients against the weighted gap integrated again at perturbed nodal positions, the
//! clipping edge cases, and the refusals.

use contact_patch::contact::discretization::mortar3::{
    clip_convex_polygons, collapsed_triangle_rule, dual_coefficients, mortar_integrals3,
    mortar_integrals3_with_points, mortar_rows3, weighted_gap, FacetSet3, MortarIntegrals3,
    RowNumbering, NON_AFFINE_POINTS,
};
use contact_patch::contact::Constraint;
use contact_patch::fe::{gauss_square, triangle_rule, ElementKind};
use contact_patch::io::scene::MultiplierSpace;
use std::collections::BTreeMap;

const SPACES: [MultiplierSpace; 2] = [MultiplierSpace::Standard, MultiplierSpace::Dual];
const KINDS: [(ElementKind, ElementKind); 11] = [
    (ElementKind::Q4, ElementKind::Q4),
    (ElementKind::T3, ElementKind::T3),
    (ElementKind::Q4, ElementKind::T3),
    (ElementKind::T3, ElementKind::Q4),
    (ElementKind::Q9, ElementKind::Q9),
    (ElementKind::Q9, ElementKind::Q4),
    (ElementKind::T3, ElementKind::Q9),
    (ElementKind::T6, ElementKind::T6),
    (ElementKind::T6, ElementKind::Q4),
    (ElementKind::Q4, ElementKind::T6),
    (ElementKind::T6, ElementKind::Q9),
];
/// Master node ids start here (slave ids from 0).
const MASTER_IDS: usize = 10_000;

type Map = Box<dyn Fn([f64; 2]) -> [f64; 2]>;

/// A surface over the parameter square `[0, 1]^2` cut into `nx x ny` cells, mapped into the
/// plane `z = z` by `map` then rotated by `rotation`; facets ordered for an outward normal
/// along `+z` (`up`) or `-z` before the rotation; each quad split in two triangles for Tri3
/// and Tri6; Quad9 and Tri6 nodes on the grid of half cells (mid-edge and centre nodes mapped
/// too, so a map that is not affine curves their edges).
#[allow(clippy::too_many_arguments)]
fn surface(
    kind: ElementKind,
    nx: usize,
    ny: usize,
    map: &dyn Fn([f64; 2]) -> [f64; 2],
    z: f64,
    up: bool,
    first_id: usize,
    rotation: &[[f64; 3]; 3],
) -> FacetSet3 {
    // grid points per cell side: 1, or 2 for Quad9 and Tri6
    let r = if matches!(kind, ElementKind::Q9 | ElementKind::T6) {
        2
    } else {
        1
    };
    let id = |i: usize, j: usize| first_id + j * (r * nx + 1) + i;
    let position = |i: usize, j: usize| {
        let [x, y] = map([i as f64 / (r * nx) as f64, j as f64 / (r * ny) as f64]);
        rotate(rotation, [x, y, z])
    };
    let mut facets = Vec::new();
    let mut coords = Vec::new();
    let mut push = |mut nodes: Vec<(usize, usize)>| {
        if !up {
            // the same facet seen from the other side: corners 0 3 2 1, mid-edges 7 6 5 4
            // (Quad9); corners 0 2 1, mid-edges 5 4 3 (Tri6)
            let order: &[usize] = match nodes.len() {
                9 => &[0, 3, 2, 1, 7, 6, 5, 4, 8],
                6 => &[0, 2, 1, 5, 4, 3],
                4 => &[0, 3, 2, 1],
                _ => &[0, 2, 1],
            };
            nodes = order.iter().map(|&k| nodes[k]).collect();
        }
        facets.push(nodes.iter().map(|&(i, j)| id(i, j)).collect());
        coords.push(nodes.iter().map(|&(i, j)| position(i, j)).collect());
    };
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1));
            match kind {
                ElementKind::Q4 => push(vec![a, b, c, d]),
                ElementKind::Q9 => {
                    let (i, j) = (2 * i, 2 * j);
                    push(vec![
                        (i, j),
                        (i + 2, j),
                        (i + 2, j + 2),
                        (i, j + 2),
                        (i + 1, j),
                        (i + 2, j + 1),
                        (i + 1, j + 2),
                        (i, j + 1),
                        (i + 1, j + 1),
                    ])
                }
                ElementKind::T6 => {
                    let (i, j) = (2 * i, 2 * j);
                    // corners a b c and a c d, mid-edge nodes of edges 0-1, 1-2, 2-0
                    push(vec![
                        (i, j),
                        (i + 2, j),
                        (i + 2, j + 2),
                        (i + 1, j),
                        (i + 2, j + 1),
                        (i + 1, j + 1),
                    ]);
                    push(vec![
                        (i, j),
                        (i + 2, j + 2),
                        (i, j + 2),
                        (i + 1, j + 1),
                        (i + 1, j + 2),
                        (i, j + 1),
                    ]);
                }
                _ => {
                    push(vec![a, b, c]);
                    push(vec![a, c, d]);
                }
            }
        }
    }
    FacetSet3::new(kind, facets, coords).expect("a valid facet set")
}

fn rotate(r: &[[f64; 3]; 3], x: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| r[i][0] * x[0] + r[i][1] * x[1] + r[i][2] * x[2])
}

const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A general rotation (about the axis (1, 2, 3) by 0.7 rad, Rodrigues' formula).
fn tilt() -> [[f64; 3]; 3] {
    let l = 14f64.sqrt();
    let k = [1.0 / l, 2.0 / l, 3.0 / l];
    let (s, c) = 0.7f64.sin_cos();
    let mut r = [[0.0; 3]; 3];
    let skew = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = if i == j { c } else { 0.0 } + s * skew[i][j] + (1.0 - c) * k[i] * k[j];
        }
    }
    r
}

fn rotated_by(degrees: f64, half: f64) -> Map {
    let (s, c) = degrees.to_radians().sin_cos();
    Box::new(move |[u, v]| {
        let (x, y) = (2.0 * half * (u - 0.5), 2.0 * half * (v - 0.5));
        [0.5 + c * x - s * y, 0.5 + s * x + c * y]
    })
}

/// The interface layouts: (name, slave map and cells, master map and cells, whether every
/// slave facet is a parallelogram, whether the master covers the slave surface).
struct Layout {
    name: &'static str,
    slave: (Map, usize, usize),
    master: (Map, usize, usize),
    affine: bool,
}

fn layouts() -> Vec<Layout> {
    let unit: fn() -> Map = || Box::new(|p| p);
    vec![
        Layout {
            name: "matching",
            slave: (unit(), 3, 3),
            master: (unit(), 3, 3),
            affine: true,
        },
        Layout {
            name: "nested 2x2 master facets in each slave facet",
            slave: (unit(), 2, 2),
            master: (unit(), 4, 4),
            affine: true,
        },
        Layout {
            name: "nested 2x2 slave facets in each master facet",
            slave: (unit(), 4, 4),
            master: (unit(), 2, 2),
            affine: true,
        },
        Layout {
            name: "master rotated by 30 degrees",
            slave: (unit(), 3, 3),
            master: (rotated_by(30.0, 1.0), 5, 5),
            affine: true,
        },
        Layout {
            name: "skewed slave and master",
            slave: (
                Box::new(|[u, v]| [0.1 + 0.8 * u + 0.15 * v, 0.1 + 0.8 * v]),
                3,
                4,
            ),
            master: (
                Box::new(|[u, v]| [-0.5 + 2.0 * u + 0.25 * (v - 0.5), -0.5 + 2.0 * v]),
                5,
                5,
            ),
            affine: true,
        },
        Layout {
            name: "distorted slave, master rotated by 30 degrees",
            slave: (
                Box::new(|[u, v]| {
                    let bump =
                        0.06 * (std::f64::consts::PI * u).sin() * (std::f64::consts::PI * v).sin();
                    [u + bump * (1.0 + v), v - 0.7 * bump * (1.0 - u)]
                }),
                3,
                3,
            ),
            master: (rotated_by(30.0, 1.0), 6, 5),
            affine: false,
        },
    ]
}

/// Slave (outward `-z`, at height `gap`) and master (outward `+z`, at 0) of `layout`, rotated.
fn interface(
    layout: &Layout,
    kinds: (ElementKind, ElementKind),
    gap: f64,
    rotation: &[[f64; 3]; 3],
) -> (FacetSet3, FacetSet3) {
    let (sm, sx, sy) = &layout.slave;
    let (mm, mx, my) = &layout.master;
    (
        surface(kinds.0, *sx, *sy, sm.as_ref(), gap, false, 0, rotation),
        surface(
            kinds.1,
            *mx,
            *my,
            mm.as_ref(),
            0.0,
            true,
            MASTER_IDS,
            rotation,
        ),
    )
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Vector area of a facet's corner polygon (its area times its outward normal); of a Quad9,
/// the sum of its four sub-quadrilaterals'; of a Tri6, of its four sub-triangles'.
fn vector_area(xs: &[[f64; 3]]) -> [f64; 3] {
    if xs.len() == 9 || xs.len() == 6 {
        let mut v = [0.0; 3];
        let pieces: Vec<Vec<usize>> = if xs.len() == 9 {
            vec![
                vec![0, 4, 8, 7],
                vec![4, 1, 5, 8],
                vec![8, 5, 2, 6],
                vec![7, 8, 6, 3],
            ]
        } else {
            vec![vec![0, 3, 5], vec![3, 1, 4], vec![5, 4, 2], vec![3, 4, 5]]
        };
        for piece in pieces {
            let corners: Vec<[f64; 3]> = piece.iter().map(|&k| xs[k]).collect();
            let a = vector_area(&corners);
            for d in 0..3 {
                v[d] += a[d];
            }
        }
        return v;
    }
    let k = if xs.len() == 4 { 4 } else { 3 };
    let mut v = [0.0; 3];
    for i in 0..k {
        let c = cross(xs[i], xs[(i + 1) % k]);
        for d in 0..3 {
            v[d] += 0.5 * c[d];
        }
    }
    v
}

/// Area-weighted outward nodal normals (unit) of a surface.
fn nodal_normals(s: &FacetSet3) -> BTreeMap<usize, [f64; 3]> {
    let mut out: BTreeMap<usize, [f64; 3]> = BTreeMap::new();
    for (ids, xs) in s.facets.iter().zip(&s.coords) {
        let a = vector_area(xs);
        for id in ids {
            let n = out.entry(*id).or_default();
            for d in 0..3 {
                n[d] += a[d];
            }
        }
    }
    for n in out.values_mut() {
        let l = dot(*n, *n).sqrt();
        *n = n.map(|v| v / l);
    }
    out
}

fn polygon_area(polygon: &[[f64; 3]]) -> f64 {
    let mut v = [0.0; 3];
    for i in 0..polygon.len() {
        let c = cross(polygon[i], polygon[(i + 1) % polygon.len()]);
        for d in 0..3 {
            v[d] += 0.5 * c[d];
        }
    }
    dot(v, v).sqrt()
}

fn area_2d(p: &[[f64; 2]]) -> f64 {
    (0..p.len())
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            0.5 * (a[0] * b[1] - a[1] * b[0])
        })
        .sum()
}

fn every_case() -> Vec<(String, FacetSet3, FacetSet3, bool)> {
    let mut out = Vec::new();
    for layout in layouts() {
        for kinds in KINDS {
            for (rotation, tilted) in [(IDENTITY, "flat"), (tilt(), "tilted")] {
                let (s, m) = interface(&layout, kinds, 0.0, &rotation);
                out.push((
                    format!("{} ({kinds:?}, {tilted})", layout.name),
                    s,
                    m,
                    layout.affine,
                ));
            }
        }
    }
    out
}

#[test]
fn clip_polygons_tile_every_covered_slave_facet() {
    for (name, slave, master, _) in every_case() {
        let integrals =
            mortar_integrals3(&slave, &master, MultiplierSpace::Standard, None).expect("integrals");
        let mut covered = vec![0.0; slave.facets.len()];
        for cell in &integrals.cells {
            let independent = polygon_area(&cell.polygon);
            assert!(
                (cell.area - independent).abs() <= 1e-14,
                "{name}: cell area {} vs its polygon's {independent}",
                cell.area
            );
            covered[cell.slave_facet] += cell.area;
        }
        let mut worst = 0.0f64;
        for (f, xs) in slave.coords.iter().enumerate() {
            let a = vector_area(xs);
            let area = dot(a, a).sqrt();
            worst = worst.max((covered[f] - area).abs() / area);
        }
        assert!(
            worst <= 1e-13,
            "{name}: clip areas off the facet areas by {worst:e}"
        );
    }
}

/// Largest relative defect of linear (`sum_k D_jk = sum_l M_jl`) and angular
/// (`sum_k D_jk x_k = sum_l M_jl x_l`) momentum over the slave nodes.
fn momentum_defects(
    integrals: &MortarIntegrals3,
    slave: &FacetSet3,
    master: &FacetSet3,
) -> (f64, f64) {
    let (xs, xm) = (slave.positions(), master.positions());
    let (mut linear, mut angular) = (0.0f64, 0.0f64);
    for (j, dj) in &integrals.d {
        let mj = &integrals.m[j];
        let area: f64 = dj.values().sum();
        let sum_m: f64 = mj.values().sum();
        linear = linear.max((area - sum_m).abs() / area);
        for c in 0..3 {
            let ds: f64 = dj.iter().map(|(k, w)| w * xs[k][c]).sum();
            let ms: f64 = mj.iter().map(|(l, w)| w * xm[l][c]).sum();
            // relative to the row's area times the interface's size (1)
            angular = angular.max((ds - ms).abs() / area);
        }
    }
    (linear, angular)
}

#[test]
fn linear_and_angular_momentum_on_flat_coplanar_interfaces() {
    let mut seen = (0.0f64, 0.0f64);
    for (name, slave, master, _) in every_case() {
        for space in SPACES {
            let integrals = mortar_integrals3(&slave, &master, space, None).expect("integrals");
            let (linear, angular) = momentum_defects(&integrals, &slave, &master);
            seen = (seen.0.max(linear), seen.1.max(angular));
            assert!(
                linear <= 1e-13,
                "{name} {space:?}: linear momentum off by {linear:e}"
            );
            assert!(
                angular <= 1e-13,
                "{name} {space:?}: angular momentum off by {angular:e}"
            );
        }
    }
    println!(
        "largest relative defects: linear {:e}, angular {:e}",
        seen.0, seen.1
    );
}

#[test]
fn weighted_gap_of_a_uniform_separation_is_the_separation_times_the_row_area() {
    let d = 0.0125;
    for layout in layouts() {
        for kinds in KINDS {
            for rotation in [IDENTITY, tilt()] {
                let (slave, master) = interface(&layout, kinds, d, &rotation);
                let normals = nodal_normals(&slave);
                for space in SPACES {
                    let numbering = RowNumbering {
                        slave_body: 0,
                        pair: 0,
                        pass: 1,
                        slave_dof: &|n, i| 3 * n + i,
                        master_dof: &|n, i| 3 * n + i,
                        tied: false,
                    };
                    let (rows, integrals) =
                        mortar_rows3(&slave, &master, space, &normals, &numbering, None)
                            .expect("rows");
                    assert_eq!(rows.len(), slave.positions().len(), "{}", layout.name);
                    for row in &rows {
                        let area: f64 = integrals.d[&row.slave_node].values().sum();
                        let g = weighted_gap(
                            &integrals,
                            row.slave_node,
                            row.normal,
                            &slave.positions(),
                            &master.positions(),
                        )
                        .expect("a D line");
                        assert!(
                            (g - d * area).abs() <= 1e-13 * area,
                            "{} {kinds:?} {space:?}: weighted gap {g} vs {}",
                            layout.name,
                            d * area
                        );
                        assert!((row.g0 - d).abs() <= 1e-13, "row gap {} vs {d}", row.g0);
                        assert!((row.area - area).abs() <= 1e-15);
                    }
                }
            }
        }
    }
}

/// The consistent mass matrix of a flat parallelogram Quad4 or a flat Tri3 facet (closed
/// form): `A/36 [4 on the node, 2 along an edge, 1 across]`, `A/12 (1 + delta)`; of a flat
/// straight-edged parallelogram Quad9, `A/4 m(xi_a, xi_b) m(eta_a, eta_b)` with the Line3
/// mass `m` on nodes -1, 0, 1: `[[4, 2, -1], [2, 16, 2], [-1, 2, 4]] / 15`.
fn closed_form_mass(xs: &[[f64; 3]]) -> Vec<Vec<f64>> {
    let a = vector_area(xs);
    let area = dot(a, a).sqrt();
    let n = xs.len();
    if n == 9 {
        let line3 = |s: f64, t: f64| {
            let (i, j) = ((s + 1.0) as usize, (t + 1.0) as usize);
            [[4.0, 2.0, -1.0], [2.0, 16.0, 2.0], [-1.0, 2.0, 4.0]][i][j] / 15.0
        };
        let natural = ElementKind::Q9.node_coordinates();
        return (0..9)
            .map(|j| {
                (0..9)
                    .map(|k| {
                        let (a, b) = (natural[j], natural[k]);
                        0.25 * area * line3(a[0], b[0]) * line3(a[1], b[1])
                    })
                    .collect()
            })
            .collect();
    }
    (0..n)
        .map(|j| {
            (0..n)
                .map(|k| match (n, (k + n - j) % n) {
                    (3, 0) => area / 6.0,
                    (3, _) => area / 12.0,
                    (_, 0) => 4.0 * area / 36.0,
                    (_, 2) => area / 36.0,
                    _ => 2.0 * area / 36.0,
                })
                .collect()
        })
        .collect()
}

/// The consistent mass matrix `int N_j N_k dA` of a flat straight-edged Tri6 of area `A`:
/// `A/180 [6 -1 -1 0 -4 0; ...; 0 0 -4 32 16 16; ...]` (a corner against the mid-edge node
/// opposite it -4, against the others 0; mid-edge nodes 32 on the diagonal, 16 off it).
fn tri6_mass(area: f64) -> [[f64; 6]; 6] {
    let m = [
        [6.0, -1.0, -1.0, 0.0, -4.0, 0.0],
        [-1.0, 6.0, -1.0, 0.0, 0.0, -4.0],
        [-1.0, -1.0, 6.0, -4.0, 0.0, 0.0],
        [0.0, 0.0, -4.0, 32.0, 16.0, 16.0],
        [-4.0, 0.0, 0.0, 16.0, 32.0, 16.0],
        [0.0, -4.0, 0.0, 16.0, 16.0, 32.0],
    ];
    m.map(|row| row.map(|v| v * area / 180.0))
}

/// The Tri6 modified basis as a matrix, `N~ = T N`: corner `v` is `N_v + (N_e + N_e') / 5`
/// over its two edges, mid-edge node `e` is `3/5 N_e` (corners 0 1 2, mid-edge nodes 3 (0-1),
/// 4 (1-2), 5 (2-0)).
fn tri6_modification() -> [[f64; 6]; 6] {
    let mut t = [[0.0; 6]; 6];
    for (v, edges) in [(0, [3, 5]), (1, [3, 4]), (2, [4, 5])] {
        t[v][v] = 1.0;
        for e in edges {
            t[v][e] = 0.2;
        }
    }
    for e in 3..6 {
        t[e][e] = 0.6;
    }
    t
}

/// Closed forms of a flat affine slave facet's `D` (standard and dual) and standard
/// multiplier mass, by local node: where the multipliers are built on the shape functions,
/// standard `D` and the mass are the consistent mass and dual `D` its row sums on the
/// diagonal; on a Tri6 (modified basis `N~ = T N`, `N = T^-1 N~`) standard `D = T M`, the mass
/// `T M T^T`, and dual `D_jk = int Psi_j N_k = (T^-1)_kj int N~_j`: `2A/15` on a corner's
/// diagonal, `A/3` on a mid-edge node's and `-A/15` at its edge's two corners.
fn closed_forms(xs: &[[f64; 3]]) -> [Vec<Vec<f64>>; 3] {
    if xs.len() != 6 {
        let m = closed_form_mass(xs);
        let n = m.len();
        let dual = (0..n)
            .map(|j| {
                (0..n)
                    .map(|k| if j == k { m[j].iter().sum() } else { 0.0 })
                    .collect()
            })
            .collect();
        return [m.clone(), dual, m];
    }
    let a = vector_area(xs);
    let area = dot(a, a).sqrt();
    let (m, t) = (tri6_mass(area), tri6_modification());
    let product = |a: &dyn Fn(usize, usize) -> f64, b: &dyn Fn(usize, usize) -> f64| {
        (0..6)
            .map(|j| {
                (0..6)
                    .map(|k| (0..6).map(|i| a(j, i) * b(i, k)).sum())
                    .collect::<Vec<f64>>()
            })
            .collect::<Vec<_>>()
    };
    let standard = product(&|j, i| t[j][i], &|i, k| m[i][k]);
    let mass = product(&|j, i| standard[j][i], &|i, k| t[k][i]);
    let mut dual = vec![vec![0.0; 6]; 6];
    for v in 0..3 {
        dual[v][v] = 2.0 * area / 15.0;
    }
    for (e, corners) in [(3, [0, 1]), (4, [1, 2]), (5, [2, 0])] {
        dual[e][e] = area / 3.0;
        for v in corners {
            dual[e][v] = -area / 15.0;
        }
    }
    [standard, dual, mass]
}

#[test]
fn standard_and_dual_d_match_their_closed_forms() {
    // standard D is the consistent mass and dual D its lumped diagonal, on the modified
    // basis for Tri6 (see `closed_forms`)
    let mut tri6_cases = 0;
    for (name, slave, master, affine) in every_case() {
        if !affine {
            continue;
        }
        tri6_cases += usize::from(slave.kind == ElementKind::T6);
        // the closed forms, assembled
        let mut exact: [BTreeMap<(usize, usize), f64>; 3] = Default::default();
        let mut scale: BTreeMap<usize, f64> = BTreeMap::new();
        for (ids, xs) in slave.facets.iter().zip(&slave.coords) {
            let forms = closed_forms(xs);
            for j in 0..ids.len() {
                for k in 0..ids.len() {
                    for (sum, form) in exact.iter_mut().zip(&forms) {
                        *sum.entry((ids[j], ids[k])).or_default() += form[j][k];
                    }
                    *scale.entry(ids[j]).or_default() += forms[0][j][k].abs();
                }
            }
        }
        let standard =
            mortar_integrals3(&slave, &master, MultiplierSpace::Standard, None).expect("integrals");
        let dual =
            mortar_integrals3(&slave, &master, MultiplierSpace::Dual, None).expect("integrals");
        let [standard_d, dual_d, mass] = &exact;
        for (what, integrated, closed) in [
            ("standard D", &standard.d, standard_d),
            ("dual D", &dual.d, dual_d),
            ("standard multiplier mass", &standard.multiplier_mass, mass),
        ] {
            for (&(j, k), &exact) in closed {
                let got = integrated[&j].get(&k).copied().unwrap_or(0.0);
                assert!(
                    (got - exact).abs() <= 1e-13 * scale[&j],
                    "{name}: {what}[{j}][{k}] = {got} vs {exact}"
                );
            }
            let entries: usize = integrated.values().map(|row| row.len()).sum();
            assert_eq!(entries, closed.len(), "{name}: {what} has other entries");
        }
    }
    assert!(tri6_cases > 0);
}

#[test]
fn dual_coefficients_match_the_closed_forms_and_are_biorthogonal() {
    // an affine Tri3 and a parallelogram Quad4 in the plane
    let tri = [[0.2, 0.1], [1.3, 0.4], [0.5, 1.1]];
    let a = dual_coefficients(ElementKind::T3, &tri).expect("coefficients");
    for j in 0..3 {
        for k in 0..3 {
            let exact = if j == k { 3.0 } else { -1.0 };
            assert!(
                (a[j][k] - exact).abs() <= 1e-13,
                "Tri3 a[{j}][{k}] = {}",
                a[j][k]
            );
        }
    }
    let quad = [[0.0, 0.0], [1.2, 0.3], [1.6, 1.3], [0.4, 1.0]];
    let a = dual_coefficients(ElementKind::Q4, &quad).expect("coefficients");
    for j in 0..4 {
        for k in 0..4 {
            let exact = [4.0, -2.0, 1.0, -2.0][(k + 4 - j) % 4];
            assert!(
                (a[j][k] - exact).abs() <= 1e-12,
                "Quad4 a[{j}][{k}] = {}",
                a[j][k]
            );
        }
    }
    // a trapezoid (not affine): int Psi_j N_k |J| = delta_jk int N_k |J|, by a 4x4 Gauss rule
    let trapezoid = [[0.0, 0.0], [2.0, 0.0], [1.4, 1.0], [0.3, 1.2]];
    let a = dual_coefficients(ElementKind::Q4, &trapezoid).expect("coefficients");
    let mut integral = [[0.0; 4]; 4];
    let mut lumped = [0.0; 4];
    for qp in gauss_square(4) {
        let mut n = [0.0; 4];
        let mut dn = [[0.0; 2]; 4];
        ElementKind::Q4.shape(qp.xi, &mut n, &mut dn);
        let mut jac = [[0.0; 2]; 2];
        for (b, q) in trapezoid.iter().enumerate() {
            for r in 0..2 {
                for c in 0..2 {
                    jac[r][c] += dn[b][c] * q[r];
                }
            }
        }
        let w = qp.weight * (jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]);
        for j in 0..4 {
            let psi: f64 = (0..4).map(|k| a[j][k] * n[k]).sum();
            lumped[j] += w * n[j];
            for k in 0..4 {
                integral[j][k] += w * psi * n[k];
            }
        }
    }
    for j in 0..4 {
        for k in 0..4 {
            let exact = if j == k { lumped[j] } else { 0.0 };
            assert!(
                (integral[j][k] - exact).abs() <= 1e-14,
                "trapezoid: int Psi_{j} N_{k} = {} vs {exact}",
                integral[j][k]
            );
        }
    }
    // on a triangle, by the degree-2 rule (exact for Psi N, degree 2)
    let a = dual_coefficients(ElementKind::T3, &tri).expect("coefficients");
    for qp_rule in [triangle_rule(2)] {
        let mut integral = [[0.0; 3]; 3];
        for qp in &qp_rule {
            let n = [1.0 - qp.xi[0] - qp.xi[1], qp.xi[0], qp.xi[1]];
            for j in 0..3 {
                let psi: f64 = (0..3).map(|k| a[j][k] * n[k]).sum();
                for k in 0..3 {
                    integral[j][k] += qp.weight * psi * n[k];
                }
            }
        }
        for j in 0..3 {
            for k in 0..3 {
                let exact = if j == k { 1.0 / 6.0 } else { 0.0 };
                assert!((integral[j][k] - exact).abs() <= 1e-15);
            }
        }
    }
}

#[test]
fn tri6_dual_basis_is_biorthogonal_to_the_modified_basis_and_reproduces_constants() {
    // an affine Tri6 (mid-edge nodes at the midpoints) and one curved in its plane (mid-edge
    // nodes moved): int Psi_j N~_k |J| = delta_jk int N~_k |J| (the integrand has degree 6 on
    // the curved one, |J| quadratic), by the collapsed 5 x 5 product (degree 8), not the
    // 4 x 4 one the coefficients are built with; sum_j Psi_j = 1 (constants); on the
    // affine one int N~ = 2A/15 (corner), A/5 (mid-edge) and int Psi_j N_k the dual D of
    // `closed_forms`
    let corners = [[0.2, 0.1], [1.3, 0.4], [0.5, 1.1]];
    let midpoint = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let affine: Vec<[f64; 2]> = corners
        .iter()
        .copied()
        .chain([(0, 1), (1, 2), (2, 0)].map(|(a, b)| midpoint(corners[a], corners[b])))
        .collect();
    let mut curved = affine.clone();
    curved[3][1] -= 0.08;
    curved[4][0] += 0.05;
    curved[5] = [curved[5][0] - 0.03, curved[5][1] + 0.04];
    let t = tri6_modification();
    let area = 0.5
        * ((corners[1][0] - corners[0][0]) * (corners[2][1] - corners[0][1])
            - (corners[2][0] - corners[0][0]) * (corners[1][1] - corners[0][1]));
    for (label, q) in [("affine", &affine), ("curved", &curved)] {
        let a = dual_coefficients(ElementKind::T6, q).expect("coefficients");
        let mut biorthogonal = [[0.0; 6]; 6];
        let mut nodal = [[0.0; 6]; 6];
        let mut modified_integral = [0.0; 6];
        for qp in collapsed_triangle_rule(5) {
            let mut n = [0.0; 6];
            let mut dn = [[0.0; 2]; 6];
            ElementKind::T6.shape(qp.xi, &mut n, &mut dn);
            let mut jac = [[0.0; 2]; 2];
            for (b, p) in q.iter().enumerate() {
                for r in 0..2 {
                    for c in 0..2 {
                        jac[r][c] += dn[b][c] * p[r];
                    }
                }
            }
            let w = qp.weight * (jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]);
            let modified: Vec<f64> = (0..6)
                .map(|j| (0..6).map(|k| t[j][k] * n[k]).sum())
                .collect();
            let psi: Vec<f64> = (0..6)
                .map(|j| (0..6).map(|k| a[j][k] * modified[k]).sum())
                .collect();
            let total: f64 = psi.iter().sum();
            assert!(
                (total - 1.0).abs() <= 1e-13,
                "{label}: sum Psi = {total} at {:?}",
                qp.xi
            );
            for j in 0..6 {
                modified_integral[j] += w * modified[j];
                for k in 0..6 {
                    biorthogonal[j][k] += w * psi[j] * modified[k];
                    nodal[j][k] += w * psi[j] * n[k];
                }
            }
        }
        for j in 0..6 {
            for k in 0..6 {
                let exact = if j == k { modified_integral[j] } else { 0.0 };
                assert!(
                    (biorthogonal[j][k] - exact).abs() <= 1e-14,
                    "{label}: int Psi_{j} N~_{k} = {} vs {exact}",
                    biorthogonal[j][k]
                );
            }
        }
        if label == "affine" {
            let corners3 = [0, 1, 2].map(|c| [corners[c][0], corners[c][1], 0.0]);
            let facet: Vec<[f64; 3]> = (0..6)
                .map(|k| {
                    if k < 3 {
                        corners3[k]
                    } else {
                        [affine[k][0], affine[k][1], 0.0]
                    }
                })
                .collect();
            let [_, dual, _] = closed_forms(&facet);
            for j in 0..6 {
                let exact = if j < 3 { 2.0 * area / 15.0 } else { area / 5.0 };
                assert!((modified_integral[j] - exact).abs() <= 1e-15);
                for k in 0..6 {
                    assert!(
                        (nodal[j][k] - dual[j][k]).abs() <= 1e-14,
                        "int Psi_{j} N_{k} = {} vs {}",
                        nodal[j][k],
                        dual[j][k]
                    );
                }
            }
        }
    }
}

/// The bilinear shape function of the corner `c` of the axis-aligned rectangle `[lo, hi]`
/// at `x` (independent of any node ordering).
fn hat(lo: [f64; 2], hi: [f64; 2], c: [f64; 2], x: [f64; 2]) -> f64 {
    (0..2)
        .map(|i| 1.0 - (x[i] - c[i]).abs() / (hi[i] - lo[i]))
        .product()
}

#[test]
fn nested_m_matches_an_integration_over_the_finer_masters_facets() {
    // slave 2x2 over [0,1]^2 (outward -z), master 4x4 (outward +z): each master facet lies in
    // one slave facet, so M_jl = sum over master facets of int Phi_j N_l, a polynomial on it
    let layout = &layouts()[1];
    let (slave, master) = interface(layout, (ElementKind::Q4, ElementKind::Q4), 0.0, &IDENTITY);
    let rect = |xs: &[[f64; 3]]| {
        let lo = [0, 1].map(|i| xs.iter().map(|p| p[i]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1].map(|i| xs.iter().map(|p| p[i]).fold(f64::NEG_INFINITY, f64::max));
        (lo, hi)
    };
    for space in SPACES {
        let integrals = mortar_integrals3(&slave, &master, space, None).expect("integrals");
        let mut reference: BTreeMap<(usize, usize), f64> = BTreeMap::new();
        for (mids, mxs) in master.facets.iter().zip(&master.coords) {
            let (mlo, mhi) = rect(mxs);
            let centre = [0.5 * (mlo[0] + mhi[0]), 0.5 * (mlo[1] + mhi[1])];
            let (f, sxs) = slave
                .coords
                .iter()
                .enumerate()
                .find(|(_, s)| {
                    let (lo, hi) = rect(s);
                    (0..2).all(|i| lo[i] < centre[i] && centre[i] < hi[i])
                })
                .expect("a slave facet over the master facet");
            let (slo, shi) = rect(sxs);
            for qp in gauss_square(3) {
                let x = [0, 1].map(|i| mlo[i] + 0.5 * (qp.xi[i] + 1.0) * (mhi[i] - mlo[i]));
                let w = qp.weight * 0.25 * (mhi[0] - mlo[0]) * (mhi[1] - mlo[1]);
                let n_s: Vec<f64> = sxs.iter().map(|c| hat(slo, shi, [c[0], c[1]], x)).collect();
                for (j, cj) in sxs.iter().enumerate() {
                    // dual: 4 N_j - 2 (edge neighbours) + N (opposite), by geometry
                    let phi = match space {
                        MultiplierSpace::Standard => n_s[j],
                        MultiplierSpace::Dual => sxs
                            .iter()
                            .zip(&n_s)
                            .map(|(ck, nk)| {
                                let shared = (0..2).filter(|&i| ck[i] == cj[i]).count();
                                [1.0, -2.0, 4.0][shared] * nk
                            })
                            .sum(),
                    };
                    for (l, cl) in mids.iter().zip(mxs) {
                        *reference.entry((slave.facets[f][j], *l)).or_default() +=
                            w * phi * hat(mlo, mhi, [cl[0], cl[1]], x);
                    }
                }
            }
        }
        for (&(j, l), &exact) in &reference {
            let got = integrals.m[&j].get(&l).copied().unwrap_or(0.0);
            assert!(
                (got - exact).abs() <= 1e-14,
                "{space:?}: M[{j}][{l}] = {got} vs {exact}"
            );
        }
        let entries: usize = integrals.m.values().map(|mj| mj.len()).sum();
        assert_eq!(
            entries,
            reference.len(),
            "{space:?}: M has entries the reference lacks"
        );
    }
}

fn numbering(tied: bool) -> RowNumbering<'static> {
    RowNumbering {
        slave_body: 0,
        pair: 0,
        pass: 1,
        slave_dof: &|n, i| 3 * n + i,
        master_dof: &|n, i| 3 * n + i,
        tied,
    }
}

/// `coeff` of `dof` in `row` (0 if absent).
fn coefficient(row: &Constraint<3>, dof: usize) -> f64 {
    row.dofs
        .iter()
        .position(|&d| d == dof)
        .map(|k| row.coeffs[k])
        .unwrap_or(0.0)
}

/// `surface` with the node `id` moved by `h` along component `c`.
fn moved(s: &FacetSet3, id: usize, c: usize, h: f64) -> FacetSet3 {
    let mut coords = s.coords.clone();
    for (ids, xs) in s.facets.iter().zip(coords.iter_mut()) {
        for (k, &n) in ids.iter().enumerate() {
            if n == id {
                xs[k][c] += h;
            }
        }
    }
    FacetSet3::new(s.kind, s.facets.clone(), coords).expect("a valid facet set")
}

#[test]
fn row_coefficients_are_the_derivatives_of_the_integrated_weighted_gap() {
    // a coplanar, tilted, non-matching interface: the weighted gap integrated again at
    // perturbed nodal positions (same normals; the segmentation follows the nodes) has, at
    // zero gap, the frozen D and M times nu as its gradient (the gap vanishes pointwise, so
    // the variations of D, M and the cells do not enter)
    let layout = Layout {
        name: "rotated",
        slave: (Box::new(|p| p), 2, 2),
        master: (rotated_by(30.0, 1.0), 3, 3),
        affine: true,
    };
    let h = 1e-6;
    let mut worst = 0.0f64;
    for kinds in KINDS {
        let (slave, master) = interface(&layout, kinds, 0.0, &tilt());
        let normals = nodal_normals(&slave);
        for space in SPACES {
            let (rows, _) = mortar_rows3(&slave, &master, space, &normals, &numbering(false), None)
                .expect("rows");
            let gaps = |s: &FacetSet3, m: &FacetSet3| -> BTreeMap<usize, f64> {
                let integrals = mortar_integrals3(s, m, space, None).expect("integrals");
                rows.iter()
                    .map(|r| {
                        let g = weighted_gap(
                            &integrals,
                            r.slave_node,
                            r.normal,
                            &s.positions(),
                            &m.positions(),
                        )
                        .expect("a D line");
                        (r.slave_node, g)
                    })
                    .collect()
            };
            let sides = [(true, &slave), (false, &master)];
            for (is_slave, side) in sides {
                for &id in side.positions().keys() {
                    for c in 0..3 {
                        let (plus, minus) = if is_slave {
                            (
                                gaps(&moved(&slave, id, c, h), &master),
                                gaps(&moved(&slave, id, c, -h), &master),
                            )
                        } else {
                            (
                                gaps(&slave, &moved(&master, id, c, h)),
                                gaps(&slave, &moved(&master, id, c, -h)),
                            )
                        };
                        for row in &rows {
                            let fd = (plus[&row.slave_node] - minus[&row.slave_node]) / (2.0 * h);
                            let exact = coefficient(row, 3 * id + c) * row.area;
                            let error = (fd - exact).abs() / row.area;
                            worst = worst.max(error);
                            assert!(
                                error <= 1e-7,
                                "{kinds:?} {space:?}: row {} dof ({id}, {c}): FD {fd} vs {exact}",
                                row.slave_node
                            );
                        }
                    }
                }
            }
        }
    }
    println!("largest finite-difference defect (relative to the row area): {worst:e}");
}

#[test]
fn rows_are_affine_in_the_displacements_with_the_frozen_weighted_gap() {
    // at a gap, with D and M frozen: g_j(u) = g~_j(x + u) / A_j for any displacement u
    let layout = &layouts()[4];
    for kinds in KINDS {
        let (slave, master) = interface(layout, kinds, 0.03, &tilt());
        let normals = nodal_normals(&slave);
        for space in SPACES {
            let (rows, integrals) =
                mortar_rows3(&slave, &master, space, &normals, &numbering(false), None)
                    .expect("rows");
            let u_of = |id: usize, c: usize| 1e-3 * ((7 * id + 3 * c) as f64 * 0.37).sin();
            let mut u = vec![0.0; 3 * (MASTER_IDS + 100)];
            for (i, v) in u.iter_mut().enumerate() {
                *v = u_of(i / 3, i % 3);
            }
            let shift = |s: &FacetSet3| -> BTreeMap<usize, [f64; 3]> {
                s.positions()
                    .into_iter()
                    .map(|(id, x)| (id, [0, 1, 2].map(|c| x[c] + u_of(id, c))))
                    .collect()
            };
            for row in &rows {
                let g = weighted_gap(
                    &integrals,
                    row.slave_node,
                    row.normal,
                    &shift(&slave),
                    &shift(&master),
                )
                .expect("a D line");
                assert!(
                    (row.gap(&u) - g / row.area).abs() <= 1e-14,
                    "{kinds:?} {space:?}: row {} gap {} vs {}",
                    row.slave_node,
                    row.gap(&u),
                    g / row.area
                );
                // the row's direction is the reversed unit nodal normal; its owner a dof of its node
                let n = normals[&row.slave_node];
                assert!((0..3).all(|c| (row.normal[c] + n[c]).abs() <= 1e-15));
                assert_eq!(row.owner / 3, row.slave_node);
                match space {
                    MultiplierSpace::Standard => {
                        let total: f64 = row.mass.iter().map(|m| m.1).sum();
                        assert!((total - row.area).abs() <= 1e-14 * row.area);
                        assert_eq!(row.mass[0].0, row.slave_node);
                    }
                    MultiplierSpace::Dual => assert!(row.mass.is_empty()),
                }
            }
        }
    }
}

#[test]
fn tied_rows_restrain_the_three_directions_with_zero_gap() {
    let layout = &layouts()[3];
    let (slave, master) = interface(layout, (ElementKind::Q4, ElementKind::T3), 0.02, &tilt());
    let normals = nodal_normals(&slave);
    let (rows, integrals) = mortar_rows3(
        &slave,
        &master,
        MultiplierSpace::Dual,
        &normals,
        &numbering(true),
        None,
    )
    .expect("rows");
    assert_eq!(rows.len(), 3 * integrals.d.len());
    for (k, row) in rows.iter().enumerate() {
        assert!(row.bilateral && row.g0 == 0.0);
        let mut e = [0.0; 3];
        e[k % 3] = 1.0;
        assert_eq!(row.normal, e);
        // dual: the row's own slave dof and the master dofs along e only
        let dj = &integrals.d[&row.slave_node];
        assert!(
            (coefficient(row, 3 * row.slave_node + k % 3) - dj[&row.slave_node] / row.area).abs()
                <= 1e-15
        );
    }
}

#[test]
fn clipping_edge_cases() {
    let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let tol = 1e-12;
    let shifted = |dx: f64, dy: f64| square.map(|p| [p[0] + dx, p[1] + dy]);
    // disjoint
    assert!(clip_convex_polygons(&shifted(2.0, 0.3), &square, tol).is_empty());
    // touching along an edge, and at a corner
    assert!(clip_convex_polygons(&shifted(1.0, 0.0), &square, tol).is_empty());
    assert!(clip_convex_polygons(&shifted(1.0, 0.5), &square, tol).is_empty());
    assert!(clip_convex_polygons(&shifted(1.0, 1.0), &square, tol).is_empty());
    assert!(clip_convex_polygons(&shifted(1.0 + 1e-13, 0.0), &square, tol).is_empty());
    // identical: the square itself, four vertices
    let same = clip_convex_polygons(&square, &square, tol);
    assert_eq!(same.len(), 4, "{same:?}");
    assert!((area_2d(&same) - 1.0).abs() <= 1e-15);
    // one inside the other, both ways
    let small = [[0.2, 0.3], [0.6, 0.3], [0.6, 0.8], [0.2, 0.8]];
    let inner = clip_convex_polygons(&small, &square, tol);
    assert!((area_2d(&inner) - 0.2).abs() <= 1e-15, "{inner:?}");
    let inner = clip_convex_polygons(&square, &small, tol);
    assert!((area_2d(&inner) - 0.2).abs() <= 1e-15, "{inner:?}");
    // half overlap and a quarter overlap
    assert!(
        (area_2d(&clip_convex_polygons(&shifted(0.5, 0.0), &square, tol)) - 0.5).abs() <= 1e-15
    );
    assert!(
        (area_2d(&clip_convex_polygons(&shifted(0.5, 0.5), &square, tol)) - 0.25).abs() <= 1e-15
    );
    // a square rotated by 45 degrees about the centre: the regular octagon, area 2 (sqrt 2 - 1)
    let c = 0.5;
    let r = 0.5 * 2f64.sqrt();
    let diamond: Vec<[f64; 2]> = (0..4)
        .map(|k| {
            let t = std::f64::consts::FRAC_PI_2 * k as f64;
            [c + r * t.cos(), c + r * t.sin()]
        })
        .collect();
    let octagon = clip_convex_polygons(&diamond, &square, tol);
    assert_eq!(octagon.len(), 8, "{octagon:?}");
    assert!((area_2d(&octagon) - 2.0 * (2f64.sqrt() - 1.0)).abs() <= 1e-15);
    // nearly parallel edges: the square turned by 1e-12 and by 1e-9 rad about its corner
    for angle in [1e-12f64, 1e-9, 1e-6] {
        let (s, co) = angle.sin_cos();
        let turned = square.map(|p| [co * p[0] - s * p[1], s * p[0] + co * p[1]]);
        let clip = clip_convex_polygons(&turned, &square, tol);
        // the overlap is the square less two thin triangles of area tan(angle)/2 each
        let exact = 1.0 - angle.tan();
        assert!(
            (area_2d(&clip) - exact).abs() <= 1e-12,
            "turned by {angle}: {} vs {exact} ({clip:?})",
            area_2d(&clip)
        );
        assert!(clip.iter().all(|p| p
            .iter()
            .all(|v| v.is_finite() && *v >= -1e-12 && *v <= 1.0 + 1e-12)));
    }
    // a triangle against the square
    let triangle = [[-0.5, -0.5], [2.0, -0.5], [-0.5, 2.0]];
    let clip = clip_convex_polygons(&triangle, &square, tol);
    assert!((area_2d(&clip) - 0.875).abs() <= 1e-15, "{clip:?}");
}

#[test]
fn partially_covered_slave_facets_integrate_only_the_covered_part() {
    // a master shifted by half a slave facet: the overlap is exactly the covered strip
    let layout = Layout {
        name: "shifted",
        slave: (Box::new(|p| p), 2, 2),
        master: (Box::new(|[u, v]| [u + 0.25, v]), 2, 2),
        affine: true,
    };
    let (slave, master) = interface(&layout, (ElementKind::Q4, ElementKind::Q4), 0.0, &IDENTITY);
    let integrals =
        mortar_integrals3(&slave, &master, MultiplierSpace::Standard, None).expect("integrals");
    let total: f64 = integrals.cells.iter().map(|c| c.area).sum();
    assert!((total - 0.75).abs() <= 1e-15, "overlap {total} vs 0.75");
    let (linear, angular) = momentum_defects(&integrals, &slave, &master);
    assert!(
        linear <= 1e-13 && angular <= 1e-13,
        "{linear:e} {angular:e}"
    );
}

#[test]
fn bad_input_is_refused_with_a_reason() {
    let tri6 = FacetSet3::new(
        ElementKind::T6,
        vec![(0..6).collect()],
        vec![vec![
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [1.5, 0.0, 0.0],
            [1.0, 0.0, 0.0],
        ]],
    );
    assert!(tri6.unwrap_err().contains("degenerate"));
    let short = FacetSet3::new(ElementKind::T3, vec![vec![0, 1, 2]], vec![]);
    assert!(short.unwrap_err().contains("coordinate lists"));
    let flat = FacetSet3::new(
        ElementKind::T3,
        vec![vec![0, 1, 2]],
        vec![vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]],
    );
    assert!(flat.unwrap_err().contains("degenerate"));
    let twice = FacetSet3::new(
        ElementKind::T3,
        vec![vec![0, 1, 2], vec![0, 2, 3]],
        vec![
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0.5, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
        ],
    );
    assert!(twice.unwrap_err().contains("two positions"));
    let nan = FacetSet3::new(
        ElementKind::T3,
        vec![vec![0, 1, 2]],
        vec![vec![[0.0; 3], [f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]]],
    );
    assert!(nan.unwrap_err().contains("non-finite"));
    // surfaces that do not face each other give no row, and say why
    let layout = &layouts()[0];
    let (slave, _) = interface(layout, (ElementKind::Q4, ElementKind::Q4), 0.0, &IDENTITY);
    let (_, master) = interface(layout, (ElementKind::Q4, ElementKind::Q4), 0.0, &IDENTITY);
    let (same_way, _) = interface(layout, (ElementKind::Q4, ElementKind::Q4), -0.1, &IDENTITY);
    let normals = nodal_normals(&slave);
    let err = mortar_rows3(
        &slave,
        &FacetSet3::new(
            ElementKind::Q4,
            same_way
                .facets
                .iter()
                .map(|f| f.iter().map(|n| n + MASTER_IDS).collect())
                .collect(),
            same_way.coords.clone(),
        )
        .expect("facets"),
        MultiplierSpace::Standard,
        &normals,
        &numbering(false),
        None,
    )
    .unwrap_err();
    assert!(err.contains("face each other"), "{err}");
    // a missing nodal normal
    let mut partial = normals.clone();
    partial.remove(&0);
    let err = mortar_rows3(
        &slave,
        &master,
        MultiplierSpace::Standard,
        &partial,
        &numbering(false),
        None,
    )
    .unwrap_err();
    assert!(err.contains("no nodal normal"), "{err}");
    let err =
        mortar_integrals3(&slave, &master, MultiplierSpace::Dual, Some(f64::NAN)).unwrap_err();
    assert!(err.contains("search distance"), "{err}");
}

#[test]
fn block_meshes_stacked_with_non_matching_faces() {
    use contact_patch::fe3d::SolidKind;
    use contact_patch::mesh::block3;
    // a foundation [0, 1]^2 x [-0.5, 0] (master: its top) under a punch
    // [0.1, 0.9]^2 x [d, 0.5 + d] (slave: its bottom) on other breaks, vertices moved in plane
    let d = 0.004;
    for (punch_kind, foundation_kind) in [
        (SolidKind::Hex8, SolidKind::Hex8),
        (SolidKind::Tet4, SolidKind::Hex8),
        (SolidKind::Hex8, SolidKind::Tet4),
        (SolidKind::Tet4, SolidKind::Tet4),
        (SolidKind::Hex27, SolidKind::Hex8),
        (SolidKind::Hex27, SolidKind::Hex27),
        (SolidKind::Tet4, SolidKind::Hex27),
        (SolidKind::Tet10, SolidKind::Tet10),
        (SolidKind::Tet10, SolidKind::Hex8),
        (SolidKind::Hex8, SolidKind::Tet10),
        (SolidKind::Tet10, SolidKind::Hex27),
    ] {
        let foundation = block3(
            foundation_kind,
            &[0.0, 0.3, 0.55, 1.0],
            &[0.0, 0.25, 0.6, 0.8, 1.0],
            &[-0.5, -0.2, 0.0],
            &[([0.3, 0.25, 0.0], [0.36, 0.2, 0.0])],
        )
        .expect("foundation");
        let punch = block3(
            punch_kind,
            &[0.1, 0.4, 0.9],
            &[0.1, 0.35, 0.65, 0.9],
            &[d, 0.5 + d],
            &[([0.4, 0.35, d], [0.45, 0.31, d])],
        )
        .expect("punch");
        let slave = FacetSet3::from_mesh(&punch, &punch.facet_sets["bottom"]).expect("slave");
        let master =
            FacetSet3::from_mesh(&foundation, &foundation.facet_sets["top"]).expect("master");
        let normals = nodal_normals(&slave);
        assert!(normals.values().all(|n| (n[2] + 1.0).abs() < 1e-15));
        let punch_nodes = punch.nodes.len();
        let numbering = RowNumbering {
            slave_body: 1,
            pair: 0,
            pass: 1,
            slave_dof: &|n, i| 3 * n + i,
            master_dof: &|n, i| 3 * (punch_nodes + n) + i,
            tied: false,
        };
        for space in SPACES {
            let (rows, integrals) =
                mortar_rows3(&slave, &master, space, &normals, &numbering, None).expect("rows");
            let covered: f64 = integrals.cells.iter().map(|c| c.area).sum();
            assert!(
                (covered - 0.64).abs() <= 1e-14,
                "{punch_kind:?}: overlap {covered}"
            );
            let (linear, _) = momentum_defects(&integrals, &slave, &master);
            assert!(linear <= 1e-13, "{linear:e}");
            assert_eq!(rows.len(), slave.positions().len());
            for row in &rows {
                assert!(
                    (row.g0 - d).abs() <= 1e-14,
                    "{punch_kind:?} {space:?}: {}",
                    row.g0
                );
                let e_z = [0.0, 0.0, 1.0];
                assert!((0..3).all(|c| (row.normal[c] - e_z[c]).abs() <= 1e-15));
            }
            // angular momentum at the gap: sum D x - sum M x = d e_z A_j
            let (xs, xm) = (slave.positions(), master.positions());
            for (j, dj) in &integrals.d {
                let area: f64 = dj.values().sum();
                for c in 0..3 {
                    let ds: f64 = dj.iter().map(|(k, w)| w * xs[k][c]).sum();
                    let ms: f64 = integrals.m[j].iter().map(|(l, w)| w * xm[l][c]).sum();
                    let exact = if c == 2 { d * area } else { 0.0 };
                    assert!((ds - ms - exact).abs() <= 1e-14 * area.max(1.0));
                }
            }
        }
    }
}

#[test]
fn matching_curved_surfaces_have_zero_weighted_gap_and_m_equal_to_d() {
    // both sides the same doubly curved (warped Quad4, curved Tri3) cap z = 0.3 (x^2 - 0.5 y^2):
    // every Gauss point of a slave facet maps to the same point of its twin master facet
    for kind in [
        ElementKind::Q4,
        ElementKind::T3,
        ElementKind::Q9,
        ElementKind::T6,
    ] {
        let map = |p: [f64; 2]| p;
        let lift = |s: &FacetSet3, offset: usize| {
            let coords = s
                .coords
                .iter()
                .map(|xs| {
                    xs.iter()
                        .map(|x| [x[0], x[1], 0.3 * (x[0] * x[0] - 0.5 * x[1] * x[1])])
                        .collect()
                })
                .collect();
            let facets = s
                .facets
                .iter()
                .map(|f| f.iter().map(|n| n + offset).collect())
                .collect();
            FacetSet3::new(kind, facets, coords).expect("curved facets")
        };
        let flat_slave = surface(kind, 4, 3, &map, 0.0, false, 0, &IDENTITY);
        let flat_master = surface(kind, 4, 3, &map, 0.0, true, 0, &IDENTITY);
        let slave = lift(&flat_slave, 0);
        let master = lift(&flat_master, MASTER_IDS);
        let normals = nodal_normals(&slave);
        for space in SPACES {
            let (rows, integrals) =
                mortar_rows3(&slave, &master, space, &normals, &numbering(false), None)
                    .expect("rows");
            for row in &rows {
                assert!(row.g0.abs() <= 1e-14, "{kind:?} {space:?}: gap {}", row.g0);
            }
            for (j, dj) in &integrals.d {
                for (k, v) in dj {
                    let mv = integrals.m[j]
                        .get(&(k + MASTER_IDS))
                        .copied()
                        .unwrap_or(0.0);
                    assert!(
                        (v - mv).abs() <= 1e-14,
                        "{kind:?} {space:?}: D[{j}][{k}] {v} vs M {mv}"
                    );
                }
                assert_eq!(
                    dj.len(),
                    integrals.m[j].len(),
                    "{kind:?}: M touches other nodes"
                );
            }
        }
    }
}

#[test]
fn collapsed_triangle_rule_integrates_degree_eight_exactly() {
    // int_T x^i y^j = i! j! / (i + j + 2)! on the reference triangle
    let factorial = |n: usize| (1..=n).map(|k| k as f64).product::<f64>();
    let rule = collapsed_triangle_rule(5);
    for i in 0..=8 {
        for j in 0..=8 - i {
            let got: f64 = rule
                .iter()
                .map(|q| q.weight * q.xi[0].powi(i as i32) * q.xi[1].powi(j as i32))
                .sum();
            let exact = factorial(i) * factorial(j) / factorial(i + j + 2);
            assert!(
                (got - exact).abs() <= 1e-14 * exact,
                "x^{i} y^{j}: {got} vs {exact}"
            );
        }
    }
}

/// The largest difference between two sets of integrals (`D` and `M`, entry by entry, an entry
/// missing from one side counting as zero), relative to the largest entry.
fn integrals_difference(a: &MortarIntegrals3, b: &MortarIntegrals3) -> f64 {
    let mut largest = 0.0f64;
    let mut difference = 0.0f64;
    for (x, y) in [(&a.d, &b.d), (&a.m, &b.m)] {
        for (j, row) in x.iter().chain(y.iter()) {
            for (k, _) in row.iter() {
                let get = |m: &BTreeMap<usize, BTreeMap<usize, f64>>| {
                    m.get(j).and_then(|r| r.get(k)).copied().unwrap_or(0.0)
                };
                let (p, q) = (get(x), get(y));
                largest = largest.max(p.abs()).max(q.abs());
                difference = difference.max((p - q).abs());
            }
        }
    }
    difference / largest
}

#[test]
fn non_affine_quad4_and_tri6_cells_are_integrated_to_round_off() {
    // Quad4 facets that are not parallelograms, and Tri6 facets curved in their plane (the
    // distorted layout maps their mid-edge nodes off the chords), have maps that are not
    // affine: the integrands are not polynomials on the clip cells. The rule they take
    // (NON_AFFINE_POINTS per direction) agrees with a 20 x 20 product to round-off, where a
    // degree-4 rule (3 x 3, about the accuracy of the affine cells' Radon rule) does not.
    let layout = layouts()
        .into_iter()
        .find(|l| !l.affine)
        .expect("a distorted layout");
    for kinds in [
        (ElementKind::Q4, ElementKind::Q4),
        (ElementKind::Q4, ElementKind::T3),
        (ElementKind::T6, ElementKind::T6),
        (ElementKind::T6, ElementKind::Q4),
    ] {
        let (slave, master) = interface(&layout, kinds, 0.0, &tilt());
        for space in SPACES {
            let at = |n| mortar_integrals3_with_points(&slave, &master, space, None, n).unwrap();
            let reference = at(20);
            let used = integrals_difference(&at(NON_AFFINE_POINTS), &reference);
            let coarse = integrals_difference(&at(3), &reference);
            assert!(used < 1e-13, "{kinds:?} {space:?}: {used:e}");
            assert!(
                coarse > 1e-9,
                "{kinds:?} {space:?}: the coarse rule is already exact ({coarse:e})"
            );
            let default = mortar_integrals3(&slave, &master, space, None).unwrap();
            assert_eq!(integrals_difference(&default, &at(NON_AFFINE_POINTS)), 0.0);
        }
    }
}
