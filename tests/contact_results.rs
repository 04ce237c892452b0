//! Contact results per point (issue 16, item 1): `<pair>.contact.csv`, `.json` and `.vtu`, the
//! contact point data of the body `.vtu` files and the pair totals in `summary.json`, read back
//! from what `contact-patch run` writes and judged against closed forms: Hertz's pressure under
//! a rigid cylinder, the uniform pressure of the contact patch test, the penalty law
//! `p = -kappa g`, and Coulomb's `|tau| = mu p` at slipping points.

mod common;
use common::run_case;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn case(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Run `case` into `out`; the exit code must be `code`.
fn run(case: &Path, out: &Path, code: i32) {
    let o = run_case(case, out);
    assert_eq!(
        o.status.code(),
        Some(code),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A copy of case `rel` with its first pair changed by `edit`, written into `dir`.
fn edited(rel: &str, dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(case(rel)).unwrap()).unwrap();
    edit(&mut c);
    let path = dir.join("case.json");
    std::fs::write(&path, serde_json::to_string(&c).unwrap()).unwrap();
    path
}

/// The CSV rows as maps from column to text.
fn csv_rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            let fields: Vec<&str> = l.split(',').collect();
            assert_eq!(fields.len(), header.len(), "{l}");
            header
                .iter()
                .cloned()
                .zip(fields.iter().map(|f| f.to_string()))
                .collect()
        })
        .collect()
}

fn num(row: &BTreeMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column}: '{}'", row[column]))
}

/// A `.vtu` file's points (x, y) and named point-data arrays.
struct Vtu {
    points: Vec<[f64; 2]>,
    arrays: BTreeMap<String, (usize, Vec<f64>)>,
    cell_types: Vec<u8>,
}

fn read_vtu(path: &Path) -> Vtu {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let numbers = |n: roxmltree::Node| -> Vec<f64> {
        n.text()
            .unwrap_or("")
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect()
    };
    let mut points = Vec::new();
    let mut arrays = BTreeMap::new();
    let mut cell_types = Vec::new();
    for n in doc.descendants().filter(|n| n.has_tag_name("DataArray")) {
        let parent = n.parent().unwrap().tag_name().name();
        match (parent, n.attribute("Name")) {
            ("Points", _) => {
                points = numbers(n).chunks(3).map(|c| [c[0], c[1]]).collect();
            }
            ("PointData", Some(name)) => {
                let comps: usize = n
                    .attribute("NumberOfComponents")
                    .map_or(1, |c| c.parse().unwrap());
                arrays.insert(name.to_string(), (comps, numbers(n)));
            }
            ("Cells", Some("types")) => {
                cell_types = numbers(n).iter().map(|&t| t as u8).collect();
            }
            _ => {}
        }
    }
    Vtu {
        points,
        arrays,
        cell_types,
    }
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// Hertz (Johnson, Contact Mechanics, eqs. 4.43 and 4.45; rigid cylinder, plane strain), written
/// here from the formula: `(a, p0, p(x))`.
fn hertz(load: f64, radius: f64, e: f64, nu: f64) -> (f64, f64, impl Fn(f64) -> f64) {
    let e_star = e / (1.0 - nu * nu);
    let a = (4.0 * load * radius / (std::f64::consts::PI * e_star)).sqrt();
    let p0 = 2.0 * load / (std::f64::consts::PI * a);
    (a, p0, move |x: f64| {
        p0 * (1.0 - (x / a).powi(2)).max(0.0).sqrt()
    })
}

/// The Hertz case's pressure profile, read back from the CSV and from the contact `.vtu` (the
/// same numbers, bit for bit, and the same as the JSON file), against Hertz's closed form:
/// within 2% of p0 over |x| <= 0.8 a (measured 1.25e-2: the block is finite, 8.3 a deep, and
/// its centre pressure sits 1.25% below the half-space value on the committed 0.1 mesh too,
/// where the case's own check allows 3%), the outermost closed node within one element
/// (0.02) of a, and the pressures integrating to the load P = 4 to 1e-10.
#[test]
fn hertz_profile_from_csv_and_contact_vtu_against_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hertz");
    run(&case("cases/contact/hertz-profile.json"), &out, 0);
    let rows = csv_rows(&out.join("cylinder.contact.csv"));
    let vtu = read_vtu(&out.join("cylinder.contact.vtu"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("cylinder.contact.json")).unwrap())
            .unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(rows.len(), vtu.points.len());
    assert_eq!(rows.len(), points.len());
    assert_eq!(
        rows.len(),
        125,
        "the slave surface's nodes (a rigid master has none)"
    );
    assert!(vtu.cell_types.iter().all(|&t| t == 3), "Line2 facets");
    assert_eq!(vtu.cell_types.len(), 124);
    let pressure = &vtu.arrays["contact_pressure"].1;
    let gap = &vtu.arrays["contact_gap"].1;
    let status = &vtu.arrays["contact_status"].1;
    for (k, row) in rows.iter().enumerate() {
        let x = num(row, "x");
        assert_eq!(x, vtu.points[k][0]);
        assert_eq!(x, points[k]["x"][0].as_f64().unwrap());
        assert_eq!(num(row, "pressure"), pressure[k], "point {k}");
        assert_eq!(
            num(row, "pressure"),
            points[k]["pressure"].as_f64().unwrap()
        );
        assert_eq!(num(row, "gap"), gap[k]);
        let code = match row["status"].as_str() {
            "open" => 1.0,
            "closed" => 2.0,
            s => panic!("status {s} on a frictionless rigid pair"),
        };
        assert_eq!(code, status[k]);
        assert_eq!(row["slip"], "", "no slip without friction");
    }

    let (a, p0, p) = hertz(4.0, 10.0, 200.0, 0.3);
    let mut interior = 0.0f64;
    let mut extent = 0.0f64;
    let mut total = 0.0;
    for row in &rows {
        let (x, got) = (num(row, "x"), num(row, "pressure"));
        total += got * num(row, "area");
        if row["status"] == "closed" {
            extent = extent.max(x.abs());
            // a closed node does not gap; an open one carries nothing
            assert!(num(row, "gap").abs() <= 1e-12, "{row:?}");
        } else {
            assert_eq!(got, 0.0, "{row:?}");
            assert!(num(row, "gap") > 0.0, "{row:?}");
        }
        if x.abs() <= 0.8 * a {
            interior = interior.max((got - p(x)).abs() / p0);
        }
    }
    println!("Hertz a = {a:.6}, p0 = {p0:.6}: largest |p - p_H| / p0 over |x| <= 0.8 a = {interior:.3e}; outermost closed node {extent}; sum p A = {total}");
    assert!(interior <= 0.02, "{interior}");
    assert!((extent - a).abs() <= 0.02, "{extent} vs {a}");
    assert!((total - 4.0).abs() <= 1e-10 * 4.0, "{total}");

    let pair = &summary(&out)["contact"]["pairs"][0];
    assert!((pair["normal_force"].as_f64().unwrap() - 4.0).abs() <= 4e-10);
    let closed = rows.iter().filter(|r| r["status"] == "closed").count();
    assert_eq!(pair["point_status"]["closed"], closed);
    assert_eq!(pair["point_status"]["open"], rows.len() - closed);
    assert_eq!(
        pair["files"],
        serde_json::json!([
            "cylinder.contact.vtu",
            "cylinder.contact.csv",
            "cylinder.contact.json"
        ])
    );
    // the body file carries the same pressures at the same nodes
    let body = read_vtu(&out.join("block.vtu"));
    for row in &rows {
        let node: usize = row["node"].parse().unwrap();
        assert_eq!(
            body.arrays["contact_pressure"].1[node],
            num(row, "pressure")
        );
        assert_eq!(
            body.arrays["contact_force"].1[3 * node + 1],
            num(row, "force_y")
        );
    }
}

/// The contact patch test (mesh C, non-matching) with two-pass node-to-surface Lagrange rows:
/// every node of both surfaces carries a row, is closed with zero gap, and has the exact
/// pressure 10 (the multipliers of the dependent rows are not unique, their nodal forces are);
/// the case's `contact_pressure` check (1e-10) passes.
#[test]
fn two_pass_points_have_the_patch_test_pressure_on_both_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let path = edited("cases/patch/patch-C-nu0.3.json", dir.path(), |c| {
        c["contact"][0]["discretization"] =
            serde_json::json!({"kind": "node_to_surface", "passes": 2});
        // the case expects its one-pass pair to fail the patch test; two passes pass it
        c.as_object_mut().unwrap().remove("expected_failures");
    });
    let out = dir.path().join("out");
    run(&path, &out, 0);
    let rows = csv_rows(&out.join("interface.contact.csv"));
    let sides: Vec<&str> = rows.iter().map(|r| r["side"].as_str()).collect();
    assert!(sides.contains(&"slave") && sides.contains(&"master"));
    let mut worst = 0.0f64;
    for row in &rows {
        assert_eq!(row["status"], "closed", "{row:?}");
        assert!(num(row, "gap").abs() <= 1e-12, "{row:?}");
        worst = worst.max((num(row, "pressure") - 10.0).abs() / 10.0);
        assert!(num(row, "shear").abs() <= 1e-10 * 10.0, "{row:?}");
    }
    println!("two-pass mesh C: largest |p - 10| / 10 = {worst:.3e}");
    assert!(worst <= 1e-10, "{worst}");
    let s = summary(&out);
    let check = s["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["check"].as_str().unwrap().starts_with("contact pressure"))
        .unwrap();
    assert_eq!(check["passed"], true, "{check}");
}

/// One pass: the master surface's nodes have forces (the projection's share) but no row, so
/// they are `unmeasured`; the forces of the two surfaces balance.
#[test]
fn one_pass_master_points_are_unmeasured_and_balance_the_slave() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run(&case("cases/patch/patch-D-nu0.3.json"), &out, 0);
    let rows = csv_rows(&out.join("interface.contact.csv"));
    let mut net = [0.0f64; 2];
    let mut scale = 0.0f64;
    for row in &rows {
        let expected = if row["side"] == "slave" {
            "closed"
        } else {
            "unmeasured"
        };
        assert_eq!(row["status"], expected, "{row:?}");
        if expected == "unmeasured" {
            assert_eq!(row["gap"], "");
        }
        net[0] += num(row, "force_x");
        net[1] += num(row, "force_y");
        scale += num(row, "force_y").abs();
    }
    assert!(net[0].abs().max(net[1].abs()) <= 1e-12 * scale, "{net:?}");
    let vtu = read_vtu(&out.join("interface.contact.vtu"));
    let unmeasured = vtu.arrays["contact_status"]
        .1
        .iter()
        .filter(|&&s| s == 0.0)
        .count();
    assert_eq!(
        unmeasured,
        rows.iter().filter(|r| r["status"] == "unmeasured").count()
    );
    assert!(unmeasured > 0);
}

/// Penalty rows: the pressure is the penalty force per tributary area, `p = kappa (-g)`, at
/// every slave node of the Signorini block on a rigid line (and near the exact 5).
#[test]
fn penalty_pressure_is_kappa_times_the_penetration() {
    let dir = tempfile::tempdir().unwrap();
    let kappa = 1e6;
    let path = edited(
        "cases/contact/signorini-block-on-rigid-line.json",
        dir.path(),
        |c| {
            c["contact"][0]["enforcement"] = serde_json::json!({"kind": "penalty", "kappa": kappa});
            c["checks"] = serde_json::json!([]);
        },
    );
    let out = dir.path().join("out");
    run(&path, &out, 0);
    let rows = csv_rows(&out.join("ground.contact.csv"));
    assert!(!rows.is_empty());
    for row in &rows {
        let (p, g) = (num(row, "pressure"), num(row, "gap"));
        assert_eq!(row["status"], "closed");
        assert!((p - kappa * (-g)).abs() <= 1e-9 * p, "{row:?}");
        assert!((p - 5.0).abs() <= 1e-6 * 5.0, "{row:?}");
    }
}

/// Coulomb pairs: every slave point of the sliding patch test slips, its shear traction is
/// `mu p` (mu = 0.3, p = 10: 3, the case's exact field, to the case's 1e-8), and it reports
/// its slip; the summary counts agree.
#[test]
fn slipping_points_carry_mu_times_their_pressure() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run(&case("cases/contact/coulomb-patch-slip.json"), &out, 0);
    let rows = csv_rows(&out.join("interface.contact.csv"));
    let slave: Vec<_> = rows.iter().filter(|r| r["side"] == "slave").collect();
    assert!(!slave.is_empty());
    for row in &slave {
        assert_eq!(row["status"], "slip", "{row:?}");
        let (p, tau) = (num(row, "pressure"), num(row, "shear"));
        assert!((p - 10.0).abs() <= 1e-8 * 10.0, "{row:?}");
        assert!((tau.abs() - 0.3 * p).abs() <= 1e-8 * 10.0, "{row:?}");
        assert!(num(row, "slip").abs() > 0.0, "{row:?}");
    }
    let pair = &summary(&out)["contact"]["pairs"][0];
    assert_eq!(pair["point_status"]["slip"], slave.len());
    assert_eq!(pair["friction"]["slip"], slave.len());
}

/// Physics is opt-in: a scene without contact writes exactly its summary and body file, with
/// no contact arrays and no contact section.
#[test]
fn a_scene_without_contact_writes_no_contact_results() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run(&case("cases/patch-single/q4-distorted.json"), &out, 0);
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [".contact-patch-output.json", "patch.vtu", "summary.json"]
    );
    let xml = std::fs::read_to_string(out.join("patch.vtu")).unwrap();
    assert!(!xml.contains("contact_"));
    assert!(xml.contains("</DataArray></PointData>"));
    assert!(summary(&out).get("contact").is_none());
}

/// `contact-patch profile` writes the plot and its table, and names a missing pair.
#[test]
fn profile_command_writes_the_plot_and_refuses_an_unknown_pair() {
    let dir = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_contact-patch");
    let hertz = case("cases/contact/hertz-profile.json");
    let o = Command::new(bin)
        .args([
            "profile",
            hertz.to_str().unwrap(),
            "--pair",
            "cylinder",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let svg =
        std::fs::read_to_string(dir.path().join("hertz-profile.cylinder.pressure.svg")).unwrap();
    assert!(svg.contains("Hertz") && svg.contains("nodal pressure"));
    let md =
        std::fs::read_to_string(dir.path().join("hertz-profile.cylinder.pressure.md")).unwrap();
    assert!(md.contains("a = 0.481383, p0 = 5.289923"), "{md}");
    let o = Command::new(bin)
        .args([
            "profile",
            hertz.to_str().unwrap(),
            "--pair",
            "nope",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("'nope'") && err.contains("cylinder"), "{err}");
}

/// Defect W02 (second report): tied node-to-surface with the slave face [0, 4] longer than the
/// master's [1, 3]. The corner condition's fallback glued the slave nodes beyond the master's
/// ends to the interior master vertex at x = 2 (two bilateral rows with zero gap), a stress
/// error of 0.65 on a case that is exact with mortar (W02b, the control). Now a slave node
/// with no master facet under it gets no row, and the run names it.
#[test]
fn a_tie_glues_only_slave_nodes_with_a_master_facet_under_them() {
    for name in ["W02a", "W02b"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let o = run_case(&common::defect(name), &out);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{name}: the uniform stress check fails\n{}",
            String::from_utf8_lossy(&o.stdout)
        );
        let s = summary(&out);
        let error = s["checks"][0]["error"].as_f64().unwrap();
        assert!(error < 1e-12, "{name}: stress error {error}");
        // the four slave nodes outside [1, 3] are named, and no other
        let warnings: Vec<&str> = s["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|w| w.as_str())
            .filter(|w| w.contains("not tied"))
            .collect();
        assert_eq!(warnings.len(), 1, "{name}: {warnings:?}");
        for x in [
            "(0.000000, 1.000000)",
            "(0.500000, 1.000000)",
            "(3.500000, 1.000000)",
        ] {
            assert!(
                warnings[0].contains(x),
                "{name}: {x} not named in {}",
                warnings[0]
            );
        }
        assert!(warnings[0].contains("4 slave node(s)"), "{}", warnings[0]);
        assert!(
            !warnings[0].contains("(1.000000, 1.000000)"),
            "{}",
            warnings[0]
        );
    }
}

/// Issue 38, item 9 (no slip at open points): the Cattaneo-Mindlin indentation with Lagrange
/// multipliers (cases/hard) has 60 open slave points beside 9 stick and 4 slip points. Each
/// open point reported a slip and a plastic slip (-7.80e-4 at x = -16): the tangential motion
/// of a point not in contact. Now an open point has no slip in any of the three files (empty in
/// the CSV, `null` in the JSON, 0 in the `.vtu` where `contact_status` says open), and the
/// stick and slip points keep theirs.
#[test]
fn open_points_report_no_slip() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run(&case("cases/hard/cattaneo-lagrange-friction.json"), &out, 0);
    let rows = csv_rows(&out.join("interface.contact.csv"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("interface.contact.json")).unwrap())
            .unwrap();
    let vtu = read_vtu(&out.join("interface.contact.vtu"));
    let slip = &vtu.arrays["contact_slip"].1;
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for (k, row) in rows.iter().enumerate() {
        *counts.entry(row["status"].clone()).or_default() += 1;
        let point = &json["points"][k];
        match row["status"].as_str() {
            "open" | "unmeasured" => {
                assert_eq!(row["slip"], "", "{row:?}");
                assert_eq!(row["plastic_slip"], "", "{row:?}");
                assert!(point["slip"].is_null() && point["plastic_slip"].is_null());
                assert_eq!(slip[k], 0.0, "{row:?}");
            }
            "stick" | "slip" => {
                let s = num(row, "slip");
                assert!(s.is_finite(), "{row:?}");
                assert_eq!(point["slip"].as_f64().unwrap(), s);
                assert_eq!(slip[k], s);
            }
            other => panic!("status {other}"),
        }
    }
    assert_eq!(counts["open"], 60, "{counts:?}");
    assert!(counts["stick"] > 0 && counts["slip"] > 0, "{counts:?}");
}

/// Issue 38, item 2 (the contact half of defect W02): W02a's slave surface (the lower body's
/// top, x in [0, 4]) is wider than its master (the upper body's bottom, x in [1, 3], two
/// facets), here as a frictionless contact pair pressed by 10. A slave node past the master's
/// free end (beyond the quarter-facet extension) has no facet under it. It was held against
/// the nearest vertex that two facets share, the interior vertex (2, 1): x = 0.5 reported the
/// gap 1.5, a distance to a point of the master it is nowhere near. Now such a node has no row:
/// `unmeasured`, no gap, no force; the nodes under the master are closed at the pressure 10.
#[test]
fn a_contact_node_past_the_masters_end_has_no_row() {
    // Under finite kinematics (rows built at the iterate `X + u`) such a node keeps a row to
    // that vertex while Newton iterates (the finite patch test D needs it); its gap, the
    // distance 1.5 and up, carries no force and was reported as an open gap until 2026-12-03.
    // Now that row is marked past the free end and its node reported as unmeasured too.
    for finite in [false, true] {
        let dir = tempfile::tempdir().unwrap();
        let path = edited(
            "tests/defects/s4/W02a-tied-nts-slave-past-free-end.json",
            dir.path(),
            |c| {
                c["contact"][0]["interaction"] = serde_json::json!("frictionless");
                // the upper body slides freely on the lower one: hold its x at one point
                c["bodies"][1]["node_sets"] = serde_json::json!({"corner": {"point": [1.0, 2.0]}});
                c["supports"]
                    .as_array_mut()
                    .unwrap()
                    .push(serde_json::json!({"body": "upper", "set": "corner", "x": 0.0}));
                if finite {
                    c["materials"]["m"]["model"] = serde_json::json!("neo_hookean");
                    c["physics"] =
                        serde_json::json!({"kinematics": "finite", "contact_geometry": "current"});
                    c["solver"] = serde_json::json!({"scheme": "newton", "load_steps": 2});
                    // the case's uniform-stress check is the small-strain state's
                    c["checks"] = serde_json::json!([]);
                }
            },
        );
        let out = dir.path().join("out");
        run(&path, &out, 0);
        let rows = csv_rows(&out.join("tie.contact.csv"));
        let slave: Vec<_> = rows.iter().filter(|r| r["side"] == "slave").collect();
        assert_eq!(slave.len(), 9);
        let mut unmeasured = 0;
        for row in slave {
            // the reference x: the master spans [1, 3]
            let x = num(row, "x");
            if (1.0..=3.0).contains(&x) {
                assert_eq!(row["status"], "closed", "finite {finite}: {row:?}");
                // the ends' nodes carry the half of their tributary that the master covers,
                // and read their force over that half (issue 38, item 9: they read 5 over the
                // whole tributary before); at finite strain the pressure is the true traction
                // over the current area, within the strain (1e-2) of the nominal 10
                let tol = if finite { 1e-1 } else { 1e-9 };
                assert!(
                    (num(row, "pressure") - 10.0).abs() < tol,
                    "finite {finite}: {row:?}"
                );
            } else {
                assert_eq!(row["status"], "unmeasured", "finite {finite}: {row:?}");
                assert_eq!(row["gap"], "", "finite {finite}: {row:?}");
                assert_eq!(num(row, "force_y"), 0.0, "finite {finite}: {row:?}");
                unmeasured += 1;
            }
        }
        assert_eq!(unmeasured, 4, "finite {finite}");
        // the closed area is the master's length (2, the ends' nodes covering half their
        // tributaries), and the force it transmits the pressure 10 over it
        if !finite {
            let totals = &summary(&out)["contact"]["pairs"][0];
            let closed_area = totals["closed_area"].as_f64().unwrap();
            assert!((closed_area - 2.0).abs() < 1e-12, "{totals}");
            let normal_force = totals["normal_force"].as_f64().unwrap();
            assert!((normal_force - 10.0 * closed_area).abs() < 1e-9, "{totals}");
        }
    }
}

/// Issue 38, item 9 (the pressure at the edge of a partly covered slave facet): W07 presses a
/// block by a uniform 100 onto a base whose top is two master surfaces, one per pair, so that
/// each pair's slave surface extends past its master's end and the slave facet [1, 1.5] is
/// covered 0.6 by one pair and 0.4 by the other (standard mortar). The stress is uniform, so
/// every closed point of both pairs has the pressure 100. At 7f42d35 the nodes of that facet
/// read their force over their whole tributary area: 92.0 and 18.0 at x = 1 and 1.5 (pair
/// 'left'), 8.0 and 82.0 ('right'), closed areas 1.75 and 1.25. Now every closed point reads
/// 100 to round-off in the CSV, the JSON and the `.vtu`, frictionless and tied, and each pair's
/// totals agree: its normal force is the force it transmits (the slave's nodal forces), 100
/// times its closed area (1.3 and 0.7), and no larger pressure. (Dual mortar does not pass this
/// patch test: the dual function of x = 1.5 integrates to a negative number over its part
/// covered by 'left', the node gets no row there, and the stress is off by 0.8 %; node-to-surface
/// one pass is off by 6.6 %.)
#[test]
fn a_partly_covered_slave_facet_reads_the_uniform_pressure() {
    for interaction in ["frictionless", "tied"] {
        let dir = tempfile::tempdir().unwrap();
        let path = edited(
            "tests/defects/s4/W07-partly-covered-slave-facet-pressure.json",
            dir.path(),
            |c| {
                for pair in c["contact"].as_array_mut().unwrap() {
                    if interaction == "tied" {
                        pair["interaction"] = "tied".into();
                    }
                }
            },
        );
        let out = dir.path().join("out");
        run(&path, &out, 0);
        let s = summary(&out);
        let mut total = 0.0;
        for (k, (pair, width)) in [("left", 1.3), ("right", 0.7)].into_iter().enumerate() {
            let rows = csv_rows(&out.join(format!("{pair}.contact.csv")));
            let json: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(out.join(format!("{pair}.contact.json"))).unwrap(),
            )
            .unwrap();
            let vtu = read_vtu(&out.join(format!("{pair}.contact.vtu")));
            let (mut transmitted, mut closed) = (0.0, 0);
            for (i, row) in rows.iter().enumerate() {
                let p = num(row, "pressure");
                assert_eq!(json["points"][i]["pressure"].as_f64().unwrap(), p);
                assert_eq!(vtu.arrays["contact_pressure"].1[i], p);
                if row["side"] != "slave" {
                    continue;
                }
                transmitted -= num(row, "force_x") * num(row, "normal_x")
                    + num(row, "force_y") * num(row, "normal_y");
                if row["status"] == "closed" {
                    closed += 1;
                    assert!(
                        (p - 100.0).abs() <= 1e-10 * 100.0,
                        "{interaction}, {pair}: pressure {p} at x = {}",
                        row["x"]
                    );
                    assert!(num(row, "shear").abs() <= 1e-10 * 100.0, "{row:?}");
                } else {
                    assert_eq!(p, 0.0, "{interaction}, {pair}: {row:?}");
                }
            }
            assert!(closed >= 3, "{interaction}, {pair}: {closed} closed points");
            let totals = &s["contact"]["pairs"][k];
            assert_eq!(totals["name"], pair);
            let normal_force = totals["normal_force"].as_f64().unwrap();
            let closed_area = totals["closed_area"].as_f64().unwrap();
            let max_pressure = totals["max_pressure"].as_f64().unwrap();
            assert!(
                (normal_force - transmitted).abs() <= 1e-12 * normal_force,
                "{totals}"
            );
            assert!(
                (normal_force - 100.0 * width).abs() <= 1e-10 * normal_force,
                "{totals}"
            );
            assert!((closed_area - width).abs() <= 1e-10 * width, "{totals}");
            assert!((max_pressure - 100.0).abs() <= 1e-10 * 100.0, "{totals}");
            assert_eq!(
                json["totals"]["normal_force"].as_f64().unwrap(),
                normal_force
            );
            total += normal_force;
        }
        // the two pairs carry the whole load, 100 over the block's width 2
        assert!(
            (total - 200.0).abs() <= 1e-10 * 200.0,
            "{interaction}: {total}"
        );
    }
}

/// Issue 40, item 3 (per-point contact output in 3D): a 3D run writes the pair's `.contact.csv`,
/// `.json` and `.vtu` and the body `.vtu` contact fields as 2D does, with three components.
/// Gmsh's punch on foundation (Hex8 punch on Tet4 foundation, standard mortar, Lagrange) is a
/// contact patch test: every point of the punch's base is closed at the pressure 10 with no
/// shear and no gap, the pair transmits 10 over the closed area 1 (the base), and the contact
/// surfaces are written as Quad4 (VTK 9) and Tri3 (VTK 5) cells. Until 2026-12-03 a 3D run
/// wrote none of these (summary.json had the pair's penetration only).
#[test]
fn a_3d_pair_writes_its_points_as_a_2d_one_does() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run(&case("cases/gmsh/3d/punch-on-foundation.json"), &out, 0);
    let text = std::fs::read_to_string(out.join("interface.contact.csv")).unwrap();
    assert!(text.starts_with(
        "side,body,node,x,y,z,u_x,u_y,u_z,normal_x,normal_y,normal_z,area,force_x,force_y,force_z,"
    ));
    let rows = csv_rows(&out.join("interface.contact.csv"));
    let slave: Vec<_> = rows.iter().filter(|r| r["side"] == "slave").collect();
    // the punch's base: 4 x 4 Hex8 faces (25 nodes)
    assert_eq!(slave.len(), 25);
    for row in &slave {
        assert_eq!(row["status"], "closed", "{row:?}");
        assert!((num(row, "pressure") - 10.0).abs() < 1e-9, "{row:?}");
        assert!(num(row, "shear").abs() < 1e-9, "{row:?}");
        assert!(num(row, "gap").abs() < 1e-12, "{row:?}");
        assert_eq!(num(row, "normal_z"), -1.0, "{row:?}");
        // the force is the pressure over the node's tributary, along -n
        assert!(
            (num(row, "force_z") - 10.0 * num(row, "area")).abs() < 1e-9,
            "{row:?}"
        );
    }
    let totals = &summary(&out)["contact"]["pairs"][0];
    assert!(
        (totals["normal_force"].as_f64().unwrap() - 10.0).abs() < 1e-9,
        "{totals}"
    );
    assert!(
        (totals["closed_area"].as_f64().unwrap() - 1.0).abs() < 1e-12,
        "{totals}"
    );
    assert_eq!(totals["point_status"]["closed"], 25, "{totals}");
    assert_eq!(totals["force_on_slave"].as_array().unwrap().len(), 3);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("interface.contact.json")).unwrap())
            .unwrap();
    assert_eq!(json["points"].as_array().unwrap().len(), rows.len());
    assert_eq!(json["master"], "foundation");
    let vtu = std::fs::read_to_string(out.join("interface.contact.vtu")).unwrap();
    for kind in ["9", "5"] {
        assert!(
            vtu.split("Name=\"types\"")
                .nth(1)
                .unwrap()
                .split_whitespace()
                .any(|t| t == kind),
            "VTK cell type {kind}"
        );
    }
    for body in ["punch", "foundation"] {
        let vtu = std::fs::read_to_string(out.join(format!("{body}.vtu"))).unwrap();
        for field in [
            "contact_force",
            "contact_pressure",
            "contact_gap",
            "contact_status",
        ] {
            assert!(
                vtu.contains(&format!("Name=\"{field}\"")),
                "{body}: {field}"
            );
        }
    }
}

/// The per-point pressure of a 3D run against Hertz: the sphere of
/// `cases/gmsh/3d/hertz-sphere-h0.2.json` on a rigid plane reads at its pole node (CSV
/// `pressure`) the peak pressure p0 = 14.2799 to 4.7e-2 (as the rows' own force over area in
/// `tests/gmsh_import.rs`; that test shows the error halving under refinement), and the
/// quarter model's resultant is a quarter of the load P = 31.1529.
#[test]
fn a_3d_pole_pressure_reads_hertz() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run(&case("cases/gmsh/3d/hertz-sphere-h0.2.json"), &out, 0);
    let rows = csv_rows(&out.join("ground.contact.csv"));
    let pole = rows
        .iter()
        .find(|r| num(r, "x").hypot(num(r, "y")) < 1e-12)
        .expect("a node at the pole");
    let (p0, load) = (14.2799, 31.1529);
    let error = num(pole, "pressure") / p0 - 1.0;
    assert!(error.abs() < 5e-2, "{pole:?}: {error:e}");
    // (the load to the digits given; `normal_force`, `sum -f_a . n_a` along the sphere's own
    // normals, is 0.2 % less)
    let totals = &summary(&out)["contact"]["pairs"][0];
    let resultant = totals["force_on_slave"][2].as_f64().unwrap();
    assert!((4.0 * resultant / load - 1.0).abs() < 1e-5, "{totals}");
}
