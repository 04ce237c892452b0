//! `contact-patch judge` on 3D cases (src/harness/judge3.rs, issue 13): our own 3D results,
//! written as `.vtu` and judged as another code's, give the run's errors and verdicts (the
//! `uniform_stress_3d` check from the displacement, and from the results' own `stress` field);
//! a wrong displacement fails with its error; results on another mesh are refused with the node
//! that found no point.

use contact_patch::harness::judge3::{judge3, load_results3};
use contact_patch::io::paths::OutputFolder;
use contact_patch::run::run_case3;
use contact_patch::run3d::{read_3d_case, write_run3};
use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_contact-patch");
const CASES: [&str; 4] = [
    "cases/3d/patch-hex8.json",
    "cases/3d/patch-hex27.json",
    "cases/3d/patch-tet4.json",
    "cases/3d/patch-tet10.json",
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN)
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

fn say(o: &Output) -> String {
    format!(
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The run `direct` written to `tmp` as `.vtu` results and judged as another code's.
fn written_and_judged(
    direct: &contact_patch::run3d::Outcome3,
    tmp: &Path,
) -> contact_patch::harness::judge3::Judgement3 {
    let folder = OutputFolder::new(&tmp.join(&direct.model.name)).unwrap();
    write_run3(&folder, direct).unwrap();
    let results = load_results3(&direct.model, folder.path()).unwrap();
    judge3(&direct.model, &results, 1e-8).unwrap()
}

/// The judged check with the words of the run's check `of`.
fn same_check<'a>(
    j: &'a contact_patch::harness::judge3::Judgement3,
    of: &contact_patch::harness::checks::CheckResult,
) -> &'a contact_patch::harness::checks::CheckResult {
    j.checks
        .iter()
        .find(|c| c.check == of.check)
        .unwrap_or_else(|| panic!("{:?}", j.checks))
}

#[test]
fn our_3d_results_judged_as_outside_results_give_the_direct_verdicts() {
    let tmp = tempfile::tempdir().unwrap();
    for path in CASES {
        let case = read_3d_case(&root().join(path)).unwrap();
        let direct = run_case3(&case, path).unwrap();
        let folder = OutputFolder::new(&tmp.path().join(&direct.model.name)).unwrap();
        write_run3(&folder, &direct).unwrap();
        let results = load_results3(&direct.model, folder.path()).unwrap();
        let j = judge3(&direct.model, &results, 1e-8).unwrap();
        assert_eq!(j.nodes * 3, direct.model.dof_count, "{path}");
        assert_eq!(
            j.largest_distance, 0.0,
            "{path}: coordinates are written exactly"
        );
        assert!(j.not_judged.is_empty());
        // u is read back bit for bit, so the check's error is the run's
        assert_eq!(
            j.checks.len(),
            2,
            "{path}: the check and its stress-field twin"
        );
        let (d, o) = (&direct.checks[0], &j.checks[0]);
        assert_eq!(o.check, d.check, "{path}");
        assert_eq!(o.error, d.error, "{path}");
        assert!(o.passed && d.passed, "{path}: {:e}", o.error);
        // our nodal stress is the mean of the cells' centre stresses: uniform to round-off
        let s = &j.checks[1];
        assert!(s.check.starts_with(&d.check), "{path}: {}", s.check);
        assert!(s
            .check
            .ends_with("in the results' own nodal 'stress' field"));
        assert!(s.passed, "{path}: {} error {:e}", s.check, s.error);
        assert!(j.stress_field);
    }
}

#[test]
fn a_wrong_3d_displacement_fails_and_another_mesh_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let case = "cases/3d/patch-hex27.json";
    let out = tmp.path().join("run");
    let o = run(&["run", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let vtu = out.join("block.vtu");

    // as written: every judged check passes (exit 0), the JUnit file has no failure
    let junit = tmp.path().join("judge.xml");
    let o = run(&[
        "judge",
        case,
        vtu.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
    ]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(0), "{s}");
    assert!(s.contains("  pass uniform stress [0.0, 0.0, -2.0, 0.0, 0.0, 0.0] (3D: xx, yy, zz, yz, xz, xy) (error"), "{s}");
    assert!(
        s.contains("2 judged checks: 2 pass, 0 fail; 0 not judged"),
        "{s}"
    );
    assert!(!std::fs::read_to_string(&junit)
        .unwrap()
        .contains("<failure"));

    // u_z scaled by 1.01: a 1% error in e_zz, so sigma_zz is off by about 2% of its value
    let text = std::fs::read_to_string(&vtu).unwrap();
    let edited = tmp.path().join("edited.vtu");
    std::fs::write(
        &edited,
        edit_array(&text, "displacement", |v| vec![v[0], v[1], v[2] * 1.01]),
    )
    .unwrap();
    let o = run(&["judge", case, edited.to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(1), "{s}");
    let line = s
        .lines()
        .find(|l| l.starts_with("  FAIL uniform stress [0.0, 0.0, -2.0"))
        .unwrap_or_else(|| panic!("{s}"));
    let error: f64 = line
        .split("(error ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!(error > 5e-3 && error < 5e-2, "{line}");
    // the results' own stress field was not edited: that check still passes
    assert!(s.contains("  pass uniform stress [0.0, 0.0, -2.0, 0.0, 0.0, 0.0] (3D: xx, yy, zz, yz, xz, xy) in the results' own nodal 'stress' field"), "{s}");

    // the Hex8 mesh of the same block has none of the Hex27 mid-edge nodes
    let out8 = tmp.path().join("run8");
    let o = run(&[
        "run",
        "cases/3d/patch-hex8.json",
        "--out",
        out8.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let o = run(&["judge", case, out8.join("block.vtu").to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(2), "{s}");
    assert!(s.contains("no result point within"), "{s}");
    assert!(s.contains("of body 'block' at ("), "{s}");
}

/// `edit` applied to the values of point array `name` (one point per line) in `text`.
fn edit_array(text: &str, name: &str, edit: impl Fn(&[f64]) -> Vec<f64>) -> String {
    let tag = format!("Name=\"{name}\"");
    let (head, rest) = text.split_once(&tag).unwrap();
    let (data, tail) = rest.split_once("</DataArray>").unwrap();
    let (attrs, values) = data.split_once('>').unwrap();
    let lines: Vec<String> = values
        .trim()
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split(' ').map(|w| w.parse().unwrap()).collect();
            let e: Vec<String> = edit(&v).iter().map(|x| format!("{x:?}")).collect();
            e.join(" ")
        })
        .collect();
    format!(
        "{head}{tag}{attrs}>\n{}\n</DataArray>{tail}",
        lines.join("\n")
    )
}

/// A `reaction` check of a 3D case without contact (the Gmsh patch: the base carries the lid's
/// load 1.6 in z) is judged from the results' displacements (`K u - f` on this mesh) as the run
/// judges it; a 2D case that names the component z is refused.
#[test]
fn a_3d_reaction_check_is_judged_from_the_results_as_the_run_judges_it() {
    let tmp = tempfile::tempdir().unwrap();
    let path = "cases/gmsh/3d/patch-hex8.json";
    let case = read_3d_case(&root().join(path)).unwrap();
    let direct = run_case3(&case, &root().join(path).display().to_string()).unwrap();
    let reaction = direct
        .checks
        .iter()
        .find(|c| c.check.starts_with("reaction Z on block.base"))
        .unwrap_or_else(|| panic!("{:?}", direct.checks));
    assert!(reaction.passed, "{reaction:?}");
    let j = written_and_judged(&direct, tmp.path());
    let judged = same_check(&j, reaction);
    assert!(judged.passed, "{judged:?}");
    assert!(
        (judged.error - reaction.error).abs() < 1e-12,
        "{judged:?} {reaction:?}"
    );
    // a z component in 2D
    let text = std::fs::read_to_string(root().join("cases/gmsh/patch-q4.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["checks"][2]["component"] = "z".into();
    let source = root()
        .join("cases/gmsh/patch-q4.json")
        .display()
        .to_string();
    let err = contact_patch::model::Model::build(
        &contact_patch::model::parse(&v.to_string(), &source).unwrap(),
        &source,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("checks[2]"), "{err}");
    assert!(
        err.contains("the check names the component z, but the case is 2D"),
        "{err}"
    );
}

/// The `displacement` check of a 3D case is judged from the results' displacements as the run
/// judges it; the checks of how our own solve ran (`equilibrium`, `warns`, ...) are listed as
/// not judged, with the reason, as in 2D.
#[test]
fn a_3d_displacement_check_is_judged_from_the_results_and_our_solves_checks_are_not() {
    let tmp = tempfile::tempdir().unwrap();
    let path = root().join("cases/3d/patch-hex8.json");
    let mut case = read_3d_case(&path).unwrap();
    let extra: Vec<contact_patch::io::scene::Check> = serde_json::from_value(serde_json::json!([
        {"check": "displacement", "body": "block", "point": [1.0, 0.8, 1.2], "component": "z",
         "value": -0.012, "tol": 1e-9},
        {"check": "equilibrium", "tol": 1e-10}
    ]))
    .unwrap();
    case.checks.extend(extra);
    let direct = run_case3(&case, &path.display().to_string()).unwrap();
    let displacement = direct
        .checks
        .iter()
        .find(|c| {
            c.check
                .starts_with("displacement Z of block at (1, 0.8, 1.2)")
        })
        .unwrap_or_else(|| panic!("{:?}", direct.checks));
    assert!(displacement.passed, "{displacement:?}");
    let j = written_and_judged(&direct, tmp.path());
    let judged = same_check(&j, displacement);
    assert_eq!(
        judged.error, displacement.error,
        "u is read back bit for bit"
    );
    assert_eq!(j.not_judged.len(), 1, "{:?}", j.not_judged);
    assert!(j.not_judged[0].check.contains("equilibrium"));
    assert!(
        j.not_judged[0].why.contains("how our own solve ran"),
        "{}",
        j.not_judged[0].why
    );
}
