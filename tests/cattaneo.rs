//! The Cattaneo-Mindlin study (`contact-patch cattaneo`, src/harness/cattaneo.rs) on the cases of
//! cases/friction-bench (a cylinder of radius 100 pressed onto a block of the same material, then
//! sheared by Q ~ mu P / 2; Coulomb penalty friction): every number is judged against Hertz's and
//! Cattaneo-Mindlin's closed forms or an exact balance, never against a stored result.
//!
//! * at the moderate level L2 (h = 0.04): the stick half-width c_h within 1.5 h of
//!   c = a sqrt(1 - Q/(mu P)) (the stick/slip boundary lies between two nodes), the contact
//!   half-width within 1.5 h of Hertz's a, the tangential contact forces summing to the force the
//!   indenter's supports carry to 1e-9, |q| <= mu p at every point (to round-off), Dundurs'
//!   beta = 0;
//! * under refinement L1 -> L2 -> L3 (h = 0.08, 0.04, 0.02): the L2 errors of the shear traction
//!   and of the pressure over the contact zone, and of the pressure over 0.8 a, fall at every
//!   step (L4 is left to the report: see docs/verification.md, Cattaneo-Mindlin);
//! * the command writes the table, the JSON and the plot, and refuses a frictionless pair.

use std::path::{Path, PathBuf};
use std::process::Command;

fn case(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
}

fn cattaneo(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .arg("cattaneo")
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn stick_zone_traction_and_balance_converge_to_cattaneo_mindlin() {
    let dir = tempfile::tempdir().unwrap();
    let cases: Vec<String> = (1..=3)
        .map(|l| {
            case(&format!("cases/friction-bench/cattaneo-mindlin-L{l}.json"))
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    let out = dir.path().join("reports");
    let mut args: Vec<&str> = cases.iter().map(String::as_str).collect();
    args.extend(["--out", out.to_str().unwrap()]);
    let o = cattaneo(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("cattaneo-mindlin.json")).unwrap())
            .unwrap();
    let levels = json.as_array().unwrap();
    assert_eq!(levels.len(), 3);
    let num = |l: &serde_json::Value, k: &str| l[k].as_f64().unwrap_or_else(|| panic!("{k}"));

    let moderate = &levels[1];
    let h = num(moderate, "spacing");
    assert!((h - 0.04).abs() < 1e-9, "h = {h}");
    assert_eq!(num(moderate, "dundurs_beta"), 0.0);
    let cf = &moderate["closed_form"];
    let (load, shear, mu) = (num(cf, "load"), num(cf, "shear"), num(cf, "mu"));
    let ratio = shear.abs() / (mu * load);
    assert!(
        (0.3..0.7).contains(&ratio),
        "Q/(mu P) = {ratio}: the case should shear to about half the friction limit"
    );
    // c follows from the measured P and Q
    let (a, c) = (
        num(moderate, "half_width"),
        num(moderate, "stick_half_width"),
    );
    assert!((c - a * (1.0 - ratio).sqrt()).abs() <= 1e-12 * a);
    let (a_h, c_h) = (
        num(moderate, "measured_half_width"),
        num(moderate, "measured_stick_half_width"),
    );
    assert!((c_h - c).abs() <= 1.5 * h, "c_h = {c_h}, c = {c}, h = {h}");
    assert!((a_h - a).abs() <= 1.5 * h, "a_h = {a_h}, a = {a}, h = {h}");
    // the stick zone is central: both ends within 1.5 h of +-c
    let ends = moderate["stick_ends"].as_array().unwrap();
    let (lo, hi) = (ends[0].as_f64().unwrap(), ends[1].as_f64().unwrap());
    assert!(
        (lo + c).abs() <= 1.5 * h && (hi - c).abs() <= 1.5 * h,
        "[{lo}, {hi}]"
    );
    // the tangential contact forces carry exactly what the indenter's supports carry
    let support = num(moderate, "support_shear");
    assert!(
        (shear - support).abs() <= 1e-9 * shear.abs(),
        "sum q A = {shear}, supports {support}"
    );
    // Coulomb's inequality at every point, and the slip points on the cone
    for l in levels {
        let ratio = num(l, "max_cone_ratio");
        assert!(
            ratio <= 1.0 + 1e-12,
            "{}: max |q|/(mu p) = {ratio}",
            l["case"]
        );
        let mu = num(&l["closed_form"], "mu");
        let slipping: Vec<_> = l["points"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|p| p["status"] == "slip")
            .collect();
        assert!(!slipping.is_empty(), "{}: no slip zone", l["case"]);
        for p in slipping {
            let (q, pr) = (num(p, "traction"), num(p, "pressure"));
            assert!(
                (q.abs() - mu * pr).abs() <= 1e-12 * mu * pr,
                "{}: slip point at s = {} with |q| = {q}, mu p = {}",
                l["case"],
                p["s"],
                mu * pr
            );
        }
    }
    // the errors against the closed forms fall under refinement
    for key in [
        "traction_error",
        "pressure_error",
        "pressure_error_interior",
    ] {
        let errors: Vec<f64> = levels.iter().map(|l| num(l, key)).collect();
        assert!(
            errors.windows(2).all(|w| w[1] < w[0]),
            "{key} does not fall under refinement: {errors:?}"
        );
    }
    let md = std::fs::read_to_string(out.join("cattaneo-mindlin.md")).unwrap();
    assert_eq!(md.matches("| cattaneo-mindlin-L").count(), 3, "{md}");
    let svg = std::fs::read_to_string(out.join("cattaneo-mindlin.svg")).unwrap();
    for name in ["q (nodal)", "mu p (nodal)", "q closed form", "mu p Hertz"] {
        assert!(svg.contains(name), "the plot lacks '{name}'");
    }
}

#[test]
fn a_frictionless_pair_or_an_unknown_pair_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reports");
    let hertz = case("cases/contact/hertz-profile.json");
    for (pair, says) in [
        ("cylinder", "has no Coulomb friction"),
        ("nothing", "names no contact pair"),
    ] {
        let o = cattaneo(&[
            hertz.to_str().unwrap(),
            "--pair",
            pair,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(says), "{err}");
        assert!(!out.join("cattaneo-mindlin.md").exists());
    }
}
