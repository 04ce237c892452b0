"""What the cross-check solvers share: the case's boundary conditions, loads and exact field,
resolved on the mesh that our tool wrote (`<out>/<body>.vtu`), never on a regenerated mesh.

The definitions mirror the Rust sources:

* exact fields (src/exact.rs): uniform stress `sigma_0` with `u = [e_xx x + g/2 y, g/2 x + e_yy y]`,
  `e = D^-1 sigma_0`; Timoshenko & Goodier's cantilever (plane-stress formulas, plane strain
  through `E/(1 - nu^2)`, `nu/(1 - nu)`);
* materials (src/solid.rs): plane strain `lambda = E nu/((1+nu)(1-2nu))`, plane stress
  `lambda* = E nu/(1 - nu^2)`, `mu = E/(2(1+nu))` in both;
* sets (src/mesh.rs): `left/right/bottom/top` are the nodes and boundary facets on the sides of
  the bounding box, the corner sets the node at each corner, tolerance `1e-9 * size`;
  `box` sets are closed axis-aligned boxes, `point` the node at a point, `nodes` node ids
  (which are the .vtu point ids: the .vtu keeps our node order);
* loads (src/model.rs): traction `t`, pressure `t = -p n` (outward `n`), exact traction
  `t = sigma_exact(x) n`, body force `b`; all times the thickness.

Each solver receives supports as (node coordinates, component, values) and loads as
(facet box, traction function), and finds its own dofs and facets geometrically.
"""

import json
import math
from pathlib import Path

import meshio
import numpy as np

# VTK cell types our tool writes -> (element name, meshio cell name)
MESHIO_CELL = {"Q4": "quad", "Q9": "quad9", "T3": "triangle", "T6": "triangle6"}
ELEMENT_OF_MESHIO = {v: k for k, v in MESHIO_CELL.items()}

# The stiffness quadrature of our tool (src/fe.rs): Gauss 2x2 (Q4), 3x3 (Q9), 1 point (T3),
# degree 2 (T6). The oracles use rules of the same points where it matters (non-affine quads):
# basix and scikit-fem both use tensor Gauss-Legendre with ceil((q+1)/2) points per direction
# for degree q, so q = 3 -> 2x2 and q = 5 -> 3x3. Triangles here are affine, where any rule of
# at least the integrand's degree gives the same matrix.
STIFFNESS_DEGREE = {"Q4": 3, "Q9": 5, "T3": 1, "T6": 2}
# Loads: the exact tractions are polynomials of degree <= 3 along a straight edge, times a shape
# function of degree <= 2; degree 8 integrates them exactly.
LOAD_DEGREE = 8
# Body forces are constant: shape function (<= degree 2 per direction) times det J.
BODY_FORCE_DEGREE = 6


class Unsupported(Exception):
    """The case uses something this cross-check does not model (yet)."""


class Material:
    def __init__(self, E, nu, plane):
        self.E, self.nu, self.plane = float(E), float(nu), plane
        self.mu = self.E / (2.0 * (1.0 + self.nu))
        if plane == "strain":
            self.lam = self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
        elif plane == "stress":
            self.lam = self.E * self.nu / (1.0 - self.nu * self.nu)
        else:
            raise Unsupported(f"analysis.plane {plane!r}")

    def strain_of_stress(self, s):
        """In-plane engineering strain [e_xx, e_yy, gamma_xy] of in-plane stress s."""
        a, b = self.lam + 2.0 * self.mu, self.lam
        det = a * a - b * b
        return [(a * s[0] - b * s[1]) / det, (-b * s[0] + a * s[1]) / det, s[2] / self.mu]

    def plane_stress_equivalent(self):
        if self.plane == "stress":
            return self.E, self.nu
        return self.E / (1.0 - self.nu**2), self.nu / (1.0 - self.nu)


class Exact:
    """The case's `exact` field. `stress(x, y)` uses only arithmetic, so it works on numpy
    arrays (scikit-fem quadrature points) and on UFL expressions (DOLFINx) alike."""

    def __init__(self, spec):
        self.kind = spec["kind"]
        if self.kind == "uniform_stress":
            self.s0 = [float(v) for v in spec["stress"]]
        elif self.kind == "timoshenko_cantilever":
            self.P, self.L, self.D = float(spec["load"]), float(spec["length"]), float(spec["depth"])
        else:
            raise Unsupported(f"exact.kind {self.kind!r}")

    def stress(self, x, y):
        if self.kind == "uniform_stress":
            return self.s0
        P, L, D = self.P, self.L, self.D
        i = D**3 / 12.0
        return [-P * (L - x) * y / i, 0.0 * x, P / (2.0 * i) * (D * D / 4.0 - y * y)]

    def displacement(self, p, mat):
        x, y = p[:, 0], p[:, 1]
        if self.kind == "uniform_stress":
            e = mat.strain_of_stress(self.s0)
            return np.stack([e[0] * x + 0.5 * e[2] * y, 0.5 * e[2] * x + e[1] * y], axis=1)
        E, nu = mat.plane_stress_equivalent()
        P, L, D = self.P, self.L, self.D
        i = D**3 / 12.0
        c = P / (6.0 * E * i)
        d2 = D * D / 4.0
        ux = -c * y * ((6.0 * L - 3.0 * x) * x + (2.0 + nu) * (y * y - d2))
        uy = c * (3.0 * nu * y * y * (L - x) + (4.0 + 5.0 * nu) * d2 * x + (3.0 * L - x) * x * x)
        return np.stack([ux, uy], axis=1)


class Load:
    """A distributed load on the boundary facets inside `box` (lo, hi, tol), or a body force
    (`box` None). `traction(x, y, n)` returns [tx, ty] given the outward unit normal n."""

    def __init__(self, box, kind, value, exact=None):
        self.box, self.kind, self.value, self.exact = box, kind, value, exact

    def traction(self, x, y, n):
        if self.kind == "vector":
            return [self.value[0] + 0.0 * x, self.value[1] + 0.0 * x]
        if self.kind == "pressure":
            return [-self.value * n[0], -self.value * n[1]]
        if self.kind == "exact":
            s = self.exact.stress(x, y)
            return [s[0] * n[0] + s[2] * n[1], s[2] * n[0] + s[1] * n[1]]
        raise AssertionError(self.kind)


def in_box(points, box):
    """Boolean mask of points (N, 2) inside the closed box (lo, hi) with tolerance tol."""
    lo, hi, tol = box
    p = np.asarray(points)
    return np.all((p >= np.asarray(lo) - tol) & (p <= np.asarray(hi) + tol), axis=1)


class Problem:
    """One case with one body, resolved on the body's .vtu mesh."""

    def __init__(self, case_path, out_dir):
        self.case_path = Path(case_path)
        self.case = json.loads(self.case_path.read_text())
        self.name = self.case["name"]
        c = self.case
        bodies = c.get("bodies", [])
        if len(bodies) != 1:
            raise Unsupported(f"{len(bodies)} bodies (only single-body cases are cross-checked)")
        for key in c:
            if key not in {"name", "description", "analysis", "materials", "bodies", "exact",
                           "supports", "loads", "checks", "physics"}:
                raise Unsupported(f"case section {key!r}")
        physics = c.get("physics", {}) or {}
        if any(k != "kinematics" or v != "small_strain" for k, v in physics.items()):
            raise Unsupported(f"physics {physics}")
        body = bodies[0]
        self.body = body["name"]
        an = c["analysis"]
        self.thickness = float(an.get("thickness", 1.0))
        m = c["materials"][body["material"]]
        self.material = Material(m["E"], m["nu"], an["plane"])
        self.exact = Exact(c["exact"]) if c.get("exact") else None

        self.vtu = Path(out_dir) / f"{self.body}.vtu"
        mesh = meshio.read(self.vtu)
        if len(mesh.cells) != 1 or mesh.cells[0].type not in ELEMENT_OF_MESHIO:
            raise Unsupported(f"cells {[b.type for b in mesh.cells]} in {self.vtu}")
        self.meshio = mesh
        self.element = ELEMENT_OF_MESHIO[mesh.cells[0].type]
        self.points = np.ascontiguousarray(mesh.points[:, :2], dtype=np.float64)
        self.cells = np.asarray(mesh.cells[0].data, dtype=np.int64)
        self.u_ours = np.asarray(mesh.point_data["displacement"][:, :2], dtype=np.float64)
        lo, hi = self.points.min(axis=0), self.points.max(axis=0)
        self.lo, self.hi = lo, hi
        self.size = float(np.hypot(*(hi - lo)))
        self.tol = 1e-9 * self.size

        self.node_set_specs = dict(body.get("node_sets", {}) or {})
        self.facet_set_specs = dict(body.get("facet_sets", {}) or {})
        self.supports = self._supports()
        self.loads = self._loads()

    # --- sets -----------------------------------------------------------------------------
    def _side_box(self, name):
        lo, hi, inf = self.lo, self.hi, math.inf
        boxes = {
            "left": ([lo[0], -inf], [lo[0], inf]),
            "right": ([hi[0], -inf], [hi[0], inf]),
            "bottom": ([-inf, lo[1]], [inf, lo[1]]),
            "top": ([-inf, hi[1]], [inf, hi[1]]),
            "bottom_left": ([lo[0], lo[1]], [lo[0], lo[1]]),
            "bottom_right": ([hi[0], lo[1]], [hi[0], lo[1]]),
            "top_left": ([lo[0], hi[1]], [lo[0], hi[1]]),
            "top_right": ([hi[0], hi[1]], [hi[0], hi[1]]),
            "all": ([-inf, -inf], [inf, inf]),
        }
        return boxes.get(name)

    def node_set(self, name):
        """Indices of .vtu points in the node set `name`."""
        spec = self.node_set_specs.get(name)
        if spec is None:
            b = self._side_box(name)
            if b is None:
                raise Unsupported(f"node set {name!r}")
            return np.flatnonzero(in_box(self.points, (b[0], b[1], self.tol)))
        if "box" in spec:
            return np.flatnonzero(in_box(self.points, (spec["box"]["min"], spec["box"]["max"], self.tol)))
        if "point" in spec:
            d = np.linalg.norm(self.points - np.asarray(spec["point"]), axis=1)
            return np.array([int(np.argmin(d))])
        if "nodes" in spec:
            return np.asarray(spec["nodes"], dtype=np.int64)
        raise Unsupported(f"node set spec {spec}")

    def facet_box(self, name):
        """The closed box (lo, hi, tol) that selects the boundary facets of set `name`."""
        spec = self.facet_set_specs.get(name)
        if spec is None:
            b = self._side_box(name)
            if b is None or name not in ("left", "right", "bottom", "top"):
                raise Unsupported(f"facet set {name!r}")
            return (b[0], b[1], self.tol)
        if "box" in spec:
            return (spec["box"]["min"], spec["box"]["max"], self.tol)
        raise Unsupported(f"facet set spec {spec} (only boxes)")

    # --- supports and loads ------------------------------------------------------------------
    def _supports(self):
        """[(coords (k, 2), component, values (k,))] in case order; later entries win, as in
        our tool (it rejects conflicting values)."""
        out = []
        for s in self.case.get("supports", []):
            if s["body"] != self.body:
                raise Unsupported(f"support on body {s['body']!r}")
            nodes = self.node_set(s["set"])
            if len(nodes) == 0:
                raise Unsupported(f"support set {s['set']!r} is empty")
            coords = self.points[nodes]
            for comp, key in ((0, "x"), (1, "y")):
                v = s.get(key)
                if v is None:
                    continue
                if v == "exact":
                    if self.exact is None:
                        raise Unsupported("an exact support without an exact field")
                    vals = self.exact.displacement(coords, self.material)[:, comp]
                else:
                    vals = np.full(len(nodes), float(v))
                out.append((coords, comp, vals))
        return out

    def _loads(self):
        out = []
        for ld in self.case.get("loads", []):
            if ld["body"] != self.body:
                raise Unsupported(f"load on body {ld['body']!r}")
            if "body_force" in ld:
                out.append(Load(None, "body_force", [float(v) for v in ld["body_force"]]))
                continue
            box = self.facet_box(ld["set"])
            if "pressure" in ld:
                out.append(Load(box, "pressure", float(ld["pressure"])))
            elif ld.get("traction") == "exact":
                out.append(Load(box, "exact", None, self.exact))
            elif "traction" in ld:
                out.append(Load(box, "vector", [float(v) for v in ld["traction"]]))
            else:
                raise Unsupported(f"load {ld}")
        return out

    def match(self, coords):
        """Map solver node coordinates (M, 2) onto .vtu point ids; returns (ids, max distance).
        Raises when the map is not one-to-one within the geometric tolerance."""
        from scipy.spatial import cKDTree

        d, ids = cKDTree(self.points).query(np.asarray(coords)[:, :2])
        if len(np.unique(ids)) != len(ids) or len(ids) != len(self.points):
            raise RuntimeError(
                f"{self.name}: solver nodes do not map one-to-one onto the .vtu points "
                f"({len(ids)} nodes, {len(np.unique(ids))} distinct, {len(self.points)} points)")
        if d.max() > self.tol:
            raise RuntimeError(f"{self.name}: node match distance {d.max():.3e} > {self.tol:.3e}")
        return ids, float(d.max())


def write_reference(path, problem, solver, u_on_vtu, extra):
    """A reference result: displacement at every .vtu point (in .vtu order)."""
    data = {
        "case": problem.name,
        "solver": solver,
        "element": problem.element,
        "mesh": str(problem.vtu),
        "points": len(problem.points),
        "u": u_on_vtu.tolist(),
    }
    data.update(extra)
    Path(path).write_text(json.dumps(data))
