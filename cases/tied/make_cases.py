#!/usr/bin/env python3
"""Writes the tied-interface patch tests (meshes B, C, E x three stress states) in this folder.

A block [0,2]x[0,1] ("lower") tied to a block [0,2]x[1,2] ("upper") along y = 1 across a
non-matching interface (shared/design/benchmarks.md section 5): every constant stress state,
normal (sigma_yy), parallel (sigma_xx) and shear (sigma_xy), must be reproduced to round-off by a
consistent tie. Rerun after changing it: python3 cases/tied/make_cases.py
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
S = 10.0
MESHES = {
    # name: (element, lower x-breaks, upper x-breaks)
    "B": ("Q4", [0, 1, 2], [0, 0.5, 1, 1.5, 2]),
    "C": ("Q4", [0, 1, 2], [0, 2 / 3, 4 / 3, 2]),
    "E": ("Q9", [0, 1, 2], [0, 2 / 3, 4 / 3, 2]),
}
STRESSES = {"normal": [0.0, -S, 0.0], "parallel": [S, 0.0, 0.0], "shear": [0.0, 0.0, S]}
KAPPA = 1e4


def case(mesh, state):
    element, lx, ux = MESHES[mesh]
    stress = STRESSES[state]
    name = f"tied-{mesh}-{state}"
    return {
        "name": name,
        "description": f"Tied patch test, mesh {mesh}, uniform {state} stress {stress}: exact tractions on the outer "
        "boundary, the upper block held only by the tie. The pair as written is a dual mortar tie with Lagrange "
        "multipliers; `contact-patch table` runs the sweep.",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 1000.0, "nu": 0.3}},
        "bodies": [
            {"name": "lower", "material": "m", "mesh": {"block": {"element": element, "x": lx, "y": [0, 0.5, 1]}}},
            {"name": "upper", "material": "m", "mesh": {"block": {"element": element, "x": ux, "y": [1, 1.5, 2]}}},
        ],
        "supports": [
            {"body": "lower", "set": "bottom_left", "x": "exact", "y": "exact"},
            {"body": "lower", "set": "bottom_right", "y": "exact"},
        ],
        "loads": [{"body": b, "set": s, "traction": "exact"} for b, sets in [("lower", ["left", "right", "bottom"]), ("upper", ["left", "right", "top"])] for s in sets],
        "exact": {"kind": "uniform_stress", "stress": stress},
        "contact": [
            {
                "name": "tie",
                "slave": {"body": "upper", "set": "bottom"},
                "master": {"body": "lower", "set": "top"},
                "interaction": "tied",
                "discretization": {"kind": "mortar", "multiplier": "dual"},
                "enforcement": {"kind": "lagrange"},
            }
        ],
        "sweep": {
            "catalogue": "tied",
            "mesh": f"{mesh}-{state}",
            "discretizations": [
                {"discretization": {"kind": "node_to_surface", "passes": 1}, "slave": "upper"},
                {"discretization": {"kind": "node_to_surface", "passes": 1}, "slave": "lower"},
                {"discretization": {"kind": "mortar", "multiplier": "standard"}, "slave": "upper"},
                {"discretization": {"kind": "mortar", "multiplier": "dual"}, "slave": "upper"},
            ],
            "enforcements": [{"kind": "lagrange"}, {"kind": "penalty", "kappa": KAPPA}, {"kind": "elimination"}],
            "penalty_factor": 1000.0,
            "pressure": S,
            "tol": 1e-10,
        },
        "checks": [
            {"check": "uniform_stress", "stress": stress, "tol": 1e-10},
            {"check": "contact_pressure", "pair": "tie", "tol": 1e-10},
            {"check": "force_balance", "tol": 1e-12},
        ],
    }


for mesh in MESHES:
    for state in STRESSES:
        c = case(mesh, state)
        with open(os.path.join(HERE, c["name"] + ".json"), "w") as f:
            json.dump(c, f, indent=2)
            f.write("\n")
