#!/usr/bin/env python3
"""The peer-code cross-check: the contact patch tests, the tied patch tests and Hertz's
cylinder solved by Kratos Multiphysics (ContactStructuralMechanicsApplication: mortar
augmented Lagrangian, mortar penalty, mortar mesh tying), judged by our tool, side by side
with our own verdicts; writes reports/peer-codes.md and reports/peer-codes.json.

    python3 crosscheck/peer_kratos.py TOOL KRATOS_PYTHON RUN_DIR REPORT_DIR

TOOL is our built `contact-patch`, KRATOS_PYTHON the interpreter of the Kratos environment
(crosscheck/run.sh makes .venv-kratos), RUN_DIR a scratch folder. Every number in the report is
measured here, in this run:

1. `contact-patch export` of every case (RUN_DIR/export/<case>/);
2. per case and Kratos method: kratos_convert.py (exit 3 = Kratos cannot take the case: its
   reason goes to RUN_DIR/results/<method>/<case>/not-applicable.txt, so that `table --results`
   makes the cell n/a with it), kratos_solve.py under one thread (taskset -c 0,
   OMP_NUM_THREADS=1), `contact-patch judge RUN_DIR/export/<case>/ RESULTS` (verdict lines and
   exit code kept in RUN_DIR). ALM: one solve, RESULTS = results/alm/<case>/. Penalty: a kappa
   series, one solve per kappa of PENALTY_KAPPAS, RESULTS = results/penalty/<case>/kappa-<k>/,
   which `table --results` judges as our own penalty cells (the trend of the stress error as
   kappa grows, the contact forces at the largest kappa);
3. for each penalty cell the table fails, and for KAPPA_SCAN_REFERENCE, a wider scan
   (KAPPA_SCAN: the stress error, the out-of-balance force and Kratos' Newton iterations per
   kappa), to say what was measured about the failure and why the series stops where it does;
4. `contact-patch table cases/patch cases/tied --results ... --code kratos-alm` (and
   kratos-penalty), and our own `contact-patch table cases/patch cases/tied` on one thread; the
   peer table puts our mortar cells (augmented Lagrangian per iteration, penalty; for ties the
   mortar Lagrange multiplier cells) beside Kratos' cells;
5. Hertz: `contact-patch run cases/gmsh/hertz-cylinder.json` and Kratos' two methods on its
   export: peak nodal pressure and half-width of the pressed zone against the closed form
   (benchmarks.md s. 3), with the cross-check's bounds (3 % of p0, one node spacing of a).

Exit 0 when everything ran (Kratos failing a cell is a result, recorded in the table); 1 when
our tool crashed (exit >= 2 where it must work) or a script broke.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PATCH = sorted((ROOT / "cases/patch").glob("patch-*.json"))
TIED = sorted((ROOT / "cases/tied").glob("tied-*.json"))
HERTZ = ROOT / "cases/gmsh/hertz-cylinder.json"
METHODS = {"alm": "kratos-alm", "penalty": "kratos-penalty"}
# Our cells beside Kratos': the same mortar discretization (standard multipliers, punch slave)
OURS = {
    "alm": ("mortar", "augmented_lagrange"),
    "penalty": ("mortar", "penalty"),
    "tie": ("mortar", "lagrange"),
}
HERTZ_PEAK = 0.03  # as crosscheck/report.py: peak within 3 % of p0
# hertz-cylinder is a Lagrange case: Kratos' penalty gets the kappa of the cross-check's penalty
# Hertz cases at the same E (crosscheck/cases/contact/cylinder-penalty-*.json)
HERTZ_KAPPA = 1e5
# Kratos' penalty series: two kappas 100x apart (the smallest span `table --results` takes). The
# largest is the sweep's kappa (1e4): above it the out-of-balance force of Kratos' results grows
# with kappa past the force-balance tolerance 1e-12 (the scan of KAPPA_SCAN_REFERENCE in the
# report measures it), so a series up to the sweep's 1e7 would fail on round-off, not on the
# method.
PENALTY_KAPPAS = ("1e2", "1e4")
KAPPA_SCAN = ("1e2", "1e3", "1e4", "1e5", "1e6", "1e7", "1e8")
KAPPA_SCAN_REFERENCE = "patch-A-nu0.3"
ONE_THREAD = {"OMP_NUM_THREADS": "1", "RAYON_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
              "MKL_NUM_THREADS": "1"}


class Broken(Exception):
    """Our tool or a script failed where it must work."""


def can_pin():
    """Whether `taskset -c 0` works here (a container may not allow core 0)."""
    if not shutil.which("taskset"):
        return False
    return subprocess.run(["taskset", "-c", "0", "true"], capture_output=True).returncode == 0


PIN = can_pin()


def pinned(cmd):
    """cmd on one core (taskset -c 0 where the machine allows it; else the thread variables
    of ONE_THREAD alone)."""
    return (["taskset", "-c", "0"] if PIN else []) + cmd


def run(cmd, log=None, env=None, ok=(0,)):
    """Run cmd; returns (exit code, wall seconds, stdout+stderr). Raises Broken for an exit
    code outside ok when ok is not None."""
    t = time.perf_counter()
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True,
                       env={**os.environ, **(env or {})})
    wall = time.perf_counter() - t
    out = p.stdout + p.stderr
    if log:
        Path(log).write_text(out)
    if ok is not None and p.returncode not in ok:
        raise Broken(f"{' '.join(map(str, cmd))}: exit {p.returncode}\n{out[-3000:]}")
    return p.returncode, wall, out


def judged_lines(text):
    """The verdict lines of `contact-patch judge` (pass/fail), and its closing count."""
    lines = [ln.strip() for ln in text.splitlines()]
    verdicts = [ln for ln in lines if ln.lower().startswith(("pass ", "fail "))]
    closing = next((ln for ln in lines if "judged checks" in ln), "")
    return verdicts, closing


def read_point_field(vtu, name):
    """(points, values) of one point field of an ASCII .vtu (our writer's or kratos_solve's)."""
    root = ET.parse(vtu).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    flat = [float(v) for v in piece.find("Points/DataArray").text.split()]
    pts = [(flat[i], flat[i + 1]) for i in range(0, len(flat), 3)]
    for a in piece.find("PointData").iter("DataArray"):
        if a.get("Name", "").lower() == name:
            v = [float(x) for x in a.text.split()]
            nc = int(a.get("NumberOfComponents", "1"))
            return pts, [v[i:i + nc] if nc > 1 else v[i] for i in range(0, len(v), nc)]
    return pts, None


def solve_kratos(kpy, export, case, method, rundir, extra=(), sub="", root="results"):
    """Convert and solve one case with one Kratos method into RUN_DIR/<root>/<method>/<case>/
    (or its subfolder `sub`, e.g. kappa-1e4); a dict for the report, with "results" the folder.
    When Kratos cannot take the case: status n/a and the converter's reason."""
    kdir = rundir / "kratos" / root / method / case / sub
    rdir = rundir / root / method / case / sub
    for d in (kdir, rdir):
        shutil.rmtree(d, ignore_errors=True)
    rc, _, out = run([kpy, HERE / "kratos_convert.py", export / case, kdir, "--contact", method,
                      *extra], ok=(0, 3))
    if rc == 3:
        reason = next((ln[4:].strip() for ln in out.splitlines() if ln.startswith("n/a:")), out)
        return {"status": "n/a", "reason": reason}
    # exit 0 converged, 1 not converged, 2 Kratos failed: results; 4 (or other) a broken script
    rc, wall, out = run(pinned([kpy, HERE / "kratos_solve.py", kdir, rdir]), log=kdir / "solve.log",
                        env=ONE_THREAD, ok=(0, 1, 2))
    entry = {"status": {0: "converged", 1: "not converged"}.get(rc, "failed"),
             "process_seconds": wall}
    solve_json = kdir / "solve.json"
    if solve_json.is_file():
        s = json.loads(solve_json.read_text())
        entry.update({"solve_seconds": s["solve_seconds"], "import_seconds": s["import_seconds"],
                      "newton_iterations": s["newton_iterations"],
                      "mortar_type": s["mortar_type"]})
    if rc in (1, 2):
        entry["newton"] = newton_history(out)
    if rc >= 2:
        entry["reason"] = "Kratos' solve failed: " + out.strip().splitlines()[-1][:300]
    return entry


def newton_history(log):
    """The displacement ratio of each Newton iteration from Kratos' convergence table."""
    ratios = []
    for ln in log.splitlines():
        cols = [c.strip() for c in ln.split("|")]
        if len(cols) > 3 and cols[1].isdigit():
            try:
                ratios.append(float(cols[2]))
            except ValueError:
                pass
    return ratios


def not_applicable(rundir, method, case, reason):
    """RUN_DIR/results/<method>/<case>/not-applicable.txt with the converter's reason: the
    file by which `table --results` makes the cell n/a with the outside code's reason."""
    folder = rundir / "results" / method / case
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    (folder / "not-applicable.txt").write_text(reason + "\n")


def solve_one(tool, kpy, export, case, method, rundir):
    """One Kratos solve of a case (ALM, or mesh tying for tied cases), judged."""
    k = solve_kratos(kpy, export, case, method, rundir)
    if k["status"] == "n/a":
        not_applicable(rundir, method, case, k["reason"])
    elif k["status"] in ("converged", "not converged"):
        k["judge"] = judge(tool, export, case, rundir / "results" / method / case, rundir,
                           method)
    return k


def solve_series(tool, kpy, export, case, method, rundir, kappas=PENALTY_KAPPAS,
                 root="results"):
    """Kratos' penalty at each kappa of `kappas`, into RUN_DIR/<root>/<method>/<case>/kappa-<k>/
    (the kappa series `table --results` judges), each judged; n/a for the case when the
    converter refuses it."""
    series = {}
    for kappa in kappas:
        k = solve_kratos(kpy, export, case, method, rundir, extra=("--kappa", kappa),
                         sub=f"kappa-{kappa}", root=root)
        if k["status"] == "n/a":
            if root == "results":
                not_applicable(rundir, method, case, k["reason"])
            return k
        if k["status"] in ("converged", "not converged"):
            k["judge"] = judge(tool, export, case,
                               rundir / root / method / case / f"kappa-{kappa}", rundir,
                               f"{root}-{method}-kappa-{kappa}")
        series[kappa] = k
    states = {k["status"] for k in series.values()}
    if "failed" in states and root == "results":
        # a kappa without results: no series for the table (its cell reads "no results"); the
        # report gives Kratos' failure
        shutil.rmtree(rundir / root / method / case, ignore_errors=True)
    status = "converged" if states == {"converged"} else (
        "failed" if "failed" in states else "not converged")
    return {"status": status, "series": series,
            "process_seconds": sum(k.get("process_seconds", 0.0) for k in series.values()),
            "solve_seconds": sum(k.get("solve_seconds", 0.0) for k in series.values())}


def check_error(k, start):
    """The error of the judge line of `k` that begins with `start` (e.g. "uniform stress",
    "force balance"), or None."""
    for line in k.get("judge", {}).get("checks", []):
        text = line.split(" ", 1)[1]
        if text.startswith(start) and "(error " in text:
            return float(text.rsplit("(error ", 1)[1].split(",")[0])
    return None


def judge(tool, export, case, rdir, rundir, tag):
    """`contact-patch judge` of one result folder; exit 2 (bad input) is a broken script here:
    kratos_solve.py wrote the folder."""
    rc, _, out = run([tool, "judge", export / case, rdir, "--junit",
                      rundir / "judge" / f"{tag}-{case}.xml"],
                     log=rundir / "judge" / f"{tag}-{case}.txt", ok=(0, 1))
    verdicts, closing = judged_lines(out)
    return {"rc": rc, "verdict": "pass" if rc == 0 else "fail", "checks": verdicts,
            "summary": closing}


def table_cells(path):
    """{case: [cells]} of one of our tables (patch-table.json or tied-table.json)."""
    cells = {}
    if path.is_file():
        for c in json.loads(path.read_text()):
            cells.setdefault(c["case"], []).append(c)
    return cells


def ours_cell(cells, case, kind):
    disc, enf = OURS[kind]
    for c in cells.get(case, []):
        if c["discretization"] == disc and c["enforcement"] == enf:
            return c
    return None


def hertz_numbers(pts, pressure, slave_nodes=None):
    """Peak nodal pressure and half-width (half the x-extent of the nodes with p > 0)."""
    pressed = [(x, p) for (x, _), p in zip(pts, pressure) if p > 0.0]
    if not pressed:
        return None, None
    xs = [x for x, _ in pressed]
    return max(p for _, p in pressed), 0.5 * (max(xs) - min(xs))


def pressure_of_forces(export, case, results_dir, body):
    """Peak of -f_a . n_a / A_a over the slave nodes of the case's first pair, from a result's
    contact_force (n_a, A_a in the reference configuration, as our tool defines the pressure):
    the pressure of the code's own assembled forces, beside its nodal pressure field."""
    side = json.loads((export / case / f"{case}.json").read_text())
    pair = side["contact"][0]["slave"]
    b = next(x for x in side["bodies"] if x["name"] == pair["body"])
    facets = b["facet_sets"][pair["set"]]["facets"]
    pts, f = read_point_field(results_dir / f"{body}.vtu", "contact_force")
    if f is None:
        return None
    area, normal = {}, {}
    for a, c in facets:
        (xa, ya), (xc, yc) = pts[a], pts[c]
        for n in (a, c):
            area[n] = area.get(n, 0.0) + 0.5 * math.hypot(xc - xa, yc - ya)
            nx, ny = normal.get(n, (0.0, 0.0))
            normal[n] = (nx + yc - ya, ny - (xc - xa))
    t = side["analysis"]["thickness"]
    return max(-(f[n][0] * nx + f[n][1] * ny) / math.hypot(nx, ny) / (t * area[n])
               for n, (nx, ny) in normal.items())


def hertz_closed_form(export):
    """P, R, E*, a, p0 of hertz-cylinder: a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a)
    (benchmarks.md s. 3, rigid plane), from the sidecar: P = the applied load's y resultant."""
    side = json.loads((export / "hertz-cylinder" / "hertz-cylinder.json").read_text())
    P = -sum(f["force"] for f in side["resolved"]["consistent_nodal_forces"]
             if f["component"] == "y") / side["analysis"]["thickness"]
    m = side["bodies"][0]["material"]
    estar = m["E"] / (1.0 - m["nu"] ** 2) if side["analysis"]["plane"] == "strain" else m["E"]
    R = 10.0  # the cylinder's radius (the case's description; hertz-q4.msh)
    a = math.sqrt(4.0 * P * R / (math.pi * estar))
    return {"P": P, "R": R, "E_star": estar, "a": a, "p0": 2.0 * P / (math.pi * a)}


def node_spacing_at_contact(pts, a):
    """The largest spacing between neighbouring surface nodes within the Hertz zone |x| <= a
    (y within 0.1 of the lowest node), the bound of the half-width as in crosscheck/report.py."""
    ymin = min(y for _, y in pts)
    xs = sorted(x for x, y in pts if y - ymin < 0.1 and abs(x) <= 1.5 * a)
    return max((b - c for c, b in zip(xs, xs[1:])), default=float("nan"))


def main(argv):
    if len(argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    tool, kpy, rundir, report_dir = (Path(a) for a in argv[1:])
    tool, rundir = tool.resolve(), rundir.resolve()
    rundir.mkdir(parents=True, exist_ok=True)
    (rundir / "judge").mkdir(exist_ok=True)
    export = rundir / "export"
    for stale in ("results", "kratos", "scan"):  # a kind of results another run left
        shutil.rmtree(rundir / stale, ignore_errors=True)
    t_start = time.perf_counter()

    # 1. the export ----------------------------------------------------------------------------
    run([tool, "export", *PATCH, *TIED, HERTZ, "--out", export], log=rundir / "export.log")

    # 2. our own tables on one thread -------------------------------------------------------------
    rc, ours_wall, _ = run(pinned([tool, "table", ROOT / "cases/patch", ROOT / "cases/tied",
                                   "--out", rundir / "ours"]), log=rundir / "ours-table.log",
                           env=ONE_THREAD, ok=(0, 1))
    ours_patch = table_cells(rundir / "ours" / "patch-table.json")
    ours_tied = table_cells(rundir / "ours" / "tied-table.json")

    # 3. Kratos, per case and method -------------------------------------------------------------
    rows = []
    for case_file in [*PATCH, *TIED]:
        case = case_file.stem
        catalogue = "patch" if case.startswith("patch") else "tied"
        row = {"case": case, "catalogue": catalogue, "kratos": {}, "ours": {}}
        for method in METHODS:
            row["kratos"][method] = (solve_series if method == "penalty" else solve_one)(
                tool, kpy, export, case, method, rundir)
        cells = ours_patch if catalogue == "patch" else ours_tied
        for kind in (("alm", "penalty") if catalogue == "patch" else ("tie",)):
            c = ours_cell(cells, case, kind)
            row["ours"][kind] = None if c is None else {
                key: c.get(key) for key in ("discretization", "enforcement", "verdict",
                                            "stress_error", "pressure_error", "load_error",
                                            "force_balance", "time_ms", "note")}
        rows.append(row)
        print(f"peer: {case}: " + ", ".join(f"{m} {r['status']}"
                                            for m, r in row["kratos"].items()), flush=True)

    # 4. the tables of Kratos' results --------------------------------------------------------------
    tables = {}
    (rundir / "tables").mkdir(exist_ok=True)
    for method, code in METHODS.items():
        results = rundir / "results" / method
        results.mkdir(parents=True, exist_ok=True)
        run([tool, "table", ROOT / "cases/patch", ROOT / "cases/tied", "--results", results,
             "--code", code, "--out", rundir / "tables" / method],
            log=rundir / "tables" / f"{method}.log", ok=(0, 1))
        for name in ("patch-table.json", "tied-table.json"):
            for c in json.loads((rundir / "tables" / method / name).read_text()):
                tables.setdefault(method, {})[c["case"]] = c
    for row in rows:
        for method in METHODS:
            c = tables.get(method, {}).get(row["case"])
            if c is not None:
                row["kratos"][method]["table"] = {
                    key: c.get(key) for key in ("verdict", "kappa", "stress_error",
                                                "stress_error_stiff", "penalty_trend",
                                                "pressure_error", "load_error",
                                                "force_balance", "note")}

    # 3b. the penalty's kappa scan: the failing penalty cells and the reference ----------------
    for row in rows:
        k = row["kratos"]["penalty"]
        failing = k.get("table", {}).get("verdict") == "fail"
        if row["catalogue"] == "patch" and (failing or row["case"] == KAPPA_SCAN_REFERENCE):
            scan = solve_series(tool, kpy, export, row["case"], "penalty", rundir,
                                kappas=KAPPA_SCAN, root="scan")
            k["scan"] = [{"kappa": float(kappa), "status": e["status"],
                          "newton_iterations": e.get("newton_iterations"),
                          "stress_error": check_error(e, "uniform stress"),
                          "pressure_error": check_error(e, "contact pressure"),
                          "force_balance": check_error(e, "force balance")}
                         for kappa, e in scan.get("series", {}).items()]
            print(f"peer: {row['case']}: penalty scan " + ", ".join(
                f"{e['kappa']:.0e}: {fmt(e['stress_error'])}" for e in k["scan"]), flush=True)

    # 5. Hertz ---------------------------------------------------------------------------------
    h = hertz_closed_form(export)
    hertz = {"case": "hertz-cylinder", **h, "codes": {}}
    rc, wall, out = run(pinned([tool, "run", HERTZ, "--out", rundir / "ours-hertz"]),
                        log=rundir / "ours-hertz.log", env=ONE_THREAD, ok=(0, 1))
    pts, p = read_point_field(rundir / "ours-hertz" / "cylinder.vtu", "contact_pressure")
    if p is None:
        raise Broken("our hertz-cylinder run wrote no contact_pressure")
    spacing = node_spacing_at_contact(pts, h["a"])
    hertz["node_spacing"] = spacing
    peak, half = hertz_numbers(pts, p)
    hertz["codes"]["ours (node-to-surface, Lagrange)"] = {
        "status": "converged" if rc == 0 else f"exit {rc}",
        "peak": peak, "half_width": half, "wall_seconds": wall, "exit": rc,
        "peak_of_forces": pressure_of_forces(export, "hertz-cylinder", rundir / "ours-hertz",
                                             "cylinder"),
        "judge": judge(tool, export, "hertz-cylinder", rundir / "ours-hertz", rundir, "ours")}
    for method in METHODS:
        extra = ("--kappa", str(HERTZ_KAPPA)) if method == "penalty" else ()
        k = solve_kratos(kpy, export, "hertz-cylinder", method, rundir, extra=extra)
        entry = {"status": k["status"], "wall_seconds": k.get("process_seconds"),
                 "solve_seconds": k.get("solve_seconds"),
                 "newton_iterations": k.get("newton_iterations"), "reason": k.get("reason")}
        vtu = rundir / "results" / method / "hertz-cylinder" / "cylinder.vtu"
        if vtu.is_file():
            kp_pts, kp = read_point_field(vtu, "contact_pressure")
            entry["peak"], entry["half_width"] = hertz_numbers(kp_pts, kp)
            entry["peak_of_forces"] = pressure_of_forces(export, "hertz-cylinder", vtu.parent,
                                                         "cylinder")
            entry["newton"] = k.get("newton")
            entry["judge"] = judge(tool, export, "hertz-cylinder", vtu.parent, rundir, method)
        hertz["codes"][f"Kratos {METHODS[method]}"] = entry
    for entry in hertz["codes"].values():
        if entry.get("peak") is not None:
            entry["peak_error"] = abs(entry["peak"] - h["p0"]) / h["p0"]
            entry["half_width_error"] = abs(entry["half_width"] - h["a"])
            entry["verdict"] = ("pass" if entry["peak_error"] <= HERTZ_PEAK
                                and entry["half_width_error"] <= spacing else "fail")

    report = {
        "generated_by": "crosscheck/peer_kratos.py (bash crosscheck/run.sh)",
        "kratos": kratos_versions(kpy),
        "ours_version": os.environ.get("XCHECK_OURS_VERSION", "unknown"),
        "ours_table_seconds": ours_wall,
        "threads": ("one core each (taskset -c 0; OMP_NUM_THREADS=1, RAYON_NUM_THREADS=1)"
                    if PIN else "one thread each (OMP_NUM_THREADS=1, RAYON_NUM_THREADS=1; "
                    "taskset unavailable)"),
        "rows": rows,
        "hertz": hertz,
        "elapsed_seconds": time.perf_counter() - t_start,
    }
    report_dir.mkdir(parents=True, exist_ok=True)
    (report_dir / "peer-codes.json").write_text(json.dumps(report, indent=1) + "\n")
    (report_dir / "peer-codes.md").write_text(markdown(report))
    print(f"peer: wrote {report_dir}/peer-codes.md and .json "
          f"({report['elapsed_seconds']:.0f} s)")
    return 0


def kratos_versions(kpy):
    _, _, out = run([kpy, "-m", "pip", "freeze", "--disable-pip-version-check"], ok=None)
    return [ln for ln in out.splitlines() if ln.lower().startswith("kratos")]


def fmt(x):
    return "-" if x is None else f"{x:.1e}"


def kratos_cell(k):
    """Kratos' cell as `table --results` judged it: the verdict with its errors (a penalty
    series: the stress error at the smallest and the largest kappa, and the trend), or n/a."""
    t = k.get("table")
    if k["status"] == "failed":
        return "fail (Kratos failed)"
    if t is None or t.get("verdict") is None:
        return "n/a" if k["status"] == "n/a" else f"fail ({k['status']})"
    if t["verdict"] == "n/a":
        return "n/a"
    if t.get("penalty_trend"):
        return (f"{t['verdict']} (stress {fmt(t['stress_error'])} -> "
                f"{fmt(t['stress_error_stiff'])}: {t['penalty_trend']}, p {fmt(t['pressure_error'])})")
    return f"{t['verdict']} (stress {fmt(t['stress_error'])}, p {fmt(t['pressure_error'])})"


def reason(k):
    """Why Kratos' cell is not a pass: the n/a reason as `table --results` recorded it, or what
    was measured (the table's note, the judge's failing checks, Kratos' Newton, the kappa
    scan)."""
    t = k.get("table") or {}
    if t.get("verdict") == "pass":
        return ""
    if k["status"] == "failed" and "series" in k:
        return "; ".join(
            f"kappa {kappa}: {e['status']}" + (
                f" ({e['reason']})" if e.get("reason") else "") + (
                ", Kratos' Newton, displacement ratio per iteration: " + ", ".join(
                    f"{x:.1e}" for x in e["newton"][:6]) + f", ..., last {e['newton'][-1]:.1e} "
                f"after {len(e['newton'])} iterations" if e.get("newton") else "")
            for kappa, e in k["series"].items())
    if (t.get("verdict") == "n/a" or k["status"] == "n/a") and k["status"] != "failed":
        return t.get("note") or k.get("reason", "n/a")
    parts = []
    if k["status"] == "failed":
        parts.append(k.get("reason", "Kratos' solve failed"))
    if k["status"] == "not converged":
        parts.append("Kratos' Newton did not converge")
    if k.get("newton"):
        parts.append("Kratos' Newton, displacement ratio per iteration: " + ", ".join(
            f"{x:.1e}" for x in k["newton"][:8]) + (" ..." if len(k["newton"]) > 8 else ""))
    if t.get("note"):
        parts.append("table: " + t["note"])
    checks = [c for e in ([k] + list(k.get("series", {}).values()))
              for c in e.get("judge", {}).get("checks", []) if c.lower().startswith("fail")]
    if checks and "series" not in k:
        parts.append("judge: " + "; ".join(short(c[5:]) for c in checks))
    if k.get("scan"):
        parts.append("kappa scan: " + scan_words(k["scan"]))
    return ". ".join(parts)


def scan_words(scan):
    """The kappa scan, one entry per kappa: stress error, out-of-balance, Newton iterations."""
    return "; ".join(
        f"{e['kappa']:.0e}: stress {fmt(e['stress_error'])}, balance {fmt(e['force_balance'])}, "
        + (f"{e['newton_iterations']} Newton iterations" if e["status"] == "converged"
           else f"{e['status']} after {e.get('newton_iterations')} Newton iterations")
        for e in scan)


def verdict_counts(rows, method, catalogue):
    """(cells Kratos solved, passing, n/a) of one catalogue for one method, from the tables."""
    ks = [r["kratos"][method] for r in rows if r["catalogue"] == catalogue]
    v = ["fail" if k["status"] == "failed" else k.get("table", {}).get("verdict") for k in ks]
    return sum(x in ("pass", "fail") for x in v), v.count("pass"), v.count("n/a")


def short(check):
    """A judge line without its bracketed source: the check and its error."""
    text = check
    if " [from" in text:
        start = text.index(" [from")
        text = text[:start] + text[text.index("]", start) + 1:]
    return text.replace(" of each pair between bodies and the out-of-balance force", "")


def markdown(r):
    rows = r["rows"]
    L = ["# Peer codes: Kratos Multiphysics on the contact catalogue", "",
         f"Generated by `{r['generated_by']}`; our tool {r['ours_version']}; "
         f"{', '.join(r['kratos'])}; {r['threads']}. Every number below is measured by that "
         "script in the run that wrote this file.", "",
         "Kratos solves each case on our exported mesh (`contact-patch export`, converted by "
         "`crosscheck/kratos_convert.py`, solved and written by `crosscheck/kratos_solve.py`); "
         "`contact-patch judge` and `contact-patch table --results` judge its `.vtu` results "
         "with the case's own checks and the table's criteria (stress error and pressure error "
         "within the sweep's tolerance 1e-10, total contact force, force balance). Our cells are "
         "the same discretization: mortar with standard multipliers, punch (upper body) slave. "
         "See docs/judge-your-code.md for the walk-through.", "",
         "## Patch and tied tests", "",
         "| case | ours: mortar ALM | Kratos ALM (mortar) | ours: mortar penalty | Kratos penalty "
         "(mortar) | DOLFINx |", "|---|---|---|---|---|---|"]
    dolfinx = ("n/a: the cross-check's DOLFINx solves contact against rigid lines and circles "
               "only (crosscheck/ref_dolfinx.py), not two meshed bodies")
    for row in rows:
        ok, kk = row["ours"], row["kratos"]

        def our(kind):
            c = ok.get(kind)
            return "-" if c is None else (f"{c['verdict']} (stress {fmt(c['stress_error'])}, "
                                          f"p {fmt(c['pressure_error'])})")
        if row["catalogue"] == "patch":
            L.append(f"| {row['case']} | {our('alm')} | {kratos_cell(kk['alm'])} | "
                     f"{our('penalty')} | {kratos_cell(kk['penalty'])} | n/a |")
        else:
            L.append(f"| {row['case']} | {our('tie')} (mortar Lagrange tie) | "
                     f"{kratos_cell(kk['alm'])} (mesh tying) | - | "
                     f"{kratos_cell(kk['penalty'])} | n/a |")
    L += ["", f"DOLFINx: {dolfinx}.", "", "### Counts", ""]
    for method, code in METHODS.items():
        for cat in ("patch", "tied"):
            n, ok, na = verdict_counts(rows, method, cat)
            L.append(f"- {code}, {cat}: {ok} of {n} cells Kratos took pass; {na} n/a.")
    unconverged = [f"{row['case']} {METHODS[m]}" for row in rows for m, k in row["kratos"].items()
                   if k.get("table", {}).get("verdict") == "pass"
                   and (k["status"] == "not converged" or any(
                       e["status"] == "not converged" for e in k.get("series", {}).values()))]
    if unconverged:
        L += ["", "Kratos' Newton reported no convergence (its relative displacement criterion "
              "1e-13 not reached in 100 iterations) on cells the judge passes: "
              + ", ".join(unconverged) + "."]
    L += ["", "The patch cases hold the punch's top-left corner at the exact u_x, so their exact "
          "solution does not slide at the interface: a code that takes the contact geometry in "
          "the current configuration (Kratos moves its mesh) solves the same problem as one "
          "that takes it in the reference configuration (ours).", "",
          "Kratos' penalty is handed to `table --results` as a kappa series (folders "
          f"`<case>/kappa-{PENALTY_KAPPAS[0]}/` ... `kappa-{PENALTY_KAPPAS[-1]}/`) and judged as "
          "our penalty cells are: the trend of the stress error from the smallest to the largest "
          "kappa (round-off at both, 1/kappa when it falls by at least a tenth of the kappa "
          "ratio, else no fall), the total contact force and the force balance at the largest "
          f"kappa. The series stops at {PENALTY_KAPPAS[-1]}: the scan of "
          f"{KAPPA_SCAN_REFERENCE} below gives the out-of-balance force of Kratos' results per "
          "kappa against the balance tolerance 1e-12. Our penalty cells are at the sweep's kappa "
          "(1e4) and 1000 times it. Cells Kratos cannot take have the converter's reason in "
          "`<case>/not-applicable.txt`; the reasons below are the table's notes.", "",
          "### Why Kratos' cells are not a pass", ""]
    why = {}  # the same reason for several cells is said once
    for row in rows:
        for method, k in row["kratos"].items():
            text = reason(k)
            if text:
                key = text if k["status"] == "n/a" else f"{row['case']}/{method}"
                why.setdefault(key, (text, []))[1].append(f"{row['case']} {METHODS[method]}")
    for text, cells in why.values():
        L.append(f"- **{', '.join(cells)}**: {text}")
    if not why:
        L.append("- every Kratos cell passes")
    ref = next((r for r in rows if r["case"] == KAPPA_SCAN_REFERENCE), None)
    if ref and ref["kratos"]["penalty"].get("scan"):
        L += ["", f"Kratos' penalty on {KAPPA_SCAN_REFERENCE} (the scan's reference) per kappa: "
              + scan_words(ref["kratos"]["penalty"]["scan"]) + "."]
    L.append("")
    # wall times
    L += ["", "### Wall times (one core each)", "",
          f"Ours: the whole patch and tied tables (every cell of both catalogues) in "
          f"{r['ours_table_seconds']:.2f} s (process wall time); per "
          "cell below, the cell's own solve (`time_ms` of the table). Kratos: the process "
          "(Python, Kratos' import, reading the input, the solve, writing the .vtu) and, in "
          "brackets, Kratos' analysis alone (`solve_seconds`, from reading the mdpa to the end "
          "of the solve).", "",
          "| case | ours mortar ALM | Kratos ALM | ours mortar penalty / tie | Kratos penalty |",
          "|---|---|---|---|---|"]
    for row in rows:
        ok, kk = row["ours"], row["kratos"]

        def t_ours(kind):
            c = ok.get(kind)
            return "-" if c is None or c.get("time_ms") is None else f"{c['time_ms']:.2f} ms"

        def t_k(k):
            if "process_seconds" not in k:
                return "n/a"
            if "series" in k:
                return (f"{k['process_seconds']:.2f} s ({k['solve_seconds']:.3f} s), "
                        f"{len(k['series'])} kappas")
            s = k.get("solve_seconds")
            return f"{k['process_seconds']:.2f} s ({s:.3f} s)" if s is not None else \
                f"{k['process_seconds']:.2f} s"
        second = "penalty" if row["catalogue"] == "patch" else "tie"
        L.append(f"| {row['case']} | {t_ours('alm')} | {t_k(row['kratos']['alm'])} | "
                 f"{t_ours(second)} | {t_k(row['kratos']['penalty'])} |")
    # Hertz
    h = r["hertz"]
    L += ["", "## Hertz: elastic cylinder on a rigid plane (cases/gmsh/hertz-cylinder.json)", "",
          f"Closed form (benchmarks.md s. 3, plane strain, rigid plane): P = {h['P']:.4g}, "
          f"R = {h['R']:.4g}, E* = {h['E_star']:.5g}, a = sqrt(4 P R / (pi E*)) = {h['a']:.5f}, "
          f"p0 = 2 P / (pi a) = {h['p0']:.5f}. Bounds as in the cross-check's Hertz table: peak "
          f"within {HERTZ_PEAK:.0%} of p0, half-width within one node spacing "
          f"({h['node_spacing']:.3g}) of a. Kratos meshes the rigid plane as a held strip "
          "(kratos_convert.py, `rigid_line_body`): its mortar pairs two meshed surfaces.", "",
          "The peak is the largest nodal `contact_pressure` of the results; beside it the "
          "largest -f_a . n_a / A_a of their `contact_force` (the pressure of the code's own "
          "assembled forces, reference normals and lengths). The half-width is half the x-extent "
          "of the nodes with a positive pressure. `judge` applies the case's checks (force "
          "balance and total force to 1e-10, peak pressure within 1 % of 5.2899).", "",
          "| code | Newton | peak pressure | error / p0 | peak of -f.n/A | half-width | error | "
          "verdict | judge | wall time (one core) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for name, e in h["codes"].items():
        newton = e.get("status", "-")
        if e.get("newton"):
            newton += (f" after {len(e['newton'])} iterations (displacement ratio per iteration "
                       + ", ".join(f"{x:.1e}" for x in e["newton"][:6])
                       + f", ..., last {e['newton'][-1]:.1e})")
        elif e.get("newton_iterations"):
            newton += f" in {e['newton_iterations']} iterations"
        wall = "-" if e.get("wall_seconds") is None else f"{e['wall_seconds']:.2f} s" + (
            f" ({e['solve_seconds']:.2f} s solve)" if e.get("solve_seconds") else "")
        if e.get("peak") is None:
            why = (e.get("reason") or "fail").replace("|", "\\|")
            L.append(f"| {name} | {newton} | - | - | - | - | - | {why} | - | {wall} |")
            continue
        j = e.get("judge")
        jtxt = "-" if j is None else f"{j['verdict']}: {j['summary']}" + "".join(
            f"; {short(c[5:])}" for c in j["checks"] if c.lower().startswith("fail"))
        jtxt = jtxt.replace("|", "\\|")  # a table cell: |K u - f - f_c| has bars
        pf = "-" if e.get("peak_of_forces") is None else f"{e['peak_of_forces']:.4f}"
        L.append(f"| {name} | {newton} | {e['peak']:.4f} | {e['peak_error']:.2%} | {pf} | "
                 f"{e['half_width']:.4f} | {e['half_width_error']:.4f} | {e['verdict']} | {jtxt} "
                 f"| {wall} |")
    L += ["", "DOLFINx: n/a for this case (the cross-check's DOLFINx Hertz is the rigid cylinder "
          "on a block, crosscheck/cases/contact/cylinder-penalty-*.json, in reports/crosscheck.md)."
          "", "", f"Elapsed: {r['elapsed_seconds']:.0f} s.", ""]
    return "\n".join(L)


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except Broken as e:
        print(f"peer: {e}", file=sys.stderr)
        sys.exit(1)
