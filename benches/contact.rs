//! Criterion benchmarks of the contact solve: what each enforcement method costs on one
//! representative nonlinear problem (a Q4 block, 6,642 dofs, pressed on a rigid cylinder; 81
//! candidate rows, 11 active at the solution), what each discretization costs on the Q9
//! patch mesh E, and what the low-rank and trailing-block updates of the factorization save in
//! the active-set loop of a 21,586-dof block on a rigid line (src/solver/low_rank.rs). Read the figures as ratios within one run (e.g. augmented Lagrangian vs
//! Lagrange), never as absolute times across machines.

use contact_patch::io::scene::{
    DiscretizationSpec, EnforcementSpec, FactorUpdate, MultiplierSpace, MultiplierUpdate,
    NormalChoice,
};
use contact_patch::model::admit::load;
use contact_patch::model::Model;
use contact_patch::solver::solve_static;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use std::path::Path;

fn case(name: &str) -> Model {
    load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(name)).unwrap()
}

fn enforcement(c: &mut Criterion) {
    let base = case("cases/contact/block-on-rigid-cylinder-lagrange.json");
    let mut group = c.benchmark_group("cylinder_enforcement");
    group.sample_size(10);
    let methods = [
        ("lagrange", EnforcementSpec::Lagrange),
        ("penalty", EnforcementSpec::Penalty { kappa: 1e5 }),
        (
            "perturbed_tangent",
            EnforcementSpec::PerturbedTangent { kappa: 1e5 },
        ),
        (
            "augmented_lagrange",
            EnforcementSpec::AugmentedLagrange {
                kappa: 1e5,
                update: MultiplierUpdate::PerIteration,
            },
        ),
        (
            "augmented_lagrange_outer",
            EnforcementSpec::AugmentedLagrange {
                kappa: 1e5,
                update: MultiplierUpdate::OuterLoop,
            },
        ),
        ("elimination", EnforcementSpec::Elimination),
    ];
    for (name, e) in methods {
        let mut model = base.clone();
        model.contact[0].enforcement = e;
        group.bench_function(name, |b| {
            b.iter(|| solve_static(black_box(&model), &mut |_| {}).unwrap())
        });
    }
    group.finish();
}

fn discretization(c: &mut Criterion) {
    let base = case("cases/patch/patch-E-nu0.3.json");
    let mut group = c.benchmark_group("patch_e_discretization");
    let variants = [
        (
            "node_to_surface_1p",
            DiscretizationSpec::NodeToSurface {
                passes: 1,
                normal: NormalChoice::Master,
                slave_normal_variation: None,
            },
        ),
        (
            "node_to_surface_2p",
            DiscretizationSpec::NodeToSurface {
                passes: 2,
                normal: NormalChoice::Master,
                slave_normal_variation: None,
            },
        ),
        (
            "mortar",
            DiscretizationSpec::Mortar {
                multiplier: MultiplierSpace::Standard,
            },
        ),
        (
            "dual_mortar",
            DiscretizationSpec::Mortar {
                multiplier: MultiplierSpace::Dual,
            },
        ),
    ];
    for (name, d) in variants {
        let mut model = base.clone();
        model.contact[0].discretization = d;
        group.bench_function(name, |b| {
            b.iter(|| solve_static(black_box(&model), &mut |_| {}).unwrap())
        });
    }
    group.finish();
}

/// The active-set loop of a penalty contact solve that changes many rows and then few: the
/// cross-check's block on a rigid line refined to 250 x 42 Q4 (21,586 dofs, penalty 1e5,
/// `tests/data/block-on-rigid-line-240x40.json` with more divisions; about 100 rows change in
/// its first iteration, then 15, 8, 5, 3, 1), factoring every matrix anew, updating the last
/// factorization by low rank (`solver.factor_update: "low_rank"`), and the default `"auto"`,
/// which from 20,000 equations factors once with the contact equations last and solves every
/// later set through the trailing block (src/solver/low_rank.rs, `TrailingUpdate`).
fn factor_update(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text =
        std::fs::read_to_string(root.join("tests/data/block-on-rigid-line-240x40.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let block = &mut json["bodies"][0]["mesh"]["block"];
    block["x"]["divisions"] = 250.into();
    block["y"]["divisions"] = 42.into();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("block-250x42.json");
    std::fs::write(&path, serde_json::to_string(&json).unwrap()).unwrap();
    let base = load(&path).unwrap();
    let mut group = c.benchmark_group("block_on_rigid_line_factor_update");
    group.sample_size(10);
    for (name, mode) in [
        ("refactor", FactorUpdate::Refactor),
        ("low_rank", FactorUpdate::LowRank),
        ("auto_trailing", FactorUpdate::Auto),
    ] {
        let mut model = base.clone();
        model.solver.factor_update = mode;
        group.bench_function(name, |b| {
            b.iter(|| solve_static(black_box(&model), &mut |_| {}).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, enforcement, discretization, factor_update);
criterion_main!(benches);
