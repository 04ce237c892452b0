//! The Newton core (`solver.scheme: "newton"`, `src/solver/newton.rs` and
//! `src/solver/contact_newton.rs`) against the active-set scheme, two independent paths to the
//! same discrete problem: every penalty-type and Lagrange cell of the patch and tied catalogues
//! must agree (Lagrange cells with dependent rows excepted: the active-set scheme picks the
//! minimum-norm multipliers, the Newton scheme stops `Singular` and says why), and Newton must
//! converge quadratically where its tangent is exact.

mod common;

use contact_patch::model::{parse, Model};
use contact_patch::run::{run_model, Outcome};
use contact_patch::solver::active_set::Termination;
use serde_json::{json, Value};
use std::path::Path;

fn read(case: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(case);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn run(v: &Value, name: &str) -> contact_patch::Result<Outcome> {
    let case = parse(&v.to_string(), name)?;
    let model = Model::build(&case, name)?;
    run_model(model, 0.0, std::time::Instant::now(), &mut |_| {})
}

fn with_scheme(v: &Value, scheme: &str) -> Value {
    let mut v = v.clone();
    if v.get("solver").is_none() {
        v["solver"] = json!({});
    }
    v["solver"]["scheme"] = json!(scheme);
    v
}

/// Largest difference of the displacements relative to the largest displacement.
fn difference(a: &Outcome, b: &Outcome) -> f64 {
    let scale = a.solution.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.solution
        .u
        .iter()
        .zip(&b.solution.u)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

fn termination(o: &Outcome) -> Termination {
    o.solution.contact.as_ref().unwrap().termination.clone()
}

/// The cells of a catalogue case's sweep with a penalty-type method, the perturbed tangent or
/// Lagrange multipliers, as case values. (The active-set scheme runs the perturbed tangent as
/// written, a multiplier update `lambda + w (-g - b . dx)` after each solve of the perturbed
/// tangent; the Newton scheme as the augmented Lagrangian updated per iteration, which its
/// notes derive to be the same iteration: the two must agree.)
fn newton_cells(case: &str) -> Vec<(String, Value)> {
    let v = read(case);
    let sweep = v["sweep"].clone();
    let pair = v["contact"][0].clone();
    let mut cells = Vec::new();
    for d in sweep["discretizations"].as_array().unwrap() {
        for e in sweep["enforcements"].as_array().unwrap() {
            let kind = e["kind"].as_str().unwrap();
            if !matches!(
                kind,
                "penalty"
                    | "perturbed_lagrange"
                    | "augmented_lagrange"
                    | "perturbed_tangent"
                    | "lagrange"
                    | "elimination"
            ) {
                continue;
            }
            let mut c = v.clone();
            c.as_object_mut().unwrap().remove("sweep");
            let mut p = pair.clone();
            if let Some(slave) = d.get("slave") {
                if p["slave"]["body"] != *slave {
                    let s = p["slave"].clone();
                    p["slave"] = p["master"].clone();
                    p["master"] = s;
                }
            }
            p["discretization"] = d["discretization"].clone();
            p["enforcement"] = e.clone();
            c["contact"] = json!([p]);
            cells.push((format!("{case} {} {}", d, e), c));
        }
    }
    cells
}

#[test]
fn newton_agrees_with_the_active_set_scheme_on_every_penalty_perturbed_tangent_and_lagrange_cell_of_the_catalogue(
) {
    let mut compared = 0;
    let mut singular = 0;
    let mut refused = 0;
    let mut eliminated = 0;
    let mut elimination_refused = 0;
    let mut worst = 0.0f64;
    let mut cases = Vec::new();
    for mesh in ["A", "B", "C", "D", "E"] {
        for nu in ["0.0", "0.3", "0.4"] {
            cases.push(format!("cases/patch/patch-{mesh}-nu{nu}.json"));
        }
        for load in ["normal", "parallel", "shear"] {
            cases.push(format!("cases/tied/tied-{mesh}-{load}.json"));
        }
    }
    {
        for case in cases {
            if !Path::new(env!("CARGO_MANIFEST_DIR")).join(&case).exists() {
                continue;
            }
            for (name, cell) in newton_cells(&case) {
                let old = run(&with_scheme(&cell, "active_set"), &name);
                let new = run(&with_scheme(&cell, "newton"), &name);
                let pair = &cell["contact"][0];
                if pair["enforcement"]["kind"] == "perturbed_lagrange"
                    && pair["discretization"]["kind"] == "mortar"
                    && pair["discretization"]["multiplier"] == "standard"
                {
                    // the consistent mortar coupling: the active-set scheme only, for now
                    let msg = new.err().unwrap().to_string();
                    assert!(msg.contains("does not yet solve"), "{name}: {msg}");
                    assert!(old.is_ok(), "{name}");
                    refused += 1;
                    continue;
                }
                let (old, new) = match (old, new) {
                    (Ok(a), Ok(b)) => (a, b),
                    (Err(a), Err(b)) => {
                        assert_eq!(a.to_string(), b.to_string(), "{name}");
                        if pair["enforcement"]["kind"] == "elimination" {
                            // rows that own no dof of their own: refused alike by both
                            assert!(a.to_string().contains("does not apply"), "{name}: {a}");
                            elimination_refused += 1;
                        }
                        continue;
                    }
                    (a, b) => panic!(
                        "{name}: one scheme failed: {:?} / {:?}",
                        a.err().map(|e| e.to_string()),
                        b.err().map(|e| e.to_string())
                    ),
                };
                let dependent = old.solution.contact.as_ref().unwrap().rank_deficiency;
                if cell["contact"][0]["enforcement"]["kind"] == "lagrange"
                    && dependent.unwrap_or(0) > 0
                {
                    // dependent rows: the active-set scheme picks the minimum-norm
                    // multipliers, the Newton scheme's saddle-point matrix is singular
                    let t = termination(&new);
                    assert!(
                        matches!(&t, Termination::Singular(why) if why.contains("depend on each other")),
                        "{name}: {t:?}"
                    );
                    singular += 1;
                    continue;
                }
                assert_eq!(termination(&old), termination(&new), "{name}");
                let d = difference(&old, &new);
                worst = worst.max(d);
                assert!(d <= 1e-9, "{name}: the schemes differ by {d:e}");
                assert_eq!(
                    old.passed(),
                    new.passed(),
                    "{name}: {:#?} / {:#?} ({:?})",
                    old.checks,
                    new.checks,
                    new.solution.contact.as_ref().unwrap().history
                );
                if pair["enforcement"]["kind"] == "elimination" {
                    eliminated += 1;
                }
                compared += 1;
            }
        }
    }
    eprintln!("{compared} cells compared ({eliminated} by constraint elimination, {elimination_refused} more refused alike), largest relative difference {worst:e}; {singular} Lagrange cells with dependent rows end singular; {refused} perturbed Lagrangian standard-mortar cells refused");
    assert!(compared >= 300, "only {compared} cells compared");
    assert!(
        eliminated >= 30,
        "only {eliminated} elimination cells compared"
    );
}

/// The rigid cylinder in the current geometry with a penalty: each Newton iteration searches
/// the rows again at the iterate, and with the second derivative of the gap the tangent is
/// exact, so the residual falls quadratically; the answer is the active-set scheme's
/// (geometry updates around active-set loops). The augmented Lagrangian (outer loop) reaches
/// the same answer as the active-set scheme too.
#[test]
fn newton_converges_quadratically_on_the_rigid_cylinder_in_current_geometry() {
    for enforcement in [
        json!({"kind": "penalty", "kappa": 1.0e4}),
        json!({"kind": "lagrange"}),
        json!({"kind": "augmented_lagrange", "kappa": 1.0e3, "update": "outer_loop"}),
    ] {
        let mut v = read("cases/contact/block-on-rigid-cylinder-finite-sliding.json");
        v["contact"][0]["enforcement"] = enforcement.clone();
        // the checks are the Lagrange case's (the penalty's force balance holds, its pressure
        // differs): keep the equilibrium checks only
        v["checks"] = json!([{"check": "force_balance", "tol": 1e-10}]);
        let old = run(&with_scheme(&v, "active_set"), "cylinder").unwrap();
        let new = run(&with_scheme(&v, "newton"), "cylinder").unwrap();
        assert_eq!(termination(&new), Termination::Converged, "{enforcement}");
        assert!(new.passed(), "{enforcement}: {:#?}", new.checks);
        let d = difference(&old, &new);
        assert!(d <= 1e-10, "{enforcement}: schemes differ by {d:e}");
        if enforcement["kind"] == "augmented_lagrange" {
            // the Uzawa updates between Newton solves converge linearly by design
            continue;
        }
        let history = &new.solution.contact.as_ref().unwrap().history;
        let r: Vec<f64> = history.iter().map(|h| h.residual).collect();
        eprintln!("{enforcement}: residuals {r:?}");
        // quadratic where the status is settled: below 1e-3, each residual is below
        // 10 times the square of the last, until round-off (1e-13)
        let settled: Vec<(f64, f64)> = history
            .windows(2)
            .filter(|w| w[0].status_changes == 0 && w[0].residual < 1e-3 && w[0].residual > 1e-13)
            .map(|w| (w[0].residual, w[1].residual))
            .collect();
        assert!(!settled.is_empty(), "{enforcement}: {r:?}");
        for (a, b) in settled {
            assert!(b <= 10.0 * a * a + 1e-13, "{enforcement}: {r:?}");
        }
    }
}

/// Frictionless contact has no history: 1 and 10 load steps agree under Newton too.
#[test]
fn newton_one_and_ten_load_steps_agree() {
    for case in [
        "cases/contact/signorini-block-on-rigid-line.json",
        "cases/patch/patch-C-nu0.3.json",
    ] {
        let mut v = read(case);
        v.as_object_mut().unwrap().remove("sweep");
        v["contact"][0]["enforcement"] = json!({"kind": "penalty", "kappa": 1.0e4});
        v["checks"] = json!([]);
        // the case's expected failures name the checks removed here
        v.as_object_mut().unwrap().remove("expected_failures");
        let mut ten = with_scheme(&v, "newton");
        ten["solver"]["load_steps"] = json!(10);
        let one = run(&with_scheme(&v, "newton"), case).unwrap();
        let ten = run(&ten, case).unwrap();
        let d = difference(&one, &ten);
        assert!(d <= 1e-12, "{case}: 1 and 10 steps differ by {d:e}");
        assert_eq!(ten.solution.contact.as_ref().unwrap().steps.len(), 10);
    }
}

/// Constraint elimination in the Newton scheme reduces every Newton step, so it combines with
/// no other method, and it keeps to the reference geometry (rows searched again at every
/// iterate could change the dofs they own): both are refused with the reason.
#[test]
fn newton_elimination_refuses_mixed_pairs_and_the_current_geometry() {
    let mut v = read("cases/contact/signorini-block-on-rigid-line.json");
    v["contact"][0]["enforcement"] = json!({"kind": "elimination"});
    let mut second = v["contact"][0].clone();
    second["name"] = json!("second");
    second["enforcement"] = json!({"kind": "lagrange"});
    let mut mixed = v.clone();
    mixed["contact"] = json!([v["contact"][0].clone(), second]);
    let msg = run(&with_scheme(&mixed, "newton"), "mixed")
        .err()
        .unwrap()
        .to_string();
    assert!(msg.contains("contact[1] 'second'.enforcement"), "{msg}");
    assert!(msg.contains("combines only with itself"), "{msg}");
    let mut current = v.clone();
    current["physics"]["contact_geometry"] = json!("current");
    let msg = run(&with_scheme(&current, "newton"), "current")
        .err()
        .unwrap()
        .to_string();
    assert!(msg.contains("reference contact geometry only"), "{msg}");
    assert!(msg.contains("solver.scheme"), "{msg}");
}

/// Defect D17 under Newton: the punch slides past the end of the foundation's contact facets;
/// the slave nodes that leave the master surface are named, as in the active-set scheme.
#[test]
fn newton_names_slave_nodes_that_leave_the_master_surface() {
    let v = read("tests/defects/D17-force-balance-check-uses-reference-positions.json");
    let old = run(&with_scheme(&v, "active_set"), "D17").unwrap();
    let new = run(&with_scheme(&v, "newton"), "D17").unwrap();
    let nodes = |o: &Outcome| -> Vec<usize> {
        let mut n: Vec<usize> = o
            .solution
            .contact
            .as_ref()
            .unwrap()
            .departures
            .iter()
            .map(|d| d.node)
            .collect();
        n.sort();
        n
    };
    // the four nodes past the master's end and its extension (`tests/finite_sliding.rs`)
    assert_eq!(nodes(&new), [18, 20, 22, 24]);
    assert_eq!(nodes(&old), nodes(&new));
    assert!(
        new.warnings
            .iter()
            .any(|w| w.contains("slave node 22 of body 'punch' left the master surface")),
        "{:?}",
        new.warnings
    );
    assert_eq!(termination(&new), termination(&old));
    // both iterate on a nonlinear problem and stop at their own tolerances (Newton: residual
    // 1e-10 of the forces; the active-set scheme: a geometry change of 1e-12, reached linearly
    // without the deformable master's second derivative), so they agree to about 1e-10
    let d = difference(&old, &new);
    assert!(d <= 1e-9, "the schemes differ by {d:e}");
}

/// `contact-patch run` on reproducer `name` of `tests/defects/s4/`: exit code, summary.json
/// and the output folder (kept alive by the returned temporary folder).
fn run_reproducer(name: &str) -> (i32, Value, tempfile::TempDir) {
    let file = common::defect(name);
    let out = tempfile::tempdir().unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["run", file.to_str().unwrap(), "--out"])
        .arg(out.path().join("o"))
        .output()
        .unwrap();
    let summary = std::fs::read_to_string(out.path().join("o/summary.json"))
        .map(|t| serde_json::from_str(&t).unwrap())
        .unwrap_or_else(|_| json!({ "stderr": String::from_utf8_lossy(&o.stderr) }));
    (o.status.code().unwrap(), summary, out)
}

/// Newton's iterations of every load step of a 2D run (`contact.steps`), every step converged.
fn converged_iterations(name: &str, summary: &Value) -> Vec<u64> {
    summary["contact"]["steps"]
        .as_array()
        .unwrap_or_else(|| panic!("{name}: {summary}"))
        .iter()
        .map(|s| {
            assert_eq!(s["termination"], "converged", "{name}: {s}");
            s["iterations"].as_u64().unwrap()
        })
        .collect()
}

/// Defects N02 to N04 (second report): Newton's convergence test had no round-off floor under
/// finite kinematics. N02b, the finite-strain penalty block of N02a moved rigidly by (0, 1),
/// stalled at a relative residual near 1e-8 (the penalty's round-off `kappa eps |x|` grows
/// with the coordinates); N04a/b, the nested Hex8 two-block patch tests at finite strain,
/// stalled at 1.9e-12 and 2.9e-9 with every cut spent. N03, a finite Signorini block with a
/// penalty, reached 1.8e-15 but a row with a gap zero to round-off flipped open and closed
/// every iteration. Each converges now: N02b in N02a's iterations with N02a's answer moved.
#[test]
fn finite_strain_newton_converges_at_its_round_off_floor_wherever_the_problem_sits() {
    let (code_a, at_origin, dir_a) = run_reproducer("N02a");
    let (code_b, moved, dir_b) = run_reproducer("N02b");
    assert_eq!((code_a, code_b), (0, 0), "{moved}");
    assert_eq!(
        converged_iterations("N02a", &at_origin),
        converged_iterations("N02b", &moved)
    );
    // the same displacements (a vtu's displacement field), to the round-off of the moved
    // problem's coordinates
    let displacement = |dir: &tempfile::TempDir| -> Vec<f64> {
        let text = std::fs::read_to_string(dir.path().join("o/block.vtu"))
            .or_else(|_| {
                let vtu = std::fs::read_dir(dir.path().join("o"))
                    .unwrap()
                    .map(|e| e.unwrap().path())
                    .find(|p| {
                        p.extension().is_some_and(|e| e == "vtu")
                            && !p.to_string_lossy().contains(".contact.")
                    })
                    .unwrap();
                std::fs::read_to_string(vtu)
            })
            .unwrap();
        let start = text.find("Name=\"displacement\"").unwrap();
        let from = start + text[start..].find('>').unwrap() + 1;
        let to = from + text[from..].find("</DataArray>").unwrap();
        text[from..to]
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect()
    };
    let (ua, ub) = (displacement(&dir_a), displacement(&dir_b));
    let scale = ua.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = ua
        .iter()
        .zip(&ub)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        diff <= 1e-9 * scale,
        "moved by (0, 1): displacements differ by {:e}",
        diff / scale
    );
    let (code, summary, _dir) = run_reproducer("N03");
    assert_eq!(code, 0, "{summary}");
    converged_iterations("N03", &summary);
    for name in ["N04a", "N04b"] {
        let (code, summary, _dir) = run_reproducer(name);
        assert_eq!(code, 0, "{name}: {summary}");
        assert_eq!(summary["contact"]["termination"], "Converged", "{name}");
        assert_eq!(summary["finite"]["cuts"], 0, "{name}");
    }
}

/// Defect N01 (second report): an 8 x 4 block pressed onto a rigid line (penalty Coulomb,
/// mu 0.3) and then moved at its top stopped at its second step, `IterationLimit` after 200
/// iterations: a node that slipped in step 1 started step 2 with a trial force on the cone only
/// up to round-off, on the slip branch without tangential stiffness, and the iterates ran
/// away. Now the trial force at a step's start is the committed force to the last bit, the
/// point sticks, and each step converges in a few iterations, with 7 points in stick and 2 in
/// slip at the end (the reference's plain semi-smooth Newton: 2 iterations).
#[test]
fn friction_newton_converges_in_the_step_after_a_slip() {
    let (code, summary, _dir) = run_reproducer("N01");
    assert_eq!(code, 0, "{summary}");
    let iterations = converged_iterations("N01", &summary);
    assert_eq!(iterations.len(), 2, "{iterations:?}");
    assert!(iterations.iter().all(|&k| k <= 5), "{iterations:?}");
    let last = &summary["contact"]["steps"][1]["friction"];
    assert_eq!(
        (&last["stick"], &last["slip"]),
        (&json!(7), &json!(2)),
        "{last}"
    );
}
