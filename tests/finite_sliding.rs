//! `physics.contact_geometry: "current"`: the contact rows are re-evaluated at `X + u` until the
//! solution stops changing. At convergence the gaps measured afresh in the deformed
//! configuration must satisfy the contact conditions: no penetration, and zero gap wherever a
//! row carries force.

use contact_patch::contact::discretization::constraints;
use contact_patch::run::run_case;
use std::path::Path;

#[test]
fn current_configuration_contact_converges_to_a_consistent_state() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/contact/block-on-rigid-cylinder-finite-sliding.json");
    let o = run_case(&path, &mut |_| {}).unwrap();
    assert!(o.passed(), "{:?}", o.checks);
    let state = o.solution.contact.as_ref().unwrap();
    assert!(
        state.geometry_updates >= 2,
        "the geometry was re-evaluated {} times",
        state.geometry_updates
    );
    // re-measure every gap in the deformed configuration
    let mut moved = o.model.clone();
    for b in &mut moved.bodies {
        let off = b.dof_offset;
        for (n, p) in b.mesh.nodes.iter_mut().enumerate() {
            p[0] += o.solution.u[off + 2 * n];
            p[1] += o.solution.u[off + 2 * n + 1];
        }
    }
    let rows = constraints(&moved, &moved.contact[0]).unwrap();
    let size = moved.bodies[0].mesh.size();
    for r in &rows {
        assert!(
            r.g0 >= -1e-10 * size,
            "penetration {} at node {}",
            r.g0,
            r.slave_node
        );
        let k = state
            .rows
            .iter()
            .position(|q| q.slave_node == r.slave_node)
            .unwrap();
        if state.forces[k] > 1e-12 {
            assert!(
                r.g0.abs() <= 1e-10 * size,
                "node {} carries {} but its gap is {}",
                r.slave_node,
                state.forces[k],
                r.g0
            );
        }
    }
    // the reference-configuration solve of the same scene differs (the geometry matters)
    let reference = run_case(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("cases/contact/block-on-rigid-cylinder-lagrange.json"),
        &mut |_| {},
    )
    .unwrap();
    let diff = reference
        .solution
        .u
        .iter()
        .zip(&o.solution.u)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        diff > 1e-6,
        "current and reference geometry gave the same displacement ({diff})"
    );
}
