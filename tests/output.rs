//! `contact-patch run` writes `summary.json` and one `.vtu` per body; both are read back here.

mod common;

use std::process::Command;

/// The numbers inside the `<DataArray ... Name="name" ...>` element of a VTU file's `section`
/// (`Points`, `PointData`, `CellData`, `Cells`).
fn data_array(xml: &str, section: &str, name: Option<&str>) -> Vec<f64> {
    let start = xml
        .find(&format!("<{section}"))
        .unwrap_or_else(|| panic!("no <{section}>"));
    let end = start + xml[start..].find(&format!("</{section}>")).unwrap();
    let body = &xml[start..end];
    let open = match name {
        Some(n) => body
            .find(&format!("Name=\"{n}\""))
            .unwrap_or_else(|| panic!("no array {n} in {section}")),
        None => body.find("<DataArray").unwrap(),
    };
    let from = open + body[open..].find('>').unwrap() + 1;
    let to = from + body[from..].find("</DataArray>").unwrap();
    body[from..to]
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

fn attribute(xml: &str, name: &str) -> usize {
    let k = xml.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
    xml[k..k + xml[k..].find('"').unwrap()].parse().unwrap()
}

#[test]
fn vtu_and_summary_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("q9");
    let case = format!(
        "{}/cases/patch-single/q9-distorted.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["run", &case, "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["dofs"], 98);
    assert_eq!(summary["passed"], true);
    for stage in ["mesh", "assembly", "factorization", "solve", "total"] {
        assert!(
            summary["timings"][stage].as_f64().unwrap() >= 0.0,
            "timing {stage}"
        );
    }
    let body = &summary["bodies"][0];
    assert_eq!(body["element"], "Q9");
    // the exact stress is uniform, so every extreme equals it
    for (field, value) in [("stress_xx", 3.0), ("stress_yy", -10.0), ("stress_xy", 2.0)] {
        for v in body[field].as_array().unwrap() {
            assert!((v.as_f64().unwrap() - value).abs() < 1e-10, "{field}: {v}");
        }
    }

    let xml = std::fs::read_to_string(out.join("patch.vtu")).unwrap();
    assert!(xml.starts_with("<?xml") && xml.trim_end().ends_with("</VTKFile>"));
    let (points, cells) = (
        attribute(&xml, "NumberOfPoints"),
        attribute(&xml, "NumberOfCells"),
    );
    assert_eq!((points, cells), (49, 9));
    let coords = data_array(&xml, "Points", None);
    let u = data_array(&xml, "PointData", Some("displacement"));
    let nodal = data_array(&xml, "PointData", Some("stress"));
    let cell = data_array(&xml, "CellData", Some("stress"));
    let types = data_array(&xml, "Cells", Some("types"));
    let offsets = data_array(&xml, "Cells", Some("offsets"));
    assert_eq!(
        (coords.len(), u.len(), nodal.len(), cell.len()),
        (3 * points, 3 * points, 3 * points, 3 * cells)
    );
    assert!(
        types.iter().all(|&t| t == 28.0),
        "Q9 is VTK_BIQUADRATIC_QUAD"
    );
    assert_eq!(offsets.last(), Some(&(9.0 * cells as f64)));
    // the displacement read back is the exact field u = eps x (plane strain, E = 1000, nu = 0.3)
    let (e, nu) = (1000.0, 0.3);
    let (sxx, syy, sxy) = (3.0, -10.0, 2.0);
    let exx = (1.0 + nu) / e * ((1.0 - nu) * sxx - nu * syy);
    let eyy = (1.0 + nu) / e * ((1.0 - nu) * syy - nu * sxx);
    let gxy = 2.0 * (1.0 + nu) / e * sxy;
    for k in 0..points {
        let (x, y) = (coords[3 * k], coords[3 * k + 1]);
        let exact = [exx * x + 0.5 * gxy * y, 0.5 * gxy * x + eyy * y];
        for i in 0..2 {
            assert!(
                (u[3 * k + i] - exact[i]).abs() < 1e-14,
                "node {k}: {} vs {}",
                u[3 * k + i],
                exact[i]
            );
        }
    }
    for s in cell.chunks(3).chain(nodal.chunks(3)) {
        assert!(
            (s[0] - sxx).abs() < 1e-10 && (s[1] - syy).abs() < 1e-10 && (s[2] - sxy).abs() < 1e-10,
            "{s:?}"
        );
    }
}

#[test]
fn a_failed_run_keeps_the_previous_output_whole() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let case = format!(
        "{}/cases/patch-single/t3-distorted.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let bin = env!("CARGO_BIN_EXE_contact-patch");
    assert!(Command::new(bin)
        .args(["run", &case, "--out", out.to_str().unwrap()])
        .status()
        .unwrap()
        .success());
    let before = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"name\": \"x\", ").unwrap();
    let status = Command::new(bin)
        .args(["run", bad.to_str().unwrap(), "--out", out.to_str().unwrap()])
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        before
    );
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "no partial folder may remain: {names:?}");
}

/// `summary.json` of `case` (relative to the repository) after `run`.
fn summary_of(case: &str) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let case = format!("{}/{case}", env!("CARGO_MANIFEST_DIR"));
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args(["run", &case, "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn the_summary_lists_only_the_effects_the_scene_asked_for() {
    // elasticity alone: no contact section, one effect owning all the solver phases
    let s = summary_of("cases/patch-single/q4-distorted.json");
    assert!(s.get("contact").is_none());
    let effects = s["effects"].as_array().unwrap();
    assert_eq!(effects.len(), 1, "{effects:?}");
    assert_eq!(effects[0]["effect"], "elasticity");
    let t = &s["timings"];
    let phases: f64 = ["mesh", "assembly", "factorization", "solve"]
        .iter()
        .map(|k| t[k].as_f64().unwrap())
        .sum();
    assert!((effects[0]["seconds"].as_f64().unwrap() - phases).abs() <= 1e-12);
    // contact in the current configuration: elasticity, the contact pair in the case's words,
    // the geometry updates; the shares of the timed effects add up to at most the total
    let s = summary_of("cases/contact/block-on-rigid-cylinder-finite-sliding.json");
    let effects = s["effects"].as_array().unwrap();
    let names: Vec<&str> = effects
        .iter()
        .map(|e| e["effect"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["elasticity", "contact", "current contact geometry"]);
    let detail = effects[1]["detail"].as_str().unwrap();
    assert!(
        detail.contains("frictionless")
            && detail.contains("node_to_surface")
            && detail.contains("lagrange"),
        "{detail}"
    );
    let shares: f64 = effects.iter().filter_map(|e| e["share"].as_f64()).sum();
    assert!(shares > 0.0 && shares <= 1.0 + 1e-12, "{shares}");
}

/// Two outputs of one case with the same name: a body called `interface.contact` beside the pair
/// `interface` would write `interface.contact.vtu` twice. The run is refused naming the file,
/// and the previous output and a user's file beside it stay as they were.
#[test]
fn two_outputs_with_one_name_are_refused_not_written_over_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("cases/contact/coulomb-patch-slip.json"),
    )
    .unwrap()
    .replace("\"punch\"", "\"interface.contact\"");
    let case = dir.path().join("case.json");
    std::fs::write(&case, text).unwrap();
    let keep = dir.path().join("mine.txt");
    std::fs::write(&keep, "the user's").unwrap();
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_contact-patch"))
        .args([
            "run",
            case.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("would both be named 'interface.contact.vtu'"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing is moved into place");
    assert_eq!(std::fs::read_to_string(&keep).unwrap(), "the user's");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// Defect W03 (second report): under finite kinematics the `.vtu` field `stress_zz` was the
/// small-strain relation `nu (sigma_xx + sigma_yy)` (-28.912 where the neo-Hookean law gives
/// -31.028). One neo-Hookean Q4 cell under a dead top traction (0, -100) on rollers: the
/// homogeneous stretch `F = diag(l1, l2)` is exact, and every stress field written is checked
/// against the law at that stretch: `sigma = (mu (b - I) + lambda ln J I) / J` with
/// `b = diag(l1^2, l2^2)`, `J = l1 l2`, so `sigma_zz = lambda ln J / J`; equilibrium gives
/// `sigma_yy = -100 / l1` (the dead load over the current width).
#[test]
fn every_stress_field_at_finite_strain_is_the_hyperelastic_law_s() {
    let case = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/defects/s4/W03-finite-stress-zz-small-strain-formula.json");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = common::run_case(&case, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let xml = std::fs::read_to_string(out.join("b.vtu")).unwrap();
    let points = data_array(&xml, "Points", None);
    let u = data_array(&xml, "PointData", Some("displacement"));
    // the stretches from the node at (1, 1)
    let corner = (0..points.len() / 3)
        .find(|&n| points[3 * n] == 1.0 && points[3 * n + 1] == 1.0)
        .unwrap();
    let (l1, l2) = (1.0 + u[3 * corner], 1.0 + u[3 * corner + 1]);
    let (e, nu) = (1000.0f64, 0.3f64);
    let mu = e / (2.0 * (1.0 + nu));
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let j = l1 * l2;
    let expected = [
        (mu * (l1 * l1 - 1.0) + lambda * j.ln()) / j,
        (mu * (l2 * l2 - 1.0) + lambda * j.ln()) / j,
        0.0,
        lambda * j.ln() / j,
    ];
    assert!(
        (expected[1] + 100.0 / l1).abs() < 1e-9,
        "the stretch is not the law's equilibrium: {expected:?}, l1 {l1}"
    );
    assert!((expected[3] + 31.028).abs() < 1e-3, "{expected:?}");
    let nodal = data_array(&xml, "PointData", Some("stress"));
    let zz = data_array(&xml, "PointData", Some("stress_zz"));
    let cells = data_array(&xml, "CellData", Some("stress"));
    for (n, s) in nodal.chunks(3).enumerate() {
        for i in 0..3 {
            assert!(
                (s[i] - expected[i]).abs() < 1e-9,
                "node {n}: stress {s:?}, law {expected:?}"
            );
        }
        assert!(
            (zz[n] - expected[3]).abs() < 1e-9,
            "node {n}: stress_zz {}, law {}",
            zz[n],
            expected[3]
        );
    }
    for i in 0..3 {
        assert!(
            (cells[i] - expected[i]).abs() < 1e-9,
            "cell: {cells:?}, law {expected:?}"
        );
    }
}

/// Issue 38, item 9 (reactions per support set): the punch on its foundation
/// (cases/hard/slave-past-master-end.json) is held by `bottom` in y, `bottom_left` (the corner
/// node, also in `bottom`) in x, and here `bottom_left` in y too; the punch's `top_left` in x.
/// Each set summed both components over all its nodes, so `bottom_left` reported the corner's
/// y reaction 9.5496 (it belongs to `bottom`, where it was counted too: the y reactions summed
/// to 89.55 under a load of 80) and `bottom` reported the corner's x reaction 0.0736, which it
/// does not hold. Now each set reports its own components; the corner's y, held by both,
/// counts once, in `bottom` (the first support that prescribes it), and `bottom_left` lists it
/// as shared.
#[test]
fn each_support_set_reports_its_own_reaction() {
    let dir = tempfile::tempdir().unwrap();
    let source = format!(
        "{}/cases/hard/slave-past-master-end.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut case: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(source).unwrap()).unwrap();
    case["supports"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"body": "foundation", "set": "bottom_left", "y": 0.0}));
    let path = dir.path().join("case.json");
    std::fs::write(&path, case.to_string()).unwrap();
    let out = dir.path().join("out");
    let o = common::run_case(&path, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    println!("{}", s["reactions"]);
    let reactions = s["reactions"].as_array().unwrap();
    assert_eq!(reactions.len(), 3, "one entry per (body, set)");
    let of = |set: &str| reactions.iter().find(|r| r["set"] == set).unwrap();
    let (bottom, corner, punch) = (of("bottom"), of("bottom_left"), of("top_left"));
    let value = |r: &serde_json::Value, c: &str| r[c].as_f64().unwrap();
    // `bottom` holds y only and carries the whole load (pressure 10 over the width 8)
    assert_eq!(bottom["held"], serde_json::json!(["y"]));
    assert_eq!(value(bottom, "x"), 0.0);
    assert!(
        (value(bottom, "y") - 80.0).abs() <= 1e-10 * 80.0,
        "{bottom}"
    );
    assert_eq!(bottom["shared"], serde_json::json!([]));
    // `bottom_left` holds x and y; its y counts in `bottom`
    assert_eq!(corner["held"], serde_json::json!(["x", "y"]));
    assert_eq!(value(corner, "y"), 0.0);
    assert_eq!(
        corner["shared"],
        serde_json::json!([{"component": "y", "counted_in": "foundation.bottom", "nodes": 1}])
    );
    assert_eq!(punch["held"], serde_json::json!(["x"]));
    assert_eq!(value(punch, "y"), 0.0);
    // every reaction counted once: no horizontal load, and the vertical ones sum to the load
    let total = |c: &str| reactions.iter().map(|r| value(r, c)).sum::<f64>();
    assert!(total("x").abs() <= 1e-10 * 80.0, "{}", total("x"));
    assert!((total("y") - 80.0).abs() <= 1e-10 * 80.0, "{}", total("y"));
    assert!(
        value(corner, "x") != 0.0,
        "the corner holds the foundation in x"
    );
    assert!((value(corner, "x") + value(punch, "x")).abs() <= 1e-10 * 80.0);
}

/// Issue 38, item 3 (every field of the law the run used), with contact: W03's neo-Hookean
/// cell under the dead top traction (0, -100), its bottom now held by frictionless contact
/// with a rigid line y = 0 (Lagrange multipliers, node-to-surface, finite kinematics) instead
/// of rollers. The homogeneous stretch `F = diag(l1, l2)` is exact as before, so every field
/// written is checked against it: the body's stress ranges in `summary.json` (Cauchy,
/// `sigma_yy = -100 / l1`, `sigma_xx = sigma_xy = 0`), the displacement ranges, the pair's
/// total force (the dead load, 100 on the reference width 1) and its largest pressure, and per
/// point in `<pair>.contact.csv`: the force (50 a node), the tributary area of the current
/// surface (`l1 / 2`), the pressure per that area (`100 / l1 = -sigma_yy`: a true traction, as
/// `src/contact/results.rs` states), the gap (zero to round-off) and the status (closed).
#[test]
fn every_field_with_contact_at_finite_strain_is_the_law_s() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut case: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(
            root.join("tests/defects/s4/W03-finite-stress-zz-small-strain-formula.json"),
        )
        .unwrap(),
    )
    .unwrap();
    case["supports"] = serde_json::json!([{"body": "b", "set": "bottom_left", "x": 0.0}]);
    case["physics"]["contact_geometry"] = serde_json::json!("current");
    case["contact"] = serde_json::json!([{
        "name": "ground",
        "slave": {"body": "b", "set": "bottom"},
        "master": {"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}},
        "discretization": {"kind": "node_to_surface", "passes": 1},
        "enforcement": {"kind": "lagrange"}
    }]);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    std::fs::write(&path, serde_json::to_string(&case).unwrap()).unwrap();
    let out = dir.path().join("out");
    let o = common::run_case(&path, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let body = &summary["bodies"][0];
    let range = |field: &str| -> [f64; 2] {
        let r = body[field]
            .as_array()
            .unwrap_or_else(|| panic!("{field}: {body}"));
        [r[0].as_f64().unwrap(), r[1].as_f64().unwrap()]
    };
    // the stretches: u_x at x = 1 and u_y at y = 1 (the bottom rests on the line at y = 0)
    let (ux, uy) = (range("u_x"), range("u_y"));
    let (l1, l2) = (1.0 + ux[1], 1.0 + uy[0]);
    assert_eq!(ux[0], 0.0, "{body}");
    assert!(uy[1].abs() < 1e-9, "the bottom sits on the line: {body}");
    let (e, nu) = (1000.0f64, 0.3f64);
    let (mu, lambda) = (
        e / (2.0 * (1.0 + nu)),
        e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
    );
    let j = l1 * l2;
    let law = [
        (mu * (l1 * l1 - 1.0) + lambda * j.ln()) / j,
        (mu * (l2 * l2 - 1.0) + lambda * j.ln()) / j,
    ];
    // W03's stretch (the rollers' answer), and the law's equilibrium with the dead load
    assert!(
        (l1 - 1.03762).abs() < 1e-5 && (l2 - 0.91573).abs() < 1e-5,
        "{l1} {l2}"
    );
    assert!(
        law[0].abs() < 1e-9 && (law[1] + 100.0 / l1).abs() < 1e-9,
        "{law:?}"
    );
    for (field, value) in [
        ("stress_xx", law[0]),
        ("stress_yy", law[1]),
        ("stress_xy", 0.0),
    ] {
        for v in range(field) {
            assert!((v - value).abs() < 1e-9, "{field}: {v}, law {value}");
        }
    }
    let contact = &summary["contact"];
    let total = contact["total_force"].as_array().unwrap();
    assert!(total[0].as_f64().unwrap().abs() < 1e-9, "{contact}");
    assert!(
        (total[1].as_f64().unwrap() - 100.0).abs() < 1e-9,
        "{contact}"
    );
    let pressure = 100.0 / l1;
    assert!(
        (contact["max_pressure"].as_f64().unwrap() - pressure).abs() < 1e-9,
        "{contact}"
    );
    let text = std::fs::read_to_string(out.join("ground.contact.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |row: &[&str], name: &str| -> f64 {
        let k = header.iter().position(|h| *h == name).unwrap();
        row[k].parse().unwrap_or_else(|_| panic!("{name}: {row:?}"))
    };
    let mut points = 0;
    for line in lines {
        let row: Vec<&str> = line.split(',').collect();
        let status = header.iter().position(|h| *h == "status").unwrap();
        assert_eq!(row[status], "closed", "{line}");
        assert!((column(&row, "force_y") - 50.0).abs() < 1e-9, "{line}");
        assert!(column(&row, "force_x").abs() < 1e-9, "{line}");
        assert!((column(&row, "pressure") - pressure).abs() < 1e-9, "{line}");
        assert!(column(&row, "gap").abs() < 1e-12, "{line}");
        assert!((column(&row, "area") - l1 / 2.0).abs() < 1e-12, "{line}");
        points += 1;
    }
    assert_eq!(points, 2);
}
