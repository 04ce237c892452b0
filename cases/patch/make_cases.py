#!/usr/bin/env python3
"""Writes the contact patch-test catalogue (meshes A-E x nu) as case files in this folder.

The geometry is the reconstruction of Taylor & Papadopoulos (1991) in
shared/design/benchmarks.md, section 1: a punch [4,6]x[5,7] pressed by p = 10 onto a
foundation [0,8]x[0,5]. Rerun after changing it: python3 cases/patch/make_cases.py
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
P = 10.0
MESHES = {
    # name: (element, foundation x-breaks, punch x-breaks, punch y-breaks, character)
    "A": ("Q4", [0, 2, 4, 5, 6, 7, 8], [4, 5, 6], [5, 6, 7], "matching Q4"),
    "B": ("Q4", [0, 2, 4, 5, 6, 7, 8], [4, 4.5, 5, 5.5, 6], [5, 6, 7], "non-matching nested Q4 (punch 2:1 finer)"),
    "C": ("Q4", [0, 2, 4, 5, 6, 7, 8], [4, 4 + 2 / 3, 4 + 4 / 3, 6], [5, 6, 7], "non-matching, not nested Q4"),
    "D": ("Q9", [0, 2, 4, 5, 6, 7, 8], [4, 5, 6], [5, 7], "matching Q9"),
    "E": ("Q9", [0, 2, 4, 5, 6, 7, 8], [4, 4 + 2 / 3, 4 + 4 / 3, 6], [5, 7], "non-matching Q9"),
}
KAPPA = 1e4  # pressure per unit gap: 10 E / (1 length unit)
# The meshes on which the pair as written (node-to-surface one-pass, punch slave) is known not to
# pass the patch test (the verdict row of Taylor & Papadopoulos 1991: C-1p and E fail): their
# cases state it in "expected_failures", so that `contact-patch check` reports an expected
# failure with the reason, not a failed run (a listed check that passes fails the case).
NOT_PASSING = {"C", "E"}

ENFORCEMENTS = [
    {"kind": "lagrange"},
    {"kind": "perturbed_lagrange", "kappa": KAPPA},
    {"kind": "penalty", "kappa": KAPPA},
    {"kind": "perturbed_tangent", "kappa": KAPPA},
    {"kind": "augmented_lagrange", "kappa": KAPPA, "update": "per_iteration"},
    {"kind": "augmented_lagrange", "kappa": KAPPA, "update": "outer_loop"},
    {"kind": "elimination"},
]
DISCRETIZATIONS = [
    {"discretization": {"kind": "node_to_node"}},
    {"discretization": {"kind": "node_to_surface", "passes": 1}, "slave": "punch"},
    {"discretization": {"kind": "node_to_surface", "passes": 1}, "slave": "foundation"},
    {"discretization": {"kind": "node_to_surface", "passes": 2}},
    {"discretization": {"kind": "mortar", "multiplier": "standard"}, "slave": "punch"},
    {"discretization": {"kind": "mortar", "multiplier": "dual"}, "slave": "punch"},
]


def expected_failures(mesh):
    """The checks the pair as written fails on `mesh`, with the reason (none on A, B, D)."""
    if mesh not in NOT_PASSING:
        return []
    reason = (
        f"node-to-surface one-pass with the punch as slave on the non-matching mesh {mesh} "
        f"({MESHES[mesh][4]}) does not pass the contact patch test (Taylor & Papadopoulos 1991); "
        "`contact-patch table` runs the methods that do"
    )
    return [{"check": check, "reason": reason} for check in ("uniform_stress", "contact_pressure")]


def case(mesh, nu):
    element, fx, px, py, character = MESHES[mesh]
    name = f"patch-{mesh}-nu{nu}"
    c = {
        "name": name,
        "description": f"Contact patch test, mesh {mesh} ({character}), nu = {nu}: punch on foundation under "
        f"uniform pressure {P}; exact solution sigma_yy = -{P} everywhere. The pair as written is node-to-surface "
        "one-pass (punch slave) with Lagrange multipliers; `contact-patch table` runs the sweep. The punch's "
        "top-left corner is held at the exact u_x, so the exact solution does not slide at the interface "
        "and a code that takes contact in the current geometry solves the same problem.",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": nu}},
        "bodies": [
            {
                "name": "foundation",
                "material": "m",
                "mesh": {"block": {"element": element, "x": fx, "y": [0, 2.5, 5]}},
                "facet_sets": {
                    "contact": {"box": {"min": [4, 5], "max": [6, 5]}},
                    "exposed_left": {"box": {"min": [0, 5], "max": [4, 5]}},
                    "exposed_right": {"box": {"min": [6, 5], "max": [8, 5]}},
                },
            },
            {"name": "punch", "material": "m", "mesh": {"block": {"element": element, "x": px, "y": py}}},
        ],
        "supports": [
            {"body": "foundation", "set": "bottom", "y": 0.0},
            {"body": "foundation", "set": "bottom_left", "x": 0.0},
            {"body": "punch", "set": "top_left", "x": "exact"},
        ],
        "loads": [
            {"body": "punch", "set": "top", "pressure": P},
            {"body": "foundation", "set": "exposed_left", "pressure": P},
            {"body": "foundation", "set": "exposed_right", "pressure": P},
        ],
        "exact": {"kind": "uniform_stress", "stress": [0.0, -P, 0.0]},
        "contact": [
            {
                "name": "interface",
                "slave": {"body": "punch", "set": "bottom"},
                "master": {"body": "foundation", "set": "contact"},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": {"kind": "lagrange"},
            }
        ],
        "sweep": {
            "mesh": mesh,
            "discretizations": DISCRETIZATIONS,
            "enforcements": ENFORCEMENTS,
            "penalty_factor": 1000.0,
            "pressure": P,
            "tol": 1e-10,
        },
        "checks": [
            {"check": "uniform_stress", "stress": [0.0, -P, 0.0], "tol": 1e-10},
            {"check": "contact_pressure", "pair": "interface", "tol": 1e-10},
            {"check": "force_balance", "tol": 1e-12},
        ],
    }
    failures = expected_failures(mesh)
    if failures:
        c["expected_failures"] = failures
    return c


for mesh in MESHES:
    for nu in [0.0, 0.3, 0.4]:
        c = case(mesh, nu)
        with open(os.path.join(HERE, c["name"] + ".json"), "w") as f:
            json.dump(c, f, indent=2)
            f.write("\n")
