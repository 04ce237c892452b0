//! Rendering of the patch-test report (`reports/patch-table.md`): the seed's row first, then
//! the two-pass claims of the talk checked against the measured cells, then the full grid.

use crate::harness::{grid_markdown, seed_row, Cell, SEED_ROW};

/// Whether `cells` hold any of the seed's method (Lagrange multipliers, node-to-surface), the
/// only cells its published row can be compared with.
pub fn has_seed_cells(cells: &[Cell]) -> bool {
    cells
        .iter()
        .any(|c| c.enforcement == "lagrange" && c.discretization == "node_to_surface")
}

/// The seed's row next to ours, for every nu of the seed's method's cells; a sentence saying so
/// when the cells hold none of them (another code's results, a sweep of other methods).
pub fn seed_summary(cells: &[Cell]) -> String {
    if !has_seed_cells(cells) {
        return "No cell of this table uses the seed's method (Lagrange multipliers, node-to-surface): \
                its row is not compared.\n"
            .into();
    }
    let mut nus: Vec<f64> = cells
        .iter()
        .filter(|c| c.enforcement == "lagrange" && c.discretization == "node_to_surface")
        .map(|c| c.nu)
        .collect();
    nus.sort_by(f64::total_cmp);
    nus.dedup();
    let mut s = String::from("| row | A | B-1p | B-2p | C-1p | C-2p | D | E | matches the seed |\n|---|---|---|---|---|---|---|---|---|\n");
    s += "| Taylor 2004 (seed) |";
    for (_, v) in SEED_ROW {
        s += &format!(" {v} |");
    }
    s += " |\n";
    for nu in nus {
        let row = seed_row(cells, nu);
        let matches = row.iter().zip(SEED_ROW).all(|((_, a), (_, b))| a == b);
        // a `?` is a cell the table does not hold: no verdict either way
        let complete = row.iter().all(|(_, v)| v != "?");
        s += &format!("| Lagrange, nu = {nu} |");
        for (_, v) in &row {
            s += &format!(" {v} |");
        }
        let verdict = match (matches, complete) {
            (true, _) => "yes",
            (false, true) => "NO",
            (false, false) => "not all measured",
        };
        s += &format!(" {verdict} |\n");
    }
    s
}

fn find<'a>(cells: &'a [Cell], mesh: &str, nu: f64, enforcement: &str) -> Option<&'a Cell> {
    cells.iter().find(|c| {
        c.mesh == mesh && c.nu == nu && c.passes == Some(2) && c.enforcement == enforcement
    })
}

/// The talk's claims about two-pass node-to-surface, checked cell by cell at every nu.
fn two_pass_claims(cells: &[Cell]) -> String {
    let mut s = String::new();
    s += "The talk (\"1991: The Contact Patch Test\" and \"FEM Node-to-Surface Contact Analysis\") says that with two passes\n";
    s += "the penalty method passes while penetrating, the augmented Lagrangian and the perturbed tangent fail,\n";
    s += "and Lagrange multipliers fail the stability test. Measured, for the two-pass cells of meshes B and C\n";
    // each claim: (cells measured, cells agreeing with the claim)
    let mut penalty = (0usize, 0usize);
    let mut al = (0usize, 0usize);
    let mut pt = (0usize, 0usize);
    let mut lm = (0usize, 0usize);
    // the talk reports two-pass results for meshes B and C only
    let mut keys: Vec<(String, f64)> = cells
        .iter()
        .filter(|c| c.passes == Some(2) && (c.mesh == "B" || c.mesh == "C"))
        .map(|c| (c.mesh.clone(), c.nu))
        .collect();
    keys.dedup();
    if keys.is_empty() {
        return "No two-pass cell of meshes B or C is in this table: the talk's two-pass claims are not checked.\n".into();
    }
    s +=
        "(the meshes the talk reports two-pass results for; the full grid has A, D and E too):\n\n";
    s += "| mesh | nu | penalty (trend, max penetration) | augmented Lagrangian (iterations) | perturbed tangent (iterations) | Lagrange: consistency, rank deficiency |\n|---|---|---|---|---|---|\n";
    let count = |tally: &mut (usize, usize), c: Option<&Cell>, agrees: &dyn Fn(&Cell) -> bool| {
        if let Some(c) = c {
            tally.0 += 1;
            tally.1 += usize::from(agrees(c));
        }
    };
    for (mesh, nu) in keys {
        let pen = find(cells, &mesh, nu, "penalty");
        let al_cell = find(cells, &mesh, nu, "augmented_lagrange");
        let pt_cell = find(cells, &mesh, nu, "perturbed_tangent");
        let lm_cell = find(cells, &mesh, nu, "lagrange");
        let v = |c: Option<&Cell>| c.map(|c| c.verdict.clone()).unwrap_or_else(|| "-".into());
        count(&mut penalty, pen, &|p| {
            p.verdict == "pass" && p.max_penetration.unwrap_or(0.0) > 0.0
        });
        count(&mut al, al_cell, &|c| c.verdict == "fail");
        count(&mut pt, pt_cell, &|c| c.verdict == "fail");
        count(&mut lm, lm_cell, &|c| c.rank_deficiency.unwrap_or(0) > 0);
        let dash = |x: Option<String>| x.unwrap_or_else(|| "-".into());
        s += &format!(
            "| {mesh} | {nu} | {} ({}, {}) | {} ({}) | {} ({}) | {}, {} |\n",
            v(pen),
            dash(pen.and_then(|c| c.penalty_trend.clone())),
            dash(
                pen.and_then(|c| c.max_penetration)
                    .map(|p| format!("{p:.1e}"))
            ),
            v(al_cell),
            dash(
                al_cell
                    .and_then(|c| c.newton_iterations)
                    .map(|n| n.to_string())
            ),
            v(pt_cell),
            dash(
                pt_cell
                    .and_then(|c| c.newton_iterations)
                    .map(|n| n.to_string())
            ),
            v(lm_cell),
            dash(
                lm_cell
                    .and_then(|c| c.rank_deficiency)
                    .map(|r| r.to_string())
            ),
        );
    }
    s += "\n";
    let say = |(measured, agreeing): (usize, usize)| match (measured, agreeing) {
        (0, _) => "not measured (no such cell in this table)".to_string(),
        (m, a) if m == a => "confirmed".to_string(),
        (m, a) => format!("not confirmed ({a} of {m} cells)"),
    };
    s += &format!("- Penalty passes while penetrating: {}.\n", say(penalty));
    s += &format!("- Augmented Lagrangian fails: {}.\n", say(al));
    s += &format!("- Perturbed tangent fails: {}.\n", say(pt));
    s += &format!(
        "- Lagrange multipliers fail the stability test (singular multiplier system): {}.\n",
        say(lm)
    );
    let al_fails = al.0 > 0 && al.0 == al.1;
    let pt_fails = pt.0 > 0 && pt.0 == pt.1;
    let measured_both = al.0 > 0 && pt.0 > 0;
    if measured_both && !(al_fails && pt_fails) {
        s += "\n**Why the augmented Lagrangian and the perturbed tangent pass here.** With node-based rows in\n";
        s += "small strain every gap is affine in u, and for a linear problem one perturbed-tangent Newton\n";
        s += "step is exactly one Uzawa step of the augmented Lagrangian, so both iterate towards the\n";
        s += "Lagrange solution of the two-pass constraints. The two passes' rows are dependent but\n";
        s += "consistent (the Lagrange system is singular yet solvable: its pseudo-inverse finds no\n";
        s += "residual in the null space), so the displacement they converge to is the exact one; only the\n";
        s += "split of the force between dependent rows stays undetermined (rank deficiency); the nodal forces\n";
        s += "B^T lambda, from which pressures are reported, do not depend on that split (pressure error 0).\n";
        s += "What the talk's failure shows up as here is cost: on mesh C the iteration needs several times\n";
        s += "as many linear solves as on B (the iterations columns). These verdicts hold at the kappa of this\n";
        s += "table on these coarse meshes: the iterative methods stop on a force criterion (the Uzawa update\n";
        s += "below 1e-12 of the largest contact force, or the gap at the round-off floor) within 200 solves, and\n";
        s += "with a much smaller or larger kappa, or finer meshes, they can end at the iteration limit instead.\n";
        s += "We have not reproduced an outright failure at this kappa; it may need the talk's exact meshes or\n";
        s += "finite-deformation kinematics, where the two passes measure different gaps.\n";
    }
    s
}

/// What the perturbed Lagrangian is on standard mortar, and what the cells measured of its
/// difference from penalty (empty when no cell compared them).
fn perturbed_lagrange_note(cells: &[Cell]) -> String {
    let compared: Vec<&Cell> = cells.iter().filter(|c| c.vs_penalty.is_some()).collect();
    if compared.is_empty() {
        return String::new();
    }
    let largest = compared
        .iter()
        .filter_map(|c| c.vs_penalty)
        .fold(0.0f64, |m, d| if d.is_nan() || d > m { d } else { m });
    let mut s = String::new();
    s += "The perturbed Lagrangian uses the consistent multiplier mass of standard mortar (`C = A^-1 M A^-1 / kappa` with\n";
    s += "`M_jk = int N_j N_k`, not diagonal; its multipliers are unknowns of a saddle-point system) and therefore differs from\n";
    s += "penalty wherever the interface traction is not uniform; with node-based rows and dual mortar (a lumped mass) it is the\n";
    s += "penalty method. Each of its `mortar` cells gives in its note the largest stress difference from penalty at the same\n";
    s += "kappa: ";
    s += &format!(
        "over these {} cells at most {largest:.1e} of the load scale",
        compared.len()
    );
    if largest <= 1e-10 {
        s += ", round-off: the exact traction of these tests is uniform, and\n";
        s += "then `(C lambda)_j = t / kappa` at every row, as for penalty. ";
    } else {
        s += ".\n";
    }
    s += "`tests/perturbed_lagrange.rs` shows the difference under a non-uniform load.\n";
    s
}

/// The whole report.
pub fn patch_report(cells: &[Cell]) -> String {
    let mut s = String::from(
        "# The contact patch test: meshes A-E across discretizations and enforcement methods\n\n",
    );
    s += "Generated by `contact-patch table` (do not edit by hand). Geometry, loads and pass criteria:\n";
    s += "`shared/design/benchmarks.md` section 1, encoded in `cases/patch/` (written by `cases/patch/make_cases.py`).\n";
    let pressures: std::collections::BTreeSet<String> =
        cells.iter().map(|c| c.pressure.to_string()).collect();
    let kappas: std::collections::BTreeSet<String> = cells
        .iter()
        .filter(|c| c.discretization != "outside")
        .filter_map(|c| c.kappa)
        .map(|k| format!("{k:e}"))
        .collect();
    let p_list: Vec<String> = pressures.into_iter().collect();
    let k_list: Vec<String> = kappas.into_iter().collect();
    s += &format!("Errors are relative to the applied pressure p = {}; `0` means below 1e-10 (round-off).\n\n", p_list.join(", "));
    s += "## The seed's row (Lagrange multipliers, node-to-surface)\n\n";
    s += "1p = one-pass: `p/f` when the verdict depends on which body is the slave (punch slave / foundation slave);\n";
    s += "2p = two-pass. A, D and E are the one-pass verdicts as well.\n\n";
    s += &seed_summary(cells);
    s += "\n## Two-pass: the talk's claims against the measurements\n\n";
    s += &two_pass_claims(cells);
    s += "\n## The full grid\n\n";
    if !k_list.is_empty() {
        s += &format!("Penalty-type methods run at kappa = {} and at 1000 kappa; `trend` says whether the stress error is round-off at both,\n", k_list.join(", "));
        s += "falls like 1/kappa, or does not fall. ";
    }
    if cells
        .iter()
        .any(|c| c.discretization == "outside" && c.kappa.is_some())
    {
        s += "Another code's kappa series (`DIR/<case>/kappa-<value>/`) is judged the same way, from its smallest kappa (the `kappa` of\n";
        s += "the cell) to its largest (the `at 1000 kappa` column; the note gives the ratio and every kappa's error). ";
    }
    s += "`load error` compares the total contact force with the exact load. `rank def.` is the number of\n";
    s += "dependent active constraints; `stability` is `unstable` when a multiplier system (Lagrange, elimination) is singular.\n";
    s += "`iterations` counts linear solves of the active-set loop. ";
    s += &times_sentence(cells, "patch-table.times.csv");
    s += &perturbed_lagrange_note(cells);
    s += "\n";
    s += &grid_markdown(cells);
    s += &closing_count(cells);
    s
}

/// Where the cells' wall times are, or that none was solved here (another code's results
/// judged by `table --results`): the sentence after the grid's legend.
fn times_sentence(cells: &[Cell], file: &str) -> String {
    if cells.iter().any(|c| c.time_ms.is_some()) {
        format!(
            "Wall times per cell are in `{file}` (`-`: nothing solved), out of this file so that a \
             rerun changes it only where a result changes.\n"
        )
    } else {
        "No cell was solved here: the results are another code's, judged, not timed.\n".into()
    }
}

/// The table's last line: how many cells, solved or judged.
fn closing_count(cells: &[Cell]) -> String {
    let verb = if cells.iter().any(|c| c.time_ms.is_some()) {
        "cells"
    } else {
        "cells judged"
    };
    format!("\n{} {verb}.\n", cells.len())
}

/// The tied-interface patch tests: every constant stress state across non-matching interfaces.
pub fn tied_report(cells: &[Cell]) -> String {
    let mut s = String::from(
        "# Tied interfaces: constant-stress patch tests across non-matching meshes\n\n",
    );
    s +=
        "Generated by `contact-patch table` (do not edit by hand) from `cases/tied/` (written by\n";
    s += "`cases/tied/make_cases.py`): a block [0,2]x[0,1] tied to a block [0,2]x[1,2] along y = 1, with\n";
    s += "non-matching interface meshes B (nested), C (not nested) and E (quadratic), under a uniform\n";
    s += "normal (sigma_yy), parallel (sigma_xx, which contact cannot test) and shear (sigma_xy) stress of 10.\n";
    s += "Exact tractions on the outer boundary; the upper block is held only by the tie.\n";
    s += "Errors are relative to the stress (10); `0` means below 1e-10. `pressure error` compares the\n";
    s += "traction at every interface node that carries ties (its nodal tie force over its area) with the exact one.\n\n";
    s += "## Summary (Lagrange multipliers)\n\n";
    if !cells.iter().any(|c| c.enforcement == "lagrange") {
        s += "No cell of this table uses Lagrange multipliers: no summary.\n\n## The full grid\n\n";
        s += &grid_markdown(cells);
        s += "\n";
        s += &times_sentence(cells, "tied-table.times.csv");
        return s;
    }
    s += "| mesh and stress | node-to-surface (upper slave) | node-to-surface (lower slave) | mortar | dual mortar |\n|---|---|---|---|---|\n";
    let mut meshes: Vec<&str> = cells.iter().map(|c| c.mesh.as_str()).collect();
    meshes.dedup();
    for mesh in meshes {
        let find = |disc: &str, slave: &str| {
            cells
                .iter()
                .find(|c| {
                    c.mesh == mesh
                        && c.enforcement == "lagrange"
                        && c.discretization == disc
                        && c.passes.unwrap_or(1) == 1
                        && c.slave.as_deref() == Some(slave)
                })
                .map(|c| {
                    format!(
                        "{} ({})",
                        c.verdict,
                        crate::harness::rounded(c.stress_error)
                    )
                })
                .unwrap_or_else(|| "-".into())
        };
        s += &format!(
            "| {mesh} | {} | {} | {} | {} |\n",
            find("node_to_surface", "upper"),
            find("node_to_surface", "lower"),
            find("mortar", "upper"),
            find("dual_mortar", "upper")
        );
    }
    s += "\n(verdict and stress error)\n\n## The full grid\n\n";
    let note = perturbed_lagrange_note(cells);
    if !note.is_empty() {
        s += &note;
        s += "\n";
    }
    s += &grid_markdown(cells);
    s += "\n";
    s += &times_sentence(cells, "tied-table.times.csv");
    s
}

/// The frictional patch tests (`reports/friction-table.md`).
pub fn friction_report(cells: &[Cell]) -> String {
    let mut s = String::from(
        "# The frictional contact patch test: meshes A-E across discretizations and enforcement methods\n\n",
    );
    s += "Generated by `contact-patch table` (do not edit by hand) from `cases/friction/` (written by\n";
    s += "`cases/friction/make_cases.py`): the patch test of `shared/design/benchmarks.md` s. 1 with Coulomb\n";
    s += "friction (s. 4), the uniform field [0, -p, q] loaded by its own tractions on every free boundary,\n";
    s += "the pressure in the first load step and the tangential load after it. `stick`: q = mu p / 2 on the punch top,\n";
    s += "every point must stick and the stress is exactly uniform. `slip`: the punch top dragged along x,\n";
    s += "every point must slip with |lambda_t| = mu lambda_n, the tangential traction mu p at every node.\n";
    s += "Errors are relative to p; `0` means below 1e-10. `tangential error` compares the nodal tangential\n";
    s += "traction (nodal force over area) with the exact one; `cone ratio` is the largest |lambda_t| / (mu lambda_n)\n";
    s += "over every step (<= 1); `min dissipation` the smallest dissipation of a step (>= 0). Penalty-type methods\n";
    s += "are judged on their stress trend at kappa and 1000 kappa, as in the patch table. `n/a` cells say\n";
    s += "what the friction code does not solve yet.\n\n";
    s += "## Summary: the enforcement methods that pass, per discretization\n\n";
    s += &crate::harness::friction::summary_markdown(cells);
    s += "\n## The full grid\n\n";
    s += &crate::harness::friction::grid_markdown(cells);
    s += &closing_count(cells);
    s += &times_sentence(cells, "friction-table.times.csv");
    s
}

/// The wall times of one catalogue's cells, `<catalogue>-table.times.csv`: a comment line with
/// the whole run's time (`seconds`, every catalogue of it), then one row per cell in the
/// table's order, keyed as the baseline matches cells. Kept out of the verdict tables so that a
/// rerun changes those only where a result changes.
pub fn times_csv(cells: &[Cell], seconds: f64) -> String {
    let mut s = format!(
        "# wall times of the cells of one `contact-patch table` run, which took {seconds:.2} s in all\n"
    );
    s += "case,mesh,nu,status,discretization,passes,slave,enforcement,time_ms\n";
    for c in cells {
        s += &format!(
            "{},{},{},{},{},{},{},{},{}\n",
            c.case,
            c.mesh,
            c.nu,
            c.friction.as_ref().map(|f| f.expect.as_str()).unwrap_or(""),
            c.discretization,
            c.passes.map(|p| p.to_string()).unwrap_or_default(),
            c.slave.as_deref().unwrap_or(""),
            c.enforcement,
            crate::harness::time_text(c.time_ms)
        );
    }
    s
}

/// The stem of a table's files: `patch-table` in 2D, `patch-table-3d` in 3D.
pub fn table_stem(catalogue: crate::io::scene::Catalogue, dimension: u8) -> String {
    match dimension {
        2 => format!("{}-table", catalogue.name()),
        d => format!("{}-table-{d}d", catalogue.name()),
    }
}

/// The discretization of a cell as the 3D tables name it: `node-to-surface 1p, punch slave`,
/// `node-to-surface 2p`, `node-to-node`, `mortar standard`, `mortar dual`.
pub fn discretization_label(c: &Cell) -> String {
    match (c.discretization.as_str(), c.passes) {
        ("node_to_surface", Some(2)) => "node-to-surface 2p".into(),
        ("node_to_surface", p) => format!(
            "node-to-surface {}p, {} slave",
            p.unwrap_or(1),
            c.slave.as_deref().unwrap_or("-")
        ),
        ("node_to_node", _) => "node-to-node".into(),
        ("mortar", _) => "mortar standard".into(),
        ("dual_mortar", _) => "mortar dual".into(),
        (other, _) => other.replace('_', "-"),
    }
}

/// The letter of a cell in the 3D verdict grids: `p` pass, `k` pass on the penalty's 1/kappa
/// trend (above the tolerance at kappa: a penalty error, not a consistency error), `f` fail
/// with the contact iterations converged, `s` the iterations did not converge, `n/a`.
pub fn verdict_letter(c: &Cell) -> &'static str {
    match c.verdict.as_str() {
        "pass" if c.penalty_trend.as_deref() == Some("1/kappa") => "k",
        "pass" => "p",
        "fail" if c.termination.as_deref().is_some_and(|t| t != "converged") => "s",
        "fail" => "f",
        _ => "n/a",
    }
}

/// The report of a 3D catalogue (`patch-table-3d.md`, `tied-table-3d.md`): a summary per
/// discretization, the verdict grids (one per group of meshes: the part of the mesh label
/// before `": "`, e.g. a tied load), and every cell.
pub fn report_3d(catalogue: crate::io::scene::Catalogue, cells: &[Cell]) -> String {
    use crate::io::scene::Catalogue;
    let stem = table_stem(catalogue, 3);
    let mut s = match catalogue {
        Catalogue::Tied => String::from("# The 3D tied patch tests\n\n"),
        _ => String::from("# The 3D contact patch test\n\n"),
    };
    s += "Generated by `contact-patch table cases/3d` (do not edit by hand) from the sweeps of the case files in `cases/3d/` \
          (written by `cases/3d/make_cases.py`, whose notes give the scene, the loads and the exact uniform states). \
          Each cell solves its case with the pair's discretization and enforcement replaced; its stress error is the \
          largest difference over the quadrature points of both bodies and the six components from the stress of the \
          case's `uniform_stress_3d` check, relative to the sweep's `pressure` (the largest exact component). \
          A cell passes when the contact iterations converge, the force balance holds and the stress error is at most \
          the sweep's tolerance; a penalty-type cell (penalty, perturbed Lagrangian) runs again at 1000 kappa and \
          passes when the error is round-off at both or falls at least 100 times (`1/kappa`: a penalty error, not a \
          consistency error). 3D has no exact field yet: no pressure or load error is measured.\n\n";
    s += "Letters: `p` pass; `k` pass on the 1/kappa trend (the error at kappa is in the grid); `f` fail (converged, \
          error above the tolerance); `s` the contact iterations did not converge; `n/a` the model refuses the \
          combination (the reason is in the note of the full grid).\n\n";
    s += "## Summary per discretization\n\n";
    s += "| discretization | p | k | f | s | n/a | largest error where it fails |\n|---|---|---|---|---|---|---|\n";
    let mut labels: Vec<String> = Vec::new();
    for c in cells {
        let l = discretization_label(c);
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    for label in &labels {
        let mine: Vec<&Cell> = cells
            .iter()
            .filter(|c| discretization_label(c) == *label)
            .collect();
        let count = |letter: &str| mine.iter().filter(|c| verdict_letter(c) == letter).count();
        let worst = mine
            .iter()
            .filter(|c| matches!(verdict_letter(c), "f" | "s"))
            .filter_map(|c| c.stress_error)
            .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))));
        s += &format!(
            "| {label} | {} | {} | {} | {} | {} | {} |\n",
            count("p"),
            count("k"),
            count("f"),
            count("s"),
            count("n/a"),
            worst.map_or("-".into(), |e| format!("{e:.2e}"))
        );
    }
    let mut groups: Vec<&str> = Vec::new();
    for c in cells {
        let g = c.mesh.split_once(": ").map_or("", |(g, _)| g);
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    for group in groups {
        let mine: Vec<&Cell> = cells
            .iter()
            .filter(|c| c.mesh.split_once(": ").map_or("", |(g, _)| g) == group)
            .collect();
        let mesh_of = |c: &Cell| -> String {
            c.mesh
                .split_once(": ")
                .map_or(c.mesh.clone(), |(_, m)| m.to_string())
        };
        let mut meshes: Vec<String> = Vec::new();
        let mut rows: Vec<(String, String)> = Vec::new();
        for c in &mine {
            let m = mesh_of(c);
            if !meshes.contains(&m) {
                meshes.push(m);
            }
            let r = (discretization_label(c), c.enforcement.clone());
            if !rows.contains(&r) {
                rows.push(r);
            }
        }
        s += &if group.is_empty() {
            "\n## Verdicts\n\n".to_string()
        } else {
            format!("\n## Verdicts: {group}\n\n")
        };
        s += &format!(
            "| discretization | enforcement | {} |\n|---|---|{}\n",
            meshes.join(" | "),
            "---|".repeat(meshes.len())
        );
        for (label, enforcement) in &rows {
            s += &format!("| {label} | {enforcement} |");
            for m in &meshes {
                let cell = mine.iter().find(|c| {
                    mesh_of(c) == *m
                        && discretization_label(c) == *label
                        && c.enforcement == *enforcement
                });
                s += &match cell {
                    None => " - |".to_string(),
                    Some(c) => match verdict_letter(c) {
                        "p" | "n/a" => format!(" {} |", verdict_letter(c)),
                        letter => format!(
                            " {letter} {} |",
                            c.stress_error.map_or("-".into(), |e| format!("{e:.2e}"))
                        ),
                    },
                };
            }
            s += "\n";
        }
    }
    s += "\n## Every cell\n\n";
    s += "`iterations` counts the linear solves of the contact iterations; `rank def.` the dependent active rows \
          (`-` where not measured); `stability` is `unstable` when a multiplier system (Lagrange, elimination) is \
          singular. ";
    s += &times_sentence(cells, &format!("{stem}.times.csv"));
    s += "\n";
    s += &grid_markdown(cells);
    s += &closing_count(cells);
    s
}
