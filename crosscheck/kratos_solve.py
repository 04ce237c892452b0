#!/usr/bin/env python3
"""Solve the Kratos input that kratos_convert.py wrote and write the results as our judge reads
them (docs/judge-your-code.md):

    OMP_NUM_THREADS=1 python crosscheck/kratos_solve.py KRATOS_DIR RESULTS_DIR

runs Kratos' structural analysis (static, non-linear: Newton on the contact active set) on
KRATOS_DIR/ProjectParameters.json and writes RESULTS_DIR/<body>.vtu for every body (ASCII VTK
XML at the reference coordinates, VTK node order) with the point fields

* `displacement`: Kratos' DISPLACEMENT (x, y);
* `contact_force`: the nodal force the interface puts on the node's body: the displacement
  rows of the right-hand side of Kratos' own contact conditions (mortar contact or
  mesh tying), evaluated at the solution and assembled by their dofs; zero elsewhere. It is the
  contact part of Kratos' residual, not something rebuilt from the stresses, so `judge`'s
  force balance (K u - f - f_c over the free dofs) tests Kratos' equilibrium;
* `contact_pressure` (frictionless pairs): the normal pressure at the slave nodes, positive in
  compression, per reference area (see `slave_pressure`: for ALM Kratos' own nodal pressure,
  which is per current area, times A_current / A_reference; for penalty -f_a . n_a / A_a of
  Kratos' assembled contact force).

No `contact_gap`: Kratos' nodal NORMAL_GAP is not the gap of the solution (measured on patch A
with penalty: -8.9e-16 where the bodies overlap by 2e-3), and none of the judged checks of
these cases needs it.

and KRATOS_DIR/solve.json: wall times (import, solve) and Kratos' Newton iterations. Exit 0
when Kratos' solve returned converged, 1 when it ran but did not converge (the results are still
written and judged), 2 when Kratos failed (raised an error), 4 when this script broke.
"""

import json
import math
import os
import sys
import time
from pathlib import Path

T0 = time.perf_counter()
import KratosMultiphysics as KM  # noqa: E402
import KratosMultiphysics.StructuralMechanicsApplication  # noqa: E402,F401
import KratosMultiphysics.ContactStructuralMechanicsApplication as CSMA  # noqa: E402
from KratosMultiphysics.StructuralMechanicsApplication.structural_mechanics_analysis import (  # noqa: E402
    StructuralMechanicsAnalysis)

T_IMPORT = time.perf_counter() - T0


def contact_conditions(model_part):
    """Kratos' contact conditions after the solve: the mortar pairs (or tying pairs) that the
    contact process created, not the input edges (LineCondition2D2N) nor the point loads."""
    out = []
    for cond in model_part.Conditions:
        name = cond.Info()
        if "Mortar" in name or "MeshTying" in name or "Tying" in name:
            out.append(cond)
    return out


def assembled_contact_force(model_part):
    """The displacement rows of the contact conditions' right-hand sides: a Kratos condition's
    RHS is the force it applies to its nodes (as a point load's RHS is its load), so these rows,
    assembled by dof, are the forces the interface puts on each body."""
    info = model_part.ProcessInfo
    force = {}
    for cond in contact_conditions(model_part):
        lhs, rhs = KM.Matrix(), KM.Vector()
        cond.CalculateLocalSystem(lhs, rhs, info)
        dofs = cond.GetDofList(info)
        if len(dofs) != rhs.Size():
            raise RuntimeError(f"{cond.Info()}: {len(dofs)} dofs, right-hand side {rhs.Size()}")
        for dof, r in zip(dofs, rhs):
            var = dof.GetVariable().Name()
            if var in ("DISPLACEMENT_X", "DISPLACEMENT_Y"):
                f = force.setdefault(dof.Id(), [0.0, 0.0])
                f[0 if var.endswith("X") else 1] += r
    return force


def slave_pressure(model_part, meta, force, points, u):
    """contact_pressure at the slave nodes of frictionless pairs, positive in compression.

    ALM: minus Kratos' nodal AUGMENTED_NORMAL_CONTACT_PRESSURE (the scaled multiplier plus the
    penalty times the weighted gap, negative in compression), a pressure per area of Kratos'
    current configuration (measured: on patch A without the slide it is 10 / (1 + eps_xx),
    error 3.9e-3 against the judge's 10), turned into a pressure per reference area by the
    ratio of the node's current and reference tributary lengths. Penalty: Kratos' nodal value of that variable is not a pressure per
    area (measured on patch A: -10.3, -20.2, -10.0 at the three slave nodes under a uniform
    p = 10), so the pressure is taken from Kratos' own assembled contact force as our tool
    defines it: -f_a . n_a / A_a, with n_a the outward normal (length-weighted mean of the
    slave edges at the node) and A_a = t int N_a ds, both in the reference configuration."""
    pressure = {}
    for pair in meta["pairs"]:
        if pair["tied"]:
            continue
        area, area_now, normal = {}, {}, {}
        for a, b in pair["slave_facets"]:
            (xa, ya), (xb, yb) = points[a], points[b]
            (ua, va), (ub, vb) = u[a], u[b]
            # our facets run counter-clockwise around their cell: the outward normal of a -> b
            # is (dy, -dx) / L; weighted by L it is (dy, -dx)
            for n in (a, b):
                area[n] = area.get(n, 0.0) + 0.5 * math.hypot(xb - xa, yb - ya) * meta["thickness"]
                area_now[n] = area_now.get(n, 0.0) + 0.5 * math.hypot(
                    xb + ub - xa - ua, yb + vb - ya - va) * meta["thickness"]
                nx, ny = normal.get(n, (0.0, 0.0))
                normal[n] = (nx + yb - ya, ny - (xb - xa))
        if meta["contact"] == "alm":
            # Kratos' pressure is per current area; the judge's is per reference area:
            # p_ref = p_current A_current / A_reference (nodal lengths of the slave edges)
            for node in model_part.GetSubModelPart(pair["slave"]).Nodes:
                p = -node.GetValue(CSMA.AUGMENTED_NORMAL_CONTACT_PRESSURE)
                pressure[node.Id] = p * area_now[node.Id] / area[node.Id]
            continue
        for n, (nx, ny) in normal.items():
            f = force.get(n, [0.0, 0.0])
            length = math.hypot(nx, ny)
            pressure[n] = -(f[0] * nx + f[1] * ny) / length / area[n]
    return pressure


VTK_NODES = {9: 4, 5: 3, 28: 9, 22: 6}


def write_vtu(path, body, fields):
    """One body's results: our mesh at the reference coordinates, point fields as given."""
    ids = body["nodes"]
    index = {k: i for i, k in enumerate(ids)}
    s = ['<?xml version="1.0"?>',
         '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">',
         "<UnstructuredGrid>",
         f'<Piece NumberOfPoints="{len(ids)}" NumberOfCells="{len(body["cells"])}">',
         '<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">']
    s += [f"{x!r} {y!r} 0" for x, y in body["points"]]
    s += ["</DataArray></Points>", "<Cells>",
          '<DataArray type="Int64" Name="connectivity" format="ascii">']
    s += [" ".join(str(index[n]) for n in conn) for _, conn in body["cells"]]
    s += ['</DataArray><DataArray type="Int64" Name="offsets" format="ascii">']
    off = 0
    for t, conn in body["cells"]:
        off += len(conn)
        s.append(str(off))
    s += ['</DataArray><DataArray type="UInt8" Name="types" format="ascii">']
    s += [str(t) for t, _ in body["cells"]]
    s += ["</DataArray></Cells>", "<PointData>"]
    for name, (ncomp, values) in fields.items():
        s.append(f'<DataArray type="Float64" Name="{name}" NumberOfComponents="{ncomp}" '
                 'format="ascii">')
        for n in ids:
            v = values.get(n, [0.0] * ncomp if ncomp > 1 else 0.0)
            s.append(" ".join(repr(float(c)) for c in v) if ncomp > 1 else repr(float(v)))
        s.append("</DataArray>")
    s += ["</PointData>", "</Piece></UnstructuredGrid></VTKFile>"]
    Path(path).write_text("\n".join(s) + "\n")


class Analysis(StructuralMechanicsAnalysis):
    """Kratos' structural analysis, counting Newton iterations and whether the step converged."""

    def __init__(self, model, parameters):
        super().__init__(model, parameters)
        self.converged = None

    def FinalizeSolutionStep(self):
        super().FinalizeSolutionStep()
        info = self._GetSolver().GetComputingModelPart().ProcessInfo
        self.iterations = info[KM.NL_ITERATION_NUMBER]

    def RunSolutionLoop(self):
        while self.KeepAdvancingSolutionLoop():
            self.time = self._AdvanceTime()
            self.InitializeSolutionStep()
            self._GetSolver().Predict()
            self.converged = self._GetSolver().SolveSolutionStep()
            self.FinalizeSolutionStep()
            self.OutputSolutionStep()


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    kdir, rdir = Path(argv[1]).resolve(), Path(argv[2])
    meta = json.loads((kdir / "bodies.json").read_text())
    parameters = KM.Parameters((kdir / "ProjectParameters.json").read_text())
    cwd = os.getcwd()
    KM.Logger.GetDefaultOutput().SetSeverity(KM.Logger.Severity.WARNING)
    t = time.perf_counter()
    os.chdir(kdir)  # the mdpa and materials are named relative to it
    try:
        model = KM.Model()
        analysis = Analysis(model, parameters)
        analysis.Run()
    except RuntimeError as e:  # Kratos' own failure (reading, solving): a result, exit 2
        print(f"kratos_solve: Kratos failed: {e}".splitlines()[0][:500], file=sys.stderr)
        return 2
    finally:
        os.chdir(cwd)
    t_solve = time.perf_counter() - t
    mp = model["Structure"]
    u = {n.Id: [n.GetSolutionStepValue(KM.DISPLACEMENT_X), n.GetSolutionStepValue(KM.DISPLACEMENT_Y)]
         for n in mp.Nodes}
    fc = assembled_contact_force(mp)
    points = {n: p for body in meta["bodies"] for n, p in zip(body["nodes"], body["points"])}
    pressure = slave_pressure(mp, meta, fc, points, u)
    rdir.mkdir(parents=True, exist_ok=True)
    for body in meta["bodies"]:
        fields = {"displacement": (2, u), "contact_force": (2, fc)}
        if pressure:
            fields["contact_pressure"] = (1, pressure)
        write_vtu(rdir / f"{body['name']}.vtu", body, fields)
    solve = {"case": meta["case"], "contact": meta["contact"], "mortar_type": meta["mortar_type"],
             "converged": bool(analysis.converged), "newton_iterations": analysis.iterations,
             "import_seconds": T_IMPORT, "solve_seconds": t_solve,
             "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
             "contact_conditions": len(contact_conditions(mp)),
             "kratos": KM.KratosGlobals.Kernel.Version() if hasattr(KM.KratosGlobals, "Kernel") else None}
    (kdir / "solve.json").write_text(json.dumps(solve, indent=2) + "\n")
    print(json.dumps(solve))
    return 0 if analysis.converged else 1


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except Exception:  # a broken script (not Kratos failing): exit 4, never taken as a result
        import traceback
        traceback.print_exc()
        sys.exit(4)
