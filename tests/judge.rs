//! A harness for any contact code (issue 17, items 1-2): `export` writes meshes other codes
//! read (checked by reading the Gmsh file back with the `mshio` crate), and `judge` applies a
//! case's checks to outside `.vtu` results. The round trip: our own results, written as `.vtu`
//! and judged through the outside-results path, give the verdicts and errors of the direct run.

use contact_patch::harness::judge::{judge, load_results, Results, DEFAULT_MATCH_SHARE};
use contact_patch::io::export::export_case;
use contact_patch::io::output::write_run;
use contact_patch::io::paths::{OutputFolder, ReportFolder};
use contact_patch::run::run_case;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_contact-patch");

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every case of the single-body catalogue, the rigid-obstacle contact cases (line, cylinder,
/// Hertz profile, the penalty block of the cross-check with its penetration check), the contact
/// patch test on meshes A and C, a tied patch test (whole traction) and the frictional slip
/// patch test.
fn round_trip_cases() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(root().join("cases/patch-single"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    cases.sort();
    for c in [
        "cases/contact/signorini-block-on-rigid-line.json",
        "cases/contact/block-on-rigid-cylinder-lagrange.json",
        "cases/patch/patch-A-nu0.3.json",
        "cases/patch/patch-C-nu0.4.json",
        "cases/contact/hertz-profile.json",
        "cases/tied/tied-C-shear.json",
        "cases/contact/coulomb-patch-slip.json",
        // penalty: a nonzero penetration for max_penetration (from contact_gap)
        "crosscheck/cases/contact/signorini-flat-penalty-q4.json",
        "cases/convergence/cantilever-q9.json",
    ] {
        cases.push(root().join(c));
    }
    cases
}

#[test]
fn our_results_judged_as_outside_results_give_the_direct_verdicts() {
    let tmp = tempfile::tempdir().unwrap();
    let mut judged_checks = 0;
    let mut judged_contact_checks = 0;
    for case in round_trip_cases() {
        let direct = run_case(&case, &mut |_| {}).unwrap();
        let name = direct.model.name.clone();
        let folder = OutputFolder::new(&tmp.path().join(&name)).unwrap();
        write_run(&folder, &direct).unwrap();
        let results = load_results(&direct.model, folder.path()).unwrap();
        let j = judge(&direct.model, &results, DEFAULT_MATCH_SHARE).unwrap();
        assert_eq!(j.nodes, direct.model.dof_count / 2, "{name}");
        assert_eq!(
            j.largest_distance, 0.0,
            "{name}: coordinates are written exactly"
        );
        // every direct check, the contact checks included (from the body files' contact_force,
        // contact_pressure and contact_gap arrays), is judged with the same verdict and error
        let mut judged = j.checks.iter();
        for d in &direct.checks {
            if d.check.starts_with("the contact solve converged") {
                continue;
            }
            let o = judged
                .next()
                .unwrap_or_else(|| panic!("{name}: {} not judged", d.check));
            // a check's words carry its measured value (a reaction's round-off differs)
            let words = |c: &str| c.split(" = ").next().unwrap().to_string();
            assert!(
                o.check.starts_with(&words(&d.check)),
                "{name}: {} vs {}",
                o.check,
                d.check
            );
            assert_eq!(o.passed, d.passed, "{name}: {}", d.check);
            // u is read back bit for bit; reactions K u - f - f_c are summed in another order,
            // so the out-of-balance force (round-off of the solve, relative to the load) agrees
            // to 1e-12 absolute; the other errors to 1e-12 relative (1e-15 absolute below 1e-3)
            let scale = d.error.abs().max(1e-300);
            let balance = d.check.starts_with("force balance");
            assert!(
                balance && (o.error - d.error).abs() <= 1e-12
                    || (o.error - d.error).abs() <= 1e-12 * scale.max(1e-3),
                "{name}: {}: judged {:e} vs direct {:e}",
                d.check,
                o.error,
                d.error
            );
            judged_checks += 1;
            if !direct.model.contact.is_empty() && is_contact_check(&d.check) {
                judged_contact_checks += 1;
            }
        }
        assert!(
            j.not_judged.is_empty(),
            "{name}: {:?}",
            j.not_judged.iter().map(|n| &n.why).collect::<Vec<_>>()
        );
        // the rest are the results' own stress-field checks, which pass where the direct
        // uniform-stress check does (nodal averages of a uniform field are that field)
        let uniform = direct
            .checks
            .iter()
            .find(|c| c.check.starts_with("uniform stress"));
        for extra in judged {
            assert!(
                extra.check.contains("results' own nodal 'stress'"),
                "{name}: {}",
                extra.check
            );
            assert_eq!(
                extra.passed,
                uniform.unwrap().passed,
                "{name}: {} error {:e}",
                extra.check,
                extra.error
            );
        }
    }
    println!("{judged_checks} checks compared, {judged_contact_checks} of them contact checks");
    assert!(judged_checks >= 20, "{judged_checks} checks compared");
    assert!(
        judged_contact_checks >= 15,
        "{judged_contact_checks} contact checks compared"
    );
}

fn is_contact_check(text: &str) -> bool {
    [
        "contact pressure",
        "force balance",
        "total contact force",
        "max contact pressure",
        "largest penetration",
    ]
    .iter()
    .any(|w| text.contains(w))
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

#[test]
fn exported_gmsh_file_reads_back_with_mshio() {
    let tmp = tempfile::tempdir().unwrap();
    let out = ReportFolder::new(tmp.path()).unwrap();
    for case in [
        "cases/patch/patch-C-nu0.3.json",
        "cases/patch-single/t6-distorted.json",
    ] {
        let (folder, files) = export_case(&root().join(case), &out).unwrap();
        let model = contact_patch::model::admit::load(&root().join(case)).unwrap();
        let msh_path = folder.path().join(format!("{}.msh", model.name));
        assert!(files.contains(&format!("{}.msh", model.name)));
        // the sidecar names every point field judge reads
        let sidecar: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(folder.path().join(format!("{}.json", model.name))).unwrap(),
        )
        .unwrap();
        let fields: Vec<&str> = sidecar["results"]["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f["name"].as_str().unwrap())
            .collect();
        assert_eq!(
            fields,
            [
                "displacement",
                "stress",
                "contact_force",
                "contact_pressure",
                "contact_gap",
                "contact_status"
            ]
        );
        let bytes = std::fs::read(&msh_path).unwrap();
        let msh = mshio::parse_msh_bytes(bytes.as_slice()).unwrap();
        assert_eq!(msh.header.version, 4.1);
        let nodes: usize = model.bodies.iter().map(|b| b.mesh.nodes.len()).sum();
        assert_eq!(msh.total_node_count(), nodes, "{case}");
        let ents = msh.data.entities.as_ref().unwrap();
        assert_eq!(ents.surfaces.len(), model.bodies.len());
        let facet_sets: usize = model.bodies.iter().map(|b| b.mesh.facet_sets.len()).sum();
        assert_eq!(ents.curves.len(), facet_sets, "{case}");
        // node coordinates, tag by tag
        let data = msh.data.nodes.as_ref().unwrap();
        for (b, block) in model.bodies.iter().zip(&data.node_blocks) {
            for (n, p) in block.nodes.iter().enumerate() {
                assert_eq!([p.x, p.y], b.mesh.nodes[n], "{case}");
            }
        }
        // cells and facets, by element type
        let counts = msh.count_element_types();
        let cells: usize = model.bodies.iter().map(|b| b.mesh.cell_count()).sum();
        let facets: usize = model
            .bodies
            .iter()
            .flat_map(|b| b.mesh.facet_sets.values())
            .map(Vec::len)
            .sum();
        let element_cells: usize = counts
            .iter()
            .filter(|(t, _)| {
                matches!(
                    t,
                    mshio::ElementType::Qua4
                        | mshio::ElementType::Qua9
                        | mshio::ElementType::Tri3
                        | mshio::ElementType::Tri6
                )
            })
            .map(|(_, n)| n)
            .sum();
        let element_lines: usize = counts
            .iter()
            .filter(|(t, _)| matches!(t, mshio::ElementType::Lin2 | mshio::ElementType::Lin3))
            .map(|(_, n)| n)
            .sum();
        assert_eq!(element_cells, cells, "{case}");
        assert_eq!(element_lines, facets, "{case}");
        // every node of a named node set is a point entity in that set's group
        let text = String::from_utf8(bytes).unwrap();
        let names: Vec<&str> = text
            .split("$PhysicalNames\n")
            .nth(1)
            .unwrap()
            .split("$EndPhysicalNames")
            .next()
            .unwrap()
            .lines()
            .skip(1)
            .collect();
        // every physical name is unique (readers such as meshio key the groups by name alone)
        let mut unique: Vec<&str> = names.iter().map(|l| l.split_once('"').unwrap().1).collect();
        unique.sort();
        let all = unique.len();
        unique.dedup();
        assert_eq!(
            unique.len(),
            all,
            "{case}: a physical name used twice: {names:?}"
        );
        for b in &model.bodies {
            for (set, nodes) in b.mesh.node_sets.iter().filter(|(s, _)| *s != "all") {
                let line = names
                    .iter()
                    .find(|l| {
                        l.starts_with("0 ") && l.ends_with(&format!("\"{}/{set}/nodes\"", b.name))
                    })
                    .unwrap_or_else(|| panic!("{case}: no group for {}/{set}", b.name));
                let tag: i32 = line.split(' ').nth(1).unwrap().parse().unwrap();
                let in_group = ents
                    .points
                    .iter()
                    .filter(|p| p.physical_tags.contains(&tag))
                    .count();
                assert_eq!(in_group, nodes.len(), "{case}: {}/{set}", b.name);
            }
        }
    }
}

/// The single-body Q4 patch test run by us, its `.vtu` rewritten by `edit`.
fn edited_results(tmp: &Path, edit: impl Fn(&str) -> String) -> PathBuf {
    let case = "cases/patch-single/q4-distorted.json";
    let out = tmp.join("run");
    let o = run(&["run", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let text = std::fs::read_to_string(out.join("patch.vtu")).unwrap();
    let path = tmp.join("edited.vtu");
    std::fs::write(&path, edit(&text)).unwrap();
    path
}

#[test]
fn a_wrong_displacement_fails_with_its_error_and_a_junit_failure() {
    let tmp = tempfile::tempdir().unwrap();
    // the displacement array: scale every x by 1.01 (a 1% error in e_xx)
    let results = edited_results(tmp.path(), |t| {
        edit_array(t, "displacement", |v| vec![v[0] * 1.01, v[1], v[2]])
    });
    let junit = tmp.path().join("judge.xml");
    let o = run(&[
        "judge",
        "cases/patch-single/q4-distorted.json",
        results.to_str().unwrap(),
        "--junit",
        junit.to_str().unwrap(),
    ]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(1), "{s}");
    assert!(
        s.contains("FAIL uniform stress [3.0, -10.0, 2.0] (error"),
        "{s}"
    );
    assert!(s.contains("FAIL relative L2 displacement error"), "{s}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let failures: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("failure"))
        .collect();
    assert!(failures.len() >= 2, "{xml}");
    assert!(
        failures
            .iter()
            .all(|f| f.attribute("message").unwrap().contains("> tol 1.0e-10")),
        "{xml}"
    );
}

#[test]
fn judge_refuses_results_it_cannot_use_and_says_how_to_fix_them() {
    let tmp = tempfile::tempdir().unwrap();
    let case = "cases/patch-single/q4-distorted.json";
    let renamed = edited_results(tmp.path(), |t| {
        t.replace("Name=\"displacement\"", "Name=\"u\"")
    });
    let o = run(&["judge", case, renamed.to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(2), "{s}");
    assert!(
        s.contains("no point field 'displacement' (the file has: stress, stress_zz, u)"),
        "{s}"
    );
    assert!(s.contains("u.name = \"displacement\""), "{s}");
    // a node moved by 1e-3: no point within the matching distance
    let moved = edited_results(tmp.path(), |t| {
        t.replacen("<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n0 0 0", "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n0.001 0 0", 1)
    });
    let o = run(&["judge", case, moved.to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(2), "{s}");
    assert!(
        s.contains("node 0 of body 'patch' at (0, 0)") && s.contains("1.000e-3 away"),
        "{s}"
    );
    assert!(s.contains("--match-tol"), "{s}");
    // a node merely off its point gets the general hint, which names the reference coordinates
    assert!(
        !s.contains("deformed positions") && s.contains("(not X + u)"),
        "{s}"
    );
    // ... which a looser matching distance accepts
    let o = run(&[
        "judge",
        case,
        moved.to_str().unwrap(),
        "--match-tol",
        "1e-3",
    ]);
    assert!(say(&o).contains("largest distance 1.000e-3"), "{}", say(&o));
    // the points written at the deformed positions X + u (issue 42, item 7): the hint says so
    let points_tag =
        "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    let deformed = edited_results(tmp.path(), |t| {
        let rows = |text: &str| -> Vec<Vec<f64>> {
            text.trim()
                .lines()
                .map(|l| l.split(' ').map(|w| w.parse().unwrap()).collect())
                .collect()
        };
        let (_, rest) = t.split_once("Name=\"displacement\"").unwrap();
        let u = rows(
            rest.split_once('>')
                .unwrap()
                .1
                .split_once("</DataArray>")
                .unwrap()
                .0,
        );
        let (head, rest) = t.split_once(points_tag).unwrap();
        let (points, tail) = rest.split_once("</DataArray>").unwrap();
        let moved: Vec<String> = rows(points)
            .iter()
            .zip(&u)
            .map(|(p, u)| format!("{} {} {}", p[0] + u[0], p[1] + u[1], p[2]))
            .collect();
        format!("{head}{points_tag}{}\n</DataArray>{tail}", moved.join("\n"))
    });
    let o = run(&["judge", case, deformed.to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(2), "{s}");
    assert!(
        s.contains("the results' points are the deformed positions X + u")
            && s.contains("reference coordinates X"),
        "{s}"
    );
    // numbers as text in an array said to be binary (base64)
    let binary = edited_results(tmp.path(), |t| {
        t.replacen("format=\"ascii\"", "format=\"binary\"", 1)
    });
    let o = run(&["judge", case, binary.to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(2), "{s}");
    assert!(
        s.contains("<Points>: format=\"binary\": not base64")
            && s.contains("for numbers as text write format=\"ascii\""),
        "{s}"
    );
    // a folder without the body's file
    let o = run(&["judge", case, tmp.path().to_str().unwrap()]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(2), "{s}");
    assert!(
        s.contains("the folder holds no") && s.contains("patch.vtu"),
        "{s}"
    );
}

#[test]
fn one_file_for_two_bodies_is_refused_where_their_displacements_differ() {
    // two bodies meet at an interface; in one file the coincident points are ambiguous as soon
    // as the two sides carry different displacements
    let tmp = tempfile::tempdir().unwrap();
    let case = root().join("cases/patch/patch-C-nu0.3.json");
    let direct = run_case(&case, &mut |_| {}).unwrap();
    let folder = OutputFolder::new(&tmp.path().join("run")).unwrap();
    write_run(&folder, &direct).unwrap();
    let Results::PerBody(files) = load_results(&direct.model, folder.path()).unwrap() else {
        panic!("a folder gives one file per body");
    };
    let mut shared = files[0].clone();
    for f in &files[1..] {
        shared.grid.points.extend(&f.grid.points);
        let d = shared.grid.fields.get_mut("displacement").unwrap();
        let mut other = f.grid.fields["displacement"].values.clone();
        // the second body moved rigidly by 1e-3 in x
        for k in (0..other.len()).step_by(3) {
            other[k] += 1e-3;
        }
        d.values.extend(other);
    }
    shared.grid.fields.retain(|k, _| k == "displacement");
    let e = judge(&direct.model, &Results::Shared(shared), DEFAULT_MATCH_SHARE)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("carry different displacements") && e.contains("<body name>.vtu"),
        "{e}"
    );
}

/// The direct sweep's cell of `case` with node-to-surface, one pass, the punch slave, and the
/// enforcement method `enforcement`.
fn direct_cell(case: &str, enforcement: &str) -> contact_patch::harness::Cell {
    contact_patch::harness::run_sweep(&root().join(case), &mut |_| {})
        .unwrap()
        .into_iter()
        .find(|c| {
            c.discretization == "node_to_surface"
                && c.passes == Some(1)
                && c.slave.as_deref() == Some("punch")
                && c.enforcement == enforcement
        })
        .unwrap()
}

#[test]
fn table_of_outside_results_matches_the_direct_cells_of_the_same_method() {
    // our own runs of the cases as written (node-to-surface, one pass, slave punch, Lagrange)
    // stand in for another code; `table --results` must find the stress errors and verdicts of
    // the direct table's cells of that method
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    std::fs::create_dir(&results).unwrap();
    let cases = [
        "cases/patch/patch-A-nu0.3.json",
        "cases/patch/patch-C-nu0.3.json",
    ];
    for case in cases {
        let direct = run_case(&root().join(case), &mut |_| {}).unwrap();
        let folder = OutputFolder::new(&results.join(&direct.model.name)).unwrap();
        write_run(&folder, &direct).unwrap();
    }
    let out = tmp.path().join("tables");
    let mut args = vec!["table"];
    args.extend(cases);
    args.extend(["--results", results.to_str().unwrap(), "--code", "stand-in"]);
    args.extend(["--out", out.to_str().unwrap()]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let table: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("patch-table.json")).unwrap())
            .unwrap();
    let cells = table.as_array().unwrap();
    assert_eq!(cells.len(), 2);
    let mut verdicts = Vec::new();
    for (case, cell) in cases.iter().zip(cells) {
        assert_eq!(cell["enforcement"], "stand-in");
        assert_eq!(cell["discretization"], "outside");
        let same = direct_cell(case, "lagrange");
        let got = cell["stress_error"].as_f64().unwrap();
        let want = same.stress_error.unwrap();
        assert!(
            (got - want).abs() <= 1e-12 * want.max(1e-3),
            "{case}: {got:e} vs {want:e}"
        );
        // the contact measures from the body files' contact_pressure and contact_force
        for (key, want) in [
            ("pressure_error", same.pressure_error.unwrap()),
            ("load_error", same.load_error.unwrap()),
        ] {
            let got = cell[key].as_f64().unwrap();
            assert!(
                (got - want).abs() <= 1e-12 * want.max(1e-3),
                "{case}: {key} {got:e} vs {want:e}"
            );
        }
        let balance = cell["force_balance"].as_f64().unwrap();
        assert!(
            (balance - same.force_balance.unwrap()).abs() <= 1e-12,
            "{case}: force balance {balance:e}"
        );
        assert!(
            cell["note"]
                .as_str()
                .unwrap()
                .contains("the contact pressure, the total contact force and the force balance"),
            "{}",
            cell["note"]
        );
        assert_eq!(cell["verdict"], same.verdict.as_str(), "{case}");
        verdicts.push(same.verdict.clone());
    }
    // the seed's verdicts: mesh A passes, mesh C one-pass fails
    assert_eq!(verdicts, ["pass", "fail"]);
    // the report states only what was measured: no seed row of `?` judged "NO", no two-pass
    // claim "confirmed" from an empty table, no kappa, no times of 0.00 (issue 42, item 3)
    let report = std::fs::read_to_string(out.join("patch-table.md")).unwrap();
    for unmeasured in [
        "matches the seed",
        "confirmed",
        "kappa = ",
        " 0.00 |",
        "| ? |",
    ] {
        assert!(
            !report.contains(unmeasured),
            "the outside table claims {unmeasured:?}:\n{report}"
        );
    }
    for stated in [
        "No cell of this table uses the seed's method",
        "No two-pass cell of meshes B or C is in this table",
        "No cell was solved here",
        "2 cells judged.",
    ] {
        assert!(report.contains(stated), "no {stated:?}:\n{report}");
    }
    // the times file: `-` where nothing was timed
    let times = std::fs::read_to_string(out.join("patch-table.times.csv")).unwrap();
    let rows: Vec<&str> = times.lines().filter(|l| l.contains(",stand-in,")).collect();
    assert_eq!(rows.len(), 2, "{times}");
    for row in rows {
        assert!(row.ends_with(",-"), "a time where nothing was timed: {row}");
    }
    assert!(!say(&o).contains("Taylor 2004 (seed)"), "{}", say(&o));
    // a missing results folder is refused before any work
    let o = run(&[
        "table",
        cases[0],
        "--results",
        "no/such/folder",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", say(&o));
    assert!(say(&o).contains("--results no/such/folder: no such folder"));
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

/// Without the array `name` (the whole `<DataArray>` element).
fn drop_array(text: &str, name: &str) -> String {
    let tag = format!("<DataArray type=\"Float64\" Name=\"{name}\"");
    let start = text.find(&tag).unwrap();
    let end = start + text[start..].find("</DataArray>").unwrap() + "</DataArray>".len();
    format!("{}{}", &text[..start], &text[end..])
}

#[test]
fn a_perturbed_contact_pressure_fails_its_check_and_missing_contact_fields_are_named() {
    let tmp = tempfile::tempdir().unwrap();
    let case = "cases/patch/patch-A-nu0.3.json";
    let out = tmp.path().join("run");
    let o = run(&["run", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let model = contact_patch::model::admit::load(&root().join(case)).unwrap();
    let bodies: Vec<String> = model.bodies.iter().map(|b| b.name.clone()).collect();
    let copy = |to: &str, edit: &dyn Fn(&str) -> String| {
        let dir = tmp.path().join(to);
        std::fs::create_dir(&dir).unwrap();
        for b in &bodies {
            let text = std::fs::read_to_string(out.join(format!("{b}.vtu"))).unwrap();
            std::fs::write(dir.join(format!("{b}.vtu")), edit(&text)).unwrap();
        }
        dir
    };
    let judge_of = |dir: &Path, junit: &Path| {
        run(&[
            "judge",
            case,
            dir.to_str().unwrap(),
            "--junit",
            junit.to_str().unwrap(),
        ])
    };
    // as written: every check passes, the contact ones judged from the contact arrays
    let junit = tmp.path().join("as-written.xml");
    let o = judge_of(&copy("as-written", &|t| t.to_string()), &junit);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(0), "{s}");
    assert!(
        s.contains("pass contact pressure of 'contact' against the exact stress (error")
            || s.contains("pass contact pressure of"),
        "{s}"
    );
    assert!(s.contains("[from the results' 'contact_pressure']"), "{s}");
    assert!(s.contains("[from the results' 'contact_force']"), "{s}");
    // the pressure 5% high at every node: the pressure check fails by 0.05 of the exact
    // pressure, with a JUnit failure; the forces (contact_force) still balance
    let junit = tmp.path().join("perturbed.xml");
    let o = judge_of(
        &copy("perturbed", &|t| {
            edit_array(t, "contact_pressure", |v| vec![v[0] * 1.05])
        }),
        &junit,
    );
    let s = say(&o);
    assert_eq!(o.status.code(), Some(1), "{s}");
    let line = s
        .lines()
        .find(|l| l.contains("contact pressure of"))
        .unwrap_or_else(|| panic!("{s}"));
    assert!(line.trim_start().starts_with("FAIL"), "{line}");
    let error: f64 = line
        .split("(error ")
        .nth(1)
        .and_then(|r| r.split(',').next())
        .and_then(|e| e.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert!((error - 0.05).abs() < 1e-9, "{line}");
    assert!(
        s.lines()
            .any(|l| l.contains("force balance") && l.trim_start().starts_with("pass")),
        "{s}"
    );
    let xml = std::fs::read_to_string(&junit).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let failures: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("failure"))
        .collect();
    assert_eq!(failures.len(), 1, "{xml}");
    assert!(
        failures[0]
            .parent()
            .unwrap()
            .attribute("name")
            .unwrap()
            .contains("contact pressure"),
        "{xml}"
    );
    // no contact arrays: both contact checks are listed as not judged, naming the fields
    let o = judge_of(
        &copy("no-contact-fields", &|t| {
            drop_array(&drop_array(t, "contact_pressure"), "contact_force")
        }),
        &tmp.path().join("missing.xml"),
    );
    let s = say(&o);
    assert_eq!(o.status.code(), Some(0), "{s}");
    assert!(
        s.contains("field 'contact_pressure': missing")
            && s.contains("field 'contact_force': missing"),
        "{s}"
    );
    let skipped = s.lines().filter(|l| l.contains("not judged")).count();
    assert!(skipped >= 2, "{s}");
    assert!(
        s.contains("a 'contact_pressure' or 'contact_force' point field"),
        "{s}"
    );
}

// ---------------------------------------------------------------------------------------------
// Issue 42: the encodings VTK writes, names in any case, the export folder alone, and the force
// balance of a current-geometry solution.

/// How [`rewrite_vtu`] writes a file's arrays.
#[derive(Clone, Copy, Debug)]
struct Encoding {
    /// `None`: inline base64 (`format="binary"`); `Some(raw)`: `<AppendedData>`, raw or base64.
    appended: Option<bool>,
    /// `header_type="UInt64"` (else the default UInt32).
    header64: bool,
    /// `compressor="vtkZLibDataCompressor"`, in blocks of 256 bytes (the last one partial or
    /// full, as VTK writes it).
    zlib: bool,
    big_endian: bool,
}

const ENCODINGS: &[Encoding] = &[
    Encoding {
        appended: None,
        header64: false,
        zlib: false,
        big_endian: false,
    },
    Encoding {
        appended: None,
        header64: true,
        zlib: false,
        big_endian: false,
    },
    Encoding {
        appended: None,
        header64: false,
        zlib: true,
        big_endian: false,
    },
    Encoding {
        appended: None,
        header64: true,
        zlib: true,
        big_endian: true,
    },
    Encoding {
        appended: Some(true),
        header64: false,
        zlib: false,
        big_endian: false,
    },
    Encoding {
        appended: Some(true),
        header64: true,
        zlib: false,
        big_endian: false,
    },
    Encoding {
        appended: Some(true),
        header64: false,
        zlib: true,
        big_endian: false,
    },
    Encoding {
        appended: Some(false),
        header64: true,
        zlib: true,
        big_endian: false,
    },
];

/// The value of attribute `name` in the start tag `head`.
fn attribute<'a>(head: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = head.find(&key)? + key.len();
    Some(&head[start..start + head[start..].find('"')?])
}

/// The `.vtu` text our tool writes rewritten as VTK writes binary files (a small writer of the
/// VTK XML format, `vtkXMLWriter`'s layout): every array's numbers as bytes of its `type` in
/// the chosen byte order, after a header of the array's length (or, compressed, of `[blocks,
/// block size, last block size, compressed sizes]`), base64-encoded inline or appended; and
/// every point field's name upper-cased.
fn rewrite_vtu(text: &str, e: Encoding) -> Vec<u8> {
    use base64::Engine as _;
    use std::io::Write as _;
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    let int = |v: usize| -> Vec<u8> {
        match (e.header64, e.big_endian) {
            (true, false) => (v as u64).to_le_bytes().to_vec(),
            (true, true) => (v as u64).to_be_bytes().to_vec(),
            (false, false) => (v as u32).to_le_bytes().to_vec(),
            (false, true) => (v as u32).to_be_bytes().to_vec(),
        }
    };
    let mut out = String::new();
    let mut appended: Vec<u8> = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("<DataArray") {
        out.push_str(&rest[..i]);
        let gt = i + rest[i..].find('>').unwrap();
        let close = gt + rest[gt..].find("</DataArray>").unwrap();
        let head = &rest[i..gt];
        let words = rest[gt + 1..close].split_ascii_whitespace();
        let ty = attribute(head, "type").unwrap();
        let mut data: Vec<u8> = Vec::new();
        for w in words {
            let mut b = match ty {
                "Float64" => w.parse::<f64>().unwrap().to_le_bytes().to_vec(),
                "Float32" => w.parse::<f32>().unwrap().to_le_bytes().to_vec(),
                "Int64" => w.parse::<i64>().unwrap().to_le_bytes().to_vec(),
                "Int32" => w.parse::<i32>().unwrap().to_le_bytes().to_vec(),
                "UInt32" => w.parse::<u32>().unwrap().to_le_bytes().to_vec(),
                "UInt8" => vec![w.parse::<u8>().unwrap()],
                other => panic!("type {other} not written by the tool"),
            };
            if e.big_endian {
                b.reverse();
            }
            data.extend(b);
        }
        let (header, body) = if e.zlib {
            const BLOCK: usize = 256;
            let blocks: Vec<Vec<u8>> = data
                .chunks(BLOCK)
                .map(|c| {
                    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), Default::default());
                    z.write_all(c).unwrap();
                    z.finish().unwrap()
                })
                .collect();
            let mut h = int(blocks.len());
            h.extend(int(BLOCK));
            h.extend(int(data.len() % BLOCK));
            for b in &blocks {
                h.extend(int(b.len()));
            }
            (h, blocks.concat())
        } else {
            (int(data.len()), data)
        };
        let mut head = head.to_string();
        if let Some(name) = attribute(&head, "Name") {
            if !["connectivity", "offsets", "types"].contains(&name) {
                head = head.replace(
                    &format!("Name=\"{name}\""),
                    &format!("Name=\"{}\"", name.to_uppercase()),
                );
            }
        }
        let content = match e.appended {
            None => {
                head = head.replace("format=\"ascii\"", "format=\"binary\"");
                b64(&header) + &b64(&body)
            }
            Some(raw) => {
                head = head.replace(
                    "format=\"ascii\"",
                    &format!("format=\"appended\" offset=\"{}\"", appended.len()),
                );
                if raw {
                    appended.extend(&header);
                    appended.extend(&body);
                } else {
                    appended.extend((b64(&header) + &b64(&body)).into_bytes());
                }
                String::new()
            }
        };
        out.push_str(&format!("{head}>{content}</DataArray>"));
        rest = &rest[close + "</DataArray>".len()..];
    }
    out.push_str(rest);
    let root = "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">";
    assert!(out.contains(root), "the tool's root element changed");
    let out = out.replace(
        root,
        &format!(
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{}\" header_type=\"{}\"{}>",
            if e.big_endian { "BigEndian" } else { "LittleEndian" },
            if e.header64 { "UInt64" } else { "UInt32" },
            if e.zlib { " compressor=\"vtkZLibDataCompressor\"" } else { "" }
        ),
    );
    let (body, tail) = out.split_at(out.rfind("</VTKFile>").unwrap());
    let mut bytes = body.as_bytes().to_vec();
    if let Some(raw) = e.appended {
        bytes.extend(
            format!(
                "<AppendedData encoding=\"{}\">\n   _",
                if raw { "raw" } else { "base64" }
            )
            .bytes(),
        );
        bytes.extend(&appended);
        bytes.extend(b"\n</AppendedData>\n");
    }
    bytes.extend(tail.as_bytes());
    bytes
}

/// The verdict lines of `judge`'s output (field uses, checks, the count), without the first
/// line, which names the results' path.
fn verdict_lines(o: &Output) -> Vec<String> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .skip(1)
        .map(String::from)
        .collect()
}

/// `run` of the case `case` into `dir`; the body files it wrote.
fn run_into(case: &str, dir: &Path) -> Vec<PathBuf> {
    let o = run(&["run", case, "--out", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let model = contact_patch::model::admit::load(&root().join(case)).unwrap();
    model
        .bodies
        .iter()
        .map(|b| dir.join(format!("{}.vtu", b.name)))
        .collect()
}

#[test]
fn results_in_every_vtk_encoding_with_upper_case_names_give_the_ascii_verdicts() {
    let tmp = tempfile::tempdir().unwrap();
    // one body with a stress field; two bodies with the contact fields
    for case in [
        "cases/patch-single/q4-distorted.json",
        "cases/patch/patch-A-nu0.3.json",
    ] {
        let ascii = tmp.path().join("ascii");
        let files = run_into(case, &ascii);
        let original = run(&["judge", case, ascii.to_str().unwrap()]);
        assert_eq!(original.status.code(), Some(0), "{}", say(&original));
        let expected = verdict_lines(&original);
        assert!(expected.iter().any(|l| l.contains("pass uniform stress")));
        for (k, &e) in ENCODINGS.iter().enumerate() {
            let dir = tmp.path().join(format!("encoding-{k}"));
            std::fs::create_dir_all(&dir).unwrap();
            for f in &files {
                let text = std::fs::read_to_string(f).unwrap();
                let bytes = rewrite_vtu(&text, e);
                let seen = String::from_utf8_lossy(&bytes);
                assert!(!seen.contains("format=\"ascii\""), "{e:?}");
                assert!(seen.contains("Name=\"DISPLACEMENT\""), "{e:?}");
                assert!(!seen.contains("Name=\"displacement\""), "{e:?}");
                std::fs::write(dir.join(f.file_name().unwrap()), bytes).unwrap();
            }
            let o = run(&["judge", case, dir.to_str().unwrap()]);
            assert_eq!(o.status.code(), Some(0), "{case} {e:?}: {}", say(&o));
            // the same verdicts, errors and measured values, digit for digit
            assert_eq!(verdict_lines(&o), expected, "{case} {e:?}: {}", say(&o));
        }
    }
}

#[test]
fn judge_takes_the_export_folder_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let export = tmp.path().join("export");
    // a case of block meshes with contact, and one meshed from a Gmsh file (written into the
    // sidecar as an explicit mesh with its physical groups as node and facet sets)
    for (case, name) in [
        ("cases/patch/patch-A-nu0.3.json", "patch-A-nu0.3"),
        ("cases/gmsh/patch-q4.json", "patch-q4"),
    ] {
        let o = run(&["export", case, "--out", export.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0), "{}", say(&o));
        let results = tmp.path().join(format!("results-{name}"));
        run_into(case, &results);
        let direct = run(&["judge", case, results.to_str().unwrap()]);
        assert_eq!(direct.status.code(), Some(0), "{}", say(&direct));
        // from a folder where the case file the sidecar records does not exist: the export
        // folder, and its sidecar, are enough
        let folder = export.join(name);
        let sidecar = folder.join(format!("{name}.json"));
        let elsewhere = tempfile::tempdir().unwrap();
        for given in [&folder, &sidecar] {
            let o = Command::new(BIN)
                .current_dir(elsewhere.path())
                .args(["judge", given.to_str().unwrap(), results.to_str().unwrap()])
                .output()
                .unwrap();
            assert_eq!(o.status.code(), Some(0), "{}", say(&o));
            assert_eq!(verdict_lines(&o), verdict_lines(&direct), "{}", say(&o));
        }
        let value: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
        if name == "patch-q4" {
            assert!(
                value["problem"]["bodies"][0]["mesh"]
                    .get("explicit")
                    .is_some(),
                "{}",
                value["problem"]["bodies"][0]
            );
        }
        // a sidecar without the case says how to get one
        let mut old = value.clone();
        old.as_object_mut().unwrap().remove("problem");
        let old_file = tmp.path().join(format!("old-{name}.json"));
        std::fs::write(&old_file, old.to_string()).unwrap();
        let o = run(&[
            "judge",
            old_file.to_str().unwrap(),
            results.to_str().unwrap(),
        ]);
        let s = say(&o);
        assert_eq!(o.status.code(), Some(2), "{s}");
        assert!(
            s.contains("holds no 'problem'") && s.contains("export the case again"),
            "{s}"
        );
    }
}

/// `cases/patch/patch-A-nu0.3.json` with the punch's top-left corner held at `x = 0` (the
/// catalogue's support before issue 42: the exact solution then slides the punch over the
/// foundation by `4 eps_xx`), its contact geometry `geometry` (`reference` or `current`); with
/// `current` the pair's moments balance about the deformed positions `X + u`.
fn sliding_patch(tmp: &Path, geometry: &str) -> PathBuf {
    let text = std::fs::read_to_string(root().join("cases/patch/patch-A-nu0.3.json")).unwrap();
    let mut case: serde_json::Value = serde_json::from_str(&text).unwrap();
    case["name"] = format!("patch-A-sliding-{geometry}").into();
    case["physics"] = serde_json::json!({"contact_geometry": geometry});
    let corner = case["supports"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|s| s["body"] == "punch" && s["set"] == "top_left")
        .unwrap();
    assert_eq!(corner["x"], "exact", "the catalogue's punch corner");
    corner["x"] = 0.0.into();
    let path = tmp.join(format!("patch-A-sliding-{geometry}.json"));
    std::fs::write(&path, case.to_string()).unwrap();
    path
}

#[test]
fn force_balance_of_a_current_geometry_run_agrees_between_run_and_judge() {
    let tmp = tempfile::tempdir().unwrap();
    let case = sliding_patch(tmp.path(), "current");
    let direct = run_case(&case, &mut |_| {}).unwrap();
    let folder = OutputFolder::new(&tmp.path().join("run")).unwrap();
    write_run(&folder, &direct).unwrap();
    let results = load_results(&direct.model, folder.path()).unwrap();
    let j = judge(&direct.model, &results, DEFAULT_MATCH_SHARE).unwrap();
    assert!(
        j.not_judged.is_empty(),
        "{:?}",
        j.not_judged.iter().map(|n| &n.why).collect::<Vec<_>>()
    );
    let balance = |checks: &[contact_patch::harness::checks::CheckResult]| {
        checks
            .iter()
            .find(|c| c.check.starts_with("force balance"))
            .cloned()
            .unwrap()
    };
    let (d, o) = (balance(&direct.checks), balance(&j.checks));
    println!(
        "run: {} ({:e})\njudge: {} ({:e})",
        d.check, d.error, o.check, o.error
    );
    assert!(d.passed && o.passed, "{d:?}\n{o:?}");
    assert!((o.error - d.error).abs() <= 1e-12, "{d:?}\n{o:?}");
    // every other check too: the pressure from areas and normals at X + u
    for d in &direct.checks {
        let o = j
            .checks
            .iter()
            .find(|c| {
                c.check.split(" = ").next() == d.check.split(" = ").next()
                    || c.check.starts_with(d.check.split(" (").next().unwrap())
            })
            .unwrap_or_else(|| panic!("{} not judged", d.check));
        assert_eq!(
            o.passed, d.passed,
            "{}: {:e} vs {:e}",
            d.check, o.error, d.error
        );
        assert!(
            (o.error - d.error).abs() <= 1e-12 * d.error.abs().max(1e-3),
            "{}: {:e} vs {:e}",
            d.check,
            o.error,
            d.error
        );
    }
    // the same results judged by the case with reference geometry (the export's): the moments
    // about X do not balance; the message names that term and the configuration they balance in
    let reference = sliding_patch(tmp.path(), "reference");
    let o = run(&[
        "judge",
        reference.to_str().unwrap(),
        folder.path().to_str().unwrap(),
    ]);
    let s = say(&o);
    assert_eq!(o.status.code(), Some(1), "{s}");
    let line = s
        .lines()
        .find(|l| {
            let l = l.trim_start();
            l.starts_with("FAIL force balance") || l.starts_with("pass force balance")
        })
        .unwrap_or_else(|| panic!("{s}"));
    println!("{line}");
    assert!(line.trim_start().starts_with("FAIL"), "{line}");
    assert!(
        line.contains("largest: the net moment / L of pair 'interface'")
            && line.contains(
                "with the moments about the deformed positions X + u the results balance"
            ),
        "{line}"
    );
}

#[test]
fn the_sidecars_facet_lists_run_counter_clockwise_with_the_body_on_the_left() {
    // issue 42, item 7: the sidecar documents its facet layout; the layout holds on the
    // rectangles of the patch test (one step to the left of a facet's midpoint is inside its
    // body, one step to the right outside)
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("export");
    let case = "cases/patch/patch-B-nu0.3.json";
    let o = run(&["export", case, "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let model = contact_patch::model::admit::load(&root().join(case)).unwrap();
    let sidecar: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join(&model.name).join(format!("{}.json", model.name)))
            .unwrap(),
    )
    .unwrap();
    let layout = sidecar["mesh"]["facet_sets"].as_str().unwrap();
    assert!(layout.contains("counter-clockwise") && layout.contains("[start, end]"));
    assert!(sidecar["mesh"]["gmsh_format"]
        .as_str()
        .unwrap()
        .contains("'<body>/<node set>/nodes'"));
    let mut checked = 0;
    for (b, body) in model.bodies.iter().enumerate() {
        let [lo, hi] = body.mesh.bounding_box();
        let inside = |p: [f64; 2]| (0..2).all(|i| p[i] > lo[i] && p[i] < hi[i]);
        let json = &sidecar["bodies"][b];
        assert_eq!(json["name"], body.name.as_str());
        for (set, value) in json["facet_sets"].as_object().unwrap() {
            assert_eq!(value["physical_group"], format!("{}/{set}", body.name));
            for facet in value["facets"].as_array().unwrap() {
                let nodes: Vec<usize> = facet
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|n| n.as_u64().unwrap() as usize)
                    .collect();
                let (a, e) = (body.mesh.nodes[nodes[0]], body.mesh.nodes[nodes[1]]);
                let t = [e[0] - a[0], e[1] - a[1]];
                let mid = [(a[0] + e[0]) / 2.0, (a[1] + e[1]) / 2.0];
                let step = 1e-3;
                let left = [mid[0] - step * t[1], mid[1] + step * t[0]];
                let right = [mid[0] + step * t[1], mid[1] - step * t[0]];
                assert!(
                    inside(left) && !inside(right),
                    "{}/{set}: facet {nodes:?} from {a:?} to {e:?}",
                    body.name
                );
                checked += 1;
            }
        }
        for (set, value) in json["node_sets"].as_object().unwrap() {
            if set != "all" {
                assert_eq!(
                    value["physical_group"],
                    format!("{}/{set}/nodes", body.name)
                );
            }
        }
    }
    assert!(checked > 10, "{checked} facets checked");
}

#[test]
fn an_outside_penalty_code_is_credited_with_its_kappa_series_and_a_cell_can_say_n_a() {
    // issue 42, item 6: our own penalty runs of patch C (node-to-surface, one pass, punch
    // slave) at kappa 1e4 and 1e7 stand in for another code's kappa series; the outside cell
    // must read the trend and errors of the direct sweep's penalty cell
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let case_c = "cases/patch/patch-C-nu0.3.json";
    let text = std::fs::read_to_string(root().join(case_c)).unwrap();
    let name = "patch-C-nu0.3";
    for kappa in [1e4, 1e7] {
        let mut case: serde_json::Value = serde_json::from_str(&text).unwrap();
        case["contact"][0]["enforcement"] = serde_json::json!({"kind": "penalty", "kappa": kappa});
        let path = tmp.path().join(format!("penalty-{kappa:e}.json"));
        std::fs::write(&path, case.to_string()).unwrap();
        let direct = run_case(&path, &mut |_| {}).unwrap();
        let folder =
            OutputFolder::new(&results.join(name).join(format!("kappa-{kappa:e}"))).unwrap();
        write_run(&folder, &direct).unwrap();
    }
    // a code without 3-node contact facets says so for patch E
    let case_e = "cases/patch/patch-E-nu0.3.json";
    let na = results.join("patch-E-nu0.3");
    std::fs::create_dir_all(&na).unwrap();
    std::fs::write(na.join("not-applicable.txt"), "no 3-node contact facets\n").unwrap();
    let out = tmp.path().join("tables");
    let table = |cases: &[&str], out: &Path| {
        let mut args = vec!["table"];
        args.extend(cases);
        args.extend([
            "--results",
            results.to_str().unwrap(),
            "--code",
            "their-penalty",
        ]);
        args.extend(["--out", out.to_str().unwrap()]);
        run(&args)
    };
    let o = table(&[case_c, case_e], &out);
    assert_eq!(o.status.code(), Some(0), "{}", say(&o));
    let cells: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("patch-table.json")).unwrap())
            .unwrap();
    let cells = cells.as_array().unwrap();
    assert_eq!(cells.len(), 2);
    let same = direct_cell(case_c, "penalty");
    assert_eq!(
        same.kappa,
        Some(1e4),
        "the sweep's penalty cell is at kappa 1e4"
    );
    let series = &cells[0];
    assert_eq!(series["kappa"], 1e4);
    assert_eq!(
        series["penalty_trend"],
        same.penalty_trend.as_deref().unwrap()
    );
    for (key, want) in [
        ("stress_error", same.stress_error.unwrap()),
        ("stress_error_stiff", same.stress_error_stiff.unwrap()),
    ] {
        let got = series[key].as_f64().unwrap();
        assert!(
            (got - want).abs() <= 1e-9 * want.max(1e-3),
            "{key}: {got:e} vs {want:e}"
        );
    }
    assert_eq!(series["verdict"], same.verdict.as_str());
    let note = series["note"].as_str().unwrap();
    assert!(
        note.contains("kappa series") && note.contains("as kappa grows 1e3x"),
        "{note}"
    );
    let na_cell = &cells[1];
    assert_eq!(na_cell["verdict"], "n/a");
    assert_eq!(
        na_cell["note"],
        "n/a (their-penalty): no 3-node contact facets"
    );
    let report = std::fs::read_to_string(out.join("patch-table.md")).unwrap();
    assert!(report.contains("Another code's kappa series"), "{report}");
    // refusals: an empty reason, a series of one kappa, a series too narrow, a bad folder name
    let refused = |setup: &dyn Fn(), says: &str| {
        setup();
        let o = table(&[case_c, case_e], &tmp.path().join("refused"));
        assert_eq!(o.status.code(), Some(2), "{}", say(&o));
        assert!(say(&o).contains(says), "no {says:?}: {}", say(&o));
    };
    refused(
        &|| std::fs::write(na.join("not-applicable.txt"), " \n").unwrap(),
        "the file is empty",
    );
    std::fs::write(na.join("not-applicable.txt"), "no 3-node contact facets").unwrap();
    let series_dir = results.join(name);
    let stiff = series_dir.join("kappa-1e7");
    let moved = series_dir.join("kappa-5e4");
    refused(
        &|| std::fs::rename(&stiff, &moved).unwrap(),
        "a factor 5.000; the trend needs at least 100",
    );
    std::fs::rename(&moved, &stiff).unwrap();
    let kept = tmp.path().join("kept");
    refused(
        &|| std::fs::rename(&stiff, &kept).unwrap(),
        "a kappa series of one kappa",
    );
    std::fs::rename(&kept, &stiff).unwrap();
    // results beside a series, or beside a reason: which is the code's answer is not clear
    let beside = series_dir.join("punch.vtu");
    refused(
        &|| std::fs::write(&beside, "").unwrap(),
        "holds results beside the kappa-<value> folders",
    );
    std::fs::remove_file(&beside).unwrap();
    let beside = na.join("foundation.vtu");
    refused(
        &|| std::fs::write(&beside, "").unwrap(),
        "says the code cannot solve the case, yet",
    );
    std::fs::remove_file(&beside).unwrap();
    refused(
        &|| std::fs::create_dir(series_dir.join("kappa-big")).unwrap(),
        "'big' is not a positive number",
    );
}

#[test]
fn the_patch_catalogue_does_not_slide_so_current_geometry_contact_passes_it_too() {
    // issue 42, item 1: the exported patch cases were small-sliding tests (the punch held at
    // x = 0 slides by 4 eps_xx), failed by O(p/E) by codes that take contact in the deformed
    // geometry; the catalogue now holds the punch's corner at the exact u_x. Mortar with
    // Lagrange multipliers and current contact geometry passes meshes A-C; the old support fails.
    let tmp = tempfile::tempdir().unwrap();
    for mesh in ["A", "B", "C"] {
        let text =
            std::fs::read_to_string(root().join(format!("cases/patch/patch-{mesh}-nu0.3.json")))
                .unwrap();
        let mut case: serde_json::Value = serde_json::from_str(&text).unwrap();
        case["physics"] = serde_json::json!({"contact_geometry": "current"});
        case["contact"][0]["discretization"] =
            serde_json::json!({"kind": "mortar", "multiplier": "standard"});
        let stress_error = |case: &serde_json::Value, name: &str| {
            let path = tmp.path().join(format!("{name}.json"));
            std::fs::write(&path, case.to_string()).unwrap();
            let run = run_case(&path, &mut |_| {}).unwrap();
            let check = run
                .checks
                .iter()
                .find(|c| c.check.starts_with("uniform stress"))
                .unwrap()
                .clone();
            check.error
        };
        let slip_free = stress_error(&case, &format!("{mesh}-current"));
        assert!(slip_free <= 1e-10, "mesh {mesh}: {slip_free:e}");
        case["supports"][2]["x"] = 0.0.into();
        let sliding = stress_error(&case, &format!("{mesh}-current-sliding"));
        assert!(
            sliding > 1e-4,
            "mesh {mesh}: the slide is seen: {sliding:e}"
        );
    }
}

#[test]
fn a_pressure_per_deformed_area_is_judged_with_pressure_area_deformed() {
    // issue 42, item 5: a code that reports its pressure per unit deformed area. Our run of
    // patch A with current contact geometry writes exactly that (p A(X + u) = the nodal force);
    // the catalogue case takes contact in the reference geometry, where the pressure is
    // per reference area: read as it is, it is off by A(X)/A(X + u) - 1 ~ eps_xx; with
    // --pressure-area deformed it is turned into the case's and passes.
    let tmp = tempfile::tempdir().unwrap();
    let case = "cases/patch/patch-A-nu0.3.json";
    let text = std::fs::read_to_string(root().join(case)).unwrap();
    let mut current: serde_json::Value = serde_json::from_str(&text).unwrap();
    current["physics"] = serde_json::json!({"contact_geometry": "current"});
    let current_file = tmp.path().join("patch-A-current.json");
    std::fs::write(&current_file, current.to_string()).unwrap();
    let run_dir = tmp.path().join("run");
    // our own run fails its contact_pressure check by the same ratio (its pressure is per
    // deformed area); its results are written all the same
    let o = run(&[
        "run",
        current_file.to_str().unwrap(),
        "--out",
        run_dir.to_str().unwrap(),
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", say(&o));
    let files = [run_dir.join("foundation.vtu"), run_dir.join("punch.vtu")];
    // the pressure alone: the forces come from -p A n
    let results = tmp.path().join("results");
    std::fs::create_dir(&results).unwrap();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        std::fs::write(
            results.join(f.file_name().unwrap()),
            drop_array(&text, "contact_force"),
        )
        .unwrap();
    }
    let pressure_line = |o: &Output| -> (String, f64) {
        let s = say(o);
        let line = s
            .lines()
            .map(str::trim_start)
            .find(|l| l.contains("contact pressure of 'interface'"))
            .unwrap_or_else(|| panic!("{s}"))
            .to_string();
        let error: f64 = line
            .split("(error ")
            .nth(1)
            .unwrap()
            .split(',')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        (line, error)
    };
    let as_is = run(&["judge", case, results.to_str().unwrap()]);
    let (line, error) = pressure_line(&as_is);
    assert!(line.starts_with("FAIL") && error > 1e-4, "{line}");
    let deformed = run(&[
        "judge",
        case,
        results.to_str().unwrap(),
        "--pressure-area",
        "deformed",
    ]);
    let (line, error) = pressure_line(&deformed);
    assert!(line.starts_with("pass") && error <= 1e-10, "{line}");
    // the same for the table of an outside code
    let out = tmp.path().join("tables");
    let dir = tmp.path().join("table-results");
    std::fs::create_dir(&dir).unwrap();
    std::fs::rename(&results, dir.join("patch-A-nu0.3")).unwrap();
    for (area, passes) in [("case", false), ("deformed", true)] {
        let o = run(&[
            "table",
            case,
            "--results",
            dir.to_str().unwrap(),
            "--pressure-area",
            area,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", say(&o));
        let cells: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("patch-table.json")).unwrap())
                .unwrap();
        let e = cells[0]["pressure_error"].as_f64().unwrap();
        assert_eq!(e <= 1e-10, passes, "--pressure-area {area}: {e:e}");
    }
    // a word it does not know is refused
    let o = run(&[
        "judge",
        case,
        dir.to_str().unwrap(),
        "--pressure-area",
        "spatial",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", say(&o));
    assert!(say(&o).contains("give 'case'"), "{}", say(&o));
}
