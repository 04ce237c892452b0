"""contact-patch against DOLFINx 0.11 on the same problems and meshes, timed in one run.

usage:
    performance.py run BIN OUT_DIR REPORT_DIR [--dofs N]   (driver; any Python 3, no numpy)
    performance.py dolfinx-square DIVISIONS SOLVER           (child; the DOLFINx venv)
    performance.py dolfinx-block NX NY                       (child; the DOLFINx venv)

The problems (issue 14), both plane strain, Q4 (DOLFINx: Q1 on `create_rectangle`'s
quadrilaterals, the same structured grid our block generator makes, nodes at the same points):
- square: the unit square, D x D cells, E = 1000, nu = 0.3, rollers on the left and bottom,
  pressure 10 on the top; exact solution sigma_yy = -10 (u linear, which Q4 reproduces). At
  the full size D = 706 (999,698 dofs).
- block: [-3, 3] x [0, 1], NX x NY cells, E = 200, nu = 0.3, pressure 1 on the top over
  x in [-2, 0], u_x = 0 at (0, 1), pressed on the rigid line y = 0 by node-to-surface penalty
  contact, kappa = 1000 per unit gap, nodal (trapezoidal) weights: the case
  crosscheck/cases/contact/signorini-flat-penalty-q4.json refined. Full size 1734 x 288
  (1,002,830 dofs). The block lifts off beyond the loaded zone, so the active set is unknown.
  Also solved by us without contact (rollers u_y = 0 on the bottom instead): the elastic
  solve of the same mesh, the yardstick of "a contact solve costs at most 2x an elastic one".

Solvers: ours as the case names it (sparse Cholesky; and CG preconditioned by our
smoothed-aggregation AMG, `solver.linear_solver: "cg_amg"`, src/solver/amg.rs, at DOLFINx's
GAMG tolerance, relative residual 1e-10, for the square, the elastic block and the block's
active-set loop; the block's active-set loop in the
default `factor_update: "auto"`, which eliminates the contact rows' equations last and solves
every later active set through the factor's trailing block, src/solver/low_rank.rs
`TrailingUpdate`, and, for comparison, with `factor_update: "refactor"`, a new factorization
per iteration); DOLFINx: MUMPS Cholesky and CG + GAMG
(rigid-body near-null space, relative tolerance 1e-10) for the square, SNES Newton (line search
"basic") with MUMPS LU for the block, the penalty term integrated by the Gauss-Lobatto rule of
degree 1 (the facet's vertices, the trapezoidal weights of our rows).

Times: ours are the phases of summary.json (`timings`; total = after start-up, including mesh
generation and output); DOLFINx's are measured in the child around mesh creation, assembly
and solve (after its imports; form compilation is cached after the first run, and its time
is reported apart as `jit`). Peak memory: the child's maximum resident set size
(`os.wait4`). Each program runs as its own child process, one after the other.
The answers are compared so that both codes demonstrably solve the same problem: the square's
displacement against the exact linear field; for the block the total contact force (2 per
unit thickness), the number of active slave nodes and the largest penetration.
"""

import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
FULL_SQUARE = 706
FULL_BLOCK = (1734, 288)


# --- the driver ---------------------------------------------------------------------------------

def sizes(dofs):
    """Divisions of the square and the block for about `dofs` unknowns each."""
    d = max(2, round(math.sqrt(dofs / 2.0)) - 1)
    # the block keeps the 6:1 cell counts of 1734 x 288, NX a multiple of 6 (nodes at x = -2
    # and x = 0, the ends of the loaded zone, so that the load is 2 at every size)
    ny = max(2, round(math.sqrt(dofs / 2.0 / (FULL_BLOCK[0] / FULL_BLOCK[1]))))
    nx = 6 * max(1, round(ny * FULL_BLOCK[0] / FULL_BLOCK[1] / 6.0))
    return d, (nx, ny)


def with_cg(case):
    """The case solved by CG + AMG at GAMG's relative tolerance (1e-10). The force-balance
    check (tolerance 1e-10 of the load, a round-off check of the direct solver) is left out:
    a relative residual of 1e-10 leaves an out-of-balance force of a few 1e-10 of the load;
    the answers are compared as the direct runs' are (exact field, contact force, active
    nodes, penetration)."""
    case = json.loads(json.dumps(case))
    case["name"] += "-cg-amg"
    case.setdefault("solver", {}).update({"linear_solver": "cg_amg", "linear_tolerance": 1e-10})
    case["checks"] = [c for c in case.get("checks", []) if c["check"] != "force_balance"]
    return case


def square_case(d):
    return {
        "name": f"perf-square-{d}",
        "description": f"Plane-strain unit square, {d} x {d} Q4, uniform pressure 10 on top, rollers left and bottom (crosscheck/performance.py).",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [{"name": "square", "material": "m", "mesh": {"block": {
            "element": "Q4", "x": {"from": 0, "to": 1, "divisions": d},
            "y": {"from": 0, "to": 1, "divisions": d}}}}],
        "supports": [{"body": "square", "set": "bottom", "y": 0.0},
                     {"body": "square", "set": "left", "x": 0.0}],
        "loads": [{"body": "square", "set": "top", "pressure": 10.0}],
        "checks": [{"check": "uniform_stress", "stress": [0.0, -10.0, 0.0], "tol": 1e-8}],
    }


def block_case(nx, ny, contact=True, update="auto"):
    with open(os.path.join(HERE, "cases", "contact", "signorini-flat-penalty-q4.json")) as f:
        case = json.load(f)
    mesh = case["bodies"][0]["mesh"]["block"]
    mesh["x"]["divisions"], mesh["y"]["divisions"] = nx, ny
    case["name"] = f"perf-block-{nx}x{ny}" + ("" if contact else "-elastic")
    case["description"] = ("The cross-check case signorini-flat-penalty-q4 refined to "
                           f"{nx} x {ny} (crosscheck/performance.py)")
    # the active set's iterations on a million dofs exceed the default work limit
    case["limits"] = {"iteration_dofs": 10**10}
    if contact:
        case["solver"] = {"factor_update": update}
        case["checks"] = [c for c in case["checks"] if c["check"] != "max_penetration"]
    else:
        del case["contact"]
        case["supports"].append({"body": "block", "set": "bottom", "y": 0.0})
        case["checks"] = []
    return case


def measured(argv):
    """Run `argv` and measure its peak memory with os.wait4 (the child's own rusage)."""
    start = time.monotonic()
    out_r, out_w = os.pipe()
    err_r, err_w = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.dup2(out_w, 1)
        os.dup2(err_w, 2)
        os.close(out_r)
        os.close(err_r)
        try:
            os.execvp(argv[0], argv)
        finally:
            os._exit(127)
    os.close(out_w)
    os.close(err_w)
    out = err = b""
    import selectors
    sel = selectors.DefaultSelector()
    sel.register(out_r, selectors.EVENT_READ, "out")
    sel.register(err_r, selectors.EVENT_READ, "err")
    open_fds = 2
    while open_fds:
        for key, _ in sel.select():
            chunk = os.read(key.fd, 65536)
            if not chunk:
                sel.unregister(key.fd)
                os.close(key.fd)
                open_fds -= 1
            elif key.data == "out":
                out += chunk
            else:
                err += chunk
    _, status, usage = os.wait4(pid, 0)
    wall = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    # ru_maxrss is in kilobytes on Linux
    return code, out.decode(), err.decode(), usage.ru_maxrss / 1024.0, wall


def slab_case(dofs):
    """cases/large/slab-3d-1m.json (a Hex8 slab on a rigid plane, 200 x 200 x 8 cells, 1,090,827
    dofs) with its in-plane divisions scaled to about `dofs` unknowns (the full case at 1M)."""
    with open(os.path.join(HERE, "..", "cases", "large", "slab-3d-1m.json")) as f:
        case = json.load(f)
    n = max(2, round(200 * math.sqrt(dofs / 1e6)))
    mesh = case["bodies"][0]["mesh"]["block3d"]
    mesh["x"]["divisions"] = mesh["y"]["divisions"] = n
    case["name"] = f"perf-slab-3d-{n}x{n}x{mesh['z']['divisions']}"
    return case


def ours(binary, case, out_dir):
    path = os.path.join(out_dir, case["name"] + ".json")
    with open(path, "w") as f:
        json.dump(case, f, indent=1)
    result = os.path.join(out_dir, case["name"])
    code, out, err, rss, wall = measured([binary, "run", path, "--out", result])
    # exit 1: solved, but a check failed (reported as such in the table)
    if code not in (0, 1) or not os.path.exists(os.path.join(result, "summary.json")):
        raise SystemExit(f"performance: contact-patch failed on {path} (exit {code}):\n{out}\n{err}")
    with open(os.path.join(result, "summary.json")) as f:
        s = json.load(f)
    entry = {"code": "contact-patch", "dofs": s["dofs"], "timings": s["timings"],
             "total": s["timings"]["total"], "peak_mb": rss, "wall": wall,
             "passed": s["passed"]}
    if s.get("linear_solver"):
        entry["cg"] = s["linear_solver"]
    if s.get("contact"):
        c = s["contact"]
        # 3D summaries name the total force `force_on_slaves` and keep no iteration history
        history = c.get("history", [])
        force = c.get("total_force", c.get("force_on_slaves"))
        entry.update({
            "iterations": c["iterations"],
            "factorizations": sum(1 for h in history if h["linear_solver"] == "cholesky"),
            "cg_solves": sum(1 for h in history if h["linear_solver"] == "cg-amg"),
            "low_rank_updates": sum(1 for h in history
                                    if h["linear_solver"] == "cholesky-low-rank-update"),
            "trailing_updates": sum(1 for h in history
                                    if h["linear_solver"] == "cholesky-trailing-update"),
            "active": c["active"], "total_force_y": force[1],
            "total_force_normal": force[-1],
            "max_penetration": c.get("max_penetration"), "history": bool(history)})
    # drop the output (.vtu of a million dofs) once measured
    subprocess.run(["rm", "-rf", result], check=True)
    return entry


def dolfinx(python, args):
    code, out, err, rss, wall = measured([python, os.path.abspath(__file__)] + args)
    if code != 0:
        raise SystemExit(f"performance: DOLFINx child {args} failed (exit {code}):\n{out}\n{err}")
    entry = json.loads(out.strip().splitlines()[-1])
    entry.update({"code": "DOLFINx 0.11", "peak_mb": rss, "wall": wall})
    return entry


def drive(binary, out_dir, report_dir, dofs, python):
    os.makedirs(out_dir, exist_ok=True)
    d, (nx, ny) = sizes(dofs)
    started = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    load = os.getloadavg()
    runs = {}
    print(f"performance: square {d} x {d}, block {nx} x {ny}", file=sys.stderr)
    runs["square_ours"] = ours(binary, square_case(d), out_dir)
    runs["square_ours_cg"] = ours(binary, with_cg(square_case(d)), out_dir)
    runs["square_mumps"] = dolfinx(python, ["dolfinx-square", str(d), "mumps-cholesky"])
    runs["square_gamg"] = dolfinx(python, ["dolfinx-square", str(d), "cg-gamg"])
    runs["block_elastic_ours"] = ours(binary, block_case(nx, ny, contact=False), out_dir)
    runs["block_elastic_ours_cg"] = ours(binary, with_cg(block_case(nx, ny, contact=False)),
                                         out_dir)
    runs["block_ours"] = ours(binary, block_case(nx, ny), out_dir)
    runs["block_ours_cg"] = ours(binary, with_cg(block_case(nx, ny)), out_dir)
    runs["block_ours_refactor"] = ours(binary, block_case(nx, ny, update="refactor"), out_dir)
    runs["block_snes"] = dolfinx(python, ["dolfinx-block", str(nx), str(ny)])
    runs["slab_3d_ours"] = ours(binary, slab_case(dofs), out_dir)
    runs["slab_3d_ours_cg"] = ours(binary, with_cg(slab_case(dofs)), out_dir)
    for k, v in runs.items():
        print(f"  {k}: total {v['total']:.2f} s, peak {v['peak_mb']:.0f} MB", file=sys.stderr)
    t = lambda k: runs[k]["total"]
    ratios = {
        "square: DOLFINx MUMPS Cholesky / ours": t("square_mumps") / t("square_ours"),
        "square: DOLFINx CG + GAMG / ours": t("square_gamg") / t("square_ours"),
        "square: DOLFINx CG + GAMG / ours CG + AMG": t("square_gamg") / t("square_ours_cg"),
        "square: ours Cholesky / ours CG + AMG": t("square_ours") / t("square_ours_cg"),
        "block: DOLFINx SNES + MUMPS / ours": t("block_snes") / t("block_ours"),
        "block: DOLFINx SNES + MUMPS / ours CG + AMG": t("block_snes") / t("block_ours_cg"),
        "block: ours CG + AMG contact / ours CG + AMG elastic, same mesh":
            t("block_ours_cg") / t("block_elastic_ours_cg"),
        "block: ours refactoring every iteration / ours": t("block_ours_refactor") / t("block_ours"),
        "block: ours contact / ours elastic, same mesh": t("block_ours") / t("block_elastic_ours"),
    }
    targets = {
        "block: DOLFINx SNES + MUMPS / ours": 4.0,
        "square: DOLFINx CG + GAMG / ours": 1.0,
        "square: DOLFINx CG + GAMG / ours CG + AMG": 1.3,
        "block: DOLFINx SNES + MUMPS / ours CG + AMG": 4.0,
    }
    report = {"dofs_requested": dofs, "square_divisions": d, "block_divisions": [nx, ny],
              "started": started, "load_average_at_start": load, "cpus": os.cpu_count(),
              "runs": runs, "ratios": ratios,
              "command": f"bash crosscheck/performance.sh {dofs}"}
    os.makedirs(report_dir, exist_ok=True)
    with open(os.path.join(report_dir, "performance.json"), "w") as f:
        json.dump(report, f, indent=1)
    with open(os.path.join(report_dir, "performance.md"), "w") as f:
        f.write(markdown(report, targets))
    return report


def markdown(r, targets):
    runs = r["runs"]
    lines = [
        "# Performance: contact-patch against DOLFINx 0.11, same problems, same meshes, one run",
        "",
        f"Regenerate: `{r['command']}` (crosscheck/performance.py; a smaller size argument runs in a minute).",
        f"Run started {r['started']} on {r['cpus']} cores; load average at the start "
        f"{r['load_average_at_start'][0]:.2f} (other builds may have shared the machine: read the ratios, "
        "which were measured minutes apart, rather than the absolute times).",
        "",
        f"Square: unit square, {r['square_divisions']} x {r['square_divisions']} Q4, plane strain, pressure on the top. "
        f"Block: [-3, 3] x [0, 1], {r['block_divisions'][0]} x {r['block_divisions'][1]} Q4, penalty 1000, "
        "node-to-surface contact with the rigid line y = 0, partial load (it lifts off). "
        "3D slab: the case cases/large/slab-3d-1m.json (Hex8, penalty node-to-surface contact "
        "with the rigid plane z = 0, uniform pressure) with its in-plane divisions scaled to the "
        "size asked for (the case itself at 1M); ours only.",
        "",
        "| problem | code, solver | dofs | total s | phases s | iterations | peak MB | answer |",
        "|---|---|---|---|---|---|---|---|",
    ]

    def row(problem, key, solver):
        e = runs[key]
        if e["code"] == "contact-patch":
            tm = e["timings"]
            phases = (f"mesh {tm['mesh']:.2f}, assembly {tm['assembly']:.2f}, factorization "
                      f"{tm['factorization']:.2f}, solve + output {tm['solve']:.2f}")
            its = (f"{e['iterations']} ({e['factorizations']} factorizations, "
                   f"{e['trailing_updates']} trailing-block updates, "
                   f"{e['low_rank_updates']} low-rank updates)" if "iterations" in e else "1")
            if "iterations" in e and not e["history"]:
                its = f"{e['iterations']} active-set"
            if "cg" in e:
                cg = e["cg"]
                phases = (f"mesh {tm['mesh']:.2f}, assembly {tm['assembly']:.2f}, AMG setup "
                          f"{tm['factorization']:.2f}, CG + output {tm['solve']:.2f}")
                cg_its = (f"{cg['iterations']} CG (relative residual {cg['relative_residual']:.1e}; "
                          f"{len(cg['levels'])} levels, {cg['setups']} setups, "
                          f"{cg['finest_updates']} finest-level updates)")
                its = (f"{e['iterations']} active-set, {cg_its}" if "iterations" in e else cg_its)
            if "active" in e:
                answer = (f"force {e.get('total_force_normal', e['total_force_y']):.12g}, "
                          f"{e['active']} active")
                if e["max_penetration"] is not None:
                    answer += f", penetration {e['max_penetration']:.4e}"
                if key.startswith("slab_3d"):
                    answer += ", checks " + ("pass" if e["passed"] else "FAIL")
            else:
                answer = "checks pass" if e["passed"] else "checks FAIL"
        else:
            phases = (f"mesh {e['mesh']:.2f}, assembly {e['assembly']:.2f}, solve "
                      f"{e['solve']:.2f} (jit {e['jit']:.2f}, not counted)")
            its = str(e.get("iterations", 1))
            answer = e["answer"]
        lines.append(f"| {problem} | {e['code']}, {solver} | {e['dofs']:,} | {e['total']:.2f} | "
                     f"{phases} | {its} | {e['peak_mb']:.0f} | {answer} |")

    row("square", "square_ours", "sparse Cholesky (faer)")
    row("square", "square_ours_cg", "CG + SA-AMG, rtol 1e-10")
    row("square", "square_mumps", "MUMPS Cholesky")
    row("square", "square_gamg", "CG + GAMG, rtol 1e-10")
    row("block, elastic (rollers)", "block_elastic_ours", "sparse Cholesky (faer)")
    row("block, elastic (rollers)", "block_elastic_ours_cg", "CG + SA-AMG, rtol 1e-10")
    row("block on a rigid line", "block_ours", "active set, trailing-block updates")
    row("block on a rigid line", "block_ours_cg", "active set, CG + SA-AMG, rtol 1e-10")
    row("block on a rigid line", "block_ours_refactor", "active set, refactoring")
    row("block on a rigid line", "block_snes", "SNES Newton + MUMPS LU")
    row("3D slab on a rigid plane (Hex8)", "slab_3d_ours", "active set, sparse Cholesky (faer)")
    row("3D slab on a rigid plane (Hex8)", "slab_3d_ours_cg", "active set, CG + SA-AMG, rtol 1e-10")
    lines += ["", "| ratio | value | target (issue 14) |", "|---|---|---|"]
    for k, v in r["ratios"].items():
        target = targets.get(k)
        goal = "-"
        if target is not None:
            goal = f"at least {target:g}: {'met' if v >= target else 'NOT met'}"
        if k.startswith("block: ours contact") or k.startswith("block: ours CG + AMG contact"):
            goal = f"at most 2: {'met' if v <= 2.0 else 'NOT met'}"
        lines.append(f"| {k} | {v:.2f} | {goal} |")
    lines += ["", "Totals: ours from summary.json (`timings.total`, after start-up: mesh, assembly, "
              "factorization, solve, output); DOLFINx from mesh creation to the solution "
              "(imports and form compilation excluded). Peak memory: the process's maximum "
              "resident set (`os.wait4`).", ""]
    return "\n".join(lines)


# --- the DOLFINx children -------------------------------------------------------------------------

def elasticity(V, E, nu):
    import ufl
    mu, lmbda = E / (2 * (1 + nu)), E * nu / ((1 + nu) * (1 - 2 * nu))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = lambda w: ufl.sym(ufl.grad(w))
    sigma = lambda w: 2 * mu * eps(w) + lmbda * ufl.tr(eps(w)) * ufl.Identity(2)
    dx = ufl.Measure("dx", metadata={"quadrature_degree": 3})
    return u, v, sigma, dx


def dofs_at(msh, component, where):
    """The dofs of one component at the mesh vertices where `where(x)` holds."""
    from dolfinx import fem, mesh
    vertices = mesh.locate_entities(msh, 0, where)
    return fem.locate_dofs_topological(component, 0, vertices)


def rigid_modes(V):
    """The near-null space of 2D elasticity for GAMG: two translations and a rotation."""
    from petsc4py import PETSc
    import numpy as np
    from dolfinx import la
    x = V.tabulate_dof_coordinates()
    n = V.dofmap.index_map.size_local
    bs = V.dofmap.index_map_bs
    basis = [la.vector(V.dofmap.index_map, bs) for _ in range(3)]
    b = [v.array for v in basis]
    b[0][0::2][:n] = 1.0
    b[1][1::2][:n] = 1.0
    b[2][0::2][:n] = -x[:n, 1]
    b[2][1::2][:n] = x[:n, 0]
    la.orthonormalize(basis)
    vecs = [PETSc.Vec().createWithArray(v.array[: n * bs], bsize=bs, comm=V.mesh.comm) for v in basis]
    return PETSc.NullSpace().create(vectors=vecs, comm=V.mesh.comm)


def child_square(d, solver):
    import dolfinx_solver  # noqa: F401  (must come before dolfinx and petsc4py)
    import numpy as np
    import ufl
    from mpi4py import MPI
    from petsc4py import PETSc
    from dolfinx import fem, mesh
    import dolfinx.fem.petsc as fp

    t0 = time.perf_counter()
    msh = mesh.create_rectangle(MPI.COMM_WORLD, [[0.0, 0.0], [1.0, 1.0]], [d, d],
                                mesh.CellType.quadrilateral)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    t_mesh = time.perf_counter() - t0
    t0 = time.perf_counter()
    E, nu, p = 1000.0, 0.3, 10.0
    u, v, sigma, dx = elasticity(V, E, nu)
    fdim = 1
    top = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], 1.0))
    tags = mesh.meshtags(msh, fdim, top, np.full(len(top), 1, dtype=np.int32))
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    a = fem.form(ufl.inner(sigma(u), ufl.grad(v)) * dx)
    L = fem.form(ufl.inner(fem.Constant(msh, np.array([0.0, -p])), v) * ds(1))
    left = dofs_at(msh, V.sub(0), lambda x: np.isclose(x[0], 0.0))
    bottom = dofs_at(msh, V.sub(1), lambda x: np.isclose(x[1], 0.0))
    bcs = [fem.dirichletbc(0.0, left, V.sub(0)), fem.dirichletbc(0.0, bottom, V.sub(1))]
    t_jit = time.perf_counter() - t0
    t0 = time.perf_counter()
    A = fp.assemble_matrix(a, bcs=bcs)
    A.assemble()
    b = fp.assemble_vector(L)
    fp.apply_lifting(b, [a], bcs=[bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fp.set_bc(b, bcs)
    t_assembly = time.perf_counter() - t0
    t0 = time.perf_counter()
    ksp = PETSc.KSP().create(msh.comm)
    ksp.setOperators(A)
    if solver == "mumps-cholesky":
        A.setOption(PETSc.Mat.Option.SPD, True)
        ksp.setType("preonly")
        ksp.getPC().setType("cholesky")
        ksp.getPC().setFactorSolverType("mumps")
    else:
        A.setNearNullSpace(rigid_modes(V))
        ksp.setType("cg")
        ksp.getPC().setType("gamg")
        ksp.setTolerances(rtol=1e-10)
    uh = fem.Function(V)
    ksp.solve(b, uh.x.petsc_vec)
    uh.x.scatter_forward()
    t_solve = time.perf_counter() - t0
    if ksp.getConvergedReason() <= 0:
        raise SystemExit(f"square: KSP failed (reason {ksp.getConvergedReason()})")
    # exact: sigma_yy = -p, plane strain: eps_yy = -(1 - nu^2) p / E, eps_xx = nu (1 + nu) p / E
    x = V.tabulate_dof_coordinates()
    n = V.dofmap.index_map.size_local
    U = uh.x.array[: 2 * n].reshape(-1, 2)
    exact = np.column_stack([nu * (1 + nu) * p / E * x[:n, 0], -(1 - nu ** 2) * p / E * x[:n, 1]])
    err = float(np.abs(U - exact).max() / np.abs(exact).max())
    print(json.dumps({"dofs": int(2 * n), "mesh": t_mesh, "assembly": t_assembly, "solve": t_solve,
                      "jit": t_jit, "total": t_mesh + t_assembly + t_solve,
                      "iterations": int(ksp.getIterationNumber()),
                      "answer": f"max displacement error {err:.1e} of the exact field"}))


def child_block(nx, ny):
    import dolfinx_solver  # noqa: F401  (must come before dolfinx and petsc4py)
    import numpy as np
    import ufl
    from mpi4py import MPI
    from petsc4py import PETSc
    from dolfinx import fem, mesh
    import dolfinx.fem.petsc as fp

    t0 = time.perf_counter()
    msh = mesh.create_rectangle(MPI.COMM_WORLD, [[-3.0, 0.0], [3.0, 1.0]], [nx, ny],
                                mesh.CellType.quadrilateral)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    t_mesh = time.perf_counter() - t0
    t0 = time.perf_counter()
    E, nu, kappa, p = 200.0, 0.3, 1000.0, 1.0
    _, v, sigma, dx = elasticity(V, E, nu)
    uh = fem.Function(V)
    fdim = 1
    loaded = mesh.locate_entities_boundary(
        msh, fdim, lambda x: np.isclose(x[1], 1.0) & (x[0] >= -2.0 - 1e-12) & (x[0] <= 1e-12))
    bottom = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], 0.0))
    facets = np.concatenate([loaded, bottom])
    values = np.concatenate([np.full(len(loaded), 1, np.int32), np.full(len(bottom), 2, np.int32)])
    order = np.argsort(facets)
    tags = mesh.meshtags(msh, fdim, facets[order], values[order])
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    dsc = ufl.Measure("ds", domain=msh, subdomain_data=tags,
                      metadata={"quadrature_rule": "GLL", "quadrature_degree": 1})
    x = ufl.SpatialCoordinate(msh)
    gap = x[1] + uh[1]
    penetration = ufl.conditional(ufl.le(gap, 0.0), -gap, 0.0)
    F = (ufl.inner(sigma(uh), ufl.grad(v)) * dx
         - ufl.inner(fem.Constant(msh, np.array([0.0, -p])), v) * ds(1)
         - kappa * penetration * v[1] * dsc(2))
    centre = dofs_at(msh, V.sub(0), lambda x: np.isclose(x[0], 0.0) & np.isclose(x[1], 1.0))
    bcs = [fem.dirichletbc(0.0, centre, V.sub(0))]
    problem = fp.NonlinearProblem(
        F, uh, bcs=bcs, petsc_options_prefix="block_",
        petsc_options={"snes_type": "newtonls", "snes_linesearch_type": "basic",
                       "snes_rtol": 1e-10, "snes_atol": 1e-12, "snes_max_it": 100,
                       "ksp_type": "preonly", "pc_type": "lu",
                       "pc_factor_mat_solver_type": "mumps"})
    t_jit = time.perf_counter() - t0
    t0 = time.perf_counter()
    problem.solve()
    snes = problem.solver
    t_solve = time.perf_counter() - t0
    if snes.getConvergedReason() <= 0:
        raise SystemExit(f"block: SNES failed (reason {snes.getConvergedReason()})")
    # the answer: total contact force, active slave nodes, largest penetration
    n = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n]
    U = uh.x.array[: 2 * n].reshape(-1, 2)
    on_line = np.isclose(X[:, 1], 0.0)
    g = X[on_line, 1] + U[on_line, 1]
    force = fp.assemble_vector(fem.form(kappa * penetration * v[1] * dsc(2))).array[: 2 * n]
    print(json.dumps({"dofs": int(2 * n), "mesh": t_mesh, "assembly": 0.0, "solve": t_solve,
                      "jit": t_jit, "total": t_mesh + t_solve,
                      "iterations": int(snes.getIterationNumber()),
                      "answer": (f"force {float(force[1::2].sum()):.12g}, {int((g <= 0).sum())} active, "
                                 f"penetration {float(max(0.0, -g.min())):.4e}")}))


def main(argv):
    if len(argv) >= 4 and argv[0] == "run":
        dofs = 1_000_000
        if "--dofs" in argv:
            dofs = int(float(argv[argv.index("--dofs") + 1]))
        python = os.environ.get("PERF_PYTHON", sys.executable)
        drive(argv[1], argv[2], argv[3], dofs, python)
    elif len(argv) == 3 and argv[0] == "dolfinx-square":
        child_square(int(argv[1]), argv[2])
    elif len(argv) == 3 and argv[0] == "dolfinx-block":
        child_block(int(argv[1]), int(argv[2]))
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
