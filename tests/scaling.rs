//! The solvers do not depend on units: the patch test B (one pass, punch slave) and its mortar
//! variant pass at Young's moduli from 1e3 to 2e11 with the load scaled alike, and Lagrange
//! multipliers keep going through the sparse LDL^T (not a fallback).

use contact_patch::io::scene::{Check, DiscretizationSpec, EnforcementSpec, MultiplierSpace};
use contact_patch::model::{parse, Model};
use contact_patch::run::run_model;
use std::time::Instant;

#[test]
fn patch_b_passes_at_every_scale() {
    let path = format!(
        "{}/cases/patch/patch-B-nu0.3.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    for e in [1e3, 1e6, 1e9, 2e11] {
        let scale = e / 1000.0;
        let mut case = parse(&text, &path).unwrap();
        case.materials.get_mut("m").unwrap().youngs_modulus = e;
        for load in &mut case.loads {
            load.pressure = load.pressure.map(|p| p * scale);
        }
        let stress = [0.0, -10.0 * scale, 0.0];
        case.exact = Some(contact_patch::io::scene::ExactSpec::UniformStress { stress });
        case.checks = vec![
            Check::UniformStress {
                body: None,
                stress,
                tol: 1e-10,
                per_condition: None,
            },
            Check::ContactPressure {
                pair: "interface".into(),
                tol: 1e-10,
            },
            Check::ForceBalance { tol: 1e-12 },
        ];
        for (disc, enforcement) in [
            (
                DiscretizationSpec::NodeToSurface {
                    passes: 1,
                    normal: Default::default(),
                    slave_normal_variation: None,
                },
                EnforcementSpec::Lagrange,
            ),
            (
                DiscretizationSpec::Mortar {
                    multiplier: MultiplierSpace::Standard,
                },
                EnforcementSpec::Lagrange,
            ),
            (
                DiscretizationSpec::NodeToSurface {
                    passes: 1,
                    normal: Default::default(),
                    slave_normal_variation: None,
                },
                EnforcementSpec::Penalty { kappa: 10.0 * e },
            ),
            (
                DiscretizationSpec::Mortar {
                    multiplier: MultiplierSpace::Dual,
                },
                EnforcementSpec::Elimination,
            ),
        ] {
            let mut c = case.clone();
            c.contact[0].discretization = disc.clone();
            c.contact[0].enforcement = enforcement.clone();
            let model = Model::build(&c, &path).unwrap();
            let o = run_model(model, 0.0, Instant::now(), &mut |_| {}).unwrap();
            assert!(
                o.passed(),
                "E = {e}, {disc:?}, {enforcement:?}: {:#?}",
                o.checks
            );
            if enforcement == EnforcementSpec::Lagrange {
                assert_eq!(
                    o.solution.contact.as_ref().unwrap().linear_solver,
                    "ldlt",
                    "E = {e}, {disc:?}"
                );
            }
        }
    }
}
