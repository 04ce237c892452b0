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

Contact with a rigid line or circle (`common.RigidContact`): the residual gains the penalty
term -int t kappa (g(u))_- (n . v) ds over the slave facets, g(u) = g0(X) + n(X) . u the gap
linearized at the reference configuration as in our rows, integrated with the Gauss-Lobatto
rule of our nodal weights (2 points = the facet's vertices for Q4, 3 points = Simpson for Q9;
basix's "GLL" of degree 1 and 3). Newton's method: each step solves the tangent (stiffness
plus t kappa (n . du)(n . v) where g <= 0) with MUMPS; the problem is piecewise linear, so the
iteration is exact once the active set repeats, and it stops there (the step that reproduced
the active set is then the exact solution of the linear problem on that set, up to round-off).
Two-body tied cases are not solved here (the tied layer's DOLFINx reference is the one-body
mesh); their reference file says so.

Penalty Coulomb contact on a rigid line (`solve_friction`; Wriggers, *Computational Contact
Mechanics*, 2nd ed., s. 5.2 and 6.3, as src/contact/friction.rs): DOLFINx assembles the
stiffness matrix, each load's vector and the nodal weights `A_a` (the GLL rule above); per load
step (the case's `path` factors) Newton's method in numpy/scipy on `K u - f - sum_a (lambda_n n
+ lambda_t t)_a`, `lambda_n = kappa A (-g)_+`, the trial force `-kappa_t A (g_t - g_t^{p,n})`
returned onto `|lambda_t| <= mu lambda_n`, the plastic slip committed at the end of each step
(see the function's text for the branches and the unsymmetric tangent).

Elastic waves (`physics.dynamics`, no contact; `solve_wave`): the stiffness form above and the
consistent mass form `int t rho u . v dx` (quadrature of our `mass_rule`: Gauss 3x3 on Q4, 4x4
on Q9; exact on triangles) assembled by DOLFINx on the same mesh, the lumped mass as the row
sums of that matrix (our HRZ lumping on parallelogram Q4 cells, whose consistent element mass
has equal diagonal entries, where HRZ is the row sum), the facet loads integrated as above;
then Newmark's method with the case's beta, gamma and dt, written here in numpy/scipy
independently of our solver: `(K + M / (beta dt^2)) d_{n+1} = f + M d~ / (beta dt^2)` on the
free dofs (SuperLU), `d~ = d_n + dt v_n + dt^2 (1/2 - beta) a_n`,
`a_{n+1} = (d_{n+1} - d~) / (beta dt^2)`, `v_{n+1} = v_n + dt ((1 - gamma) a_n + gamma a_{n+1})`,
from `d_0 = 0`, the case's initial velocities and `a_0 = M^-1 (f - K d_0)`. The reference keeps
the displacement at every step and the kinetic, strain and load energies.

Finite kinematics (`physics.kinematics: "finite"`, `solve_finite`; src/solid_finite.rs, Bonet
& Wood, *Nonlinear Continuum Mechanics for Finite Element Analysis*, 2nd ed., eqs. 6.28 and
6.6 for plane strain): the residual is UFL's derivative of the stored energy
`int t W(F) dX` (`hyperelastic_energy`: neo-Hookean `W = mu/2 (tr C + 1 - 3 - 2 ln J) +
lambda/2 (ln J)^2` or St. Venant-Kirchhoff `W = lambda/2 (tr E)^2 + mu E:E`, `F = I + grad u`,
`F_33 = 1`) with our stiffness quadrature, minus the dead loads times the load factor, minus,
against a rigid line, the penalty term above with the current gap `g = n . (X + u - p)`; UFL
derives the tangent; Newton's method in numpy/scipy per load step (the case's factors), from
the last step's state, to a relative residual of 1e-14 or its round-off floor (at most 1e-12).
No .vtu is written for these cases.

3D cases (bodies with a `block3d` mesh, src/run3d.rs; `solve3`, `common.Problem3`): the .vtu
cells (hexahedron, hexahedron27, tetra, tetra10) permuted by `cell_perm_vtk`, with a Lagrange
coordinate element of the cell's degree; the map is checked first (`check_geometry_3d`: cell
volumes against our corners in VTK order, and the degree-2 geometry nodes at basix's reference
nodes under each cell's vertex map). Vector Lagrange of the same degree, the stiffness
quadrature of src/fe3d.rs (common.STIFFNESS_DEGREE_3D), supports on the automatic sets,
pressures -p n at degree 8, MUMPS. Penalty contact against a rigid plane or sphere
(`newton_penalty3`): the 2D method above, the penalty term integrated with a custom rule whose
points are the slave facet's nodes and whose weights are our nodal weights
(`common.nodal_rule_3d`, checked against int N_a dA before use). DOLFINx's own .vtu holds
`displacement` and `stress` (xx, yy, zz, yz, xz, xy), which `contact-patch judge` reads for 3D
cases (`write_vtu3`).

The solution is also written by DOLFINx itself (`dolfinx.io.VTKFile`, ASCII) as
OUT_ROOT/<case>/dolfinx.pvd + dolfinx_p0_000000.vtu, with the point fields `displacement` and
`stress` (xx, yy, xy of sigma(u_h) interpolated at the nodes of a Lagrange space of the same
degree),
so that `contact-patch judge` can apply the case's checks to it (crosscheck/run.sh does); with
contact also `contact_force` (the assembled nodal penalty force on the body), `contact_pressure`
(kappa (-g)_+ at the slave nodes, compression positive) and `contact_gap` (see
`contact_point_fields`), from which `judge` applies the contact checks.
"""

import dolfinx_solver  # noqa: F401  (must come before dolfinx and petsc4py)

import json
import math
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
from petsc4py import PETSc
import scipy.sparse
import scipy.sparse.linalg
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (BODY_FORCE_DEGREE, LOAD_DEGREE, STIFFNESS_DEGREE,  # noqa: E402
                    STIFFNESS_DEGREE_3D, Problem, Problem3, Unsupported, facets_in_box, in_box,
                    is_3d_case, write_reference)

# Gauss-Lobatto rules with the points of our nodal contact weights (common.NODAL_RULE).
CONTACT_RULE = {"Q4": 1, "T3": 1, "Q9": 3, "T6": 3}

CELL = {"Q4": ("quadrilateral", 1), "Q9": ("quadrilateral", 2),
        "T3": ("triangle", 1), "T6": ("triangle", 2)}
DCELL = {"quadrilateral": dmesh.CellType.quadrilateral, "triangle": dmesh.CellType.triangle}


def write_vtu(path, msh, degree, uh, sigma, contact_fields=()):
    """DOLFINx's own VTK output of u_h and sigma(u_h) (see the module text), and the contact
    fields of `contact_point_fields` when the case has contact."""
    uh.name = "displacement"
    # xx, yy, xy as a 3-vector: DOLFINx pads a 2x2 tensor to 9 values as xx, xy, yx, yy, 0..
    # (not the 3x3 row-by-row layout VTK readers expect)
    W = fem.functionspace(msh, ("Lagrange", degree, (3,)))
    s = fem.Function(W)
    s.name = "stress"
    S = sigma(uh)
    s.interpolate(fem.Expression(ufl.as_vector([S[0, 0], S[1, 1], S[0, 1]]),
                                 W.element.interpolation_points))
    with dolfinx.io.VTKFile(MPI.COMM_SELF, str(path), "w") as f:
        f.write_function([uh, s, *contact_fields])


def contact_point_fields(msh, degree, V, uh, pb, contact):
    """The point fields `contact-patch judge` reads for the contact checks: `contact_force`,
    the assembled nodal force of every pair's penalty term on the body (the vector
    t kappa int (g)_- (n . v) ds, the residual's contact part); `contact_pressure`,
    kappa (-g_a)_+ at each slave node (compression positive; with the Gauss-Lobatto rule at the
    facet nodes it equals f_a . n_a / A_a, as in our tool); `contact_gap`, g_a at the slave
    nodes (g < 0: penetration). Zero away from the slave nodes."""
    fc = fem.Function(V)
    fc.name = "contact_force"
    fc.x.array[:] = 0.0
    Q = fem.functionspace(msh, ("Lagrange", degree))
    pc, gc = fem.Function(Q), fem.Function(Q)
    pc.name, gc.name = "contact_pressure", "contact_gap"
    pc.x.array[:] = 0.0
    gc.x.array[:] = 0.0
    # V's dof nodes -> Q's dofs, by coordinates (the same nodes of the same mesh)
    tree = cKDTree(Q.tabulate_dof_coordinates()[:, :2])
    d, to_q = tree.query(V.tabulate_dof_coordinates()[:, :2])
    if d.max() > pb.tol:
        raise RuntimeError(f"{pb.name}: scalar and vector dof nodes differ by {d.max():.3e}")
    for pair, entry in zip(pb.contact, contact["pairs"]):
        fc.x.array[:] += entry["nodal_force"]
        dn = np.asarray(entry["dofs"], dtype=np.int64)
        g = np.asarray(entry["gap"])
        pc.x.array[to_q[dn]] = pair.kappa * np.maximum(-g, 0.0)
        gc.x.array[to_q[dn]] = g
    return [fc, pc, gc]


def solve(pb: Problem, vtu_path=None):
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
    # Facets carry ("load", k) and ("contact", j) keys; one tag per combination.
    on_facet = {}
    L = None
    load_terms = {}   # per load: its terms (the Coulomb solve scales each by its path)
    for k, ld in enumerate(pb.loads):
        if ld.box is None:
            dxb = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": BODY_FORCE_DEGREE})
            term = th * ufl.dot(ufl.as_vector(ld.value), v) * dxb
            L = term if L is None else L + term
            load_terms.setdefault(k, []).append(term)
            continue
        f = dmesh.locate_entities_boundary(msh, fdim, lambda X, box=ld.box: in_box(X[:2].T, box))
        if len(f) == 0:
            raise RuntimeError(f"{pb.name}: load {k} selects no boundary facet")
        for i in f:
            on_facet.setdefault(int(i), []).append(("load", k))
    for j, pair in enumerate(pb.contact):
        f = dmesh.locate_entities_boundary(msh, fdim,
                                           lambda X, box=pair.box: in_box(X[:2].T, box))
        if len(f) == 0:
            raise RuntimeError(f"{pb.name}: contact '{pair.name}' selects no boundary facet")
        for i in f:
            on_facet.setdefault(int(i), []).append(("contact", j))
    contact_terms = []   # (pair index, tag) of each contact facet group
    mt = None
    if on_facet:
        combos = sorted({tuple(ks) for ks in on_facet.values()})
        tag_of = {c: j + 1 for j, c in enumerate(combos)}
        facets = np.array(sorted(on_facet), dtype=np.int32)
        tags = np.array([tag_of[tuple(on_facet[i])] for i in facets], dtype=np.int32)
        mt = dmesh.meshtags(msh, fdim, facets, tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                         metadata={"quadrature_degree": LOAD_DEGREE})
        for combo, tag in tag_of.items():
            for what, k in combo:
                if what == "contact":
                    contact_terms.append((k, tag))
                    continue
                t = pb.loads[k].traction(x[0], x[1], n)
                term = th * ufl.dot(ufl.as_vector(t), v) * ds(tag)
                L = term if L is None else L + term
                load_terms.setdefault(k, []).append(term)
    if L is None:
        L = ufl.dot(ufl.as_vector([0.0, 0.0]), v) * dx

    # Supports: per component, the dofs at the support nodes (by coordinates).
    bcs, bcs0 = [], []
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
        z = fem.Function(Vc)
        z.x.array[:] = 0.0
        bcs0.append(fem.dirichletbc(z, [cmap[idx], idx], V.sub(comp)))

    X = V.tabulate_dof_coordinates()[:, :2]
    ids, dist = pb.match(X)
    extra = {"match_distance": dist, "dofs": 2 * X.shape[0],
             "stiffness_quadrature_degree": STIFFNESS_DEGREE[pb.element],
             "load_quadrature_degree": LOAD_DEGREE}
    if pb.finite:
        uh, finite = solve_finite(pb, msh, V, load_terms, mt, contact_terms, th, ids)
        extra.update(finite)
    elif pb.frictional:
        uh, contact = solve_friction(pb, msh, V, a, load_terms, mt, contact_terms, th, ids)
        extra["contact"] = contact
    elif pb.contact:
        uh, contact = newton_penalty(pb, msh, V, a, L, bcs, bcs0, mt, contact_terms, th, ids)
        extra["contact"] = contact
    else:
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

    if vtu_path is not None and not pb.frictional and not pb.finite:
        fields = contact_point_fields(msh, degree, V, uh, pb, extra["contact"]) \
            if pb.contact else ()
        write_vtu(vtu_path, msh, degree, uh, sigma, fields)
    for entry in extra.get("contact", {}).get("pairs", []):   # not for the reference file
        for key in ("nodal_force", "dofs", "gap"):
            entry.pop(key, None)
    U = uh.x.array.reshape(-1, 2)
    out = np.empty_like(pb.u_ours)
    out[ids] = U
    return out, extra


# Our mass quadrature (src/solid.rs `mass_rule`): Gauss 3x3 (Q4) and 4x4 (Q9), i.e. basix
# degrees 4 and 7; triangles are affine, where any rule exact for the integrand agrees.
MASS_DEGREE = {"Q4": 4, "Q9": 7, "T3": 2, "T6": 4}
NEWMARK = {"average_acceleration": (0.25, 0.5), "central_difference": (0.0, 0.5)}


def solve_wave(pb: Problem):
    """Newmark time stepping of an elastic body without contact (see the module text). Returns
    the displacement at the last step (in .vtu order) and the history."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    dyn = pb.dynamics
    if pb.contact:
        raise Unsupported("dynamics with contact (the wave cross-check has none)")
    integrator = dyn.get("integrator", "average_acceleration")
    beta, gamma = (NEWMARK[integrator] if isinstance(integrator, str)
                   else (integrator["newmark"]["beta"], integrator["newmark"]["gamma"]))
    if beta <= 0.0:
        raise Unsupported("the explicit member (beta = 0)")
    dt, end = float(dyn["dt"]), float(dyn["end_time"])
    ratio = end / dt
    steps = max(1, math.ceil(ratio - 1e-9 * ratio))     # as src/model/dynamics.rs
    mass_kind = dyn.get("mass", "lumped")
    rho = float(pb.case["materials"][pb.case["bodies"][0]["material"]]["density"])

    cellname, degree = CELL[pb.element]
    perm = cell_perm_vtk(DCELL[cellname], pb.cells.shape[1])
    cells = np.ascontiguousarray(pb.cells[:, perm], dtype=np.int64)
    coord_el = basix.ufl.element("Lagrange", cellname, degree, shape=(2,),
                                 lagrange_variant=basix.LagrangeVariant.equispaced)
    msh = dmesh.create_mesh(MPI.COMM_SELF, cells, ufl.Mesh(coord_el), pb.points)
    V = fem.functionspace(msh, ("Lagrange", degree, (2,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    mat = pb.material
    th = fem.Constant(msh, pb.thickness)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    def sigma(w):
        return mat.lam * ufl.tr(eps(w)) * ufl.Identity(2) + 2.0 * mat.mu * eps(w)

    dxk = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": STIFFNESS_DEGREE[pb.element]})
    dxm = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": MASS_DEGREE[pb.element]})
    K = fem.assemble_matrix(fem.form(th * ufl.inner(sigma(u), eps(v)) * dxk)).to_scipy().tocsr()
    M = fem.assemble_matrix(fem.form(th * rho * ufl.inner(u, v) * dxm)).to_scipy().tocsr()
    if mass_kind == "lumped":
        M = sp.diags(np.asarray(M.sum(axis=1)).ravel()).tocsr()

    # facet loads (constant in time) and body forces, as in `solve`
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, msh.topology.dim)
    x, n = ufl.SpatialCoordinate(msh), ufl.FacetNormal(msh)
    f = np.zeros(K.shape[0])
    for k, ld in enumerate(pb.loads):
        if ld.box is None:
            dxb = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": BODY_FORCE_DEGREE})
            form = th * ufl.dot(ufl.as_vector(ld.value), v) * dxb
        else:
            facets = dmesh.locate_entities_boundary(
                msh, fdim, lambda X, box=ld.box: in_box(X[:2].T, box))
            if len(facets) == 0:
                raise RuntimeError(f"{pb.name}: load {k} selects no boundary facet")
            mt = dmesh.meshtags(msh, fdim, np.sort(facets).astype(np.int32),
                                np.ones(len(facets), dtype=np.int32))
            ds = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                             metadata={"quadrature_degree": LOAD_DEGREE})
            form = th * ufl.dot(ufl.as_vector(ld.traction(x[0], x[1], n)), v) * ds(1)
        f += fem.assemble_vector(fem.form(form)).array

    # dof 2 i + c is component c of the node at V's coordinate i (block size 2)
    X = V.tabulate_dof_coordinates()[:, :2]
    ids, dist = pb.match(X)                      # DOLFINx node -> .vtu point
    inv = np.empty(len(ids), dtype=np.int64)
    inv[ids] = np.arange(len(ids))               # .vtu point -> DOLFINx node
    tree = cKDTree(X)
    fixed = np.zeros(K.shape[0], dtype=bool)
    for coords, comp, values in pb.supports:
        d, idx = tree.query(coords)
        if d.max() > pb.tol:
            raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
        if np.any(values != 0.0):
            raise Unsupported("a non-zero support in a dynamic case")
        fixed[2 * idx + comp] = True
    free = np.flatnonzero(~fixed)

    vel = np.zeros(K.shape[0])
    for iv in dyn.get("initial_velocity", []):
        if iv["body"] != pb.body:
            raise Unsupported(f"initial velocity of body {iv['body']!r}")
        nodes = pb.node_set(iv["set"]) if iv.get("set") else np.arange(len(pb.points))
        for comp in (0, 1):
            vel[2 * inv[nodes] + comp] = float(iv["velocity"][comp])
    vel[fixed] = 0.0

    Kff, Mff = K[free][:, free], M[free][:, free]
    c0 = 1.0 / (beta * dt * dt)
    effective = spla.splu((Kff + c0 * Mff).tocsc())
    mass_lu = spla.splu(Mff.tocsc())
    d = np.zeros(K.shape[0])
    a = np.zeros(K.shape[0])
    a[free] = mass_lu.solve(f[free] - Kff @ d[free])

    def on_vtu(w):
        return w.reshape(-1, 2)[inv]             # DOLFINx nodes -> .vtu order

    def energies():
        return {"kinetic": 0.5 * vel @ (M @ vel), "strain": 0.5 * d @ (K @ d),
                "load": -f @ d}

    history = {"time": [0.0], "u": [on_vtu(d).tolist()]}
    energy = {k: [e] for k, e in energies().items()}
    for step in range(1, steps + 1):
        predictor = d + dt * vel + dt * dt * (0.5 - beta) * a
        d_new = np.zeros_like(d)
        d_new[free] = effective.solve(f[free] + c0 * (Mff @ predictor[free]))
        a_new = np.zeros_like(a)
        a_new[free] = c0 * (d_new[free] - predictor[free])
        vel = vel + dt * ((1.0 - gamma) * a + gamma * a_new)
        d, a = d_new, a_new
        history["time"].append(step * dt)
        history["u"].append(on_vtu(d).tolist())
        for k, e in energies().items():
            energy[k].append(float(e))
    extra = {"match_distance": dist, "dofs": int(K.shape[0]),
             "stiffness_quadrature_degree": STIFFNESS_DEGREE[pb.element],
             "mass_quadrature_degree": MASS_DEGREE[pb.element], "mass": mass_kind,
             "newmark": {"beta": beta, "gamma": gamma, "dt": dt, "steps": steps},
             "history": history, "energy": energy}
    return on_vtu(d), extra


def newton_penalty(pb, msh, V, a, L, bcs_values, bcs0, mt, contact_terms, th, ids):
    """Newton's method for K u = f + penalty contact forces (see the module text), from u = 0
    plus the supports' values. `bcs0` are the supports with zero values (for the increments).
    Returns the solution and, per pair, the total force, the nodal pressures f_i . n_i / A_i
    at the slave nodes (.vtu ids), the active nodes, and the Newton history."""
    uh = fem.Function(V)
    v = ufl.TestFunction(V)
    du = ufl.TrialFunction(V)
    x = ufl.SpatialCoordinate(msh)
    dsc = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                      metadata={"quadrature_rule": "GLL",
                                "quadrature_degree": CONTACT_RULE[pb.element]})

    def over_pair(k, integrand):
        terms = [integrand * dsc(tag) for kk, tag in contact_terms if kk == k]
        return sum(terms[1:], terms[0])

    def force_form(k, w):
        """Virtual work of pair k's contact force on the body, test function w."""
        pair = pb.contact[k]
        g, nx, ny = pair.gap(x[0], x[1], uh[0], uh[1], ufl.sqrt)
        pos = ufl.conditional(ufl.le(g, 0.0), -g, 0.0)
        return over_pair(k, th * pair.kappa * pos * (nx * w[0] + ny * w[1]))

    F = ufl.action(a, uh) - L
    for k in range(len(pb.contact)):
        F = F - force_form(k, v)
    F_form = fem.form(F)
    J_form = fem.form(ufl.derivative(F, uh, du))
    f_ext = dolfinx.fem.petsc.assemble_vector(fem.form(L))
    f_scale = max(float(np.abs(f_ext.array).max()), np.finfo(float).tiny)

    for bc in bcs_values:                        # the iterate carries the supports' values
        bc.set(uh.x.array)

    A = dolfinx.fem.petsc.create_matrix(J_form)
    b = dolfinx.fem.petsc.create_vector(V)
    ksp = PETSc.KSP().create(msh.comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    dU = fem.Function(V)

    inv = np.empty(len(ids), dtype=np.int64)
    inv[ids] = np.arange(len(ids))               # .vtu point -> DOLFINx dof node
    slave = []                                   # per pair: .vtu ids, DOLFINx nodes
    for pair in pb.contact:
        nodes = np.array(sorted({nd for f in facets_in_box(pb, pair.box) for nd in f}))
        slave.append((nodes, inv[nodes]))

    def active_sets():
        """g <= 0 at the slave nodes (reference coordinates from the .vtu, as our rows)."""
        U = uh.x.array.reshape(-1, 2)
        out = []
        for pair, (vn, dn) in zip(pb.contact, slave):
            X = pb.points[vn]
            g, _, _ = pair.gap(X[:, 0], X[:, 1], U[dn, 0], U[dn, 1], np.sqrt)
            out.append(tuple(bool(t) for t in g <= 0.0))
        return tuple(out)

    def residual():
        with b.localForm() as bl:
            bl.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, F_form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        dolfinx.fem.petsc.set_bc(b, bcs0)        # zero on supported dofs
        return b

    history = []
    seen = set()
    current = active_sets()
    for it in range(1, 101):
        A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(A, J_form, bcs=bcs0)
        A.assemble()
        r = residual()
        r.scale(-1.0)
        ksp.setOperators(A)
        ksp.solve(r, dU.x.petsc_vec)
        if ksp.getConvergedReason() <= 0:
            raise RuntimeError(f"{pb.name}: Newton step {it}: MUMPS failed "
                               f"(reason {ksp.getConvergedReason()})")
        dU.x.scatter_forward()
        uh.x.array[:] += dU.x.array
        new = active_sets()
        step = float(np.abs(dU.x.array).max() / max(np.abs(uh.x.array).max(), 1e-300))
        history.append({"iteration": it, "active": [sum(s) for s in current],
                        "relative_step": step})
        if new == current:
            break
        if new in seen:
            raise RuntimeError(f"{pb.name}: the Newton active sets cycle")
        seen.add(current)
        current = new
    else:
        raise RuntimeError(f"{pb.name}: Newton did not settle in 100 iterations")
    res = float(np.abs(residual().array).max()) / f_scale
    if not res <= 1e-9:
        raise RuntimeError(f"{pb.name}: Newton settled with relative residual {res:.2e}")

    contact = []
    U = uh.x.array.reshape(-1, 2)
    for k, (pair, (vn, dn)) in enumerate(zip(pb.contact, slave)):
        f = dolfinx.fem.petsc.assemble_vector(fem.form(force_form(k, v))).array.reshape(-1, 2)
        area = dolfinx.fem.petsc.assemble_vector(
            fem.form(over_pair(k, th * v[0]))).array.reshape(-1, 2)[:, 0]
        X = pb.points[vn]
        _, nx, ny = pair.gap(X[:, 0], X[:, 1], U[dn, 0], U[dn, 1], np.sqrt)
        nx, ny = np.broadcast_to(nx, dn.shape), np.broadcast_to(ny, dn.shape)
        normal_force = f[dn, 0] * nx + f[dn, 1] * ny
        pressure = normal_force / area[dn]
        gap, _, _ = pair.gap(X[:, 0], X[:, 1], U[dn, 0], U[dn, 1], np.sqrt)
        contact.append({"name": pair.name, "total_force": f.sum(axis=0).tolist(),
                        "nodes": vn.tolist(), "area": area[dn].tolist(),
                        "pressure": pressure.tolist(),
                        "active": [bool(t) for t in current[k]],
                        # for the .vtu point fields (contact_point_fields), then dropped
                        "nodal_force": f.reshape(-1).copy(), "dofs": dn.tolist(),
                        "gap": np.broadcast_to(gap, dn.shape).tolist()})
    return uh, {"pairs": contact, "newton": history, "iterations": len(history),
                "relative_residual": res,
                "contact_quadrature": f"GLL degree {CONTACT_RULE[pb.element]}"}


def solve_friction(pb, msh, V, a, load_terms, mt, contact_terms, th, ids):
    """Penalty Coulomb contact against a rigid line, load step by load step (see the module
    text): DOLFINx assembles the stiffness matrix K, each load's vector and the nodal contact
    weights A_a (GLL rule = our rows' tributary areas); numpy/scipy run Newton's method on
    R(u) = K u - sum_k c_k f_k - sum_a (lambda_n n + lambda_t t)_a with the return map of
    src/contact/friction.rs per slave node: lambda_n = kappa A (-g)_+ (closed iff g < 0),
    trial lambda_t = -kappa_t A (g_t - g_t^{p,n}), stick if |trial| <= mu lambda_n, else slip
    at sign(trial) mu lambda_n with g_t^p = g_t + lambda_t / (kappa_t A); open: g_t^p = g_t.
    The plastic slip is committed at the end of each step. Tangent: K + w_n n n^T (closed),
    + w_t t t^T (stick), + s mu w_n t n^T (slip; unsymmetric), solved by SuperLU."""
    v = ufl.TestFunction(V)
    dsc = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                      metadata={"quadrature_rule": "GLL",
                                "quadrature_degree": CONTACT_RULE[pb.element]})
    Kp = dolfinx.fem.petsc.assemble_matrix(fem.form(a))
    Kp.assemble()
    ip, jp, vals = Kp.getValuesCSR()
    ndof = V.dofmap.index_map.size_local * 2
    K = scipy.sparse.csr_matrix((vals, jp, ip), shape=(ndof, ndof))
    f_load = {k: dolfinx.fem.petsc.assemble_vector(fem.form(sum(t[1:], t[0]))).array.copy()
              for k, t in load_terms.items()}
    X = V.tabulate_dof_coordinates()[:, :2]          # one row per node; dof = 2 node + comp
    tree = cKDTree(X)
    fixed, fixed_vals = {}, {}
    for (coords, comp, values), path in zip(pb.supports, pb.support_paths):
        d, idx = tree.query(coords)
        if d.max() > pb.tol:
            raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
        for node, val in zip(idx, values):
            fixed[2 * int(node) + comp] = (float(val), path)   # later supports win
    fixed_dofs = np.array(sorted(fixed), dtype=np.int64)
    free = np.setdiff1d(np.arange(ndof), fixed_dofs)

    inv = np.empty(len(ids), dtype=np.int64)
    inv[ids] = np.arange(len(ids))
    pairs = []
    for k, pair in enumerate(pb.contact):
        tags = [tag for kk, tag in contact_terms if kk == k]
        form = sum((th * v[0] * dsc(tag) for tag in tags[1:]), th * v[0] * dsc(tags[0]))
        area = dolfinx.fem.petsc.assemble_vector(fem.form(form)).array.reshape(-1, 2)[:, 0]
        vn = np.array(sorted({nd for f in facets_in_box(pb, pair.box) for nd in f}))
        dn = inv[vn]
        n = np.asarray(pair.normal, dtype=float)
        t = np.array([n[1], -n[0]])
        g0 = (pb.points[vn] - pair.point) @ n
        pairs.append({"pair": pair, "vn": vn, "dn": dn, "A": area[dn], "n": n, "t": t,
                      "g0": g0, "committed": np.zeros(len(vn))})

    def contact(u, pr, first=False):
        """Per node: forces (lambda_n, lambda_t), statuses, plastic slips, weights, slip sign.
        `first` (a step's first iteration, as our rows' `closed_at_start`): a node touching
        (g <= 0) counts as closed, so a block resting on the line with g = 0 and held in x by
        friction alone has a regular first tangent."""
        pair = pr["pair"]
        U = u.reshape(-1, 2)[pr["dn"]]
        g = pr["g0"] + U @ pr["n"]
        g_t = U @ pr["t"]
        w_n, w_t = pair.kappa * pr["A"], pair.kappa_t * pr["A"]
        closed = (g <= 0.0) if first else (g < 0.0)
        lam_n = np.where(closed, -w_n * g, 0.0)
        trial = -w_t * (g_t - pr["committed"])
        bound = pair.mu * np.maximum(lam_n, 0.0)
        stick = closed & (np.abs(trial) <= bound)
        slip = closed & ~stick
        lam_t = np.where(stick, trial, np.where(slip, np.sign(trial) * bound, 0.0))
        plastic = np.where(stick, pr["committed"],
                           np.where(slip, g_t + lam_t / np.where(w_t > 0, w_t, 1.0), g_t))
        status = np.where(~closed, "open", np.where(stick, "stick", "slip"))
        return lam_n, lam_t, status, plastic, w_n, w_t, np.sign(trial)

    def assemble(u, first=False):
        R = K @ u
        rows, cols, data = [], [], []
        for pr in pairs:
            lam_n, lam_t, status, _, w_n, w_t, s = contact(u, pr, first)
            n, t = pr["n"], pr["t"]
            for i, d in enumerate(pr["dn"]):
                dofs = [2 * d, 2 * d + 1]
                R[dofs] -= lam_n[i] * n + lam_t[i] * t
                blk = np.zeros((2, 2))
                if status[i] != "open":
                    blk += w_n[i] * np.outer(n, n)
                if status[i] == "stick":
                    blk += w_t[i] * np.outer(t, t)
                elif status[i] == "slip":
                    blk += s[i] * pr["pair"].mu * w_n[i] * np.outer(t, n)
                for a_ in range(2):
                    for b_ in range(2):
                        rows.append(dofs[a_])
                        cols.append(dofs[b_])
                        data.append(blk[a_, b_])
        Kc = scipy.sparse.csr_matrix((data, (rows, cols)), shape=(ndof, ndof))
        return R, (K + Kc).tocsr()

    u = np.zeros(ndof)
    history, steps = [], []
    res = 0.0
    for step in range(1, pb.load_steps + 1):
        f = np.zeros(ndof)
        for k, fk in f_load.items():
            f += pb.factor(pb.load_paths[k], step) * fk
        for d, (val, path) in fixed.items():
            u[d] = pb.factor(path, step) * val
        f_scale = max(float(np.abs(f).max()), float(np.abs(K @ u).max()), np.finfo(float).tiny)
        for it in range(1, 101):
            R, J = assemble(u, first=it == 1)
            R -= f
            du = scipy.sparse.linalg.spsolve(J[free][:, free].tocsc(), -R[free])
            if not np.all(np.isfinite(du)):
                raise RuntimeError(f"{pb.name}: step {step}, iteration {it}: singular tangent")
            u[free] += du
            R, _ = assemble(u)
            res = float(np.abs((R - f)[free]).max()) / f_scale
            history.append({"step": step, "iteration": it, "relative_residual": res,
                            "status": [{str(k): int(c) for k, c in
                                        zip(*np.unique(contact(u, pr)[2], return_counts=True))}
                                       for pr in pairs]})
            if res <= 1e-12:
                break
        else:
            raise RuntimeError(f"{pb.name}: step {step}: Newton did not converge in 100 "
                               f"iterations (relative residual {res:.2e})")
        final = [contact(u, pr) for pr in pairs]   # the step's map, before its commit
        for pr, m in zip(pairs, final):
            pr["committed"] = m[3]
        steps.append({"step": step, "iterations": it, "relative_residual": res,
                      "status": [{str(k): int(c) for k, c in
                                  zip(*np.unique(m[2], return_counts=True))} for m in final]})

    out_pairs = []
    for pr, m in zip(pairs, final):
        lam_n, lam_t, status, plastic, *_ = m
        force = np.outer(lam_n, pr["n"]) + np.outer(lam_t, pr["t"])
        out_pairs.append({"name": pr["pair"].name, "total_force": force.sum(axis=0).tolist(),
                          "nodes": pr["vn"].tolist(), "area": pr["A"].tolist(),
                          "pressure": (lam_n / pr["A"]).tolist(),
                          "active": [bool(s_ != "open") for s_ in status],
                          "slave_force": force.tolist(), "status": status.tolist(),
                          "tangential_force": lam_t.tolist(),
                          "plastic_slip": plastic.tolist()})
    uh = fem.Function(V)
    uh.x.array[:] = u
    return uh, {"pairs": out_pairs, "newton": history, "steps": steps,
                "iterations": len(history), "relative_residual": res,
                "contact_quadrature": f"GLL degree {CONTACT_RULE[pb.element]}"}


def hyperelastic_energy(model, lam, mu, uh):
    """The stored energy per reference volume of src/solid_finite.rs in UFL, plane strain
    (F_33 = 1): F = I + grad u (2x2), C = F^T F, J = det F;
    neo-Hookean W = mu/2 (I_1 - 3 - 2 ln J) + lambda/2 (ln J)^2 with I_1 = tr C + 1 (the
    three-dimensional trace, C_33 = 1); St. Venant-Kirchhoff W = lambda/2 (tr E)^2 + mu E:E,
    E = (C - I)/2 (E_33 = 0)."""
    identity = ufl.Identity(2)
    F = identity + ufl.grad(uh)
    C = F.T * F
    if model == "neo_hookean":
        ln_j = ufl.ln(ufl.det(F))
        return 0.5 * mu * (ufl.tr(C) + 1.0 - 3.0 - 2.0 * ln_j) + 0.5 * lam * ln_j**2
    if model == "saint_venant_kirchhoff":
        E = 0.5 * (C - identity)
        return 0.5 * lam * ufl.tr(E)**2 + mu * ufl.inner(E, E)
    raise Unsupported(f"material model {model!r}")


def solve_finite(pb, msh, V, load_terms, mt, contact_terms, th, ids):
    """Finite kinematics (total Lagrangian), optionally with frictionless penalty contact
    against a rigid line: the residual is the derivative of the stored energy
    `int t W(F) dX` (hyperelastic_energy, quadrature of our stiffness rule) minus the dead
    loads times their load factors minus the penalty term `int t kappa (g)_- (n . v) dS` over
    the reference slave facets with the Gauss-Lobatto rule of our nodal weights, `g = n . (X +
    u - p)` the gap in the current configuration (for a line it is affine in u, and our rows
    take the reference nodal weights A_a as this rule does). UFL derives the tangent. Per load
    step (the case's `path` factors or k/n) the supports take their values times the factor
    and Newton's method runs in numpy/scipy on the free dofs (SuperLU) from the last step's
    solution until the relative residual (max over free dofs of |R| over the larger of the
    largest load and the largest internal force) reaches 1e-14, or stops falling below 1e-12
    (round-off); a step that ends above 1e-12 is an error."""
    v, du = ufl.TestFunction(V), ufl.TrialFunction(V)
    uh = fem.Function(V)
    x = ufl.SpatialCoordinate(msh)
    mat = pb.material
    lam, mu = fem.Constant(msh, mat.lam), fem.Constant(msh, mat.mu)
    dx = ufl.Measure("dx", domain=msh,
                     metadata={"quadrature_degree": STIFFNESS_DEGREE[pb.element]})
    internal = ufl.derivative(th * hyperelastic_energy(pb.hyperelastic, lam, mu, uh) * dx, uh, v)
    factors = {k: fem.Constant(msh, 0.0) for k in load_terms}
    external = None
    for k, terms in load_terms.items():
        term = factors[k] * sum(terms[1:], terms[0])
        external = term if external is None else external + term
    contact_forms = []
    if pb.contact:
        dsc = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                          metadata={"quadrature_rule": "GLL",
                                    "quadrature_degree": CONTACT_RULE[pb.element]})
        for k, pair in enumerate(pb.contact):
            g, nx, ny = pair.gap(x[0], x[1], uh[0], uh[1], ufl.sqrt)
            pos = ufl.conditional(ufl.le(g, 0.0), -g, 0.0)
            terms = [th * pair.kappa * pos * (nx * v[0] + ny * v[1]) * dsc(tag)
                     for kk, tag in contact_terms if kk == k]
            contact_forms.append(sum(terms[1:], terms[0]))
    F = internal
    if external is not None:
        F = F - external
    for cf in contact_forms:
        F = F - cf
    F_form, J_form = fem.form(F), fem.form(ufl.derivative(F, uh, du))
    internal_form = fem.form(internal)
    external_form = fem.form(external) if external is not None else None

    X = V.tabulate_dof_coordinates()[:, :2]          # one row per node; dof = 2 node + comp
    ndof = 2 * X.shape[0]
    tree = cKDTree(X)
    fixed = {}
    for (coords, comp, values), path in zip(pb.supports, pb.support_paths):
        d, idx = tree.query(coords)
        if d.max() > pb.tol:
            raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
        for node, val in zip(idx, values):
            fixed[2 * int(node) + comp] = (float(val), path)   # later supports win
    free = np.setdiff1d(np.arange(ndof), np.array(sorted(fixed), dtype=np.int64))

    def vector(form):
        return dolfinx.fem.petsc.assemble_vector(form).array.copy()

    def jacobian():
        A = dolfinx.fem.petsc.assemble_matrix(J_form)
        A.assemble()
        ip, jp, vals = A.getValuesCSR()
        return scipy.sparse.csr_matrix((vals, jp, ip), shape=(ndof, ndof))

    def relative_residual():
        r = vector(F_form)
        f_ext = np.abs(vector(external_form)).max() if external_form is not None else 0.0
        scale = max(f_ext, float(np.abs(vector(internal_form)).max()), np.finfo(float).tiny)
        return r, float(np.abs(r[free]).max()) / scale

    history, steps = [], []
    for step in range(1, pb.load_steps + 1):
        for k, c in factors.items():
            c.value = pb.factor(pb.load_paths[k], step)
        # the supports' increment enters the first iteration through the tangent at the last
        # step's state (J_ff du_f = -r_f - J_fc du_c), so the first iterate is the linearized
        # step and not a mesh with its supported nodes alone moved
        dofs = np.array(sorted(fixed), dtype=np.int64)
        target = np.array([pb.factor(fixed[d][1], step) * fixed[d][0] for d in dofs])
        lift = np.zeros(ndof)
        lift[dofs] = target - uh.x.array[dofs]
        r, res = relative_residual()
        it = 0
        while (res > 1e-14 or it == 0) and it < 50:
            it += 1
            J = jacobian()
            rhs = -r[free] - (J[free] @ lift) if it == 1 else -r[free]
            delta = scipy.sparse.linalg.spsolve(J[free][:, free].tocsc(), rhs)
            if it == 1:
                uh.x.array[dofs] = target
            if not np.all(np.isfinite(delta)):
                raise RuntimeError(f"{pb.name}: step {step}, iteration {it}: singular tangent")
            uh.x.array[free] += delta
            previous = res
            r, res = relative_residual()
            history.append({"step": step, "iteration": it, "relative_residual": res})
            if res <= 1e-12 and res > 0.5 * previous:   # stalled at round-off
                break
        if not res <= 1e-12:
            raise RuntimeError(f"{pb.name}: step {step}: Newton ended at relative residual "
                               f"{res:.2e} after {it} iterations")
        steps.append({"step": step, "iterations": it, "relative_residual": res})

    pairs = []
    inv = np.empty(len(ids), dtype=np.int64)
    inv[ids] = np.arange(len(ids))                   # .vtu point -> DOLFINx dof node
    U = uh.x.array.reshape(-1, 2)
    for pair, cf in zip(pb.contact, contact_forms):
        f = vector(fem.form(cf)).reshape(-1, 2)
        vn = np.array(sorted({nd for fc in facets_in_box(pb, pair.box) for nd in fc}))
        dn = inv[vn]
        P = pb.points[vn]
        g, _, _ = pair.gap(P[:, 0], P[:, 1], U[dn, 0], U[dn, 1], np.sqrt)
        pairs.append({"name": pair.name, "total_force": f.sum(axis=0).tolist(),
                      "nodes": vn.tolist(), "slave_force": f[dn].tolist(),
                      "gap": np.asarray(g).tolist(), "active": [bool(t) for t in g < 0.0]})
    return uh, {"finite": {"material": pb.hyperelastic, "steps": steps, "newton": history,
                           "relative_residual": max(s["relative_residual"] for s in steps)},
                "contact": {"pairs": pairs,
                            "contact_quadrature": f"GLL degree {CONTACT_RULE[pb.element]}"}}



# --- 3D (src/run3d.rs) -------------------------------------------------------------------------
CELL_3D = {"Hex8": ("hexahedron", 1), "Hex27": ("hexahedron", 2),
           "Tet4": ("tetrahedron", 1), "Tet10": ("tetrahedron", 2)}
DCELL_3D = {"hexahedron": dmesh.CellType.hexahedron, "tetrahedron": dmesh.CellType.tetrahedron}
# The reference corners of our (VTK) hexahedron, src/fe3d.rs HEX_CORNERS.
VTK_HEX_CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                            [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


def our_cell_volumes(pb):
    """The volume of every cell of our .vtu, from its corners in our (VTK) order alone:
    tetrahedra det[x1 - x0, x2 - x0, x3 - x0] / 6 (straight edges); hexahedra the trilinear map
    of the eight corners integrated with Gauss 2x2x2 (det J is of degree 2 per direction, so
    this is exact). Independent of DOLFINx's node order, it checks the permutation."""
    X = pb.points[pb.cells]
    if pb.element.startswith("Tet"):
        return np.linalg.det(np.stack([X[:, k] - X[:, 0] for k in (1, 2, 3)], axis=2)) / 6.0
    g = 1.0 / math.sqrt(3.0)
    vol = np.zeros(len(X))
    for q in np.array([[a, b, c] for a in (-g, g) for b in (-g, g) for c in (-g, g)]):
        s = VTK_HEX_CORNERS
        dn = np.stack([s[:, i] * np.prod([1 + s[:, j] * q[j] for j in range(3) if j != i], axis=0)
                       for i in range(3)], axis=1) / 8.0          # (8, 3): dN_a / dxi_i
        J = np.einsum("cai,aj->cij", X[:, :8], dn)
        vol += np.linalg.det(J)
    return vol


def check_geometry_3d(msh, pb, degree):
    """The VTK-to-DOLFINx node map, checked two ways against our .vtu: (1) every cell's volume
    in DOLFINx (int 1 dx per cell) equals the one from our corners in VTK order
    (`our_cell_volumes`; a wrong corner permutation twists the cell and changes it); (2) on
    degree-2 cells every geometry node sits where basix's reference node of its place in the
    DOLFINx order maps under the cell's vertex map (our meshes place the mid-edge, face and
    body nodes at that map's points, src/mesh.rs `block3`), so a misplaced mid-edge or face node
    shows. Returns the largest relative differences; raises when either exceeds 1e-12."""
    dim = 3
    Q0 = fem.functionspace(msh, ("DG", 0))
    w = ufl.TestFunction(Q0)
    vol_dolfinx = fem.assemble_vector(fem.form(w * ufl.dx(domain=msh))).array
    original = np.asarray(msh.topology.original_cell_index)
    vol_ours = our_cell_volumes(pb)[original]
    dvol = float(np.abs(vol_dolfinx - vol_ours).max() / np.abs(vol_ours).max())
    dnode = 0.0
    if degree == 2:
        cellname = CELL_3D[pb.element][0]
        bcell = basix.CellType[cellname]
        ref = basix.create_element(basix.ElementFamily.P, bcell, 2,
                                   basix.LagrangeVariant.equispaced).points
        p1 = basix.create_element(basix.ElementFamily.P, bcell, 1,
                                  basix.LagrangeVariant.equispaced)
        phi = p1.tabulate(0, ref)[0, :, :, 0]                   # (nodes, vertices)
        G = msh.geometry.x[msh.geometry.dofmaps[0]][:, :, :dim]     # (cells, nodes, 3)
        nv = phi.shape[1]
        mapped = np.einsum("pv,cvd->cpd", phi, G[:, :nv])
        dnode = float(np.abs(mapped - G).max() / pb.size)
    if dvol > 1e-12 or dnode > 1e-12:
        raise RuntimeError(f"{pb.name}: the VTK-to-DOLFINx node map fails its check (cell "
                           f"volumes differ by {dvol:.2e}, geometry nodes by {dnode:.2e})")
    return {"cell_volume_difference": dvol, "node_place_difference": dnode}


def solve3(pb, vtu_path=None):
    """Linear elasticity in 3D on our .vtu mesh (see the module text), with frictionless
    penalty contact against a rigid plane or sphere when the case has pairs (`newton_penalty3`).
    Returns the displacement in .vtu order and the reference's extra data; writes DOLFINx's own
    .vtu (`write_vtu3`) when `vtu_path` is given."""
    cellname, degree = CELL_3D[pb.element]
    nn = pb.cells.shape[1]
    perm = cell_perm_vtk(DCELL_3D[cellname], nn)
    cells = np.ascontiguousarray(pb.cells[:, perm], dtype=np.int64)
    coord_el = basix.ufl.element("Lagrange", cellname, degree, shape=(3,),
                                 lagrange_variant=basix.LagrangeVariant.equispaced)
    msh = dmesh.create_mesh(MPI.COMM_SELF, cells, ufl.Mesh(coord_el), pb.points)
    assert msh.geometry.x.shape[0] == len(pb.points)
    geometry = check_geometry_3d(msh, pb, degree)

    V = fem.functionspace(msh, ("Lagrange", degree, (3,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    lam, mu = fem.Constant(msh, pb.lam), fem.Constant(msh, pb.mu)

    def eps(w):
        return ufl.sym(ufl.grad(w))

    def sigma(w):
        return lam * ufl.tr(eps(w)) * ufl.Identity(3) + 2.0 * mu * eps(w)

    dx = ufl.Measure("dx", domain=msh,
                     metadata={"quadrature_degree": STIFFNESS_DEGREE_3D[pb.element]})
    a = ufl.inner(sigma(u), eps(v)) * dx

    # facets tagged by the combination of loads and contact pairs acting on them (as in 2D)
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, msh.topology.dim)
    n = ufl.FacetNormal(msh)
    on_facet = {}
    for what, boxes in (("load", [b for b, _ in pb.loads]), ("contact", [p.box for p in pb.contact])):
        for k, box in enumerate(boxes):
            f = dmesh.locate_entities_boundary(msh, fdim, lambda X, box=box: in_box(X.T, box))
            if len(f) == 0:
                raise RuntimeError(f"{pb.name}: {what} {k} selects no boundary facet")
            for i in f:
                on_facet.setdefault(int(i), []).append((what, k))
    # a zero load that UFL does not simplify away (a case may have no load: the sphere cases)
    L = ufl.dot(fem.Constant(msh, np.zeros(3)), v) * dx
    contact_tags = {}
    mt = None
    if on_facet:
        combos = sorted({tuple(ks) for ks in on_facet.values()})
        tag_of = {c: j + 1 for j, c in enumerate(combos)}
        facets = np.array(sorted(on_facet), dtype=np.int32)
        mt = dmesh.meshtags(msh, fdim, facets,
                            np.array([tag_of[tuple(on_facet[i])] for i in facets], dtype=np.int32))
        ds = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                         metadata={"quadrature_degree": LOAD_DEGREE})
        for combo, tag in tag_of.items():
            for what, k in combo:
                if what == "contact":
                    contact_tags.setdefault(k, []).append(tag)
                else:
                    L = L + ufl.dot(-pb.loads[k][1] * n, v) * ds(tag)

    # supports: per component, the dofs at the support nodes (by coordinates); later win
    bcs, bcs0 = [], []
    for comp in range(3):
        Vc, cmap = V.sub(comp).collapse()
        cmap = np.asarray(cmap, dtype=np.int32).reshape(-1)
        tree = cKDTree(Vc.tabulate_dof_coordinates())
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
        idx, first = np.unique(idx[::-1], return_index=True)
        val = val[::-1][first]
        g = fem.Function(Vc)
        g.x.array[:] = 0.0
        g.x.array[idx] = val
        bcs.append(fem.dirichletbc(g, [cmap[idx], idx], V.sub(comp)))
        z = fem.Function(Vc)
        z.x.array[:] = 0.0
        bcs0.append(fem.dirichletbc(z, [cmap[idx], idx], V.sub(comp)))

    X = V.tabulate_dof_coordinates()
    ids, dist = pb.match(X)
    extra = {"dimension": 3, "match_distance": dist, "dofs": 3 * X.shape[0],
             "stiffness_quadrature_degree": STIFFNESS_DEGREE_3D[pb.element],
             "load_quadrature_degree": LOAD_DEGREE, "geometry_check": geometry}
    if pb.contact:
        uh, contact = newton_penalty3(pb, msh, V, a, L, bcs, bcs0, mt, contact_tags, ids)
        extra["contact"] = contact
    else:
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
    if vtu_path is not None:
        write_vtu3(vtu_path, msh, degree, uh, sigma)
    out = np.empty_like(pb.u_ours)
    out[ids] = uh.x.array.reshape(-1, 3)
    return out, extra


def write_vtu3(path, msh, degree, uh, sigma):
    """DOLFINx's own VTK output of a 3D solution: `displacement` (3 components) and `stress`,
    sigma(u_h) interpolated at the nodes of a Lagrange space of the same degree as the six
    components xx, yy, zz, yz, xz, xy (the order of our .vtu and of `contact-patch judge`)."""
    uh.name = "displacement"
    W = fem.functionspace(msh, ("Lagrange", degree, (6,)))
    s = fem.Function(W)
    s.name = "stress"
    S = sigma(uh)
    s.interpolate(fem.Expression(ufl.as_vector([S[0, 0], S[1, 1], S[2, 2], S[1, 2], S[0, 2],
                                                S[0, 1]]), W.element.interpolation_points))
    with dolfinx.io.VTKFile(MPI.COMM_SELF, str(path), "w") as f:
        f.write_function([uh, s])


def newton_penalty3(pb, msh, V, a, L, bcs_values, bcs0, mt, contact_tags, ids):
    """Newton's method for K u = f + penalty contact forces against rigid planes and spheres
    (3D; see the module text): the penalty term -int kappa (g(u))_- (n . v) dA over the slave
    facets, integrated with the custom rule whose points are the facet's nodes and whose
    weights are our nodal weights (common.nodal_rule_3d), so that its nodal force is ours,
    kappa A_a (-g_a)_+ n_a; the tangent adds kappa (n . du)(n . v) where g <= 0. The rule is
    checked against the exact integrals int N_a dA (Lagrange facets: Hex8, Hex27, Tet4) before
    use. Stops when the active set repeats (the problem is piecewise linear)."""
    uh = fem.Function(V)
    v, du = ufl.TestFunction(V), ufl.TrialFunction(V)
    x = ufl.SpatialCoordinate(msh)
    pts, wts = pb.contact[0].rule
    dsc = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                      metadata={"quadrature_rule": "custom", "quadrature_points": pts,
                                "quadrature_weights": wts})
    dse = ufl.Measure("ds", domain=msh, subdomain_data=mt,
                      metadata={"quadrature_degree": LOAD_DEGREE})

    def over_pair(k, integrand, measure=dsc):
        tags = contact_tags[k]
        return sum((integrand * measure(t) for t in tags[1:]), integrand * measure(tags[0]))

    def force_form(k, w):
        pair = pb.contact[k]
        g, nv = pair.gap([x[0], x[1], x[2]], [uh[0], uh[1], uh[2]], ufl.sqrt)
        pos = ufl.conditional(ufl.le(g, 0.0), -g, 0.0)
        return over_pair(k, pair.kappa * pos * (nv[0] * w[0] + nv[1] * w[1] + nv[2] * w[2]))

    F = ufl.action(a, uh) - L
    for k in range(len(pb.contact)):
        F = F - force_form(k, v)
    F_form, J_form = fem.form(F), fem.form(ufl.derivative(F, uh, du))
    f_ext = dolfinx.fem.petsc.assemble_vector(fem.form(L))
    K_u = None

    inv = np.empty(len(ids), dtype=np.int64)
    inv[ids] = np.arange(len(ids))
    slave = []
    for k, pair in enumerate(pb.contact):
        vn = pb.slave_nodes(pair)
        dn = inv[vn]
        area = fem.assemble_vector(fem.form(over_pair(k, v[0]))).array.reshape(-1, 3)[dn, 0]
        exact = fem.assemble_vector(fem.form(over_pair(k, v[0], dse))).array.reshape(-1, 3)[dn, 0]
        if pb.element == "Tet10":
            # modified Tri6 weights (not int N_a dA): only their sum is the area
            dev = abs(area.sum() - exact.sum()) / exact.sum()
        else:
            dev = float(np.abs(area - exact).max() / np.abs(exact).max())
        if dev > 1e-12:
            raise Unsupported(f"{pb.name}: contact '{pair.name}': the nodal rule misses our "
                              f"weights by {dev:.1e} (slave facets that are not flat "
                              "parallelograms have no nodal rule with our weights)")
        slave.append((vn, dn, area, dev))

    for bc in bcs_values:
        bc.set(uh.x.array)
    A = dolfinx.fem.petsc.create_matrix(J_form)
    b = dolfinx.fem.petsc.create_vector(V)
    ksp = PETSc.KSP().create(msh.comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    dU = fem.Function(V)

    def gaps():
        U = uh.x.array.reshape(-1, 3)
        out = []
        for pair, (vn, dn, _, _) in zip(pb.contact, slave):
            P = pb.points[vn]
            g, _ = pair.gap([P[:, 0], P[:, 1], P[:, 2]], [U[dn, 0], U[dn, 1], U[dn, 2]], np.sqrt)
            out.append(np.broadcast_to(g, dn.shape))
        return out

    def active_sets():
        return tuple(tuple(bool(t) for t in g <= 0.0) for g in gaps())

    def residual():
        with b.localForm() as bl:
            bl.set(0.0)
        dolfinx.fem.petsc.assemble_vector(b, F_form)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        dolfinx.fem.petsc.set_bc(b, bcs0)
        return b

    history, seen = [], set()
    current = active_sets()
    for it in range(1, 101):
        A.zeroEntries()
        dolfinx.fem.petsc.assemble_matrix(A, J_form, bcs=bcs0)
        A.assemble()
        r = residual()
        r.scale(-1.0)
        ksp.setOperators(A)
        ksp.solve(r, dU.x.petsc_vec)
        if ksp.getConvergedReason() <= 0:
            raise RuntimeError(f"{pb.name}: Newton step {it}: MUMPS failed "
                               f"(reason {ksp.getConvergedReason()})")
        dU.x.scatter_forward()
        uh.x.array[:] += dU.x.array
        new = active_sets()
        history.append({"iteration": it, "active": [sum(s) for s in current],
                        "relative_step": float(np.abs(dU.x.array).max()
                                               / max(np.abs(uh.x.array).max(), 1e-300))})
        if new == current:
            break
        if new in seen:
            raise RuntimeError(f"{pb.name}: the Newton active sets cycle")
        seen.add(current)
        current = new
    else:
        raise RuntimeError(f"{pb.name}: Newton did not settle in 100 iterations")
    # relative residual: over the largest of the loads and the internal forces K u
    K_u = dolfinx.fem.petsc.assemble_vector(fem.form(ufl.action(a, uh)))
    scale = max(float(np.abs(f_ext.array).max()), float(np.abs(K_u.array).max()),
                np.finfo(float).tiny)
    res = float(np.abs(residual().array).max()) / scale
    if not res <= 1e-9:
        raise RuntimeError(f"{pb.name}: Newton settled with relative residual {res:.2e}")

    pairs = []
    for k, (pair, (vn, dn, area, dev), g) in enumerate(zip(pb.contact, slave, gaps())):
        f = fem.assemble_vector(fem.form(force_form(k, v))).array.reshape(-1, 3)
        pairs.append({"name": pair.name, "total_force": f.sum(axis=0).tolist(),
                      "nodes": vn.tolist(), "area": area.tolist(),
                      "pressure": (pair.kappa * np.maximum(-g, 0.0)).tolist(),
                      "gap": g.tolist(), "active": [bool(t) for t in g <= 0.0],
                      "slave_force": f[dn].tolist(), "weight_check": dev})
    return uh, {"pairs": pairs, "newton": history, "iterations": len(history),
                "relative_residual": res,
                "contact_quadrature": "custom: the facet's nodes, our nodal weights"}


def main(argv):
    root = Path(argv[1])
    failed = 0
    for case in argv[2:]:
        t0 = time.perf_counter()
        name = Path(case).stem
        target = root / name / "ref-dolfinx.json"
        try:
            if len(json.loads(Path(case).read_text()).get("bodies", [])) > 1:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_text(json.dumps({"not_applicable": (
                    "two-body ties are not solved with DOLFINx; the tied layer's DOLFINx "
                    "reference is the one-body mesh")}))
                print(f"dolfinx {name}: not applicable (two bodies)", flush=True)
                continue
            if is_3d_case(json.loads(Path(case).read_text())):
                pb = Problem3(case, root / name)
                u, extra = solve3(pb, root / name / "dolfinx.pvd")
            elif (json.loads(Path(case).read_text()).get("physics") or {}).get("dynamics"):
                pb = Problem(case, root / name, dynamic=True)
                u, extra = solve_wave(pb)
            else:
                pb = Problem(case, root / name)
                u, extra = solve(pb, root / name / "dolfinx.pvd")
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
