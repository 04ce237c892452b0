//! One answer, or a refusal that says why: the linear algebra and the solve tell the truth.
//!
//! * A failing pivot is named by the node it belongs to in the user's numbering, on faer's
//!   simplicial and supernodal paths alike (D09).
//! * A non-finite number anywhere is an error (exit 2) naming where it appeared, and no output
//!   is written (D08).
//! * A body whose rigid motion the active set leaves free is brought into contact (D23a, D23b,
//!   D22) or refused with the body, the motion and why (D11a/D11b); the answer does not depend
//!   on the numbering of the nodes: renumbered meshes give the same field to 1e-12, or the same
//!   refusal.

mod common;
use common::{defect, run_case};
use contact_patch::model::{parse, Model};
use contact_patch::run::{run_model, Outcome};
use contact_patch::solver::active_set::Termination;
use contact_patch::solver::linear::assemble;
use contact_patch::solver::sparse::Cholesky;
use serde_json::{json, Value};
use std::path::Path;
use std::time::Instant;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn model(case: &Value, source: &str) -> Model {
    Model::build(&parse(&case.to_string(), source).unwrap(), source).unwrap()
}

fn solve(case: &Value, source: &str) -> contact_patch::Result<Outcome> {
    run_model(model(case, source), 0.0, Instant::now(), &mut |_| {})
}

fn termination(o: &Outcome) -> &Termination {
    &o.solution
        .contact
        .as_ref()
        .expect("a contact solve")
        .termination
}

/// The message of a `Singular` termination, without the case's source (the first line's
/// `SOURCE: ` prefix).
fn refusal(o: &Outcome, source: &str) -> String {
    match termination(o) {
        Termination::Singular(msg) => msg.replacen(source, "CASE", 1),
        t => panic!("expected a refusal, got {t:?}"),
    }
}

#[test]
fn d09_names_the_unconnected_node_on_the_simplicial_path() {
    let case = read(&defect("D09"));
    let m = model(&case, "D09");
    let pattern = assemble(&m, &[]).pattern;
    assert!(
        !Cholesky::analyse(&pattern, &contact_patch::solver::sparse::UNLIMITED)
            .unwrap()
            .is_supernodal()
    );
    let e = solve(&case, "D09").unwrap_err().to_string();
    assert!(e.contains("body 'beam', node 9 at (6.3, 0.18)"), "{e}");
    assert!(
        e.contains("node 9 of body 'beam' belongs to no cell"),
        "{e}"
    );
}

/// A Q4 grid `n x n` on `[0, n]^2` held at the left side, with extra nodes that belong to no
/// cell inserted at `stray` (index, coordinates), and optionally a second grid (a part that
/// floats free) to the right of `float_from`.
fn grid_case(n: usize, stray: &[(usize, [f64; 2])], float_from: Option<f64>) -> Value {
    let mut nodes: Vec<[f64; 2]> = Vec::new();
    let mut cells: Vec<[usize; 4]> = Vec::new();
    let mut block = |x0: f64| {
        let base = nodes.len();
        for j in 0..=n {
            for i in 0..=n {
                nodes.push([x0 + i as f64, j as f64]);
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = base + j * (n + 1) + i;
                cells.push([a, a + 1, a + n + 2, a + n + 1]);
            }
        }
    };
    block(0.0);
    if let Some(x0) = float_from {
        block(x0);
    }
    for &(at, p) in stray {
        nodes.insert(at, p);
        for c in &mut cells {
            c.iter_mut().filter(|v| **v >= at).for_each(|v| *v += 1);
        }
    }
    json!({
        "name": "grid",
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "plate", "material": "m",
            "mesh": {"explicit": {"element": "Q4", "nodes": nodes, "cells": cells}},
            "node_sets": {"held": {"box": {"min": [0, 0], "max": [0, n]}}}}],
        "supports": [{"body": "plate", "set": "held", "x": 0.0, "y": 0.0}],
        "loads": [{"body": "plate", "set": "top", "pressure": 1.0}]
    })
}

#[test]
fn a_failing_pivot_on_the_supernodal_path_names_its_node() {
    let case = grid_case(60, &[(1900, [20.5, 31.25])], None);
    let m = model(&case, "grid");
    let pattern = assemble(&m, &[]).pattern;
    assert!(
        Cholesky::analyse(&pattern, &contact_patch::solver::sparse::UNLIMITED)
            .unwrap()
            .is_supernodal()
    );
    let e = solve(&case, "grid").unwrap_err().to_string();
    assert!(e.contains("node 1900 at (20.5, 31.25)"), "{e}");
    assert!(e.contains("belongs to no cell"), "{e}");
    // the same on the simplicial path
    let case = grid_case(3, &[(5, [0.5, 1.25])], None);
    let m = model(&case, "small");
    assert!(!Cholesky::analyse(
        &assemble(&m, &[]).pattern,
        &contact_patch::solver::sparse::UNLIMITED
    )
    .unwrap()
    .is_supernodal());
    let e = solve(&case, "small").unwrap_err().to_string();
    assert!(e.contains("node 5 at (0.5, 1.25)"), "{e}");
}

#[test]
fn a_part_that_floats_free_is_refused_and_located() {
    // before: the round-off pivots of the floating part passed and the run answered
    for n in [6, 40] {
        let case = grid_case(n, &[], Some(2.0 * n as f64));
        let e = solve(&case, "float").unwrap_err().to_string();
        assert!(e.contains("singular"), "{e}");
        let x: f64 = e
            .split(" at (")
            .nth(1)
            .and_then(|s| s.split(',').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no coordinates in {e}"));
        assert!(
            x >= 2.0 * n as f64,
            "the named node is not in the floating part: {e}"
        );
    }
}

#[test]
fn d08_non_finite_results_are_an_error_naming_where() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let result = run_case(&defect("D08"), &out);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(2), "{stderr}");
    for needle in [
        "is not finite",
        "body 'block', node",
        "contact iteration 1",
        "rescale the units",
    ] {
        assert!(stderr.contains(needle), "{needle:?} missing from {stderr}");
    }
    assert!(!out.exists(), "an output folder was written");
    // the same load without contact: the static solve refuses too
    let mut case = read(&defect("D08"));
    case["contact"] = json!([]);
    case["supports"] = json!([{"body": "block", "set": "bottom", "y": 0.0},
                              {"body": "block", "set": "bottom_left", "x": 0.0}]);
    let path = dir.path().join("static.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let result = run_case(&path, &out);
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert_eq!(result.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("is not finite"), "{stderr}");
    assert!(!out.exists(), "an output folder was written");
}

#[test]
fn d11_two_numberings_give_the_same_diagnosed_refusal() {
    let a = solve(&read(&defect("D11a")), "D11a").unwrap();
    let b = solve(&read(&defect("D11b")), "D11b").unwrap();
    let (ra, rb) = (refusal(&a, "D11a"), refusal(&b, "D11b"));
    assert_eq!(ra, rb);
    for needle in [
        "not unique",
        "body 'block' can rotate about (0, 4)",
        "only one node (0, 0)",
        "stay open",
        "hint: hold this motion with a support",
    ] {
        assert!(ra.contains(needle), "{needle:?} missing from {ra}");
    }
    assert!(!a.passed() && !b.passed());
}

/// The x coordinates of the slave nodes of the active rows, sorted.
fn active_x(o: &Outcome) -> Vec<f64> {
    let c = o.solution.contact.as_ref().unwrap();
    let mut x: Vec<f64> = c
        .rows
        .iter()
        .zip(&c.active)
        .filter(|(_, &a)| a)
        .map(|(r, _)| r.point[0])
        .collect();
    x.sort_by(f64::total_cmp);
    x
}

/// The y force the (only) contact pair puts on its slave body.
fn contact_force_y(o: &Outcome) -> f64 {
    let state = o.solution.contact.as_ref().unwrap();
    contact_patch::contact::forces::pair_forces(&o.model, state)[0].on_slave[1]
}

#[test]
fn d23a_a_body_across_a_gap_is_brought_into_contact() {
    let o = solve(&read(&defect("D23a")), "D23a").unwrap();
    assert_eq!(termination(&o), &Termination::Converged);
    // the closest points: the two bottom nodes nearest x = 0, at x = -+4/7
    let closed = active_x(&o);
    assert_eq!(closed.len(), 2, "{closed:?}");
    assert!((closed[0] + 4.0 / 7.0).abs() < 1e-12 && (closed[1] - 4.0 / 7.0).abs() < 1e-12);
    let total = contact_force_y(&o);
    assert!((total - 4.0).abs() < 1e-12, "{total}");
}

#[test]
fn d23b_and_d22_converge_symmetrically() {
    // D23b (Q9): node-to-surface rows close at the mid-side nodes (x = -+0.1, -+0.3); the
    // corner node at x = 0 carries no compression
    for (name, nodes) in [("D23b", 4), ("D22", 3)] {
        let o = solve(&read(&defect(name)), name).unwrap();
        assert_eq!(termination(&o), &Termination::Converged, "{name}");
        let closed = active_x(&o);
        assert_eq!(closed.len(), nodes, "{name}: {closed:?}");
        for x in &closed {
            assert!(
                closed.iter().any(|y| (x + y).abs() < 1e-12),
                "{name}: the contact zone is not symmetric: {closed:?}"
            );
        }
        let total = contact_force_y(&o);
        assert!((total - 4.0).abs() < 1e-8, "{name}: {total}");
    }
}

#[test]
fn a_body_pulled_off_its_contact_is_refused() {
    let mut case = read(&defect("D23a"));
    case["loads"][0]["pressure"] = json!(-0.5);
    let o = solve(&case, "pull").unwrap();
    let msg = refusal(&o, "pull");
    for needle in [
        "the loads push body 'block' to translate in y",
        "no contact row can stop that motion",
        "no node has u_y prescribed",
    ] {
        assert!(msg.contains(needle), "{needle:?} missing from {msg}");
    }
}

/// A small deterministic generator (xorshift64*) for the permutations.
struct Shuffle(u64);

impl Shuffle {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 33) as usize % n
    }

    /// A random permutation of `0..n` (Fisher-Yates).
    fn permutation(&mut self, n: usize) -> Vec<usize> {
        let mut p: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            p.swap(i, self.below(i + 1));
        }
        p
    }
}

/// `case` with every body's mesh written out explicitly, its nodes in a random order (the
/// cells keep their order: assembly sums element contributions in cell order, so another cell
/// order is another matrix at round-off, not another numbering); returns the new case and,
/// per body, the new index of each original node.
fn renumbered(case: &Value, shuffle: &mut Shuffle) -> (Value, Vec<Vec<usize>>) {
    let m = model(case, "original");
    let mut out = case.clone();
    let mut new_index = Vec::new();
    for (b, body) in m.bodies.iter().enumerate() {
        let mesh = &body.mesh;
        let perm = shuffle.permutation(mesh.nodes.len()); // new index of each old node
        let mut nodes = vec![[0.0; 2]; mesh.nodes.len()];
        for (old, &new) in perm.iter().enumerate() {
            nodes[new] = mesh.nodes[old];
        }
        let cells: Vec<Vec<usize>> = (0..mesh.cell_count())
            .map(|c| mesh.cell(c).iter().map(|&n| perm[n]).collect())
            .collect();
        out["bodies"][b]["mesh"] = json!({"explicit": {
            "element": format!("{:?}", mesh.kind), "nodes": nodes, "cells": cells}});
        new_index.push(perm);
    }
    (out, new_index)
}

/// Each case is solved as written and with its nodes renumbered at random (three times); a
/// converged field, mapped back, agrees to 1e-12 of its largest value, a refusal word for word.
/// (Element stiffnesses are symmetric only to round-off, so two numberings store matrices that
/// differ at that level; the LDL^T solve is refined with an accurate residual to the solution
/// of the stored matrix, which leaves about `cond eps`: 1e-13 for the cylinder.)
#[test]
fn renumbered_meshes_give_the_same_answer_or_the_same_refusal() {
    let mut shuffle = Shuffle(0x9e37_79b9_7f4a_7c15);
    let cases = [
        root().join("cases/contact/signorini-block-on-rigid-line.json"),
        root().join("cases/patch/patch-A-nu0.3.json"),
        root().join("cases/contact/block-on-rigid-cylinder-lagrange.json"),
        defect("D11a"),
        defect("D23a"),
    ];
    for path in &cases {
        let case = read(path);
        let reference = solve(&case, "case").unwrap();
        let m = &reference.model;
        for _ in 0..3 {
            let (permuted, new_index) = renumbered(&case, &mut shuffle);
            let o = solve(&permuted, "case").unwrap();
            match termination(&reference) {
                Termination::Converged => {
                    assert_eq!(termination(&o), &Termination::Converged, "{path:?}");
                    let (u, v) = (&reference.solution.u, &o.solution.u);
                    let scale = u.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                    let mut worst = 0.0f64;
                    for (b, body) in m.bodies.iter().enumerate() {
                        for (old, &new) in new_index[b].iter().enumerate() {
                            for c in 0..2 {
                                let d = (u[body.dof(old, c)] - v[body.dof(new, c)]).abs();
                                worst = worst.max(d);
                            }
                        }
                    }
                    assert!(
                        worst <= 1e-12 * scale,
                        "{path:?}: renumbering changes u by {:.2e} of its largest value",
                        worst / scale
                    );
                }
                Termination::Singular(_) => {
                    assert_eq!(refusal(&o, "case"), refusal(&reference, "case"), "{path:?}");
                }
                t => panic!("{path:?}: ended by {t:?}"),
            }
        }
    }
}
