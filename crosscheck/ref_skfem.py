"""Reference solve with scikit-fem on the mesh our tool wrote.

usage: ref_skfem.py OUT_ROOT CASE.json...   (reads OUT_ROOT/<case>/<body>.vtu, writes
OUT_ROOT/<case>/ref-skfem.json)

The mesh: `skfem.io.meshio.from_meshio` of the .vtu (quad -> MeshQuad1, quad9 -> MeshQuad2,
triangle -> MeshTri1, triangle6 -> MeshTri2; the quadratic meshes map isoparametrically).
The unknown: ElementVector of ElementQuad1 / ElementQuad2 (9-node Q2) / ElementTriP1 /
ElementTriP2. Supports: the dofs of each component at the support nodes' coordinates
(KD-tree on `basis.doflocs`), condensed out. Loads: the exact traction on a FacetBasis of
the load's boundary facets, quadrature order 8. Stiffness: the quadrature of our tool (see
common.STIFFNESS_DEGREE). Solve: scipy's sparse direct solver (SuperLU); the 1-norm condition
number of the reduced stiffness is estimated with the same factors (Hager's method), for the
report's round-off bound.

Contact with a rigid line or circle (`common.RigidContact`): Newton's method on
K u = f + int t kappa (g(u))_- n ds, the penalty term on a FacetBasis of the slave facets whose
quadrature is the nodal rule of our weights (`common.NODAL_RULE`: the facet's end points with
weights 1/2, 1/2 for Q4; end, mid, end with 1/6, 2/3, 1/6 for Q9); the tangent adds
t kappa (n . du)(n . v) where g <= 0. The iteration stops when the active set repeats (the
problem is piecewise linear, so the last step is then exact up to round-off).

3D cases (src/run3d.rs; `solve3`, `Body3`, `common.Problem3`): `from_meshio` of the .vtu
(hexahedron -> MeshHex1, hexahedron27 -> MeshHex2 through scikit-fem's own VTK permutation,
tetra -> MeshTet1, tetra10 -> MeshTet2), ElementVector of ElementHex1 / ElementHex2 /
ElementTetP1 / ElementTetP2 with the stiffness quadrature of src/fe3d.rs, pressures on a
FacetBasis (order 8), supports on the automatic sets by coordinates, SuperLU with the condition
estimate; penalty contact against a rigid plane or sphere by Newton's method as above, the
FacetBasis quadrature being the nodal rule of our weights (`common.nodal_rule_3d`: the facet's
nodes, checked against int N_a dA before use).

Two bodies tied by a mortar pair (`common.TiedCase`), in the spirit of scikit-fem's mortar
example (docs/examples/ex04.py: trace meshes of the interface, a 1D supermesh, FacetBasis
objects whose quadrature is built element by element on the supermesh with
`skfem.supermeshing.elementwise_quadrature`):

* **mortar tie, the case's multiplier space**: the rows `int Phi_j (u_s - u_m) ds = 0` per
  slave node j and component, with `Phi_j` the slave traces (standard) or the biorthogonal
  functions of src/contact/discretization/mortar.rs (dual: on each slave facet, Line2 `2 N_a - N_b`, Line3
  `(3 N_a + N_b)/2 - N_m/4` at the ends and `3 N_m/2 - N_a - N_b` in the middle), assembled
  as a mass matrix against a discontinuous (ElementDG) copy of the slave element and combined
  facet by facet; each row scaled by `int Phi_j` and coefficients below 1e-12 dropped (ours:
  1e-14, see `assemble_ties`); rows left with prescribed dofs only are dropped; Lagrange multipliers, one sparse LU
  of the saddle-point system. This is our formulation, so it must agree to round-off.
* **Nitsche tie** (ex04's formulation for the whole displacement vector, symmetric):
  `int gamma/h [u].[v] - {sigma(u) n}.[v] - {sigma(v) n}.[u] ds` with `[u] = u_s - u_m`,
  `{.}` the average, n the slave's outward normal, h the shorter of the two facets at the
  point and gamma = 10 p^2 (lambda + 2 mu) (p the element degree). A different
  formulation: it does not agree with the mortar tie to round-off, only as both converge.
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
import skfem
from scipy.spatial import cKDTree
from skfem import (Basis, BilinearForm, ElementHex1, ElementHex2, ElementQuad1, ElementQuad2,
                   ElementTetP1, ElementTetP2, ElementTriP1, ElementTriP2, ElementVector,
                   FacetBasis, LinearForm, MeshLine, asm, condense, solve)
from skfem.element import ElementDG
from skfem.helpers import dot, mul, sym_grad
from skfem.io.meshio import from_meshio
from skfem.models.elasticity import linear_elasticity, linear_stress
from skfem.supermeshing import elementwise_quadrature

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (BODY_FORCE_DEGREE, LOAD_DEGREE, NODAL_RULE, STIFFNESS_DEGREE,  # noqa: E402
                    STIFFNESS_DEGREE_3D, Problem, Problem3, TiedCase, Unsupported,
                    facets_in_box, in_box, is_3d_case, write_reference)

ELEMENT = {"Q4": ElementQuad1, "Q9": ElementQuad2, "T3": ElementTriP1, "T6": ElementTriP2}
DEGREE = {"Q4": 1, "Q9": 2, "T3": 1, "T6": 2}
# Quadrature order on the supermesh segments: Phi_j N_k is of degree 2 (Line2) or 4 (Line3).
MORTAR_ORDER = 4
# Dual multipliers in terms of the facet's shape functions, rows/columns [start, end(, mid)]
# (src/contact/discretization/mortar.rs: Line2 (1 -+ 3 s)/2; Line3 (5 s^2 -+ 2 s - 1)/4, (3 - 5 s^2)/2).
DUAL = {2: np.array([[2.0, -1.0], [-1.0, 2.0]]),
        3: np.array([[1.5, 0.5, -0.25], [0.5, 1.5, -0.25], [-1.0, -1.0, 1.5]])}
NITSCHE_GAMMA = 10.0
# Mortar coefficients (scaled by int Phi_j) at or below this are zero (see assemble_ties).
DROP = 1e-12


class Body:
    """One body assembled: stiffness, load vector, prescribed dofs, and the map from its
    dofs to the .vtu points."""

    def __init__(self, pb: Problem):
        self.pb = pb
        self.mesh = from_meshio(pb.meshio)
        self.scalar = ELEMENT[pb.element]()
        self.e = ElementVector(self.scalar)
        self.basis = Basis(self.mesh, self.e, intorder=STIFFNESS_DEGREE[pb.element])
        mat = pb.material
        self.K = pb.thickness * asm(linear_elasticity(mat.lam, mat.mu), self.basis)
        self.f = np.zeros(self.basis.N)
        self.N = self.basis.N
        mesh, e = self.mesh, self.e

        # Boundary facets of the mesh, by their two vertices (vertex dofs come first in doflocs).
        self.bfacets = mesh.boundary_facets()
        self.ends = [mesh.doflocs[:, mesh.facets[i, self.bfacets]].T for i in (0, 1)]
        for k, ld in enumerate(pb.loads):
            if ld.box is None:
                b = ld.value

                @LinearForm
                def body_force(v, w, b=b):
                    return pb.thickness * (b[0] * v.value[0] + b[1] * v.value[1])

                self.f += asm(body_force, Basis(mesh, e, intorder=BODY_FORCE_DEGREE))
                continue
            sel = self.facets(ld.box)
            if len(sel) == 0:
                raise RuntimeError(f"{pb.name}: load {k} selects no boundary facet")
            fb = FacetBasis(mesh, e, facets=sel, intorder=LOAD_DEGREE)

            @LinearForm
            def traction(v, w, ld=ld):
                t = ld.traction(w.x[0], w.x[1], w.n)
                return pb.thickness * (t[0] * v.value[0] + t[1] * v.value[1])

            self.f += asm(traction, fb)

        # Supports: dofs of each component located by coordinates; later supports win.
        self.comp_dofs = self.basis.split_indices()
        self.fixed = {}
        for coords, c, values in pb.supports:
            I = self.comp_dofs[c]
            d, idx = cKDTree(self.basis.doflocs[:, I].T).query(coords)
            if d.max() > pb.tol:
                raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
            for dof, val in zip(I[idx], values):
                self.fixed[int(dof)] = float(val)

        # dof -> .vtu point
        self.point_of = np.empty(self.N, dtype=np.int64)
        self.match_distance = 0.0
        for c in (0, 1):
            I = self.comp_dofs[c]
            ids, dc = pb.match(self.basis.doflocs[:, I].T)
            self.point_of[I] = ids
            self.match_distance = max(self.match_distance, dc)

    def facets(self, box):
        """Boundary facets with both end vertices in the box."""
        return self.bfacets[in_box(self.ends[0], box) & in_box(self.ends[1], box)]

    def on_vtu(self, u):
        out = np.empty_like(self.pb.u_ours)
        for c in (0, 1):
            I = self.comp_dofs[c]
            out[self.point_of[I], c] = u[I]
        return out

    def dof_of(self, point_ids, comp):
        """Dof of component `comp` at each .vtu point id."""
        I = self.comp_dofs[comp]
        inv = {int(p): int(d) for p, d in zip(self.point_of[I], I)}
        return np.array([inv[int(p)] for p in point_ids], dtype=np.int64)


def prescribed(body):
    D = np.array(sorted(body.fixed), dtype=np.int64)
    x0 = np.zeros(body.N)
    x0[D] = [body.fixed[i] for i in D]
    return D, x0


def cond1(lu, A):
    """kappa_1(A) = |A|_1 |A^-1|_1 for symmetric A, |A^-1|_1 by Hager's estimator (a lower
    bound, usually within a small factor; deterministic) with the LU factors of A."""
    n = A.shape[0]
    x = np.full(n, 1.0 / n)
    est = 0.0
    for _ in range(5):
        y = lu.solve(x)
        est = max(est, float(np.abs(y).sum()))
        z = lu.solve(np.sign(y))          # A symmetric: A^-T = A^-1
        j = int(np.argmax(np.abs(z)))
        if np.abs(z[j]) <= z @ x:
            break
        x = np.zeros(n)
        x[j] = 1.0
    return float(abs(A).sum(axis=0).max()) * est


def solve_elastic(pb):
    body = Body(pb)
    D, x0 = prescribed(body)
    A, b, _, I = condense(body.K, body.f, x=x0, D=D)
    lu = spla.splu(A.tocsc())
    u = x0.copy()
    u[I] = lu.solve(b)
    return body.on_vtu(u), {"match_distance": body.match_distance, "dofs": int(body.N),
                            "stiffness_quadrature_order": STIFFNESS_DEGREE[pb.element],
                            "load_quadrature_order": LOAD_DEGREE,
                            "cond1_estimate": cond1(lu, A)}


def solve_contact(pb):
    """Newton's method on the penalty problem (see the module text)."""
    body = Body(pb)
    D, u = prescribed(body)
    pts, wts = NODAL_RULE[pb.element]
    quad = (np.array([pts]), np.array(wts))
    th = pb.thickness
    pairs = []
    for pair in pb.contact:
        sel = body.facets(pair.box)
        if len(sel) == 0:
            raise RuntimeError(f"{pb.name}: contact '{pair.name}' selects no boundary facet")
        fb = FacetBasis(body.mesh, body.e, facets=sel, quadrature=quad)
        # the slave nodes (with the Line3 mid nodes) as .vtu ids
        nodes = np.array(sorted({n for f in facets_in_box(pb, pair.box) for n in f}))
        pairs.append((pair, fb, nodes))

    def forms(pair):
        @BilinearForm
        def tangent(du, v, w):
            g, nx, ny = pair.gap(w.x[0], w.x[1], w.prev[0], w.prev[1], np.sqrt)
            act = (g <= 0.0).astype(float)
            return (th * pair.kappa * act * (nx * du[0] + ny * du[1])
                    * (nx * v[0] + ny * v[1]))

        @LinearForm
        def force(v, w):
            g, nx, ny = pair.gap(w.x[0], w.x[1], w.prev[0], w.prev[1], np.sqrt)
            return th * pair.kappa * np.maximum(-g, 0.0) * (nx * v[0] + ny * v[1])

        @LinearForm
        def area(v, w):
            return th * v[0]

        return tangent, force, area

    compiled = [(pair, fb, nodes, *forms(pair)) for pair, fb, nodes in pairs]
    dof_x = {}
    for pair, fb, nodes, *_ in compiled:
        dof_x[pair.name] = (body.dof_of(nodes, 0), body.dof_of(nodes, 1))

    def active_sets(u):
        out = []
        for pair, fb, nodes, *_ in compiled:
            ix, iy = dof_x[pair.name]
            X = pb.points[nodes]
            g, _, _ = pair.gap(X[:, 0], X[:, 1], u[ix], u[iy], np.sqrt)
            out.append(tuple(bool(t) for t in g <= 0.0))
        return tuple(out)

    def residual(u):
        r = body.K @ u - body.f
        for pair, fb, nodes, tangent, force, area in compiled:
            r -= force.assemble(fb, prev=fb.interpolate(u))
        return r

    history, seen = [], set()
    current = active_sets(u)
    for it in range(1, 101):
        Kt = body.K.copy()
        for pair, fb, nodes, tangent, force, area in compiled:
            Kt = Kt + tangent.assemble(fb, prev=fb.interpolate(u))
        du = solve(*condense(Kt, -residual(u), D=D))
        u = u + du
        new = active_sets(u)
        history.append({"iteration": it, "active": [sum(s) for s in current],
                        "relative_step": float(np.abs(du).max() / np.abs(u).max())})
        if new == current:
            break
        if new in seen:
            raise RuntimeError(f"{pb.name}: the Newton active sets cycle")
        seen.add(current)
        current = new
    else:
        raise RuntimeError(f"{pb.name}: Newton did not settle in 100 iterations")
    r = residual(u)
    r[D] = 0.0
    res = float(np.abs(r).max() / np.abs(body.f).max())
    if not res <= 1e-9:
        raise RuntimeError(f"{pb.name}: Newton settled with relative residual {res:.2e}")

    out_pairs = []
    for k, (pair, fb, nodes, tangent, force, area) in enumerate(compiled):
        fvec = force.assemble(fb, prev=fb.interpolate(u))
        avec = area.assemble(fb)
        ix, iy = dof_x[pair.name]
        X = pb.points[nodes]
        _, nx, ny = pair.gap(X[:, 0], X[:, 1], u[ix], u[iy], np.sqrt)
        normal_force = fvec[ix] * nx + fvec[iy] * ny
        out_pairs.append({"name": pair.name,
                          "total_force": [float(fvec[body.comp_dofs[0]].sum()),
                                          float(fvec[body.comp_dofs[1]].sum())],
                          "nodes": nodes.tolist(), "area": avec[ix].tolist(),
                          "pressure": (normal_force / avec[ix]).tolist(),
                          "active": [bool(t) for t in current[k]]})
    return body.on_vtu(u), {"match_distance": body.match_distance, "dofs": int(body.N),
                            "stiffness_quadrature_order": STIFFNESS_DEGREE[pb.element],
                            "contact": {"pairs": out_pairs, "newton": history,
                                        "iterations": len(history), "relative_residual": res,
                                        "contact_quadrature": f"nodal rule {NODAL_RULE[pb.element]}"}}


# --- ties -------------------------------------------------------------------------------------
def straight_trace(body, facets):
    """Trace mesh (MeshLine, arc length along the interface) of straight, collinear facets."""
    P = body.mesh.p[:, np.unique(body.mesh.facets[:, facets])]
    p0 = P[:, np.argmin(P[0] + P[1])]
    far = P[:, np.argmax(np.hypot(*(P - p0[:, None])))]
    t = (far - p0) / np.linalg.norm(far - p0)
    off = np.abs(t[0] * (P[1] - p0[1]) - t[1] * (P[0] - p0[0]))
    if off.max() > 1e-9 * np.linalg.norm(far - p0):
        raise Unsupported("the interface is not straight (the mortar reference needs a line)")
    return p0, t


def supermesh_1d(ms, mm):
    """The 1D supermesh of two trace meshes: the union of their nodes on the overlap, without
    rounding (skfem.supermeshing.intersect rounds the nodes to 10 decimals, which moves the
    break points of segments like 10/7 by ~1e-11 and the integrals with them)."""
    ps, pm = ms.p[0], mm.p[0]
    lo, hi = max(ps.min(), pm.min()), min(ps.max(), pm.max())
    tol = 1e-12 * (hi - lo)
    p = np.sort(np.concatenate([ps, pm]))
    p = p[(p >= lo - tol) & (p <= hi + tol)]
    p = p[np.concatenate([[True], np.diff(p) > tol])]
    m12 = MeshLine(p)
    mid = 0.5 * (p[:-1] + p[1:])
    return m12, ms.element_finder()(mid), mm.element_finder()(mid)


def interface(tc, bodies):
    """FacetBasis objects of both sides on the supermesh, and the DG multiplier basis."""
    S, M = bodies[tc.slave], bodies[tc.master]
    sfac = S.facets(S.pb.facet_box(tc.slave_set))
    mfac = M.facets(M.pb.facet_box(tc.master_set))
    if len(sfac) == 0 or len(mfac) == 0:
        raise RuntimeError(f"{tc.name}: an interface facet set is empty")
    p0, t = straight_trace(S, sfac)

    def proj(P):
        return (t[0] * (P[0] - p0[0]) + t[1] * (P[1] - p0[1]))[None, :]

    mst, orig_s = S.mesh.trace(sfac, mtype=MeshLine, project=proj)
    mmt, orig_m = M.mesh.trace(mfac, mtype=MeshLine, project=proj)
    m12, ts, tm = supermesh_1d(mst, mmt)
    qs = elementwise_quadrature(mst, m12, ts, intorder=MORTAR_ORDER)
    qm = elementwise_quadrature(mmt, m12, tm, intorder=MORTAR_ORDER)
    fbs = FacetBasis(S.mesh, S.e, quadrature=qs, facets=orig_s[ts])
    fbm = FacetBasis(M.mesh, M.e, quadrature=qm, facets=orig_m[tm])
    fbl = FacetBasis(S.mesh, ElementVector(ElementDG(S.scalar)), quadrature=qs,
                     facets=orig_s[ts])
    return S, M, orig_s, fbs, fbm, fbl, m12


def mortar_rows(tc, S, M, orig_s, fbs, fbm, fbl, multiplier):
    """Rows [C_s, C_m] of int Phi_j (u_s - u_m) ds, one per slave node and component."""
    th = S.pb.thickness

    @BilinearForm
    def mass(u, v, w):
        return th * dot(u, v)

    Bs = mass.assemble(fbs, fbl).tocsr()      # DG rows x slave dofs
    Bm = mass.assemble(fbm, fbl).tocsr()      # DG rows x master dofs
    Ec, Edg = S.basis.dofs.element_dofs, fbl.dofs.element_dofs
    loc_dg = fbl.doflocs
    assert np.allclose(S.basis.doflocs[:, Ec], loc_dg[:, Edg]), "DG/continuous local order"
    mesh = S.mesh
    rows, cols, vals = [], [], []              # T: (slave dof row) <- DG rows
    row_of = {}
    cells_seen = set()
    for f in orig_s:
        c = int(mesh.f2t[0, f])
        if c in cells_seen:
            raise Unsupported("a slave cell with two interface facets")
        cells_seen.add(c)
        a, b = mesh.p[:, mesh.facets[0, f]], mesh.p[:, mesh.facets[1, f]]
        targets = [a, b] if DEGREE[S.pb.element] == 1 else [a, b, 0.5 * (a + b)]
        for comp in (0, 1):
            local = []
            for x in targets:
                hit = [i for i in range(Ec.shape[0]) if i % 2 == comp
                       and np.allclose(S.basis.doflocs[:, Ec[i, c]], x, atol=1e-12)]
                if len(hit) != 1:
                    raise RuntimeError(f"{tc.name}: facet node not found in its cell")
                local.append(hit[0])
            coef = DUAL[len(local)] if multiplier == "dual" else np.eye(len(local))
            for j, ij in enumerate(local):
                dof = int(Ec[ij, c])
                r = row_of.setdefault(dof, len(row_of))
                for k, ik in enumerate(local):
                    if coef[j, k] != 0.0:
                        rows.append(r)
                        cols.append(int(Edg[ik, c]))
                        vals.append(coef[j, k])
    T = sp.csr_matrix((vals, (rows, cols)), shape=(len(row_of), fbl.N))
    Cs, Cm = (T @ Bs).tocsr(), (T @ Bm).tocsr()
    owners = np.array(sorted(row_of, key=row_of.get))
    return Cs, Cm, owners


def assemble_ties(tc, bodies):
    S, M, orig_s, fbs, fbm, fbl, m12 = interface(tc, bodies)
    Cs, Cm, owners = mortar_rows(tc, S, M, orig_s, fbs, fbm, fbl, tc.multiplier)
    area = np.asarray(Cs.sum(axis=1)).ravel()
    keep = area > 1e-12 * area.max()
    blocks = {tc.slave: Cs, tc.master: -Cm}
    C = sp.hstack([blocks[n] for n in tc.order]).tocsr()      # bodies in case order
    C = sp.diags(1.0 / np.where(keep, area, 1.0)) @ C
    C = C[np.flatnonzero(keep)]
    # Coefficients that vanish in exact arithmetic (master nodes whose trace is orthogonal to
    # a dual function, cell nodes off the facet) come out at ~1e-14 here, from the inverse
    # isoparametric map of the quadrature points; our rows evaluate the 1D traces directly and
    # drop |c| <= 1e-14. Zeroing |c| <= DROP keeps a row left with such a coefficient as its
    # only free entry (e.g. the x row of a slave node on a roller) from pinning that dof.
    C.data[np.abs(C.data) <= DROP] = 0.0
    C.eliminate_zeros()

    # Nitsche blocks
    mat_s, mat_m = S.pb.material, M.pb.material
    if (mat_s.lam, mat_s.mu) != (mat_m.lam, mat_m.mu):
        raise Unsupported("Nitsche tie between different materials")
    Cst = linear_stress(mat_s.lam, mat_s.mu)
    p = max(DEGREE[S.pb.element], DEGREE[M.pb.element])
    gamma = NITSCHE_GAMMA * p * p * (mat_s.lam + 2.0 * mat_s.mu)
    hs = np.linalg.norm(S.mesh.p[:, S.mesh.facets[1, fbs.find]]
                        - S.mesh.p[:, S.mesh.facets[0, fbs.find]], axis=0)
    hm = np.linalg.norm(M.mesh.p[:, M.mesh.facets[1, fbm.find]]
                        - M.mesh.p[:, M.mesh.facets[0, fbm.find]], axis=0)
    h = np.minimum(hs, hm)[:, None] * np.ones(fbs.X.shape[-1])
    n = fbs.normals.value
    th = S.pb.thickness

    def block(si, sj):
        @BilinearForm
        def nitsche(u, v, w):
            ju, jv = sj * u, si * v
            tu = 0.5 * mul(Cst(sym_grad(u)), n)
            tv = 0.5 * mul(Cst(sym_grad(v)), n)
            return th * (gamma / h * dot(ju, jv) - dot(tu, jv) - dot(tv, ju))
        return nitsche

    sides = {tc.slave: (fbs, 1.0), tc.master: (fbm, -1.0)}
    N = sp.bmat([[block(sides[bi][1], sides[bj][1]).assemble(sides[bj][0], sides[bi][0])
                  for bj in tc.order] for bi in tc.order]).tocsr()  # test in bi, trial in bj
    info = {"supermesh_segments": int(m12.t.shape[1]), "rows": int(C.shape[0]),
            "nitsche_gamma": gamma, "multiplier": tc.multiplier}
    return C, N, info


def solve_tie(tc):
    bodies = {n: Body(tc.bodies[n]) for n in tc.order}
    offsets, ntot = {}, 0
    for n in tc.order:
        offsets[n] = ntot
        ntot += bodies[n].N
    K = sp.block_diag([bodies[n].K for n in tc.order]).tocsr()
    f = np.concatenate([bodies[n].f for n in tc.order])
    x0 = np.zeros(ntot)
    fixed = []
    for n in tc.order:
        D, x = prescribed(bodies[n])
        x0[offsets[n]:offsets[n] + bodies[n].N] = x
        fixed.append(D + offsets[n])
    D = np.concatenate(fixed)
    free = np.setdiff1d(np.arange(ntot), D)
    C, Nit, info = assemble_ties(tc, bodies)

    # mortar: saddle point on the free dofs
    Cf, Cd = C[:, free], C[:, D]
    rhs_c = -(Cd @ x0[D])
    live = np.diff(Cf.tocsr().indptr) > 0
    scale = np.abs(C).max()
    if np.abs(rhs_c[~live]).max(initial=0.0) > 1e-12 * max(scale, 1.0):
        raise RuntimeError(f"{tc.name}: a tie row on prescribed dofs only is violated")
    Cf, rhs_c = Cf[np.flatnonzero(live)], rhs_c[live]
    Kff = K[free][:, free]
    rhs_u = f[free] - K[free][:, D] @ x0[D]
    m = Cf.shape[0]
    A = sp.bmat([[Kff, Cf.T], [Cf, None]]).tocsc()
    sol = spla.spsolve(A, np.concatenate([rhs_u, rhs_c]))
    if not np.all(np.isfinite(sol)):
        raise RuntimeError(f"{tc.name}: the mortar saddle-point system is singular")
    res = np.abs(A @ sol - np.concatenate([rhs_u, rhs_c])).max() / np.abs(rhs_u).max()
    u = x0.copy()
    u[free] = sol[:len(free)]

    # Nitsche
    un = solve(*condense((K + Nit).tocsr(), f, x=x0, D=D))

    out, nit = {}, {}
    for n in tc.order:
        b = bodies[n]
        out[n] = b.on_vtu(u[offsets[n]:offsets[n] + b.N]).tolist()
        nit[n] = b.on_vtu(un[offsets[n]:offsets[n] + b.N]).tolist()
    info.update({"rows_kept": int(m), "relative_residual": float(res),
                 "dofs": int(ntot),
                 "match_distance": max(b.match_distance for b in bodies.values())})
    return out, nit, info


# --- 3D (src/run3d.rs) -------------------------------------------------------------------------
ELEMENT_3D = {"Hex8": ElementHex1, "Hex27": ElementHex2, "Tet4": ElementTetP1,
              "Tet10": ElementTetP2}


class Body3:
    """One 3D body assembled on our .vtu (`common.Problem3`): `from_meshio` (hexahedron ->
    MeshHex1, hexahedron27 -> MeshHex2 with scikit-fem's own VTK permutation, tetra ->
    MeshTet1, tetra10 -> MeshTet2), ElementVector of ElementHex1 / ElementHex2 (27-node Q2) /
    ElementTetP1 / ElementTetP2 with the stiffness quadrature of src/fe3d.rs
    (common.STIFFNESS_DEGREE_3D), pressures on a FacetBasis of quadrature order 8, supports and
    the map to the .vtu points by coordinates."""

    def __init__(self, pb):
        self.pb = pb
        self.mesh = from_meshio(pb.meshio)
        self.e = ElementVector(ELEMENT_3D[pb.element]())
        self.basis = Basis(self.mesh, self.e, intorder=STIFFNESS_DEGREE_3D[pb.element])
        self.K = asm(linear_elasticity(pb.lam, pb.mu), self.basis)
        self.N = self.basis.N
        self.f = np.zeros(self.N)
        mesh = self.mesh
        # boundary facets and their vertices (vertex dofs come first in doflocs)
        self.bfacets = mesh.boundary_facets()
        self.corners = [mesh.doflocs[:, mesh.facets[i, self.bfacets]].T
                        for i in range(mesh.facets.shape[0])]
        for k, (box, p) in enumerate(pb.loads):
            sel = self.facets(box)
            if len(sel) == 0:
                raise RuntimeError(f"{pb.name}: load {k} selects no boundary facet")
            fb = FacetBasis(mesh, self.e, facets=sel, intorder=LOAD_DEGREE)

            @LinearForm
            def pressure(v, w, p=p):
                return -p * dot(w.n, v)

            self.f += asm(pressure, fb)
        self.comp_dofs = self.basis.split_indices()
        self.fixed = {}
        for coords, c, values in pb.supports:
            I = self.comp_dofs[c]
            d, idx = cKDTree(self.basis.doflocs[:, I].T).query(coords)
            if d.max() > pb.tol:
                raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
            for dof, val in zip(I[idx], values):
                self.fixed[int(dof)] = float(val)
        self.point_of = np.empty(self.N, dtype=np.int64)
        self.match_distance = 0.0
        for c in range(3):
            I = self.comp_dofs[c]
            ids, dc = pb.match(self.basis.doflocs[:, I].T)
            self.point_of[I] = ids
            self.match_distance = max(self.match_distance, dc)

    def facets(self, box):
        """Boundary facets with every vertex in the box."""
        inside = np.ones(len(self.bfacets), dtype=bool)
        for c in self.corners:
            inside &= in_box(c, box)
        return self.bfacets[inside]

    def on_vtu(self, u):
        out = np.empty_like(self.pb.u_ours)
        for c in range(3):
            I = self.comp_dofs[c]
            out[self.point_of[I], c] = u[I]
        return out

    def dof_of(self, point_ids, comp):
        I = self.comp_dofs[comp]
        inv = {int(p): int(d) for p, d in zip(self.point_of[I], I)}
        return np.array([inv[int(p)] for p in point_ids], dtype=np.int64)


def solve3(pb):
    """3D linear elasticity (SuperLU, with the condition estimate), or with rigid contact
    pairs Newton's method on the penalty problem: the term int kappa (g)_- (n . v) dA on a
    FacetBasis of the slave facets whose quadrature is the nodal rule of our weights
    (common.nodal_rule_3d; checked against int N_a dA on Lagrange facets), the tangent
    kappa (n . du)(n . v) where g <= 0, until the active set repeats."""
    body = Body3(pb)
    D, u = prescribed(body)
    extra = {"dimension": 3, "match_distance": body.match_distance, "dofs": int(body.N),
             "stiffness_quadrature_order": STIFFNESS_DEGREE_3D[pb.element],
             "load_quadrature_order": LOAD_DEGREE}
    if not pb.contact:
        A, b, _, I = condense(body.K, body.f, x=u, D=D)
        lu = spla.splu(A.tocsc())
        u[I] = lu.solve(b)
        extra["cond1_estimate"] = cond1(lu, A)
        return body.on_vtu(u), extra

    compiled = []
    for pair in pb.contact:
        sel = body.facets(pair.box)
        if len(sel) == 0:
            raise RuntimeError(f"{pb.name}: contact '{pair.name}' selects no boundary facet")
        pts, wts = pair.rule
        fb = FacetBasis(body.mesh, body.e, facets=sel, quadrature=(pts.T.copy(), wts))
        fbe = FacetBasis(body.mesh, body.e, facets=sel, intorder=LOAD_DEGREE)
        nodes = pb.slave_nodes(pair)
        dofs = [body.dof_of(nodes, c) for c in range(3)]

        @BilinearForm
        def tangent(du, v, w, pair=pair):
            g, n = pair.gap(w.x, w.prev, np.sqrt)
            act = (g <= 0.0).astype(float)
            return pair.kappa * act * (n[0] * du[0] + n[1] * du[1] + n[2] * du[2]) \
                * (n[0] * v[0] + n[1] * v[1] + n[2] * v[2])

        @LinearForm
        def force(v, w, pair=pair):
            g, n = pair.gap(w.x, w.prev, np.sqrt)
            return pair.kappa * np.maximum(-g, 0.0) * (n[0] * v[0] + n[1] * v[1] + n[2] * v[2])

        @LinearForm
        def area(v, w):
            return v[0]

        A_rule = area.assemble(fb)[dofs[0]]
        A_exact = area.assemble(fbe)[dofs[0]]
        dev = (abs(A_rule.sum() - A_exact.sum()) / A_exact.sum() if pb.element == "Tet10"
               else float(np.abs(A_rule - A_exact).max() / np.abs(A_exact).max()))
        if dev > 1e-12:
            raise Unsupported(f"{pb.name}: contact '{pair.name}': the nodal rule misses our "
                              f"weights by {dev:.1e} (slave facets that are not flat "
                              "parallelograms)")
        compiled.append((pair, fb, nodes, dofs, tangent, force, A_rule, dev))

    def gaps(u):
        out = []
        for pair, fb, nodes, dofs, *_ in compiled:
            X = pb.points[nodes]
            g, _ = pair.gap([X[:, 0], X[:, 1], X[:, 2]], [u[d] for d in dofs], np.sqrt)
            out.append(np.broadcast_to(g, nodes.shape))
        return out

    def active_sets(u):
        return tuple(tuple(bool(t) for t in g <= 0.0) for g in gaps(u))

    def residual(u):
        r = body.K @ u - body.f
        for pair, fb, nodes, dofs, tangent, force, *_ in compiled:
            r -= force.assemble(fb, prev=fb.interpolate(u))
        return r

    history, seen = [], set()
    current = active_sets(u)
    for it in range(1, 101):
        Kt = body.K.copy()
        for pair, fb, nodes, dofs, tangent, *_ in compiled:
            Kt = Kt + tangent.assemble(fb, prev=fb.interpolate(u))
        du = solve(*condense(Kt, -residual(u), D=D))
        u = u + du
        new = active_sets(u)
        history.append({"iteration": it, "active": [sum(s) for s in current],
                        "relative_step": float(np.abs(du).max() / np.abs(u).max())})
        if new == current:
            break
        if new in seen:
            raise RuntimeError(f"{pb.name}: the Newton active sets cycle")
        seen.add(current)
        current = new
    else:
        raise RuntimeError(f"{pb.name}: Newton did not settle in 100 iterations")
    r = residual(u)
    r[D] = 0.0
    scale = max(float(np.abs(body.f).max()), float(np.abs(body.K @ u).max()))
    res = float(np.abs(r).max() / scale)
    if not res <= 1e-9:
        raise RuntimeError(f"{pb.name}: Newton settled with relative residual {res:.2e}")
    out_pairs = []
    for (pair, fb, nodes, dofs, tangent, force, A_rule, dev), g in zip(compiled, gaps(u)):
        fvec = force.assemble(fb, prev=fb.interpolate(u))
        out_pairs.append({"name": pair.name,
                          "total_force": [float(fvec[body.comp_dofs[c]].sum()) for c in range(3)],
                          "nodes": nodes.tolist(), "area": A_rule.tolist(),
                          "pressure": (pair.kappa * np.maximum(-g, 0.0)).tolist(),
                          "gap": g.tolist(), "active": [bool(t) for t in g <= 0.0],
                          "slave_force": np.stack([fvec[d] for d in dofs], axis=1).tolist(),
                          "weight_check": dev})
    extra["contact"] = {"pairs": out_pairs, "newton": history, "iterations": len(history),
                        "relative_residual": res,
                        "contact_quadrature": "the facet's nodes with our nodal weights"}
    return body.on_vtu(u), extra


def main(argv):
    root = Path(argv[1])
    failed = 0
    for case in argv[2:]:
        t0 = time.perf_counter()
        name = Path(case).stem
        target = root / name / "ref-skfem.json"
        try:
            spec = json.loads(Path(case).read_text())
            if (spec.get("physics") or {}).get("dynamics") is not None:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_text(json.dumps({"not_applicable": (
                    "time histories (physics.dynamics) are cross-checked with DOLFINx only")}))
                print(f"skfem {name}: not applicable (dynamics)", flush=True)
                continue
            if is_3d_case(spec):
                pb = Problem3(case, root / name)
                u, extra = solve3(pb)
                extra.update({"seconds": time.perf_counter() - t0,
                              "versions": {"scikit-fem": skfem.__version__}})
                write_reference(target, pb, "skfem", u, extra)
            elif len(spec.get("bodies", [])) > 1:
                tc = TiedCase(case, root / name)
                u, nit, extra = solve_tie(tc)
                extra.update({"seconds": time.perf_counter() - t0,
                              "versions": {"scikit-fem": skfem.__version__}})
                target.write_text(json.dumps({"case": tc.name, "solver": "skfem",
                                              "bodies": u, "nitsche": nit, **extra}))
            else:
                pb = Problem(case, root / name)
                if pb.frictional:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_text(json.dumps({"not_applicable": (
                        "Coulomb friction is cross-checked with DOLFINx only")}))
                    print(f"skfem {name}: not applicable (friction)", flush=True)
                    continue
                if pb.finite:
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_text(json.dumps({"not_applicable": (
                        "finite kinematics (hyperelastic bodies) is cross-checked with "
                        "DOLFINx only")}))
                    print(f"skfem {name}: not applicable (finite kinematics)", flush=True)
                    continue
                u, extra = solve_contact(pb) if pb.contact else solve_elastic(pb)
                extra.update({"seconds": time.perf_counter() - t0,
                              "versions": {"scikit-fem": skfem.__version__}})
                write_reference(target, pb, "skfem", u, extra)
            print(f"skfem {name}: {time.perf_counter() - t0:.1f} s", flush=True)
        except Exception as e:  # noqa: BLE001  (recorded; the report fails this case)
            failed += 1
            target.parent.mkdir(parents=True, exist_ok=True)
            msg = str(e) if isinstance(e, (Unsupported, RuntimeError)) else f"{type(e).__name__}: {e}"
            target.write_text(json.dumps({"error": msg}))
            print(f"skfem {name}: ERROR {e}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
