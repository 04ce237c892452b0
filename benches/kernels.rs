//! Criterion benchmarks of the element kernels and of the global assembly.
//!
//! Representative configurations, not sweeps: one stiffness per element kind on a distorted
//! cell, and full assembly (pattern + values), kernels + scatter, and factorization of a 50 x 50
//! Q4 plane-strain block (5,202 dofs), by `sparse::Cholesky` and by faer's high-level `Llt`
//! side by side. Compare the figures as ratios within one run (e.g. Q9 vs Q4 kernel,
//! factorization vs assembly, `numeric_cholesky` vs `numeric_cholesky_faer_llt`), never as
//! absolute times across machines.

use contact_patch::fe::ElementKind;
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
    let chol = Cholesky::analyse(pattern).unwrap();
    group.bench_function("symbolic_cholesky", |b| {
        b.iter(|| Cholesky::analyse(black_box(pattern)).unwrap())
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

criterion_group!(benches, kernels, assembly);
criterion_main!(benches);
