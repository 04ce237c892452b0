"""Reference solve with scikit-fem on the mesh our tool wrote.

usage: ref_skfem.py OUT_ROOT CASE.json...   (reads OUT_ROOT/<case>/<body>.vtu, writes
OUT_ROOT/<case>/ref-skfem.json)

The mesh: `skfem.io.meshio.from_meshio` of the .vtu (quad -> MeshQuad1, quad9 -> MeshQuad2,
triangle -> MeshTri1, triangle6 -> MeshTri2; the quadratic meshes map isoparametrically).
The unknown: ElementVector of ElementQuad1 / ElementQuad2 (9-node Q2) / ElementTriP1 /
ElementTriP2. Supports: the dofs of each component at the support nodes' coordinates
(KD-tree on `basis.doflocs`), condensed out. Loads: the exact traction on a FacetBasis of
the load's boundary facets, quadrature order 8. Stiffness: the quadrature of our tool (see
common.STIFFNESS_DEGREE). Solve: scipy's sparse direct solver.
"""

import json
import sys
import time
from pathlib import Path

import numpy as np
import skfem
from scipy.spatial import cKDTree
from skfem import (Basis, ElementQuad1, ElementQuad2, ElementTriP1, ElementTriP2,
                   ElementVector, FacetBasis, LinearForm, asm, condense, solve)
from skfem.io.meshio import from_meshio
from skfem.models.elasticity import linear_elasticity

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (BODY_FORCE_DEGREE, LOAD_DEGREE, STIFFNESS_DEGREE, Problem,  # noqa: E402
                    Unsupported, in_box, write_reference)

ELEMENT = {"Q4": ElementQuad1, "Q9": ElementQuad2, "T3": ElementTriP1, "T6": ElementTriP2}


def solve_case(pb: Problem):
    mesh = from_meshio(pb.meshio)
    e = ElementVector(ELEMENT[pb.element]())
    basis = Basis(mesh, e, intorder=STIFFNESS_DEGREE[pb.element])
    mat = pb.material
    K = pb.thickness * asm(linear_elasticity(mat.lam, mat.mu), basis)
    f = np.zeros(basis.N)

    # Boundary facets of the mesh, by their two vertices (vertex dofs come first in doflocs).
    bfacets = mesh.boundary_facets()
    ends = [mesh.doflocs[:, mesh.facets[i, bfacets]].T for i in (0, 1)]
    for k, ld in enumerate(pb.loads):
        if ld.box is None:
            b = ld.value

            @LinearForm
            def body_force(v, w, b=b):
                return pb.thickness * (b[0] * v.value[0] + b[1] * v.value[1])

            f += asm(body_force, Basis(mesh, e, intorder=BODY_FORCE_DEGREE))
            continue
        sel = bfacets[in_box(ends[0], ld.box) & in_box(ends[1], ld.box)]
        if len(sel) == 0:
            raise RuntimeError(f"{pb.name}: load {k} selects no boundary facet")
        fb = FacetBasis(mesh, e, facets=sel, intorder=LOAD_DEGREE)

        @LinearForm
        def traction(v, w, ld=ld):
            t = ld.traction(w.x[0], w.x[1], w.n)
            return pb.thickness * (t[0] * v.value[0] + t[1] * v.value[1])

        f += asm(traction, fb)

    # Supports: dofs of each component located by coordinates; later supports win.
    comp_dofs = basis.split_indices()
    x0 = np.zeros(basis.N)
    fixed = {}
    for coords, c, values in pb.supports:
        I = comp_dofs[c]
        d, idx = cKDTree(basis.doflocs[:, I].T).query(coords)
        if d.max() > pb.tol:
            raise RuntimeError(f"{pb.name}: support node not found (distance {d.max():.3e})")
        for dof, val in zip(I[idx], values):
            fixed[int(dof)] = float(val)
    D = np.array(sorted(fixed), dtype=np.int64)
    x0[D] = [fixed[i] for i in D]
    u = solve(*condense(K, f, x=x0, D=D))

    out = np.empty_like(pb.u_ours)
    dist = 0.0
    for c in (0, 1):
        I = comp_dofs[c]
        ids, dc = pb.match(basis.doflocs[:, I].T)
        out[ids, c] = u[I]
        dist = max(dist, dc)
    return out, {"match_distance": dist, "dofs": int(basis.N),
                 "stiffness_quadrature_order": STIFFNESS_DEGREE[pb.element],
                 "load_quadrature_order": LOAD_DEGREE}


def main(argv):
    root = Path(argv[1])
    failed = 0
    for case in argv[2:]:
        t0 = time.perf_counter()
        name = Path(case).stem
        target = root / name / "ref-skfem.json"
        try:
            pb = Problem(case, root / name)
            u, extra = solve_case(pb)
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
