"""Compare our results with the DOLFINx and scikit-fem references and write the verdict tables.

usage: report.py OUT_ROOT REPORT.md REPORT.json CASE.json...

For each case: OUT_ROOT/<case>/<body>.vtu and summary.json (ours), ref-dolfinx.json and
ref-skfem.json (each the displacement at every .vtu point, matched by coordinates, plus the
contact results or the tie solutions; see ref_dolfinx.py and ref_skfem.py). Quantities:

* every case: `u, all nodes (max abs)`: the value columns are max |u| over nodes and
  components; the relative difference is max |u_ref - u_ours| / max |u_ours| (the field, not
  just its maximum). One body: also `u_x, u_y at top_right`, the corner node's displacement,
  relative difference |u_ref - u_ours| / max |u_ours|.
* one-body elasticity: tolerance TOL = 1e-10, or kappa_1 eps when scikit-fem's 1-norm
  condition estimate of the reduced stiffness (`cond1_estimate`) makes that larger (round-off
  alone then moves the solutions by about that much).
* penalty contact against a rigid line or circle: also the total contact force
  (|F_ref - F_ours| / |F_ours|; ours: summary.json `contact.total_force`), the peak nodal
  pressure lambda_i / A_i (ours: `contact.max_pressure`), the number of active nodes and the
  ends of the active zone (these must be equal: the same count, the same nodes). Tolerance
  TOL_CONTACT = 1e-8 for every row of the case: both references stop Newton's method with a
  relative residual below 1e-9. The cylinder cases also feed the Hertz table (benchmarks.md
  s. 3): peak pressure within 3% of p0, half-width within one node spacing of a.
* penalty Coulomb contact on a rigid line (ref_dolfinx.solve_friction, DOLFINx only; load
  steps): the field, the total contact force (x, y), the nodal contact force at every slave
  node (ours: `<pair>.contact.csv`), each node's last status (equal); TOL_FRICTION = 1e-10
  (both Newton solves end below 1e-12). scikit-fem: not applicable.
* finite kinematics (a hyperelastic body, neo-Hookean or St. Venant-Kirchhoff, alone or with
  frictionless penalty contact against a rigid line; ref_dolfinx.solve_finite, DOLFINx only;
  the same load steps): the field, and with contact the total contact force (x, y), the nodal
  contact force at every slave node (ours: `<pair>.contact.csv`) and the number of closed
  nodes (equal); TOL_FINITE = 1e-10 (both Newton solves end below 1e-12). scikit-fem: n/a.
* 3D (bodies with a `block3d` mesh, src/run3d.rs; common.Problem3): the field (3
  components) and the corner `top_back_right`; elasticity at TOL (or kappa_1 eps), penalty
  contact against a rigid plane or sphere at TOL_CONTACT with also the total contact force
  (ours: summary.json `contact.force_on_slaves`) and the number of active rows (equal). Both
  references solve every 3D case.
* two bodies tied by a mortar pair: scikit-fem's mortar tie with the same multipliers; the
  field over both bodies (and per body), tolerance 1e-10. DOLFINx: not applicable (n/a).
* elastic waves (physics.dynamics, no contact): DOLFINx only (ref_dolfinx.solve_wave, the
  same Newmark steps on DOLFINx's stiffness and mass); the last step's field, the displacement
  history at every frame and node and at two nodes, and the kinetic, strain and load energy
  histories, tolerance TOL. scikit-fem: not applicable.
* studies (OUT_ROOT/studies.json, written by studies.py), sampled with common.Sampler:
  - tied layer: du of src/harness/layer.rs (our dual mortar tie against the one-body solution of our
    tool, DOLFINx and scikit-fem at the same level); the three must agree to 1e-8 (absolute)
    with each other and with reports/tied-layer.json, and du must shrink at every level;
  - two blocks: distances of our mortar tie and of scikit-fem's Nitsche tie to the fine
    one-body reference (DOLFINx on two-block-fine-q9) on a fixed grid; both, and the
    Nitsche-mortar difference, must shrink at every level, and the reference must be 10x closer
    to the exact field than the smallest distance.

Exit status 1 when any verdict fails (including a missing or failed reference solve).
"""

import csv
import json
import math
import os
import re
import subprocess
import xml.etree.ElementTree as ET
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

import meshio
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (ELEMENT_OF_MESHIO, Exact, Material, Problem, Problem3,  # noqa: E402
                    Sampler, TiedCase, facets_in_box, is_3d_case)

TOL = 1e-10            # same discrete linear problem: round-off
TOL_CONTACT = 1e-8     # penalty contact: the references' Newton residuals are <= 1e-9
TOL_FRICTION = 1e-10   # penalty Coulomb (DOLFINx only): both Newton solves end below 1e-12
TOL_FINITE = 1e-10     # finite kinematics (DOLFINx only): both Newton solves end below 1e-12
TOL_DU = 1e-8          # tied-layer du: absolute, between codes and against tied-layer.json
HERTZ_PEAK = 0.03      # peak nodal pressure within 3% of Hertz's p0
EXACT_MARGIN = 10.0    # the two-block reference must be this much closer to the exact field
EPS = float(np.finfo(float).eps)
SOLVERS = ("dolfinx", "skfem")
NAMES = {"dolfinx": "DOLFINx", "skfem": "scikit-fem"}
STUDY_NOTE_NITSCHE = (
    "The Nitsche tie is a different discretization of the interface (a consistent penalty "
    "coupling with no multipliers, gamma = 10 p^2 (lambda + 2 mu) / h), not our rows solved by "
    "another code, so it cannot agree with our mortar tie to round-off; both converge to the "
    "same continuum field, so it is judged only by its distance to the reference and by the "
    "Nitsche-mortar difference shrinking under refinement.")


# --- helpers ----------------------------------------------------------------------------------
def git_describe(repo):
    try:
        return subprocess.run(["git", "-C", str(repo), "describe", "--always", "--dirty"],
                              capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def load_ref(path):
    """(data, error, not_applicable) of a reference file."""
    if not path.exists():
        return None, f"no reference file {path.name}", None
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as e:
        return None, f"unreadable reference file {path.name}: {e}", None
    if "error" in data:
        return None, data["error"], None
    if "not_applicable" in data:
        return None, None, data["not_applicable"]
    return data, None, None


def ref_meta(data):
    meta = {k: data[k] for k in ("dofs", "match_distance", "seconds", "versions",
                                 "cond1_estimate", "relative_residual", "rows_kept",
                                 "supermesh_segments", "nitsche_gamma", "multiplier")
            if k in data}
    if "contact" in data:
        c = data["contact"]
        meta["newton_iterations"] = c.get("iterations")
        meta["newton_relative_residual"] = c.get("relative_residual")
        meta["contact_quadrature"] = c.get("contact_quadrature")
    return meta


def read_vtu(path):
    """(points (n, 2), cells, element, displacement (n, 2)) of one of our .vtu files."""
    m = meshio.read(path)
    if len(m.cells) != 1 or m.cells[0].type not in ELEMENT_OF_MESHIO:
        raise RuntimeError(f"cells {[b.type for b in m.cells]} in {path}")
    return (np.ascontiguousarray(m.points[:, :2], dtype=float),
            np.asarray(m.cells[0].data, dtype=np.int64), ELEMENT_OF_MESHIO[m.cells[0].type],
            np.asarray(m.point_data["displacement"][:, :2], dtype=float))


def clean(x):
    """JSON-safe copy: NaN and infinities become null, numpy scalars plain numbers."""
    if isinstance(x, dict):
        return {k: clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [clean(v) for v in x]
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def sci(v, digits=1):
    """Compact scientific notation: 9.7e-9, 4.4e7, 1.0e-10; 0 for zero."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    if v == 0:
        return "0"
    mant, exp = f"{v:.{digits}e}".split("e")
    return f"{mant}e{int(exp)}"


def tol_text(tol):
    return sci(tol, 0)


def shrinks(seq):
    return all(b < a for a, b in zip(seq, seq[1:]))


# --- the per-case rows ----------------------------------------------------------------------
class Rows:
    """The quantity rows of one case. Each row has ours, per solver its value and difference
    (relative, or absolute for `equal` rows), the tolerance and the verdict. Solvers in `na`
    are not applicable (shown as n/a, not judged); solvers in `errors` fail every row."""

    def __init__(self, refs, errors, na):
        self.refs, self.errors, self.na = refs, errors, na
        self.rows = []

    def add(self, quantity, ours, values, diffs, tol, tol_txt, kind="rel", fmt="abs"):
        judged = [s for s in SOLVERS if s not in self.na]
        ok = bool(judged) and all(
            s in diffs and diffs[s] is not None and math.isfinite(diffs[s]) and diffs[s] <= tol
            for s in judged)
        q = {"quantity": quantity, "kind": kind, "format": fmt, "ours": ours, "tol": tol,
             "tol_text": tol_txt, "verdict": "pass" if ok else "fail"}
        for s in SOLVERS:
            q[s] = values.get(s)
            q[f"rel_diff_{s}" if kind == "rel" else f"diff_{s}"] = diffs.get(s)
            if s in self.na:
                q[f"{s}_status"] = "not applicable"
            elif s in self.errors:
                q[f"{s}_status"] = "error"
        self.rows.append(q)


def field_rows(rows, u, refs, tol, tol_txt, corner=None, label="u, all nodes (max abs)",
               corner_name="top_right"):
    """The field row and, given the corner node, one row per component there (2 in 2D, 3 in
    3D, whose corner is `top_back_right`)."""
    scale = float(np.abs(u).max()) or 1.0
    vals = {s: float(np.abs(r).max()) for s, r in refs.items()}
    diffs = {s: float(np.abs(r - u).max() / scale) for s, r in refs.items()}
    rows.add(label, float(np.abs(u).max()), vals, diffs, tol, tol_txt)
    if corner is not None:
        for comp, name in list(enumerate(("u_x", "u_y", "u_z")))[:u.shape[1]]:
            vals = {s: float(r[corner, comp]) for s, r in refs.items()}
            diffs = {s: float(abs(r[corner, comp] - u[corner, comp]) / scale)
                     for s, r in refs.items()}
            rows.add(f"{name} at {corner_name}", float(u[corner, comp]), vals, diffs, tol,
                     tol_txt, fmt="signed")


def load_resultant(pb):
    """The resultant of the case's facet loads (pressure and vector tractions on straight
    facets), per unit thickness; None when a load is of another kind."""
    total = np.zeros(2)
    for ld in pb.loads:
        if ld.box is None or ld.kind not in ("pressure", "vector"):
            return None
        for f in facets_in_box(pb, ld.box):
            a, b = pb.points[f[0]], pb.points[f[1]]
            d = b - a
            length = float(np.hypot(*d))
            n = np.array([d[1], -d[0]]) / length        # counter-clockwise edge: outward
            t = -ld.value * n if ld.kind == "pressure" else np.asarray(ld.value)
            total += t * length
    return total


def contact_results(pb, data):
    """A reference's contact results, aggregated over the pairs as our summary is."""
    pairs = data["contact"]["pairs"]
    force = np.sum([p["total_force"] for p in pairs], axis=0)
    pressure = max(max(p["pressure"]) for p in pairs)
    active = [n for p in pairs for n, a in zip(p["nodes"], p["active"]) if a]
    pts = pb.points[np.asarray(active, dtype=np.int64)] if active else np.zeros((0, 2))
    extent = ([[float(pts[:, k].min()), float(pts[:, k].max())] for k in (0, 1)]
              if len(pts) else [[math.nan, math.nan], [math.nan, math.nan]])
    return {"force": force, "pressure": float(pressure), "active": len(active),
            "extent": extent}


def slave_axes(pb):
    """The axes along which the slave nodes of the contact pairs spread (the surface's
    tangential directions), and the node spacing along the surface."""
    nodes = sorted({n for pair in pb.contact for f in facets_in_box(pb, pair.box) for n in f})
    P = pb.points[nodes]
    span = P.max(axis=0) - P.min(axis=0)
    axes = [k for k in (0, 1) if span[k] > pb.tol]
    k = int(np.argmax(span))
    spacing = float(np.median(np.diff(np.sort(P[:, k]))))
    return axes, spacing, k


def case_entry(case_path, root, repo):
    name = Path(case_path).stem
    out = root / name
    cp = Path(case_path).resolve()
    entry = {"case": name, "source": str(cp.relative_to(repo)) if cp.is_relative_to(repo)
             else str(case_path)}
    try:
        case = json.loads(Path(case_path).read_text())
        summary = json.loads((out / "summary.json").read_text())
        if is_3d_case(case):
            pb = Problem3(case_path, out)
            kind = "contact-3d" if pb.contact else "elasticity-3d"
        elif len(case.get("bodies", [])) > 1:
            tc = TiedCase(case_path, out)
            kind = "tie"
        elif (case.get("physics") or {}).get("dynamics") is not None:
            pb = Problem(case_path, out, dynamic=True)
            kind = "wave"
        else:
            pb = Problem(case_path, out)
            kind = ("finite" if pb.finite else "friction" if pb.frictional
                    else "contact" if pb.contact else "elasticity")
    except Exception as e:  # noqa: BLE001  (any failure here is a failed verdict, with its text)
        entry.update({"kind": "?", "error": f"cannot read the case or our output: "
                      f"{type(e).__name__}: {e}", "verdict": "fail", "quantities": []})
        return entry, None
    entry.update({"kind": kind, "ours_checks_passed": summary.get("passed"),
                  "ours_seconds": (summary.get("timings") or {}).get("total")})

    datas, refs, errors, na, meta = {}, {}, {}, {}, {}
    for s in SOLVERS:
        data, err, why = load_ref(out / f"ref-{s}.json")
        if err:
            errors[s] = err
        elif why:
            na[s] = why
        else:
            datas[s] = data
            meta[s] = ref_meta(data)
    entry["references"] = meta
    if errors:
        entry["errors"] = errors
    if na:
        entry["not_applicable"] = na
    hertz = None
    try:
        if kind == "tie":
            rows = tie_rows(entry, tc, datas, errors, na)
        elif kind in ("wave", "friction", "finite"):
            if "dolfinx" in na:   # DOLFINx must solve every wave, friction and finite case
                errors["dolfinx"] = f"not applicable to a {kind} case: {na.pop('dolfinx')}"
                entry["errors"] = errors
            rows = (wave_rows(entry, pb, out, datas, errors, na) if kind == "wave"
                    else friction_rows(entry, pb, out, summary, datas, errors, na)
                    if kind == "friction" else finite_rows(entry, pb, out, summary, datas, errors, na))
        else:
            if na:   # a one-body case must be solved by both references
                for s, why in na.items():
                    errors[s] = f"not applicable to a one-body case: {why}"
                entry["errors"] = errors
                na = {}
            if kind.endswith("-3d"):
                rows = body_rows3(entry, pb, summary, kind, datas, errors)
            else:
                rows, hertz = body_rows(entry, pb, summary, kind, datas, errors)
    except Exception as e:  # noqa: BLE001
        entry.update({"error": f"comparison failed: {type(e).__name__}: {e}",
                      "verdict": "fail", "quantities": []})
        return entry, None
    entry["quantities"] = rows.rows
    entry["verdict"] = "pass" if rows.rows and all(q["verdict"] == "pass" for q in rows.rows) \
        else "fail"
    return entry, hertz


def body_rows(entry, pb, summary, kind, datas, errors):
    refs = {s: np.asarray(d["u"], dtype=float) for s, d in datas.items()}
    entry.update({"element": pb.element, "plane": pb.material.plane, "nodes": len(pb.points),
                  "cells": len(pb.cells)})
    rows = Rows(refs, errors, {})
    corner = pb.node_set("top_right")
    corner = int(corner[0]) if len(corner) == 1 else None
    if kind == "elasticity":
        k1 = (datas.get("skfem") or {}).get("cond1_estimate")
        if k1 is not None and k1 * EPS > TOL:
            tol, txt = k1 * EPS, f"{sci(k1 * EPS)} (k1 eps, k1 = {sci(k1)})"
        else:
            tol, txt = TOL, tol_text(TOL)
        entry["tolerance_rule"] = ("kappa_1 eps (scikit-fem's cond1_estimate)" if tol > TOL
                                   else "round-off, 1e-10")
        field_rows(rows, pb.u_ours, refs, tol, txt, corner)
        return rows, None

    # penalty contact
    tol, txt = TOL_CONTACT, tol_text(TOL_CONTACT)
    field_rows(rows, pb.u_ours, refs, tol, txt, corner)
    c = summary.get("contact")
    if c is None:
        raise RuntimeError("our summary.json has no contact section")
    res = {s: contact_results(pb, d) for s, d in datas.items()}
    F = np.asarray(c["total_force"], dtype=float)
    fn = float(np.linalg.norm(F)) or 1.0
    rows.add("total contact force (norm)", float(np.linalg.norm(F)),
             {s: float(np.linalg.norm(r["force"])) for s, r in res.items()},
             {s: float(np.linalg.norm(r["force"] - F) / fn) for s, r in res.items()}, tol, txt)
    p = float(c["max_pressure"])
    rows.add("peak nodal pressure", p, {s: r["pressure"] for s, r in res.items()},
             {s: abs(r["pressure"] - p) / (abs(p) or 1.0) for s, r in res.items()}, tol, txt)
    rows.add("active nodes", int(c["active"]), {s: r["active"] for s, r in res.items()},
             {s: float(abs(r["active"] - int(c["active"]))) for s, r in res.items()},
             0.0, "equal", kind="equal", fmt="int")
    axes, spacing, main_axis = slave_axes(pb)
    for k in axes:
        xy = "xy"[k]
        for end, label in ((0, "start"), (1, "end")):
            ours_v = float(c["active_extent"][k][end])
            rows.add(f"active zone {label} ({xy})", ours_v,
                     {s: r["extent"][k][end] for s, r in res.items()},
                     {s: abs(r["extent"][k][end] - ours_v) for s, r in res.items()},
                     pb.tol, "equal", kind="equal", fmt="signed")

    hertz = None
    circles = [pair for pair in pb.contact if pair.kind == "circle"]
    if circles:
        pair = circles[0]
        resultant = load_resultant(pb)
        P = float(np.linalg.norm(resultant)) if resultant is not None else fn / pb.thickness
        h = pair.hertz(pb, P)
        ext = c["active_extent"][main_axis]
        peak = {"ours": p, **{s: r["pressure"] for s, r in res.items()}}
        half = {"ours": 0.5 * (ext[1] - ext[0]),
                **{s: 0.5 * (r["extent"][main_axis][1] - r["extent"][main_axis][0])
                   for s, r in res.items()}}
        codes = ["ours", *SOLVERS]
        perr = {k: abs(peak[k] - h["p0"]) / h["p0"] if k in peak else None for k in codes}
        herr = {k: abs(half[k] - h["a"]) if k in half else None for k in codes}

        def verdict(errs, bound):
            ok = all(errs[k] is not None and math.isfinite(errs[k]) and errs[k] <= bound
                     for k in codes)
            return "pass" if ok else "fail"

        hertz = {"case": entry["case"], "element": pb.element,
                 "P": P, "P_from": "applied load" if resultant is not None else "contact force",
                 "R": h["R"], "E_star": h["E_star"], "a": h["a"], "p0": h["p0"],
                 "node_spacing": spacing,
                 "rows": [
                     {"quantity": "peak nodal pressure", "hertz": h["p0"],
                      **{k: peak.get(k) for k in codes},
                      **{f"err_{k}": perr[k] for k in codes},
                      "error": "relative to p0", "bound": HERTZ_PEAK,
                      "bound_text": f"{HERTZ_PEAK:.0%} of p0",
                      "verdict": verdict(perr, HERTZ_PEAK)},
                     {"quantity": "half-width of the active zone", "hertz": h["a"],
                      **{k: half.get(k) for k in codes},
                      **{f"err_{k}": herr[k] for k in codes},
                      "error": "absolute", "bound": spacing,
                      "bound_text": f"node spacing {spacing:.3g}",
                      "verdict": verdict(herr, spacing)}]}
    return rows, hertz


def body_rows3(entry, pb, summary, kind, datas, errors):
    """A 3D case (src/run3d.rs; common.Problem3): the displacement field (3 components) and the
    node at the corner `top_back_right`, with the elasticity tolerance (round-off, or kappa_1
    eps from scikit-fem's estimate); with penalty contact against a rigid plane or sphere
    (TOL_CONTACT) also the total contact force on the body (ours: summary.json
    `contact.force_on_slaves`, the rows' forces along their normals) and the number of active
    rows (equal). Both references must solve the case."""
    refs = {s: np.asarray(d["u"], dtype=float) for s, d in datas.items()}
    entry.update({"element": pb.element, "plane": "3D", "nodes": len(pb.points),
                  "cells": len(pb.cells)})
    rows = Rows(refs, errors, {})
    corner = pb.node_set("top_back_right")
    corner = int(corner[0]) if len(corner) == 1 else None
    if kind == "elasticity-3d":
        k1 = (datas.get("skfem") or {}).get("cond1_estimate")
        if k1 is not None and k1 * EPS > TOL:
            tol, txt = k1 * EPS, f"{sci(k1 * EPS)} (k1 eps, k1 = {sci(k1)})"
        else:
            tol, txt = TOL, tol_text(TOL)
        entry["tolerance_rule"] = ("kappa_1 eps (scikit-fem's cond1_estimate)" if tol > TOL
                                   else "round-off, 1e-10")
        field_rows(rows, pb.u_ours, refs, tol, txt, corner, corner_name="top_back_right")
        return rows
    tol, txt = TOL_CONTACT, tol_text(TOL_CONTACT)
    field_rows(rows, pb.u_ours, refs, tol, txt, corner, corner_name="top_back_right")
    c = summary.get("contact")
    if c is None:
        raise RuntimeError("our summary.json has no contact section")
    if c.get("termination") != "Converged":
        raise RuntimeError(f"our contact solve ended with {c.get('termination')}")
    F = np.asarray(c["force_on_slaves"], dtype=float)
    fn = float(np.linalg.norm(F)) or 1.0
    totals = {s: np.sum([p["total_force"] for p in d["contact"]["pairs"]], axis=0)
              for s, d in datas.items()}
    rows.add("total contact force (norm)", float(np.linalg.norm(F)),
             {s: float(np.linalg.norm(t)) for s, t in totals.items()},
             {s: float(np.linalg.norm(t - F) / fn) for s, t in totals.items()}, tol, txt)
    active = {s: sum(sum(p["active"]) for p in d["contact"]["pairs"]) for s, d in datas.items()}
    rows.add(f"active nodes (of {c['rows']} rows)", int(c["active"]), active,
             {s: float(abs(a - int(c["active"]))) for s, a in active.items()},
             0.0, "equal", kind="equal", fmt="int")
    return rows


def friction_rows(entry, pb, out, summary, datas, errors, na):
    """Penalty Coulomb contact on a rigid line, load-stepped (ref_dolfinx.solve_friction; the
    same rows, return map and committed history, so round-off): the displacement field, the
    total contact force (normal and tangential), the nodal contact forces at every slave node
    (ours: `<pair>.contact.csv` force_x, force_y), each node's status (open, stick, slip) at
    the last step (equal)."""
    entry.update({"element": pb.element, "plane": pb.material.plane, "nodes": len(pb.points),
                  "cells": len(pb.cells)})
    refs = {s: np.asarray(d["u"], dtype=float) for s, d in datas.items()}
    rows = Rows(refs, errors, na)
    tol, txt = TOL_FRICTION, tol_text(TOL_FRICTION)
    corner = pb.node_set("top_right")
    field_rows(rows, pb.u_ours, refs, tol, txt, int(corner[0]) if len(corner) == 1 else None)
    c = summary.get("contact")
    if c is None:
        raise RuntimeError("our summary.json has no contact section")
    F = np.asarray(c["total_force"], dtype=float)
    fn = float(np.linalg.norm(F)) or 1.0
    totals = {s: np.sum([p["total_force"] for p in d["contact"]["pairs"]], axis=0)
              for s, d in datas.items()}
    for k, xy in ((0, "x"), (1, "y")):
        rows.add(f"total contact force {xy} (rel. to |F|)", float(F[k]),
                 {s: float(t[k]) for s, t in totals.items()},
                 {s: abs(float(t[k]) - F[k]) / fn for s, t in totals.items()}, tol, txt,
                 fmt="signed")
    ours_force, ours_status = {}, {}
    for pair in pb.contact:
        with open(out / f"{pair.name}.contact.csv", newline="") as f:
            for r in csv.DictReader(f):
                if r["side"] != "slave":
                    continue
                node = int(r["node"])
                if np.abs(pb.points[node] - [float(r["x"]), float(r["y"])]).max() > pb.tol:
                    raise RuntimeError(f"{pair.name}.contact.csv node {node} is not .vtu point {node}")
                ours_force[node] = np.array([float(r["force_x"]), float(r["force_y"])])
                ours_status[node] = r["status"]
    scale = max(float(np.abs(v).max()) for v in ours_force.values()) or 1.0
    fdiff, sdiff, fref = {}, {}, {}
    for s, d in datas.items():
        ref_force = {n: np.asarray(f) for p in d["contact"]["pairs"]
                     for n, f in zip(p["nodes"], p["slave_force"])}
        ref_status = {n: st for p in d["contact"]["pairs"] for n, st in zip(p["nodes"], p["status"])}
        if sorted(ref_force) != sorted(ours_force):
            raise RuntimeError(f"{NAMES[s]}'s slave nodes differ from ours")
        fdiff[s] = max(float(np.abs(ref_force[n] - ours_force[n]).max()) for n in ours_force) / scale
        fref[s] = max(float(np.abs(v).max()) for v in ref_force.values())
        sdiff[s] = float(sum(ref_status[n] != ours_status[n] for n in ours_status))
    rows.add("nodal contact forces (max abs)", scale, fref, fdiff, tol, txt)
    counts = {st: sum(v == st for v in ours_status.values()) for st in ("open", "stick", "slip")}
    rows.add(f"nodes with another status (ours: {counts['open']} open, {counts['stick']} stick, "
             f"{counts['slip']} slip)", 0, {s: int(v) for s, v in sdiff.items()}, sdiff,
             0.0, "equal", kind="equal", fmt="int")
    return rows


def our_slave_forces(pb, out):
    """Our nodal contact force and status at every slave node (`<pair>.contact.csv`), by .vtu
    point id (checked by coordinates)."""
    force, status = {}, {}
    for pair in pb.contact:
        with open(out / f"{pair.name}.contact.csv", newline="") as f:
            for r in csv.DictReader(f):
                if r["side"] != "slave":
                    continue
                node = int(r["node"])
                if np.abs(pb.points[node] - [float(r["x"]), float(r["y"])]).max() > pb.tol:
                    raise RuntimeError(f"{pair.name}.contact.csv node {node} is not .vtu point {node}")
                force[node] = np.array([float(r["force_x"]), float(r["force_y"])])
                status[node] = r["status"]
    return force, status


def finite_rows(entry, pb, out, summary, datas, errors, na):
    """Finite kinematics (ref_dolfinx.solve_finite: the same stored energy in UFL, the same
    quadrature, load steps and, with contact, the same penalty rows): the field and, with
    contact, the total contact force, the nodal contact forces and the closed nodes."""
    entry.update({"element": pb.element, "plane": pb.material.plane, "nodes": len(pb.points),
                  "cells": len(pb.cells), "material": pb.hyperelastic,
                  "load_steps": pb.load_steps})
    entry["newton_relative_residual"] = {"ours": summary.get("relative_residual"),
                                         **{s: d["finite"]["relative_residual"]
                                            for s, d in datas.items()}}
    refs = {s: np.asarray(d["u"], dtype=float) for s, d in datas.items()}
    rows = Rows(refs, errors, na)
    tol, txt = TOL_FINITE, tol_text(TOL_FINITE)
    corner = pb.node_set("top_right")
    field_rows(rows, pb.u_ours, refs, tol, txt, int(corner[0]) if len(corner) == 1 else None)
    if not pb.contact:
        return rows
    c = summary.get("contact")
    if c is None:
        raise RuntimeError("our summary.json has no contact section")
    F = np.asarray(c["total_force"], dtype=float)
    fn = float(np.linalg.norm(F)) or 1.0
    totals = {s: np.sum([p["total_force"] for p in d["contact"]["pairs"]], axis=0)
              for s, d in datas.items()}
    for k, xy in ((0, "x"), (1, "y")):
        rows.add(f"total contact force {xy} (rel. to |F|)", float(F[k]),
                 {s: float(t[k]) for s, t in totals.items()},
                 {s: abs(float(t[k]) - F[k]) / fn for s, t in totals.items()}, tol, txt,
                 fmt="signed")
    ours_force, ours_status = our_slave_forces(pb, out)
    scale = max(float(np.abs(v).max()) for v in ours_force.values()) or 1.0
    fdiff, fref, cdiff, cref = {}, {}, {}, {}
    for s, d in datas.items():
        ref_force = {n: np.asarray(f) for p in d["contact"]["pairs"]
                     for n, f in zip(p["nodes"], p["slave_force"])}
        ref_active = {n: a for p in d["contact"]["pairs"] for n, a in zip(p["nodes"], p["active"])}
        if sorted(ref_force) != sorted(ours_force):
            raise RuntimeError(f"{NAMES[s]}'s slave nodes differ from ours")
        fdiff[s] = max(float(np.abs(ref_force[n] - ours_force[n]).max()) for n in ours_force) / scale
        fref[s] = max(float(np.abs(v).max()) for v in ref_force.values())
        cdiff[s] = float(sum(ref_active[n] != (ours_status[n] != "open") for n in ours_status))
        cref[s] = int(sum(ref_active.values()))
    rows.add("nodal contact forces (max abs)", scale, fref, fdiff, tol, txt)
    closed = sum(st != "open" for st in ours_status.values())
    rows.add("closed slave nodes (nodes with another status)", closed, cref, cdiff,
             0.0, "equal", kind="equal", fmt="int")
    return rows


def our_frames(out, body):
    """(times, displacements (frames, points, 2)) of our .pvd series of `body`."""
    pvd = ET.parse(out / f"{body}.pvd").getroot()
    times, frames = [], []
    for ds in pvd.iter("DataSet"):
        times.append(float(ds.get("timestep")))
        frames.append(read_vtu(out / ds.get("file"))[3])
    return np.asarray(times), np.asarray(frames)


def wave_rows(entry, pb, out, datas, errors, na):
    """An elastic wave without contact (ref_dolfinx.solve_wave): the displacement at the last
    step; the displacement history over every frame our tool wrote (each frame matched to the
    reference's step at the same time) at all nodes, at the top-right node and at the top node
    nearest mid-length; the kinetic, strain and load energy histories of every step
    (history.json). Relative differences: max over time (and nodes) of |ref - ours| over max
    |ours| of the same quantity. Tolerance TOL (round-off): the same discrete problem."""
    entry.update({"element": pb.element, "plane": pb.material.plane, "nodes": len(pb.points),
                  "cells": len(pb.cells), "mass": pb.dynamics.get("mass", "lumped"),
                  "tolerance_rule": "round-off, 1e-10"})
    refs = {s: np.asarray(d["u"], dtype=float) for s, d in datas.items()}
    rows = Rows(refs, errors, na)
    tol, txt = TOL, tol_text(TOL)
    corner = pb.node_set("top_right")
    corner = int(corner[0]) if len(corner) == 1 else None
    field_rows(rows, pb.u_ours, refs, tol, txt, corner, label="u at the last step, all nodes")
    times, ours = our_frames(out, pb.body)
    dt = float(pb.dynamics["dt"])
    hist = {}
    for s, d in datas.items():
        h = d["history"]
        steps = np.rint(times / dt).astype(int)
        if steps.max() >= len(h["time"]) or np.abs(np.asarray(h["time"])[steps] - times).max() \
                > 1e-9 * dt:
            raise RuntimeError(f"{NAMES[s]}'s steps do not meet our frame times")
        hist[s] = np.asarray(h["u"], dtype=float)[steps]
    scale = float(np.abs(ours).max()) or 1.0
    rows.add(f"u history, {len(times)} frames x all nodes", scale,
             {s: float(np.abs(r).max()) for s, r in hist.items()},
             {s: float(np.abs(r - ours).max() / scale) for s, r in hist.items()}, tol, txt)
    top = np.flatnonzero(np.abs(pb.points[:, 1] - pb.hi[1]) <= pb.tol)
    mid = int(top[np.argmin(np.abs(pb.points[top, 0] - 0.5 * (pb.lo[0] + pb.hi[0])))])
    for node, where in ((corner, "top_right"), (mid, "top, mid-length")):
        if node is None:
            continue
        h_ours = ours[:, node, 0]
        sc = float(np.abs(h_ours).max()) or 1.0
        rows.add(f"u_x history at {where}", sc,
                 {s: float(np.abs(r[:, node, 0]).max()) for s, r in hist.items()},
                 {s: float(np.abs(r[:, node, 0] - h_ours).max() / sc) for s, r in hist.items()},
                 tol, txt)
    steps = json.loads((out / "history.json").read_text())["steps"]
    for ours_key, ref_key, what in (("kinetic", "kinetic", "kinetic"),
                                    ("strain", "strain", "strain"),
                                    ("load_potential", "load", "load potential")):
        e = np.asarray([st[ours_key] for st in steps], dtype=float)
        sc = float(np.abs(e).max()) or 1.0
        refs_e = {s: np.asarray(d["energy"][ref_key], dtype=float) for s, d in datas.items()}
        for s, r in refs_e.items():
            if len(r) != len(e):
                raise RuntimeError(f"{NAMES[s]} has {len(r)} steps, ours {len(e)}")
        rows.add(f"{what} energy history, {len(e)} steps", sc,
                 {s: float(np.abs(r).max()) for s, r in refs_e.items()},
                 {s: float(np.abs(r - e).max() / sc) for s, r in refs_e.items()}, tol, txt)
    return rows


def tie_rows(entry, tc, datas, errors, na):
    pbs = [tc.bodies[n] for n in tc.order]
    els = sorted({pb.element for pb in pbs})
    entry.update({"element": "/".join(els), "plane": pbs[0].material.plane,
                  "nodes": sum(len(pb.points) for pb in pbs),
                  "cells": sum(len(pb.cells) for pb in pbs), "multiplier": tc.multiplier,
                  "bodies": tc.order, "slave": tc.slave, "master": tc.master})
    refs = {}
    for s, d in datas.items():
        if "bodies" not in d:
            raise RuntimeError(f"{NAMES[s]}'s reference has no tie solution")
        refs[s] = {n: np.asarray(d["bodies"][n], dtype=float) for n in tc.order}
    u = np.vstack([pb.u_ours for pb in pbs])
    both = {s: np.vstack([r[n] for n in tc.order]) for s, r in refs.items()}
    rows = Rows(both, errors, na)
    scale = float(np.abs(u).max()) or 1.0
    field_rows(rows, u, both, TOL, tol_text(TOL), label="u, both bodies (max abs)")
    for n, pb in zip(tc.order, pbs):
        vals = {s: float(np.abs(r[n]).max()) for s, r in refs.items()}
        diffs = {s: float(np.abs(r[n] - pb.u_ours).max() / scale) for s, r in refs.items()}
        rows.add(f"u, body {n} (max abs)", float(np.abs(pb.u_ours).max()), vals, diffs,
                 TOL, tol_text(TOL))
    return rows


# --- studies ----------------------------------------------------------------------------------
def layer_lines():
    """The sample points of src/harness/layer.rs: the interface y = 4 just inside the layer (201
    points), the vertical x = 1 through the layer (51 points)."""
    pts = [(10.0 * i / 200.0, 4.0 + 1e-6) for i in range(201)]
    pts += [(1.0, 4.0 + 1e-6 + (1.0 - 2e-6) * i / 50.0) for i in range(51)]
    return np.array(pts)


def tied_layer_study(study, root, repo):
    el = study["element"]
    out = {"study": f"tied layer {el}", "element": el, "levels": study["levels"], "rows": []}
    try:
        published = json.loads((repo / "reports" / "tied-layer.json").read_text())
        pub = {r["level"]: r["du"] for r in published
               if r["element"] == el and r["variant"] == "dual mortar"}
    except (OSError, ValueError, KeyError) as e:
        pub = {}
        out["warning"] = f"reports/tied-layer.json unreadable: {e}"
    P = layer_lines()
    problems = []
    for k, one, tie in zip(study["levels"], study["one_body"], study["tie"]):
        row = {"level": k, "one_body": one["name"], "tie": tie["name"]}
        try:
            tcase = json.loads((root / "cases" / f"{tie['name']}.json").read_text())
            mult = tcase["contact"][0]["discretization"].get("multiplier", "standard")
            if mult != "dual":
                raise RuntimeError(f"{tie['name']}: multiplier {mult!r}, the study measures "
                                   "the dual mortar tie")
            lp, lc, le, lu = read_vtu(root / tie["name"] / "layer.vtu")
            u_tie = Sampler(lp, lc, le).values(lu, P)[:, 1]
            bp, bc, be, bu = read_vtu(root / one["name"] / "body.vtu")
            sb = Sampler(bp, bc, be)
            fields = {"ours": bu}
            for s in SOLVERS:
                data, err, why = load_ref(root / one["name"] / f"ref-{s}.json")
                if data is None:
                    raise RuntimeError(f"{one['name']}: {NAMES[s]} reference: {err or why}")
                fields[s] = np.asarray(data["u"], dtype=float)
            du = {}
            for code, U in fields.items():
                ref = sb.values(U, P)[:, 1]
                du[code] = float(np.abs(u_tie - ref).max() / np.abs(ref).max())
            row.update({f"du_{c}": v for c, v in du.items()})
            row["spread"] = max(du.values()) - min(du.values())
            row["published"] = pub.get(k)
            row["diff_published"] = (max(abs(v - pub[k]) for v in du.values())
                                     if k in pub else None)
            ok = row["spread"] <= TOL_DU and row["diff_published"] is not None \
                and row["diff_published"] <= TOL_DU
            row["verdict"] = "pass" if ok else "fail"
            if row["diff_published"] is None:
                problems.append(f"level {k}: no dual-mortar du in reports/tied-layer.json")
        except Exception as e:  # noqa: BLE001
            row.update({"error": f"{type(e).__name__}: {e}", "verdict": "fail"})
            problems.append(f"level {k}: {row['error']}")
        out["rows"].append(row)
    complete = all("error" not in r for r in out["rows"])
    out["shrinks"] = complete and all(
        shrinks([r[f"du_{c}"] for r in out["rows"]]) for c in ("ours", *SOLVERS))
    out["verdict"] = "pass" if complete and out["shrinks"] and all(
        r["verdict"] == "pass" for r in out["rows"]) else "fail"
    if problems:
        out["problems"] = problems
    return out


def grid(lo, hi, nx=201, ny=41):
    xs, ys = np.linspace(lo[0], hi[0], nx), np.linspace(lo[1], hi[1], ny)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    return np.stack([X.ravel(), Y.ravel()], axis=1)


def sample_bodies(bodies, U, P):
    """Values of a two-body field at the points P: each point in every body whose bounding box
    holds it (interface points in both). Returns (point index, value) arrays."""
    idx, vals = [], []
    for name, (pts, cells, el) in bodies.items():
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        tol = 1e-9 * float(np.hypot(*(hi - lo)))
        inside = np.flatnonzero(np.all((P >= lo - tol) & (P <= hi + tol), axis=1))
        idx.append(inside)
        vals.append(Sampler(pts, cells, el).values(U[name], P[inside]))
    return np.concatenate(idx), np.vstack(vals)


def two_block_study(study, root):
    el = study["element"]
    fine = study["fine"]["name"]
    out = {"study": f"two blocks {el}", "element": el, "levels": study["levels"],
           "multiplier": study["multiplier"], "fine": fine, "rows": []}
    problems = []
    try:
        fcase = json.loads((root / "cases" / f"{fine}.json").read_text())
        fp, fc, fe, _ = read_vtu(root / fine / f"{fcase['bodies'][0]['name']}.vtu")
        data, err, why = load_ref(root / fine / "ref-dolfinx.json")
        if data is None:
            raise RuntimeError(f"{fine}: DOLFINx reference: {err or why}")
        G = grid(fp.min(axis=0), fp.max(axis=0))
        u_fine = Sampler(fp, fc, fe).values(np.asarray(data["u"], dtype=float), G)
        m = fcase["materials"][fcase["bodies"][0]["material"]]
        mat = Material(m["E"], m["nu"], fcase["analysis"]["plane"])
        u_exact = Exact(fcase["exact"]).displacement(G, mat)
        out["reference_to_exact"] = float(np.abs(u_fine - u_exact).max()
                                          / np.abs(u_exact).max())
        out["grid"] = f"{201} x {41} points over the beam"
    except Exception as e:  # noqa: BLE001
        out.update({"error": f"fine reference: {type(e).__name__}: {e}", "verdict": "fail"})
        return out

    def distances(name):
        case = json.loads((root / "cases" / f"{name}.json").read_text())
        names = [b["name"] for b in case["bodies"]]
        meshes, ours = {}, {}
        for n in names:
            p, c, e, u = read_vtu(root / name / f"{n}.vtu")
            meshes[n], ours[n] = (p, c, e), u
        scale = float(np.abs(u_fine).max())
        i, v = sample_bodies(meshes, ours, G)
        row = {"case": name, "d_mortar": float(np.abs(v - u_fine[i]).max() / scale)}
        data, err, why = load_ref(root / name / "ref-skfem.json")
        if data is None:
            raise RuntimeError(f"{name}: scikit-fem reference: {err or why}")
        nit = {n: np.asarray(data["nitsche"][n], dtype=float) for n in names}
        i, v = sample_bodies(meshes, nit, G)
        row["d_nitsche"] = float(np.abs(v - u_fine[i]).max() / scale)
        uo = np.vstack([ours[n] for n in names])
        un = np.vstack([nit[n] for n in names])
        row["nitsche_vs_mortar"] = float(np.abs(un - uo).max() / np.abs(uo).max())
        return row

    for k, tie in zip(study["levels"], study["tie"]):
        try:
            row = {"level": k, **distances(tie["name"])}
        except Exception as e:  # noqa: BLE001
            row = {"level": k, "case": tie["name"], "error": f"{type(e).__name__}: {e}"}
            problems.append(f"level {k}: {row['error']}")
        out["rows"].append(row)
    other = study.get("other_multiplier")
    if other:
        try:
            r = distances(other["name"])
            out["other_multiplier"] = {"case": other["name"], "d_mortar": r["d_mortar"]}
        except Exception as e:  # noqa: BLE001
            out["other_multiplier"] = {"case": other["name"],
                                       "error": f"{type(e).__name__}: {e}"}
    complete = all("error" not in r for r in out["rows"])
    if complete:
        rows = out["rows"]
        smallest = min(min(r["d_mortar"], r["d_nitsche"]) for r in rows)
        out["checks"] = {
            "mortar distance shrinks": shrinks([r["d_mortar"] for r in rows]),
            "Nitsche distance shrinks": shrinks([r["d_nitsche"] for r in rows]),
            "Nitsche-mortar difference shrinks": shrinks([r["nitsche_vs_mortar"] for r in rows]),
            f"reference {EXACT_MARGIN:.0f}x closer to the exact field than the smallest "
            f"distance": EXACT_MARGIN * out["reference_to_exact"] <= smallest,
        }
        out["smallest_distance"] = smallest
    out["verdict"] = "pass" if complete and all(out["checks"].values()) else "fail"
    if problems:
        out["problems"] = problems
    return out


# --- the report -------------------------------------------------------------------------------
def value(v, fmt):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    if fmt == "int":
        return f"{int(v)}"
    return f"{v:+.6e}" if fmt == "signed" else f"{v:.6e}"


def diff_cell(q, s):
    key = f"rel_diff_{s}" if q["kind"] == "rel" else f"diff_{s}"
    st = q.get(f"{s}_status")
    if st == "not applicable":
        return "n/a"
    if st == "error":
        return "error"
    d = q.get(key)
    if q["kind"] != "rel" and d is not None and math.isfinite(d):
        return f"{d:.3g}"
    return sci(d)


JUDGE_LINE = re.compile(r"^  (pass|FAIL) (.*) \(error ([^,]+), tol ([^)]+)\)$")


def check_words(text):
    """A check's words without its measured value (`reaction ... = 1.2e-15 (...)`) and without
    the results field `judge` read it from (` [from the results' 'contact_force']`)."""
    return text.split(" [from the results' ")[0].split(" = ")[0]


def judged_entry(case_path, root):
    """DOLFINx's own .vtu of a case judged by `contact-patch judge` (crosscheck/run.sh step 5):
    every judged check's error and verdict from the judge's output, its verdicts from its JUnit
    file (which must agree), and our run's verdict of the same check (summary.json). The entry
    passes when the judge ran (exit 0 or 1) and every judged verdict equals ours; a check of
    the results' own stress field is compared with our uniform-stress verdict."""
    name = Path(case_path).stem
    folder = root / name
    xml = folder / "judge-dolfinx.xml"
    rc_file = folder / "judge-dolfinx.rc"
    if not rc_file.exists():
        return None
    rc = int(rc_file.read_text())
    text = (folder / "judge-dolfinx.txt").read_text()
    entry = {"case": name, "exit": rc, "rows": [], "not_judged": [], "verdict": "fail"}
    if rc not in (0, 1) or not xml.exists():
        entry["error"] = text.strip().splitlines()[-1] if text.strip() else f"exit {rc}"
        return entry
    statuses = []
    for tc in ET.parse(xml).getroot().iter("testcase"):
        if tc.find("skipped") is not None:
            entry["not_judged"].append(tc.get("name"))
        else:
            statuses.append("fail" if tc.find("failure") is not None else "pass")
    summary = json.loads((folder / "summary.json").read_text())
    ours = {check_words(c["check"]): c for c in summary["checks"]}
    uniform = next((c for c in summary["checks"] if c["check"].startswith("uniform stress")),
                   None)
    lines = [m for m in (JUDGE_LINE.match(ln) for ln in text.splitlines()) if m]
    agree = len(lines) == len(statuses)
    for m, status in zip(lines, statuses):
        verdict, check, error, tol = m.groups()
        mine = ours.get(check_words(check))
        if mine is None and "results' own nodal 'stress'" in check:
            mine = uniform
        row = {"check": check, "error": float(error), "tol": float(tol),
               "verdict": "pass" if verdict == "pass" else "fail", "junit": status,
               "ours_error": mine["error"] if mine else None,
               "ours_verdict": ("pass" if mine["passed"] else "fail") if mine else None}
        row["agree"] = row["verdict"] == status and (mine is None
                                                     or row["verdict"] == row["ours_verdict"])
        agree &= row["agree"]
        entry["rows"].append(row)
    entry["verdict"] = "pass" if agree else "fail"
    return entry


def write_md(path, report):
    v = report["versions"]
    tl = report["studies"]["tied_layer"]
    tb = report["studies"]["two_block"]
    lines = [
        "# Cross-check: our results against DOLFINx and scikit-fem",
        "",
        f"Generated by `bash crosscheck/run.sh` on {report['generated']} (contact-patch "
        f"`{report['ours_version']}`; DOLFINx {v.get('dolfinx', '?')}, basix "
        f"{v.get('basix', '?')}, scikit-fem {v.get('scikit-fem', '?')}, Python "
        f"{report['python']}).",
        "",
        f"**{report['passed']} of {report['total']} entries pass** (cases and studies); Hertz "
        f"table: {report['hertz_passed']} of {report['hertz_rows']} rows pass. Worst relative "
        f"difference between codes solving the same discrete problem: {report['worst_text']}.",
        "",
        f"Cases: {report['cases_passed']} of {len(report['results'])} pass; studies: "
        f"{report['studies_passed']} of {len(tl) + len(tb)} pass.",
        "",
        "Each case is solved by our tool; DOLFINx and scikit-fem then solve it on the mesh our "
        "tool wrote (`<body>.vtu`, read with meshio), with the case's material, supports and "
        "loads and the same stiffness quadrature (Gauss 2x2 for Q4, 3x3 for Q9; triangles are "
        "affine). Nodal values are matched by coordinates. *rel. diff* of a displacement row is "
        "max |u_ref - u_ours| / max |u_ours| over all nodes and both components (corner rows: "
        "that node's difference over the same max |u_ours|); value columns: max |u| for the "
        "field rows, the component for the corner rows. Contact rows: |F_ref - F_ours| / "
        "|F_ours| for the total contact force, |p_ref - p_ours| / p_ours for the peak nodal "
        "pressure lambda_i / A_i; the active nodes and the ends of the active zone must be "
        "equal (their columns show the absolute difference). Tolerances: 1e-10 for linear "
        "problems (round-off), or kappa_1 eps when scikit-fem's estimate of the reduced "
        "stiffness' 1-norm condition number makes that larger (*k1 eps*); 1e-8 for penalty "
        "contact (both references stop Newton's method at a relative residual below 1e-9). "
        "Two-body ties are compared with scikit-fem's mortar tie (the same multiplier rows); "
        "DOLFINx does not solve them (n/a, not judged). Elastic waves (`wave-bar-*`, "
        "physics.dynamics without contact): DOLFINx assembles the stiffness and mass on our "
        "mesh and ref_dolfinx.py steps Newmark's method with the case's beta, gamma and dt "
        "(consistent mass, or its row sums for the lumped case); the displacement history at "
        "every frame and node, at two nodes, and the energy histories are compared, tolerance "
        "1e-10 (the same discrete problem); scikit-fem: n/a. Penalty Coulomb contact "
        "(`coulomb-block-*`, load steps): DOLFINx assembles the stiffness and load vectors and "
        "ref_dolfinx.py runs the same return map per slave node with the plastic slip committed "
        "per step; the field, the total contact force, the nodal contact forces (max abs "
        "difference over the largest nodal force) and each node's last status (equal) are "
        "compared, tolerance 1e-10; scikit-fem: n/a. Finite kinematics (`neo-hookean-*`, "
        "`svk-*`: a hyperelastic body, alone or pressed onto a rigid line with a penalty): "
        "DOLFINx solves the same total-Lagrangian problem, the stored energy written in UFL "
        "and differentiated by UFL, with the same quadrature and load steps and, with "
        "contact, the same penalty rows (the current gap at the slave nodes, our nodal "
        "weights); the field, the total and nodal contact forces and the closed nodes (equal) "
        "are compared, tolerance 1e-10 (both Newton solves end below a relative residual of "
        "1e-12); scikit-fem: n/a. 3D cases (`patch-*` of cases/3d, `*-3d-*`; plane column "
        "*3D*): both references solve them on our Hex8, Hex27, Tet4 and Tet10 meshes with the "
        "stiffness quadrature of src/fe3d.rs; the field (3 components), the corner "
        "`top_back_right` and, for the rigid sphere with penalty rows, the total contact force "
        "and the number of active rows are compared, at the 2D tolerances (1e-10 or k1 eps; "
        "1e-8 with contact).",
        "",
        "| case | element | plane | nodes | quantity | ours | DOLFINx | scikit-fem "
        "| rel. diff DOLFINx | rel. diff scikit-fem | tol | verdict |",
        "|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for e in report["results"]:
        if not e["quantities"]:
            lines.append(f"| {e['case']} | | | | {e.get('error', 'no result')} | | | | | | | "
                         f"**FAIL** |")
            continue
        for i, q in enumerate(e["quantities"]):
            head = (f"| {e['case']} | {e['element']} | {e['plane']} | {e['nodes']} |" if i == 0
                    else "| | | | |")
            vals = [value(q[k], q["format"]) if not (k != "ours" and q.get(f"{k}_status"))
                    else ("n/a" if q.get(f"{k}_status") == "not applicable" else "error")
                    for k in ("ours", "dolfinx", "skfem")]
            verdict = "pass" if q["verdict"] == "pass" else "**FAIL**"
            lines.append(f"{head} {q['quantity']} | {vals[0]} | {vals[1]} | {vals[2]} "
                         f"| {diff_cell(q, 'dolfinx')} | {diff_cell(q, 'skfem')} "
                         f"| {q['tol_text']} | {verdict} |")
    errs = [(e["case"], NAMES[s], m) for e in report["results"]
            for s, m in e.get("errors", {}).items()]
    errs += [(e["case"], "comparison", e["error"]) for e in report["results"] if e.get("error")]
    if errs:
        lines += ["", "## Errors", ""]
        lines += [f"- {c}, {s}: {m}" for c, s, m in errs]

    # studies
    lines += ["", "## Studies", ""]
    if not tl and not tb:
        lines += ["Not run (cases given on the command line, or no studies.json).", ""]
    if tl:
        lines += [
            "### Tied layer (cases/tied-layer, src/harness/layer.rs)",
            "",
            "du = max |u_y - u_y,ref| / max |u_y,ref| over the sample lines of src/harness/layer.rs "
            "(the interface y = 4 + 1e-6 at 201 points, x = 1 through the layer at 51 points), "
            "u_y from our dual mortar tie (layer body), u_y,ref from the one-body mesh at the "
            "same level solved by each code. The three du must agree to 1e-8 (absolute) with "
            "each other and with the dual-mortar du of reports/tied-layer.json, and shrink at "
            "every level.",
            "",
            "| element | level | du, ref. ours | du, ref. DOLFINx | du, ref. scikit-fem "
            "| reports/tied-layer.json | spread | max diff to json | verdict |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---|",
        ]
        for s in tl:
            for r in s["rows"]:
                verdict = "pass" if r["verdict"] == "pass" else "**FAIL**"
                if "error" in r:
                    lines.append(f"| {s['element']} | {r['level']} | {r['error']} | | | | | | "
                                 f"{verdict} |")
                    continue
                pub = "n/a" if r["published"] is None else f"{r['published']:.10f}"
                lines.append(
                    f"| {s['element']} | {r['level']} | {r['du_ours']:.10f} | "
                    f"{r['du_dolfinx']:.10f} | {r['du_skfem']:.10f} | {pub} | "
                    f"{sci(r['spread'])} | {sci(r['diff_published'])} | {verdict} |")
        lines.append("")
        for s in tl:
            shr = ("yes" if s["shrinks"] else "**no**") \
                if all("error" not in r for r in s["rows"]) else "n/a (a level is missing)"
            lines.append(f"- {s['study']}: du shrinks at every level: {shr}; study "
                         f"{'passes' if s['verdict'] == 'pass' else '**FAILS**'}."
                         + (" " + "; ".join(s["problems"]) if s.get("problems") else ""))
        lines.append("")
    if tb:
        lines += [
            "### Two blocks (crosscheck/cases/two-block)",
            "",
            "Distances to the fine one-body reference (two-block-fine-q9, the DOLFINx "
            "solution) on a fixed grid of 201 x 41 points over the beam: max |u - u_ref| / "
            "max |u_ref| over both components, each point evaluated in every block that holds "
            "it (interface points in both). *mortar*: our tie; *Nitsche*: scikit-fem's Nitsche "
            "tie; *Nitsche - mortar*: max |u_Nitsche - u_ours| / max |u_ours| over the nodes of "
            "both blocks. Passes when the distances of both ties and the Nitsche-mortar "
            f"difference shrink at every level and the reference is {EXACT_MARGIN:.0f}x closer "
            "to the exact field than the smallest distance. (Our mortar tie against "
            "scikit-fem's mortar tie with the same rows is in the case table, to 1e-10.)",
            "",
            "| element | multiplier | level | case | mortar (ours) | Nitsche (scikit-fem) "
            "| Nitsche - mortar |",
            "|---|---|---:|---|---:|---:|---:|",
        ]
        for s in tb:
            for r in s["rows"]:
                if "error" in r:
                    lines.append(f"| {s['element']} | {s['multiplier']} | {r['level']} | "
                                 f"{r['case']} | {r['error']} | | |")
                    continue
                lines.append(f"| {s['element']} | {s['multiplier']} | {r['level']} | "
                             f"{r['case']} | {sci(r['d_mortar'], 3)} | "
                             f"{sci(r['d_nitsche'], 3)} | {sci(r['nitsche_vs_mortar'], 3)} |")
            o = s.get("other_multiplier")
            if o and "d_mortar" in o:
                lines.append(f"| {s['element']} | {'standard' if s['multiplier'] == 'dual' else 'dual'}"
                             f" | 1 | {o['case']} | {sci(o['d_mortar'], 3)} | | |")
        lines.append("")
        for s in tb:
            if "error" in s:
                lines.append(f"- {s['study']}: **FAILS**: {s['error']}")
                continue
            checks = "; ".join(f"{k}: {'yes' if ok else '**no**'}"
                               for k, ok in (s.get("checks") or {}).items()) \
                or "not judged (a level is missing)"
            lines.append(
                f"- {s['study']}: reference to exact field {sci(s['reference_to_exact'])}, "
                f"smallest distance {sci(s.get('smallest_distance'))}; {checks}; study "
                f"{'passes' if s['verdict'] == 'pass' else '**FAILS**'}."
                + (" " + "; ".join(s["problems"]) if s.get("problems") else ""))
        lines += ["", STUDY_NOTE_NITSCHE, ""]

    # Hertz
    lines += ["", "## Hertz: rigid cylinder on a block (plane strain)", ""]
    if report["hertz"]:
        lines += [
            "benchmarks.md s. 3 with a rigid cylinder: E* = E/(1 - nu^2), a = sqrt(4 P R/(pi "
            "E*)), p0 = 2P/(pi a), P the applied load per unit thickness. The peak nodal "
            "pressure of each code must be within 3% of p0 and the half-width of its active "
            "zone (half the distance between its end nodes) within one node spacing of a. The "
            "discrete peak pressure is a nodal value of a penalty solution on a finite block, "
            "so it is not expected to match p0 more closely than that.",
            "",
            "| case | P | R | E* | a | p0 | quantity | Hertz | ours | DOLFINx | scikit-fem "
            "| worst error | bound | verdict |",
            "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---|---|",
        ]
        for h in report["hertz"]:
            for i, r in enumerate(h["rows"]):
                head = (f"| {h['case']} | {h['P']:.4g} | {h['R']:.4g} | {h['E_star']:.4g} | "
                        f"{h['a']:.4f} | {h['p0']:.4f} |" if i == 0 else "| | | | | | |")
                errs_r = [r.get(f"err_{k}") for k in ("ours", *SOLVERS)]
                worst = max((x for x in errs_r if x is not None), default=None)
                wtxt = ("n/a" if worst is None else
                        f"{worst:.2%}" if r["error"] == "relative to p0" else f"{worst:.4f}")
                cells = " | ".join("n/a" if r.get(k) is None else f"{r[k]:.4f}"
                                   for k in ("ours", *SOLVERS))
                verdict = "pass" if r["verdict"] == "pass" else "**FAIL**"
                lines.append(f"{head} {r['quantity']} | {r['hertz']:.4f} | {cells} | {wtxt} "
                             f"| {r['bound_text']} | {verdict} |")
    else:
        lines.append("No cylinder case in this run.")

    judged = report.get("judged", [])
    lines += ["", "## DOLFINx's own output judged by `contact-patch judge`", ""]
    if judged:
        lines += [
            "DOLFINx writes its solution of each single-body case itself (`dolfinx.io.VTKFile`: "
            "point fields `displacement` and `stress`, sigma(u_h) interpolated at the nodes; "
            "with rigid-obstacle contact also `contact_force`, its assembled nodal penalty "
            "force, `contact_pressure`, kappa (-g)_+ at the slave nodes, and `contact_gap`, "
            "from which the contact checks are judged); "
            "`contact-patch judge CASE dolfinx_p0_000000.vtu --junit ...` applies the case's "
            "checks to it, as for an outside code. *ours*: the same check on our own run. "
            f"**{report['judged_passed']} of {len(judged)} cases agree** (every judged verdict "
            "equal to ours, and to the JUnit file's).",
            "",
            "| case | check | DOLFINx error (judged) | tol | verdict | ours | our verdict |",
            "|---|---|---:|---:|---|---:|---|",
        ]
        for e in judged:
            if not e["rows"]:
                verdict = "n/a" if e["verdict"] == "pass" else "**FAIL**"
                lines.append(f"| {e['case']} | {e.get('error', 'no check judged')} | | | "
                             f"{verdict} | | |")
            for i, r in enumerate(e["rows"]):
                ours = sci(r["ours_error"]) if r["ours_error"] is not None else "-"
                verdict = r["verdict"] if r["agree"] else f"**{r['verdict']} (disagrees)**"
                lines.append(f"| {e['case'] if i == 0 else ''} | {r['check']} | "
                             f"{sci(r['error'])} | {tol_text(r['tol'])} | {verdict} | {ours} | "
                             f"{r['ours_verdict'] or '-'} |")
            if e["not_judged"]:
                lines.append(f"| | not judged (see judge-dolfinx.txt for why): "
                             f"{len(e['not_judged'])} | | | | | |")
    else:
        lines.append("No DOLFINx .vtu was judged in this run.")
    lines += [
        "",
        "## Cases",
        "",
        "- `cases/patch-single/*`: constant-stress patch tests on distorted meshes; all three "
        "codes reproduce the exact linear field, so they agree to round-off by construction.",
        "- `cases/convergence/cantilever-*`: Timoshenko's cantilever on rectangular 8x2 meshes "
        "(exact displacement on x = 0, exact parabolic traction on x = 10); the discrete "
        "solution is not the exact one, so agreement tests the assembled operator and loads.",
        "- `crosscheck/cases/*.json` (cross-check only): the same cantilever on a distorted 8x2 "
        "mesh (non-affine quadrilaterals), and a distorted block clamped on one side under "
        "pressure, a partial vector traction and a body force (plane strain and stress, "
        "thickness 0.5).",
        "- `crosscheck/cases/contact/*`: penalty contact with node-to-surface rows against a "
        "rigid line (a block pressed on part of its top, lifting off beyond the load: the "
        "active set is a genuine unknown) and a rigid cylinder (Hertz), Q4 and Q9; the "
        "references solve the same penalty problem by Newton's method with the nodal "
        "quadrature of our rows.",
        "- `cases/3d/patch-*`: the 3D uniform-stress patch tests (pressure on a distorted "
        "block, Hex8, Hex27, Tet4, Tet10).",
        "- `crosscheck/cases/3d/*`: `clamped-pressure-3d-*`, a block clamped on one side under "
        "pressures on its top and back (bending and twisting) on meshes with eight vertex "
        "moves; `sphere-block-penalty-3d-*`, a rigid sphere pressed into a block by its "
        "lifted bottom, node-to-surface penalty rows (kappa = 1e5), an off-centre contact patch "
        "of 12 to 16 of the 121 top nodes; all four elements.",
        "- `one-body-layer-*-x*`, `tied-layer-*-x*` (generated from `cases/tied-layer/`): the "
        "tied layer's one-body meshes (elasticity rows) and dual mortar ties (tie rows) at "
        "levels 1, 2, 4, 8.",
        "- `two-block-*` (generated from `crosscheck/cases/two-block/`): the cantilever cut "
        "into two non-matching blocks and tied (dual multipliers at levels 1, 2, 4, standard "
        "at level 1), and the fine one-body reference `two-block-fine-q9` (Q9 160 x 32, 42k "
        "dofs, kappa_1 about 4.4e7: all three codes differ by about 1e-10 there purely from "
        "round-off, which its k1 eps tolerance covers).",
        "",
        (f"Wall time of the run: {report['seconds']:.0f} s before the report, "
         if math.isfinite(report["seconds"]) else "Wall time of the run: unknown before the "
         "report, ") + f"{report['report_seconds']:.0f} s for the report.",
        "",
    ]
    tidy = []
    for line in lines:       # one blank line before each heading, never two in a row
        if line.startswith("#") and tidy and tidy[-1] != "":
            tidy.append("")
        if line == "" and tidy and tidy[-1] == "":
            continue
        tidy.append(line)
    Path(path).write_text("\n".join(tidy))


def main(argv):
    t0 = time.perf_counter()
    root, md, js = Path(argv[1]), Path(argv[2]), Path(argv[3])
    repo = Path(__file__).resolve().parent.parent
    cases = argv[4:]
    results, hertz = [], []
    for c in cases:
        entry, h = case_entry(c, root, repo)
        results.append(entry)
        if h is not None:
            hertz.append(h)
    studies = {"tied_layer": [], "two_block": []}
    manifest = root / "studies.json"
    if manifest.exists():
        m = json.loads(manifest.read_text())
        studies["tied_layer"] = [tied_layer_study(s, root, repo) for s in m.get("tied_layer", [])]
        studies["two_block"] = [two_block_study(s, root) for s in m.get("two_block", [])]
    all_studies = studies["tied_layer"] + studies["two_block"]
    judged = [j for j in (judged_entry(c, root) for c in cases) if j is not None]

    versions = {}
    for e in results:
        for meta in e.get("references", {}).values():
            versions.update(meta.get("versions", {}))
    worst, where = -1.0, None
    for e in results:
        for q in e["quantities"]:
            if q["kind"] != "rel":
                continue
            for s in SOLVERS:
                d = q.get(f"rel_diff_{s}")
                if d is not None and d > worst:
                    worst, where = d, (e["case"], q["quantity"], NAMES[s], q["tol_text"])
    if where:
        worst_text = (f"{sci(worst)} ({where[0]}, {where[1]}, {where[2]}; tolerance "
                      f"{where[3]})")
        rest = [(q[f"rel_diff_{s}"], e["case"]) for e in results if e["case"] != where[0]
                for q in e["quantities"] if q["kind"] == "rel" for s in SOLVERS
                if q.get(f"rel_diff_{s}") is not None]
        if rest:
            d, c = max(rest)
            worst_text += f"; every other case within {sci(d)} ({c})"
    else:
        worst_text = "n/a"
    seconds = float((root / "elapsed").read_text()) if (root / "elapsed").exists() else math.nan
    cases_passed = sum(e["verdict"] == "pass" for e in results)
    studies_passed = sum(s["verdict"] == "pass" for s in all_studies)
    hertz_rows = [r for h in hertz for r in h["rows"]]
    hertz_passed = sum(r["verdict"] == "pass" for r in hertz_rows)
    report = {
        "generated": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "ours_version": os.environ.get("XCHECK_OURS_VERSION") or git_describe(repo),
        "python": sys.version.split()[0],
        "versions": versions,
        "tolerances": {"linear": TOL, "linear_rule": "max(1e-10, kappa_1 eps) with kappa_1 "
                       "scikit-fem's cond1_estimate", "contact": TOL_CONTACT, "friction": TOL_FRICTION,
                       "finite": TOL_FINITE,
                       "tie": TOL, "tied_layer_du": TOL_DU, "hertz_peak": HERTZ_PEAK,
                       "hertz_half_width": "one node spacing",
                       "two_block_exact_margin": EXACT_MARGIN},
        "passed": cases_passed + studies_passed,
        "total": len(results) + len(all_studies),
        "cases_passed": cases_passed,
        "studies_passed": studies_passed,
        "hertz_passed": hertz_passed,
        "hertz_rows": len(hertz_rows),
        "worst_rel_diff": worst if where else None,
        "worst_location": list(where) if where else None,
        "worst_text": worst_text,
        "seconds": seconds,
        "results": results,
        "hertz": hertz,
        "studies": studies,
        "judged": judged,
        "judged_passed": sum(j["verdict"] == "pass" for j in judged),
    }
    report["report_seconds"] = time.perf_counter() - t0
    md.parent.mkdir(parents=True, exist_ok=True)
    write_md(md, report)
    Path(js).write_text(json.dumps(clean(report), indent=2) + "\n")
    failed = [e["case"] for e in results if e["verdict"] != "pass"]
    failed += [s["study"] for s in all_studies if s["verdict"] != "pass"]
    failed += [f"Hertz {h['case']} {r['quantity']}" for h in hertz for r in h["rows"]
               if r["verdict"] != "pass"]
    failed += [f"judge {j['case']} (DOLFINx .vtu)" for j in judged if j["verdict"] != "pass"]
    print(f"crosscheck: {report['passed']} of {report['total']} entries pass (cases and "
          f"studies); Hertz table: {hertz_passed} of {len(hertz_rows)} rows pass; worst "
          f"relative difference between codes: {worst_text}; DOLFINx .vtu judged: "
          f"{report['judged_passed']} of {len(judged)} cases agree; wrote {md} and {js}")
    if failed:
        print("crosscheck: FAILED: " + ", ".join(failed))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
