"""What the cross-check solvers share: the case's boundary conditions, loads and exact field,
resolved on the mesh that our tool wrote (`<out>/<body>.vtu`), never on a regenerated mesh.

The definitions mirror the Rust sources:

* exact fields (src/harness/exact.rs): uniform stress `sigma_0` with `u = [e_xx x + g/2 y, g/2 x + e_yy y]`,
  `e = D^-1 sigma_0`; Timoshenko & Goodier's cantilever (plane-stress formulas, plane strain
  through `E/(1 - nu^2)`, `nu/(1 - nu)`);
* materials (src/solid.rs): plane strain `lambda = E nu/((1+nu)(1-2nu))`, plane stress
  `lambda* = E nu/(1 - nu^2)`, `mu = E/(2(1+nu))` in both;
* sets (src/mesh.rs): `left/right/bottom/top` are the nodes and boundary facets on the sides of
  the bounding box, the corner sets the node at each corner, tolerance `1e-9 * size`;
  `box` sets are closed axis-aligned boxes, `point` the node at a point, `nodes` node ids
  (which are the .vtu point ids: the .vtu keeps our node order);
* loads (src/model/mod.rs): traction `t`, pressure `t = -p n` (outward `n`), exact traction
  `t = sigma_exact(x) n`, body force `b`; all times the thickness.

Each solver receives supports as (node coordinates, component, values) and loads as
(facet box, traction function), and finds its own dofs and facets geometrically.

3D cases (src/run3d.rs: one body with a `block3d` mesh of Hex8, Hex27, Tet4 or Tet10): `Problem3`
reads the .vtu (VTK node order, src/fe3d.rs), resolves supports with numbers on the automatic
sets (sides left/right, front/back, bottom/top; corners `bottom_front_left` ...; `all`) and
pressures on the side facet sets, and frictionless penalty pairs against a rigid plane or
sphere (`RigidContact3`) whose penalty term is integrated with the nodal rule of our weights
(`nodal_rule_3d`).

Contact (src/contact/): a single-body case may declare frictionless pairs of the body against a
rigid line or circle with node-to-surface rows and a penalty (`RigidContact`), or Coulomb pairs
against a rigid line (penalty return map of src/contact/friction.rs, load-stepped along the
supports' and loads' `path` factors, `Problem.factor`); under finite kinematics
(`physics.kinematics: "finite"`, `Problem.finite`, the material's `model`,
`Problem.hyperelastic`) a single hyperelastic body, alone or against a rigid line; a two-body case
may tie its bodies with a mortar pair (`TiedCase`). `Sampler` evaluates a nodal field of one of
our .vtu meshes at arbitrary points (as `src/post.rs::CellLocator`), for the distances of the
tied-layer and two-block studies.
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
    """One body of a case, resolved on the body's .vtu mesh. Without `body` the case must have
    exactly one body (and may have rigid contact pairs); with `body` (a name) the supports and
    loads of that body are taken and the rest of the case is left to the caller (`TiedCase`).
    A case with `physics.dynamics` is refused unless `dynamic` (then `self.dynamics` is that
    section and `u_ours` the displacement at the last step)."""

    def __init__(self, case_path, out_dir, body=None, dynamic=False):
        self.case_path = Path(case_path)
        self.case = json.loads(self.case_path.read_text())
        self.name = self.case["name"]
        c = self.case
        bodies = c.get("bodies", [])
        self.multi = body is not None
        if body is None and len(bodies) != 1:
            raise Unsupported(f"{len(bodies)} bodies (two-body cases are cross-checked as ties)")
        for key in c:
            if key not in {"name", "description", "analysis", "materials", "bodies", "exact",
                           "supports", "loads", "checks", "physics", "contact", "solver"}:
                raise Unsupported(f"case section {key!r}")
        physics = dict(c.get("physics", {}) or {})
        # a time history (physics.dynamics) only for the callers that step it (`dynamic`)
        self.dynamics = physics.pop("dynamics", None)
        if self.dynamics is not None and not dynamic:
            raise Unsupported("physics.dynamics (a time history; DOLFINx steps it, "
                              "ref_dolfinx.solve_wave)")
        # finite kinematics (src/solid_finite.rs, ref_dolfinx.solve_finite): a hyperelastic
        # body, alone or with frictionless penalty contact against a rigid line, whose gap
        # n . (X + u - p) is the same in the reference and the current geometry
        kinematics = physics.pop("kinematics", "small_strain")
        if kinematics not in ("small_strain", "finite"):
            raise Unsupported(f"physics.kinematics {kinematics!r}")
        self.finite = kinematics == "finite"
        geometry = physics.pop("contact_geometry", "reference")
        if physics or (geometry != "reference" and not (self.finite and geometry == "current")):
            raise Unsupported(f"physics {c.get('physics')}")
        if body is None:
            body = bodies[0]
        else:
            found = [b for b in bodies if b["name"] == body]
            if not found:
                raise Unsupported(f"no body {body!r}")
            body = found[0]
        self.body = body["name"]
        an = c["analysis"]
        self.thickness = float(an.get("thickness", 1.0))
        m = c["materials"][body["material"]]
        self.material = Material(m["E"], m["nu"], an["plane"])
        # the hyperelastic energy under finite kinematics (src/io/scene.rs MaterialModel)
        self.hyperelastic = m.get("model", "linear_elastic")
        if self.finite != (self.hyperelastic != "linear_elastic"):
            raise Unsupported(f"material model {self.hyperelastic!r} with "
                              f"{'finite' if self.finite else 'small-strain'} kinematics")
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
        self.contact = [] if self.multi else [RigidContact(p, self)
                                              for p in c.get("contact", []) or []]
        # Load steps (src/io/scene.rs: `path` per support and load, one factor per step of
        # `solver.load_steps`, default k / n at step k). Only the Coulomb solve
        # (ref_dolfinx.solve_friction) follows the steps; the other solves need a path that
        # ends at 1 (their solution is the last step's: frictionless and elastic problems
        # are path independent).
        solver = dict(c.get("solver", {}) or {})
        self.load_steps = int(solver.pop("load_steps", 1))
        if solver.pop("scheme", "newton") != "newton" or solver:
            raise Unsupported(f"solver {c.get('solver')} (the references run Newton only)")
        self.support_paths = [s.get("path") for s in c.get("supports", [])
                              if s["body"] == self.body for k in ("x", "y") if s.get(k) is not None]
        self.load_paths = [ld.get("path") for ld in c.get("loads", []) if ld["body"] == self.body]
        self.frictional = any(pair.mu is not None for pair in self.contact)
        if self.finite and (self.frictional or any(p.kind != "line" for p in self.contact)):
            raise Unsupported("finite kinematics with friction or a rigid circle (the "
                              "cross-check's finite cases press against a rigid line)")
        if not self.frictional and any(self.factor(pth, self.load_steps) != 1.0
                                       for pth in self.support_paths + self.load_paths):
            raise Unsupported("a load path that does not end at 1 without friction")

    def factor(self, path, step):
        """The factor of a support or load with `path` at load step `step` (1-based)."""
        if path is None:
            return step / self.load_steps
        if len(path) != self.load_steps:
            raise Unsupported(f"a path of {len(path)} factors for {self.load_steps} load steps")
        return float(path[step - 1])

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
                if self.multi:
                    continue
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
                if self.multi:
                    continue
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


# Edges of each element in our (= VTK) node order: [start, end(, mid)], counter-clockwise
# (src/fe.rs), so the outward normal of an edge is its tangent turned clockwise.
EDGES = {
    "Q4": [(0, 1), (1, 2), (2, 3), (3, 0)],
    "Q9": [(0, 1, 4), (1, 2, 5), (2, 3, 6), (3, 0, 7)],
    "T3": [(0, 1), (1, 2), (2, 0)],
    "T6": [(0, 1, 3), (1, 2, 4), (2, 0, 5)],
}

# The nodal weights of our contact rows (src/contact/discretization/geometry.rs): A_a = t int N_a ds, which on a
# straight Line2 edge is half the length at each end (the trapezoidal rule at the nodes) and on
# a Line3 edge 1/6, 2/3, 1/6 of the length (Simpson's rule at the nodes). A penalty term
# int kappa (g)_- (v . n) ds evaluated with that rule gives exactly our rows' forces
# kappa A_a (g_a)_- n_a. Points and weights on the reference edge [0, 1]:
NODAL_RULE = {
    "Q4": ([0.0, 1.0], [0.5, 0.5]),
    "T3": ([0.0, 1.0], [0.5, 0.5]),
    "Q9": ([0.0, 0.5, 1.0], [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0]),
    "T6": ([0.0, 0.5, 1.0], [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0]),
}


class RigidContact:
    """A frictionless pair of the body's facet set against a rigid line or circle with
    node-to-surface rows and a penalty (src/contact/discretization/mod.rs, `rigid_rows`).

    Small strain: the geometry is the reference one, so at a slave point X the gap is linear,
    g(u) = g0(X) + n(X) . u, with n the unit normal of the rigid surface at X:
    line through p with normal n: g0 = n . (X - p); circle (c, R): n = (X - c)/|X - c|,
    g0 = |X - c| - R (the gap |X + u - c| - R linearized at u = 0, as our rows are).
    `gap(x, y, ux, uy, sqrt)` works on numpy arrays and UFL expressions alike."""

    def __init__(self, spec, pb):
        self.name = spec["name"]
        sl = spec["slave"]
        if sl["body"] != pb.body:
            raise Unsupported(f"contact '{self.name}': slave body {sl['body']!r}")
        self.set = sl["set"]
        self.box = pb.facet_box(sl["set"])
        rigid = (spec.get("master") or {}).get("rigid")
        if rigid is None:
            raise Unsupported(f"contact '{self.name}' between bodies in a one-body case")
        self.kind = rigid["kind"]
        if self.kind == "line":
            n = np.asarray(rigid["normal"], dtype=float)
            self.normal = n / np.linalg.norm(n)
            self.point = np.asarray(rigid["point"], dtype=float)
        elif self.kind == "circle":
            self.centre = np.asarray(rigid["centre"], dtype=float)
            self.radius = float(rigid["radius"])
        else:
            raise Unsupported(f"rigid surface kind {self.kind!r}")
        inter = spec.get("interaction", "frictionless")
        # Coulomb friction (src/contact/friction.rs, penalty return map): mu and the
        # tangential penalty kappa_t (default: the normal kappa), line masters only
        self.mu = self.kappa_t = None
        if isinstance(inter, dict) and set(inter) == {"coulomb"} and self.kind == "line":
            self.mu = float(inter["coulomb"]["mu"])
            self.kappa_t = inter["coulomb"].get("kappa_t")
        elif inter != "frictionless":
            raise Unsupported(f"contact '{self.name}': interaction {inter!r} against a rigid surface")
        disc = spec["discretization"]
        if disc.get("kind") != "node_to_surface" or int(disc.get("passes", 1)) != 1:
            raise Unsupported(f"contact '{self.name}': discretization {disc}")
        enf = spec["enforcement"]
        # penalty and perturbed Lagrangian give identical numbers with node rows
        # (src/contact/enforcement/); the references solve the penalty problem.
        if enf.get("kind") not in ("penalty", "perturbed_lagrange"):
            raise Unsupported(f"contact '{self.name}': enforcement {enf.get('kind')!r} "
                              "(the cross-check solves penalty problems)")
        self.kappa = float(enf["kappa"])
        if self.mu is not None:
            if enf.get("kind") != "penalty":
                raise Unsupported(f"contact '{self.name}': Coulomb with {enf.get('kind')!r}")
            self.kappa_t = self.kappa if self.kappa_t is None else float(self.kappa_t)
        self.rule = NODAL_RULE[pb.element]

    def gap(self, x, y, ux, uy, sqrt):
        """(g, nx, ny) at reference point (x, y) for displacement (ux, uy)."""
        if self.kind == "line":
            nx, ny = float(self.normal[0]), float(self.normal[1])
            g0 = nx * (x - float(self.point[0])) + ny * (y - float(self.point[1]))
        else:
            dx, dy = x - float(self.centre[0]), y - float(self.centre[1])
            length = sqrt(dx * dx + dy * dy)
            nx, ny = dx / length, dy / length
            g0 = length - self.radius
        return g0 + nx * ux + ny * uy, nx, ny

    def hertz(self, pb, load):
        """Hertz's plane-strain half-width and peak pressure for a rigid cylinder
        (benchmarks.md s. 3; 1/E* = (1 - nu^2)/E with the rigid side's term zero), load per
        unit thickness `load`; None for a line."""
        if self.kind != "circle":
            return None
        E, nu = pb.material.E, pb.material.nu
        estar = E / (1.0 - nu * nu) if pb.material.plane == "strain" else E
        a = math.sqrt(4.0 * load * self.radius / (math.pi * estar))
        return {"P": load, "R": self.radius, "E_star": estar, "a": a,
                "p0": 2.0 * load / (math.pi * a)}


def boundary_facets(pb):
    """Boundary facets of a body's .vtu mesh: a list of node tuples [start, end(, mid)]
    (counter-clockwise around their cell), one per edge that belongs to one cell only."""
    count, first = {}, {}
    for cell in pb.cells:
        for e in EDGES[pb.element]:
            nodes = tuple(int(cell[i]) for i in e)
            key = tuple(sorted(nodes[:2]))
            count[key] = count.get(key, 0) + 1
            first.setdefault(key, nodes)
    return [first[k] for k, c in count.items() if c == 1]


def facets_in_box(pb, box):
    """The boundary facets (node tuples) whose nodes all lie in `box`."""
    return [f for f in boundary_facets(pb) if in_box(pb.points[list(f)], box).all()]


class TiedCase:
    """A two-body case whose bodies are tied by one mortar pair (interaction `tied`,
    discretization `mortar`, exact enforcement). Each body is a `Problem` with its own supports
    and loads; the pair's slave and master facet boxes select the interface."""

    def __init__(self, case_path, out_dir):
        case = json.loads(Path(case_path).read_text())
        self.name = case["name"]
        names = [b["name"] for b in case.get("bodies", [])]
        if len(names) != 2:
            raise Unsupported(f"{len(names)} bodies (ties are cross-checked between two bodies)")
        pairs = case.get("contact", []) or []
        if len(pairs) != 1:
            raise Unsupported(f"{len(pairs)} contact pairs (one tie expected)")
        pair = pairs[0]
        if pair.get("interaction") != "tied":
            raise Unsupported("a two-body pair that is not a tie")
        disc = pair["discretization"]
        if disc.get("kind") != "mortar":
            raise Unsupported(f"tie discretization {disc.get('kind')!r} (mortar only)")
        self.multiplier = disc.get("multiplier", "standard")
        if self.multiplier not in ("standard", "dual"):
            raise Unsupported(f"multiplier {self.multiplier!r}")
        enf = pair["enforcement"]["kind"]
        if enf not in ("lagrange", "elimination"):
            raise Unsupported(f"tie enforcement {enf!r} (exact enforcement only)")
        self.bodies = {n: Problem(case_path, out_dir, body=n) for n in names}
        self.order = names
        sl, ma = pair["slave"], pair["master"]
        if ma.get("rigid") is not None:
            raise Unsupported("a tie to a rigid surface")
        self.slave, self.master = sl["body"], ma["body"]
        self.slave_set, self.master_set = sl["set"], ma["set"]
        self.element = {n: pb.element for n, pb in self.bodies.items()}


# --- sampling a nodal field at points (the tied-layer and two-block distances) ----------------
def _line_shape(s, order):
    if order == 1:
        return [0.5 * (1 - s), 0.5 * (1 + s)], [-0.5 + 0 * s, 0.5 + 0 * s]
    # nodes at -1, +1, 0
    return ([0.5 * s * (s - 1), 0.5 * s * (s + 1), 1 - s * s],
            [s - 0.5, s + 0.5, -2 * s])


# (i, j) indices of each node of Q4 / Q9 into the 1D node lists [-1, +1(, 0)]
_Q_IJ = {"Q4": [(0, 0), (1, 0), (1, 1), (0, 1)],
         "Q9": [(0, 0), (1, 0), (1, 1), (0, 1), (2, 0), (1, 2), (2, 1), (0, 2), (2, 2)]}


def quad_shape(element, xi, eta):
    """Shape functions (nn, m) and derivatives d/dxi, d/deta of Q4 / Q9 (our node order)."""
    order = 1 if element == "Q4" else 2
    lx, dlx = _line_shape(xi, order)
    ly, dly = _line_shape(eta, order)
    ij = _Q_IJ[element]
    n = np.array([lx[i] * ly[j] for i, j in ij])
    dxi = np.array([dlx[i] * ly[j] for i, j in ij])
    deta = np.array([lx[i] * dly[j] for i, j in ij])
    return n, dxi, deta


class Sampler:
    """Evaluates nodal fields of a quadrilateral .vtu mesh at points: the candidate cells are the
    nearest cell centres, the isoparametric map is inverted by Newton's method, and the first
    cell whose reference square holds the point (within 1e-9) is taken (src/post.rs)."""

    def __init__(self, points, cells, element):
        from scipy.spatial import cKDTree

        if element not in _Q_IJ:
            raise Unsupported(f"sampling on {element} cells")
        self.points, self.cells, self.element = np.asarray(points), np.asarray(cells), element
        self.tree = cKDTree(self.points[self.cells].mean(axis=1))

    def locate(self, P):
        P = np.asarray(P, dtype=float)
        k = min(12, len(self.cells))
        _, cand = self.tree.query(P, k=k)
        cand = cand.reshape(len(P), k)
        cell = np.full(len(P), -1)
        xi = np.zeros((len(P), 2))
        for r in range(k):
            todo = np.flatnonzero(cell < 0)
            if len(todo) == 0:
                break
            c = cand[todo, r]
            X = self.points[self.cells[c]]          # (m, nn, 2)
            a = np.zeros(len(todo))
            b = np.zeros(len(todo))
            for _ in range(30):
                n, dxi, deta = quad_shape(self.element, a, b)   # (nn, m)
                x = np.einsum("am,mad->md", n, X)
                j11 = np.einsum("am,ma->m", dxi, X[:, :, 0])
                j12 = np.einsum("am,ma->m", deta, X[:, :, 0])
                j21 = np.einsum("am,ma->m", dxi, X[:, :, 1])
                j22 = np.einsum("am,ma->m", deta, X[:, :, 1])
                rx, ry = P[todo, 0] - x[:, 0], P[todo, 1] - x[:, 1]
                det = j11 * j22 - j12 * j21
                da = (j22 * rx - j12 * ry) / det
                db = (-j21 * rx + j11 * ry) / det
                a, b = a + da, b + db
                if np.all(np.abs(da) + np.abs(db) <= 1e-13):
                    break
            inside = (np.abs(a) <= 1 + 1e-9) & (np.abs(b) <= 1 + 1e-9)
            hit = todo[inside]
            cell[hit] = c[inside]
            xi[hit, 0], xi[hit, 1] = a[inside], b[inside]
        if (cell < 0).any():
            bad = P[np.flatnonzero(cell < 0)[0]]
            raise RuntimeError(f"sample point ({bad[0]}, {bad[1]}) is outside the mesh")
        return cell, xi

    def values(self, U, P):
        """The field U (one row per .vtu point) at the points P (m, 2)."""
        cell, xi = self.locate(P)
        n, _, _ = quad_shape(self.element, xi[:, 0], xi[:, 1])   # (nn, m)
        return np.einsum("am,mad->md", n, np.asarray(U)[self.cells[cell]])


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


# --- 3D cases (bodies with a `block3d` mesh; src/run3d.rs) -----------------------------------
# VTK cell types our tool writes in 3D (src/fe3d.rs, VTK node order) -> (element, meshio name)
MESHIO_CELL_3D = {"Hex8": "hexahedron", "Hex27": "hexahedron27", "Tet4": "tetra",
                  "Tet10": "tetra10"}
ELEMENT_OF_MESHIO_3D = {v: k for k, v in MESHIO_CELL_3D.items()}
# The stiffness quadrature of src/fe3d.rs (`SolidKind::stiffness_rule`): Gauss 2x2x2 (Hex8),
# 3x3x3 (Hex27); the centroid (Tet4) and Keast's 4-point degree-2 rule (Tet10). basix and
# scikit-fem use tensor Gauss(-Jacobi) rules of ceil((q+1)/2) points per direction on
# hexahedra, so degrees 3 and 5 are our rules; the tetrahedra are affine (straight edges, the
# Tet10 mid-edge nodes at the edge midpoints), where any rule of at least the integrand's
# degree (0 and 2) gives the same matrix.
STIFFNESS_DEGREE_3D = {"Hex8": 3, "Hex27": 5, "Tet4": 1, "Tet10": 2}
# The automatic sets of a 3D block (src/mesh.rs `add_automatic_sets`): x left/right, y
# front/back, z bottom/top; corners named from z to x (`bottom_front_left`).
SIDES_3D = (("left", "right"), ("front", "back"), ("bottom", "top"))
# Facets of each cell in our (VTK) node order, corners counter-clockwise seen from outside, then
# the mid-edge nodes and the centre (src/fe3d.rs HEX8_FACETS ... TET10_FACETS).
FACETS_3D = {
    "Hex8": [(0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2), (0, 3, 2, 1), (4, 5, 6, 7)],
    "Hex27": [(0, 4, 7, 3, 16, 15, 19, 11, 20), (1, 2, 6, 5, 9, 18, 13, 17, 21),
              (0, 1, 5, 4, 8, 17, 12, 16, 22), (3, 7, 6, 2, 19, 14, 18, 10, 23),
              (0, 3, 2, 1, 11, 10, 9, 8, 24), (4, 5, 6, 7, 12, 13, 14, 15, 25)],
    "Tet4": [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)],
    "Tet10": [(0, 2, 1, 6, 5, 4), (0, 1, 3, 4, 8, 7), (0, 3, 2, 7, 9, 6), (1, 2, 3, 5, 9, 8)],
}
# The nodal weights of our 3D contact rows (src/contact/discretization/geometry.rs
# `weight_basis`): A_a = int M_a dA with M_a the facet's shape functions, except on Tri6
# facets (Tet10), whose corner functions integrate to zero on a flat triangle: there the
# modified basis M_corner = N_corner + alpha (N_m + N_m'), M_mid = (1 - 2 alpha) N_mid,
# alpha = TRI6_MODIFIED_ALPHA = 0.2, which gives 2/15 of the area at each corner and 1/5 at
# each mid-edge node. On a flat facet of constant Jacobian (a parallelogram; every triangle
# here) these are quadrature rules with the facet's nodes as points: A_a = w_a |facet|.
# Points on basix's reference facets ([0, 1]^2, the triangle (0,0), (1,0), (0,1)) and
# weights summing to the reference area; the rules are symmetric under the facet's symmetries,
# so the facet's orientation in a cell does not matter. Q4: the vertices, 1/4 each; Q9: the
# tensor Simpson rule (1/6, 2/3, 1/6 per direction); T3: the vertices, 1/6 each (1/3 of the
# area 1/2); T6: corners 2/15 and mid-edges 1/5 of the area 1/2.
TRI6_MODIFIED_ALPHA = 0.2


def nodal_rule_3d(element):
    """(points (m, 2), weights (m,)) of the nodal rule of our contact weights on the facets of
    `element` (see above)."""
    if element in ("Hex8", "Hex27"):
        s, w = (([0.0, 1.0], [0.5, 0.5]) if element == "Hex8"
                else ([0.0, 0.5, 1.0], [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0]))
        pts = np.array([[a, b] for a in s for b in s])
        wts = np.array([wa * wb for wa in w for wb in w])
        return pts, wts
    if element == "Tet4":
        return np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), np.full(3, 1.0 / 6.0)
    a = TRI6_MODIFIED_ALPHA
    corner, mid = 2.0 * a / 3.0, (1.0 - 2.0 * a) / 3.0     # 2/15, 1/5 of the area
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]])
    return pts, 0.5 * np.array([corner] * 3 + [mid] * 3)


def is_3d_case(case):
    """Whether a case (parsed JSON) has a 3D body (src/run3d.rs `is_3d`)."""
    return any("block3d" in (b.get("mesh") or {}) for b in case.get("bodies", []))


class RigidContact3:
    """A frictionless pair of the body's facet set against a rigid plane or sphere with
    node-to-surface rows and a penalty (src/contact/discretization/node_based_rows.rs
    `rigid_rows`, `rigid_gap`). Small strain: at a slave point X the gap is linearized at the
    reference configuration, g(u) = g0(X) + n(X) . u; plane through p with unit normal n:
    g0 = n . (X - p); sphere (c, R): n = (X - c)/|X - c|, g0 = |X - c| - R. `gap(X, U, sqrt)`
    takes lists of the three coordinates and components (numpy arrays or UFL expressions)."""

    def __init__(self, spec, pb):
        self.name = spec["name"]
        sl = spec["slave"]
        if sl["body"] != pb.body:
            raise Unsupported(f"contact '{self.name}': slave body {sl['body']!r}")
        self.set = sl["set"]
        self.box = pb.facet_box(sl["set"])
        rigid = (spec.get("master") or {}).get("rigid")
        if rigid is None:
            raise Unsupported(f"contact '{self.name}' between bodies (the 3D cross-check "
                              "models rigid masters only)")
        self.kind = rigid["kind"]
        if self.kind == "plane":
            n = np.asarray(rigid["normal"], dtype=float)
            self.normal = n / np.linalg.norm(n)
            self.point = np.asarray(rigid["point"], dtype=float)
        elif self.kind == "sphere":
            self.centre = np.asarray(rigid["centre"], dtype=float)
            self.radius = float(rigid["radius"])
        else:
            raise Unsupported(f"rigid surface kind {self.kind!r} in 3D")
        if spec.get("interaction", "frictionless") != "frictionless":
            raise Unsupported(f"contact '{self.name}': interaction {spec.get('interaction')!r}")
        disc = spec["discretization"]
        if disc.get("kind") != "node_to_surface" or int(disc.get("passes", 1)) != 1:
            raise Unsupported(f"contact '{self.name}': discretization {disc}")
        enf = spec["enforcement"]
        if enf.get("kind") not in ("penalty", "perturbed_lagrange"):
            raise Unsupported(f"contact '{self.name}': enforcement {enf.get('kind')!r} "
                              "(the cross-check solves penalty problems)")
        self.kappa = float(enf["kappa"])
        for key in spec:
            if key not in {"name", "slave", "master", "interaction", "discretization",
                           "enforcement"}:
                raise Unsupported(f"contact '{self.name}': {key!r}")
        self.rule = nodal_rule_3d(pb.element)

    def gap(self, X, U, sqrt):
        """(g, n) at reference point X for displacement U (lists of 3)."""
        if self.kind == "plane":
            n = [float(c) for c in self.normal]
            g0 = sum(n[i] * (X[i] - float(self.point[i])) for i in range(3))
        else:
            d = [X[i] - float(self.centre[i]) for i in range(3)]
            length = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            n = [d[i] / length for i in range(3)]
            g0 = length - self.radius
        return g0 + n[0] * U[0] + n[1] * U[1] + n[2] * U[2], n


class Problem3:
    """One 3D body (a `block3d` mesh) resolved on its .vtu, as src/run3d.rs builds it: linear
    elasticity (E, nu), supports with numbers on the automatic node sets, pressures on the
    automatic facet sets, and frictionless penalty contact against a rigid plane or sphere.
    Everything else is refused (as run3d refuses it, or as the cross-check does not model it)."""

    def __init__(self, case_path, out_dir):
        self.case_path = Path(case_path)
        self.case = json.loads(self.case_path.read_text())
        c = self.case
        self.name = c["name"]
        bodies = c.get("bodies", [])
        if len(bodies) != 1:
            raise Unsupported(f"{len(bodies)} bodies (the 3D cross-check has one-body cases)")
        for key in c:
            if key not in {"name", "description", "materials", "bodies", "supports", "loads",
                           "checks", "contact", "analysis"}:
                raise Unsupported(f"case section {key!r} in 3D")
        body = bodies[0]
        self.body = body["name"]
        if body.get("node_sets") or body.get("facet_sets"):
            raise Unsupported("user-defined sets in 3D (src/run3d.rs refuses them)")
        m = c["materials"][body["material"]]
        if m.get("model", "linear_elastic") != "linear_elastic":
            raise Unsupported(f"material model {m.get('model')!r} in 3D")
        self.E, self.nu = float(m["E"]), float(m["nu"])
        self.mu = self.E / (2.0 * (1.0 + self.nu))
        self.lam = self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

        self.vtu = Path(out_dir) / f"{self.body}.vtu"
        mesh = meshio.read(self.vtu)
        if len(mesh.cells) != 1 or mesh.cells[0].type not in ELEMENT_OF_MESHIO_3D:
            raise Unsupported(f"cells {[b.type for b in mesh.cells]} in {self.vtu}")
        self.meshio = mesh
        self.element = ELEMENT_OF_MESHIO_3D[mesh.cells[0].type]
        self.points = np.ascontiguousarray(mesh.points[:, :3], dtype=np.float64)
        self.cells = np.asarray(mesh.cells[0].data, dtype=np.int64)
        self.u_ours = np.asarray(mesh.point_data["displacement"][:, :3], dtype=np.float64)
        self.lo, self.hi = self.points.min(axis=0), self.points.max(axis=0)
        self.size = float(np.linalg.norm(self.hi - self.lo))
        self.tol = 1e-9 * self.size
        self.supports = self._supports()
        self.loads = self._loads()
        self.contact = [RigidContact3(p, self) for p in c.get("contact", []) or []]

    # --- sets -----------------------------------------------------------------------------
    def _side_box(self, name):
        inf = math.inf
        for axis, pair in enumerate(SIDES_3D):
            for side, side_name in enumerate(pair):
                if name == side_name:
                    lo, hi = [-inf] * 3, [inf] * 3
                    lo[axis] = hi[axis] = (self.lo if side == 0 else self.hi)[axis]
                    return lo, hi
        if name == "all":
            return [-inf] * 3, [inf] * 3
        parts = name.split("_")
        if len(parts) == 3:   # a corner: z side, y side, x side
            p = []
            for axis, part in zip((2, 1, 0), parts):
                if part not in SIDES_3D[axis]:
                    return None
                p.append((axis, (self.lo if SIDES_3D[axis].index(part) == 0 else self.hi)[axis]))
            pt = [0.0] * 3
            for axis, v in p:
                pt[axis] = v
            return pt, pt
        return None

    def node_set(self, name):
        b = self._side_box(name)
        if b is None:
            raise Unsupported(f"node set {name!r} (3D has the automatic sets only)")
        return np.flatnonzero(in_box(self.points, (b[0], b[1], self.tol)))

    def facet_box(self, name):
        if name not in [s for pair in SIDES_3D for s in pair]:
            raise Unsupported(f"facet set {name!r} (3D has the six sides only)")
        b = self._side_box(name)
        return (b[0], b[1], self.tol)

    def boundary_facets(self):
        """Boundary facets (node tuples in FACETS_3D order), each a cell face no other cell
        has."""
        count, first = {}, {}
        ncorner = 4 if self.element.startswith("Hex") else 3
        for cell in self.cells:
            for f in FACETS_3D[self.element]:
                nodes = tuple(int(cell[i]) for i in f)
                key = tuple(sorted(nodes[:ncorner]))
                count[key] = count.get(key, 0) + 1
                first.setdefault(key, nodes)
        return [first[k] for k, c in count.items() if c == 1]

    def facets_in_box(self, box):
        return [f for f in self.boundary_facets() if in_box(self.points[list(f)], box).all()]

    # --- supports and loads ------------------------------------------------------------------
    def _supports(self):
        """[(coords (k, 3), component, values (k,))] in case order."""
        out = []
        for s in self.case.get("supports", []):
            if s["body"] != self.body:
                raise Unsupported(f"support on body {s['body']!r}")
            if s.get("path") is not None:
                raise Unsupported("a load path in 3D")
            nodes = self.node_set(s["set"])
            if len(nodes) == 0:
                raise Unsupported(f"support set {s['set']!r} is empty")
            for comp, key in ((0, "x"), (1, "y"), (2, "z")):
                v = s.get(key)
                if v is None:
                    continue
                if not isinstance(v, (int, float)):
                    raise Unsupported(f"support value {v!r} in 3D (numbers only)")
                out.append((self.points[nodes], comp, np.full(len(nodes), float(v))))
        return out

    def _loads(self):
        """[(facet box, pressure)]: t = -p n on the facets of the set."""
        out = []
        for ld in self.case.get("loads", []):
            if ld["body"] != self.body:
                raise Unsupported(f"load on body {ld['body']!r}")
            if set(ld) - {"body", "set", "pressure"} or "pressure" not in ld:
                raise Unsupported(f"load {ld} in 3D (pressures on facet sets only)")
            out.append((self.facet_box(ld["set"]), float(ld["pressure"])))
        return out

    def match(self, coords):
        """Map solver node coordinates (M, 3) onto .vtu point ids; (ids, max distance)."""
        from scipy.spatial import cKDTree

        d, ids = cKDTree(self.points).query(np.asarray(coords)[:, :3])
        if len(np.unique(ids)) != len(ids) or len(ids) != len(self.points):
            raise RuntimeError(
                f"{self.name}: solver nodes do not map one-to-one onto the .vtu points "
                f"({len(ids)} nodes, {len(np.unique(ids))} distinct, {len(self.points)} points)")
        if d.max() > self.tol:
            raise RuntimeError(f"{self.name}: node match distance {d.max():.3e} > {self.tol:.3e}")
        return ids, float(d.max())

    def slave_nodes(self, pair):
        """The .vtu ids of the slave nodes of `pair` (every node of its facets)."""
        return np.array(sorted({n for f in self.facets_in_box(pair.box) for n in f}))
