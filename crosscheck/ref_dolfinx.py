"""Reference solve with DOLFINx 0.11 on the mesh our tool wrote.

usage: ref_dolfinx.py OUT_ROOT CASE.json...   (reads OUT_ROOT/<case>/<body>.vtu, writes
OUT_ROOT/<case>/ref-dolfinx.json)

The mesh: the .vtu cells, permuted from VTK to DOLFINx node order (`cell_perm_vtk`), with a
Lagrange coordinate element of the cell's degree (Q9 -> degree-2 quadrilateral, i.e. the
9-node tensor Q2; T6 -> degree-2 triangle), so the geometry is the same isoparametric map.
The unknown: a vector Lagrange space of the same degree. Supports: the dofs of each
component at the support nodes' coordinates (KD-tree), set to the case's values. Loads: the
exact traction sigma(x) n integrated with UFL's `ds` at quadrature degree 8. Stiffness: the
quadrature of our tool (see common.STIFFNESS_DEGREE). Solve: PETSc LU (MUMPS).
"""

import dolfinx_solver  # noqa: F401  (must come before dolfinx and petsc4py)

import json
import sys
import time
from pathlib import Path

import basix
import basix.ufl
import dolfinx
import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem, mesh as dmesh
from dolfinx.io.utils import cell_perm_vtk
from mpi4py import MPI
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (BODY_FORCE_DEGREE, LOAD_DEGREE, STIFFNESS_DEGREE, Problem,  # noqa: E402
                    Unsupported, in_box, write_reference)

CELL = {"Q4": ("quadrilateral", 1), "Q9": ("quadrilateral", 2),
        "T3": ("triangle", 1), "T6": ("triangle", 2)}
DCELL = {"quadrilateral": dmesh.CellType.quadrilateral, "triangle": dmesh.CellType.triangle}


def solve(pb: Problem):
    cellname, degree = CELL[pb.element]
    nn = pb.cells.shape[1]
    perm = cell_perm_vtk(DCELL[cellname], nn)
    cells = np.ascontiguousarray(pb.cells[:, perm], dtype=np.int64)
    coord_el = basix.ufl.element("Lagrange", cellname, degree, shape=(2,),
                                 lagrange_variant=basix.LagrangeVariant.equispaced)
    msh = dmesh.create_mesh(MPI.COMM_SELF, cells, ufl.Mesh(coord_el), pb.points)
    assert msh.geometry.x.shape[0] == len(pb.points)

    V = fem.functionspace(msh, ("Lagrange", degree, (2,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    mat = pb.material
    lam, mu = fem.Constant(msh, mat.lam), fem.Constant(msh, mat.mu)
    th = fem.Constant(msh, pb.thickness)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    def sigma(w):
        return lam * ufl.tr(eps(w)) * ufl.Identity(2) + 2.0 * mu * eps(w)

    dx = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": STIFFNESS_DEGREE[pb.element]})
    a = th * ufl.inner(sigma(u), eps(v)) * dx

    # Loads. One meshtags for all facet loads (a form takes one subdomain_data per integral
    # type): each boundary facet is tagged by the combination of loads acting on it.
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, msh.topology.dim)
    x = ufl.SpatialCoordinate(msh)
    n = ufl.FacetNormal(msh)
    on_facet = {}
    L = None
    for k, ld in enumerate(pb.loads):
        if ld.box is None:
            dxb = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": BODY_FORCE_DEGREE})
            term = th * ufl.dot(ufl.as_vector(ld.value), v) * dxb
            L = term if L is None else L + term
            continue
        f = dmesh.locate_entities_boundary(msh, fdim, lambda X, box=ld.box: in_box(X[:2].T, box))
        if len(f) == 0:
            raise RuntimeError(f"{pb.name}: load {k} selects no boundary facet")
        for i in f:
            on_facet.setdefault(int(i), []).append(k)
    if on_facet:
        combos = sorted({tuple(ks) for ks in on_facet.values()})
        tag_of = {c: j + 1 for j, c in enumerate(combos)}
        facets = np.array(sorted(on_facet), dtype=np.int32)
        tags = np.array([tag_of[tuple(on_facet[i])] for i in facets], dtype=np.int32)
        mt = dmesh.meshtags(msh, fdim, facets, tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                         metadata={"quadrature_degree": LOAD_DEGREE})
        for combo, tag in tag_of.items():
            for k in combo:
                t = pb.loads[k].traction(x[0], x[1], n)
                term = th * ufl.dot(ufl.as_vector(t), v) * ds(tag)
                L = term if L is None else L + term
    if L is None:
        L = ufl.dot(ufl.as_vector([0.0, 0.0]), v) * dx

    # Supports: per component, the dofs at the support nodes (by coordinates).
    bcs = []
    for comp in (0, 1):
        Vc, cmap = V.sub(comp).collapse()
        cmap = np.asarray(cmap, dtype=np.int32).reshape(-1)  # 0.11: a list of one array
        tree = cKDTree(Vc.tabulate_dof_coordinates()[:, :2])
        dofs, vals = [], []
        for coords, c, values in pb.supports:
            if c != comp:
                continue
            d, idx = tree.query(coords)
            if d.max() > pb.tol:
                raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
            dofs.append(idx)
            vals.append(values)
        if not dofs:
            continue
        idx = np.concatenate(dofs).astype(np.int32)
        val = np.concatenate(vals)
        idx, first = np.unique(idx[::-1], return_index=True)  # later supports win
        val = val[::-1][first]
        g = fem.Function(Vc)
        g.x.array[:] = 0.0
        g.x.array[idx] = val
        bcs.append(fem.dirichletbc(g, [cmap[idx], idx], V.sub(comp)))

    problem = dolfinx.fem.petsc.LinearProblem(
        a, L, bcs=bcs, petsc_options_prefix=f"xcheck_{pb.name.replace('-', '_')}_",
        petsc_options={"ksp_type": "preonly", "pc_type": "lu",
                       "pc_factor_mat_solver_type": "mumps"})
    uh = problem.solve()
    if isinstance(uh, tuple):
        uh = uh[0]
    reason = problem.solver.getConvergedReason()
    if reason <= 0:
        raise RuntimeError(f"{pb.name}: PETSc solve did not converge (reason {reason})")

    U = uh.x.array.reshape(-1, 2)
    X = V.tabulate_dof_coordinates()[:, :2]
    ids, dist = pb.match(X)
    out = np.empty_like(pb.u_ours)
    out[ids] = U
    return out, {"match_distance": dist, "dofs": 2 * X.shape[0],
                 "stiffness_quadrature_degree": STIFFNESS_DEGREE[pb.element],
                 "load_quadrature_degree": LOAD_DEGREE}


def main(argv):
    root = Path(argv[1])
    failed = 0
    for case in argv[2:]:
        t0 = time.perf_counter()
        name = Path(case).stem
        target = root / name / "ref-dolfinx.json"
        try:
            pb = Problem(case, root / name)
            u, extra = solve(pb)
            extra.update({"seconds": time.perf_counter() - t0,
                          "versions": {"dolfinx": dolfinx.__version__,
                                       "basix": basix.__version__}})
            write_reference(target, pb, "dolfinx", u, extra)
            print(f"dolfinx {name}: {time.perf_counter() - t0:.1f} s", flush=True)
        except Exception as e:  # noqa: BLE001  (recorded; the report fails this case)
            failed += 1
            target.parent.mkdir(parents=True, exist_ok=True)
            msg = str(e) if isinstance(e, (Unsupported, RuntimeError)) else f"{type(e).__name__}: {e}"
            target.write_text(json.dumps({"error": msg}))
            print(f"dolfinx {name}: ERROR {e}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
