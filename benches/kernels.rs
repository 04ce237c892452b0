//! Criterion benchmarks of the element kernels and of the global assembly.
//!
//! Representative configurations, not sweeps: one stiffness per element kind on a distorted
//! cell (beside `<kind>_reference`, the array-loop kernel that preceded the nalgebra one), and full assembly (pattern + values), kernels + scatter, and factorization of a 50 x 50
//! Q4 plane-strain block (5,202 dofs), by `sparse::Cholesky` and by faer's high-level `Llt`
//! side by side, and the multigrid solver's matrix-vector product, V-cycle and setup (a CG
//! solve, really: setup and iterations) on a 200 x 200 block. Compare the figures as ratios within one run (e.g. Q9 vs Q4 kernel,
//! factorization vs assembly, `numeric_cholesky` vs `numeric_cholesky_faer_llt`), never as
//! absolute times across machines.

use contact_patch::fe::{ElementKind, QuadPoint, ReferenceCell};
use contact_patch::model::{parse, Model};
use contact_patch::solid::{element_stiffness, Elasticity, MAX_DOFS};
use contact_patch::solver::linear::{assemble, for_each_element_stiffness};
use contact_patch::solver::sparse::Cholesky;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn distorted(kind: ElementKind) -> Vec<[f64; 2]> {
    kind.node_coordinates()
        .iter()
        .map(|&[s, t]| {
            [
                2.0 + 1.3 * s + 0.2 * t + 0.05 * s * t,
                1.0 + 0.1 * s + 0.9 * t,
            ]
        })
        .collect()
}

/// The element stiffness as it was before the kernels moved to nalgebra (hand-written loops on
/// arrays, every `(a, b)` block computed), kept to measure the nalgebra kernel against it in the
/// same run.
fn element_stiffness_reference(
    kind: ElementKind,
    coords: &[[f64; 2]],
    material: &Elasticity,
    thickness: f64,
    rule: &[QuadPoint],
    ke: &mut [f64],
) {
    let nn = kind.node_count();
    let nd = 2 * nn;
    ke[..nd * nd].iter_mut().for_each(|v| *v = 0.0);
    // `D` as the array it was then (it is an nalgebra `Matrix3` now)
    let d: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| material.d[(i, j)]));
    let d = &d;
    for q in rule {
        let pv = kind.point_values(coords, q.xi);
        let w = q.weight * pv.det_j * thickness;
        for b in 0..nn {
            let [bx, by] = pv.dndx[b];
            // D B_b (3 x 2)
            let db = [
                [d[0][0] * bx + d[0][2] * by, d[0][1] * by + d[0][2] * bx],
                [d[1][0] * bx + d[1][2] * by, d[1][1] * by + d[1][2] * bx],
                [d[2][0] * bx + d[2][2] * by, d[2][1] * by + d[2][2] * bx],
            ];
            for a in 0..nn {
                let [ax, ay] = pv.dndx[a];
                // B_a^T (D B_b)
                let k00 = ax * db[0][0] + ay * db[2][0];
                let k01 = ax * db[0][1] + ay * db[2][1];
                let k10 = ay * db[1][0] + ax * db[2][0];
                let k11 = ay * db[1][1] + ax * db[2][1];
                let (r, c) = (2 * a, 2 * b);
                ke[r * nd + c] += w * k00;
                ke[r * nd + c + 1] += w * k01;
                ke[(r + 1) * nd + c] += w * k10;
                ke[(r + 1) * nd + c + 1] += w * k11;
            }
        }
    }
}

fn kernels(c: &mut Criterion) {
    let mat = Elasticity::new(1000.0, 0.3, contact_patch::io::scene::Plane::Strain);
    let mut group = c.benchmark_group("element_stiffness");
    for kind in [
        ElementKind::Q4,
        ElementKind::Q9,
        ElementKind::T3,
        ElementKind::T6,
    ] {
        let coords = distorted(kind);
        let rule = kind.stiffness_rule();
        let mut ke = [0.0; MAX_DOFS * MAX_DOFS];
        group.bench_function(format!("{kind:?}"), |b| {
            b.iter(|| element_stiffness(kind, black_box(&coords), &mat, 1.0, &rule, &mut ke))
        });
        group.bench_function(format!("{kind:?}_reference"), |b| {
            b.iter(|| {
                element_stiffness_reference(kind, black_box(&coords), &mat, 1.0, &rule, &mut ke)
            })
        });
    }
    group.finish();
}

fn block_model(n: usize) -> Model {
    let text = format!(
        r#"{{"name": "bench", "materials": {{"m": {{"E": 1000.0, "nu": 0.3}}}},
        "bodies": [{{"name": "b", "material": "m", "mesh": {{"block": {{"element": "Q4",
          "x": {{"from": 0, "to": 1, "divisions": {n}}}, "y": {{"from": 0, "to": 1, "divisions": {n}}}}}}}}}],
        "supports": [{{"body": "b", "set": "bottom", "y": 0.0}}, {{"body": "b", "set": "left", "x": 0.0}}],
        "loads": [{{"body": "b", "set": "top", "pressure": 1.0}}]}}"#
    );
    Model::build(&parse(&text, "bench").unwrap(), "bench").unwrap()
}

fn assembly(c: &mut Criterion) {
    let model = block_model(50);
    let sys = assemble(&model, &[]);
    let (eq, pattern) = (sys.constraints.equations(), &sys.pattern);
    let mut values = vec![0.0; pattern.nnz()];
    let mut group = c.benchmark_group("q4_block_50x50");
    group.sample_size(20);
    group.bench_function("assemble_pattern_and_values", |b| {
        b.iter(|| assemble(black_box(&model), &[]))
    });
    group.bench_function("kernels_and_scatter", |b| {
        b.iter(|| {
            values.iter_mut().for_each(|v| *v = 0.0);
            let mut eqs = Vec::with_capacity(MAX_DOFS);
            for_each_element_stiffness(&model, |dofs, ke| {
                eqs.clear();
                eqs.extend(dofs.iter().map(|&d| eq[d]));
                pattern.scatter(&eqs, ke, &mut values);
            });
        })
    });
    // the factorizations below read the assembled values whatever benchmarks a filter selects
    values.iter_mut().for_each(|v| *v = 0.0);
    let mut eqs = Vec::with_capacity(MAX_DOFS);
    for_each_element_stiffness(&model, |dofs, ke| {
        eqs.clear();
        eqs.extend(dofs.iter().map(|&d| eq[d]));
        pattern.scatter(&eqs, ke, &mut values);
    });
    let chol = Cholesky::analyse(pattern, &contact_patch::solver::sparse::UNLIMITED).unwrap();
    group.bench_function("symbolic_cholesky", |b| {
        b.iter(|| {
            Cholesky::analyse(
                black_box(pattern),
                &contact_patch::solver::sparse::UNLIMITED,
            )
            .unwrap()
        })
    });
    group.bench_function("numeric_cholesky", |b| {
        b.iter(|| chol.factor(pattern, black_box(&values)).unwrap())
    });
    // the same factorization through faer's high-level `Llt` (what `Cholesky` used before it
    // read the pivots and the permutation): the ratio of the two is the cost of those checks
    let symbolic =
        faer::sparse::linalg::solvers::SymbolicLlt::try_new(pattern.symbolic(), faer::Side::Upper)
            .unwrap();
    group.bench_function("numeric_cholesky_faer_llt", |b| {
        b.iter(|| {
            faer::sparse::linalg::solvers::Llt::try_new_with_symbolic(
                symbolic.clone(),
                faer::sparse::SparseColMatRef::new(pattern.symbolic(), black_box(&values)),
                faer::Side::Upper,
            )
            .unwrap()
        })
    });
    println!("factorization path: supernodal = {}", chol.is_supernodal());
    group.finish();
}

/// The 2D block mesher and the boundary facets of its mesh (every facet set and contact surface
/// of a case selects from them), 500 x 500 Q4.
fn mesh(c: &mut Criterion) {
    let breaks: Vec<f64> = (0..=500).map(|i| i as f64 / 500.0).collect();
    let mut group = c.benchmark_group("q4_block_500x500");
    group.sample_size(10);
    group.bench_function("block_mesher", |b| {
        b.iter(|| {
            contact_patch::mesh::block(
                contact_patch::fe::ElementKind::Q4,
                black_box(&breaks),
                &breaks,
                &[],
            )
            .unwrap()
        })
    });
    let mesh =
        contact_patch::mesh::block(contact_patch::fe::ElementKind::Q4, &breaks, &breaks, &[])
            .unwrap();
    group.bench_function("boundary_facets", |b| {
        b.iter(|| black_box(&mesh).boundary_facets())
    });
    group.finish();
}

/// The multigrid solver's hot paths on a 200 x 200 Q4 plane-strain block (80,400 equations):
/// one product `y = K x` of the full CSR matrix (rayon row blocks), one V-cycle of the
/// smoothed-aggregation hierarchy (src/solver/amg.rs), and the hierarchy's setup. Compare the
/// V-cycle with the product (a V-cycle is worth a handful of products) in one run.
fn multigrid(c: &mut Criterion) {
    let mut model = block_model(200);
    model.solver.linear_solver = contact_patch::io::scene::LinearSolver::CgAmg;
    let sys = assemble(&model, &[]);
    let a = contact_patch::solver::amg::CsrMatrix::from_symmetric_upper(&sys.pattern, &sys.k);
    let mut group = c.benchmark_group("q4_block_200x200");
    group.sample_size(20);
    let x: Vec<f64> = (0..sys.n).map(|i| (i as f64 * 0.618).fract()).collect();
    let mut y = vec![0.0; sys.n];
    group.bench_function("spmv", |b| b.iter(|| a.mul(black_box(&x), &mut y)));
    let mut amg =
        contact_patch::solver::iterative::AmgSolver::new(&model, sys.constraints.free_dofs());
    let mut u = vec![0.0; sys.n];
    amg.solve(&sys.pattern, &sys.k, &sys.rhs, &mut u).unwrap();
    let hierarchy = amg.hierarchy().unwrap();
    println!("multigrid levels: {:?}", hierarchy.level_sizes());
    group.bench_function("v_cycle", |b| {
        b.iter(|| hierarchy.apply(black_box(&x), &mut y))
    });
    group.sample_size(10);
    group.bench_function("amg_setup_and_cg_solve", |b| {
        b.iter(|| {
            let mut fresh = contact_patch::solver::iterative::AmgSolver::new(
                &model,
                sys.constraints.free_dofs(),
            );
            let mut u = vec![0.0; sys.n];
            fresh.solve(&sys.pattern, &sys.k, &sys.rhs, &mut u).unwrap();
        })
    });
    group.finish();
}

criterion_group!(benches, kernels, assembly, mesh, multigrid);
criterion_main!(benches);
