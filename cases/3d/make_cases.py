#!/usr/bin/env python3
"""Writes the 3D contact and tied patch-test catalogues as case files: cases/3d/patch/ and
cases/3d/tied/ (`contact-patch table cases/3d` runs their sweeps into
reports/patch-table-3d.* and reports/tied-table-3d.*).

The scene is the 2D patch test of shared/design/benchmarks.md, section 1, extruded as its
section 8 asks: a foundation [0, 2]^2 x [0, 1] (x and y breaks 0, 1, 2) and a punch
[0, 2]^2 x [1, 2] of the same footprint, E = 1000, nu = 0.3, two cells across each body's
height. Contact: the pressure p = 10 on the punch's top, u_z = 0 on the foundation's bottom,
u_x = u_y = 0 at the bottom-front-left corner of the foundation and the top-front-left corner
of the punch, u_y = 0 at the front-right corners beside them (no reaction in the exact state);
the exact state is sigma_zz = -p, all else zero (u = ((nu p / E) x, (nu p / E) y, -(p / E) z)).

Interfaces (the punch's x and y breaks against the foundation's 0, 1, 2): matching (0, 1, 2),
nested (0, 0.5, 1, 1.5, 2), non-matching (0, 0.7, 1.4, 2) and skewed (the non-matching grid
with the punch's four interior bottom vertices rotated by 15 degrees about (1, 1) in z = 1).
Elements Hex8, Tet4 (six Kuhn tetrahedra per cell), Hex27, Tet10.

Tied (benchmarks.md section 5): the same blocks glued on the non-matching and skewed
interfaces under three loads whose uniform states are exact for their supports:
- normal: the contact test's pressure and supports; sigma_zz = -p.
- parallel: u_x = 0 on x = 0 and u_x = d on x = 2 of both bodies, u_y = 0 on y = 0 of both,
  u_z = 0 on the foundation's bottom; u = (eps x, -nu eps y, -nu eps z), eps = d / 2, so
  sigma_xx = E d / 2.
- shear: u_x = s on the punch's top, u_x = u_z = 0 on the foundation's bottom, u_z = 0 on
  x = 0 and x = 2 of both, u_y = 0 on y = 0 of both; u = (gamma z, 0, 0), gamma = s / 2, so
  sigma_xz = G s / 2 (the x-faces' supports carry the traction sigma_xz a free face cannot).

Each case's own pair is standard mortar with Lagrange multipliers (it passes on every
interface, so `contact-patch check cases/3d` passes); its sweep varies the pair. The sweep's
`pressure` is the largest exact stress component, so errors are relative to it.

Rerun after changing it: python3 cases/3d/make_cases.py
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
P = 10.0
E = 1000.0
NU = 0.3
KAPPA = 1e4  # 10 E / (1 length unit), as in the 2D tables
STRETCH = 0.01
SHEAR = 0.02
SKEW_DEGREES = 15.0
FOUNDATION = [0.0, 1.0, 2.0]
ELEMENTS = ["Hex8", "Tet4", "Hex27", "Tet10"]
# file names sort as the tables' columns: linear elements first, then quadratic
DEGREE = {"Hex8": "linear", "Tet4": "linear", "Hex27": "quadratic", "Tet10": "quadratic"}

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
    {"discretization": {"kind": "node_to_surface", "passes": 1}, "slave": "punch"},
    {"discretization": {"kind": "node_to_surface", "passes": 1}, "slave": "foundation"},
    {"discretization": {"kind": "node_to_surface", "passes": 2}},
    {"discretization": {"kind": "node_to_node"}},
    {"discretization": {"kind": "mortar", "multiplier": "standard"}, "slave": "punch"},
    {"discretization": {"kind": "mortar", "multiplier": "dual"}, "slave": "punch"},
]
TIED_DISCRETIZATIONS = [
    d for d in DISCRETIZATIONS
    if d["discretization"].get("passes") != 2 and d["discretization"]["kind"] != "node_to_node"
]
TIED_ENFORCEMENTS = [{"kind": "lagrange"}, {"kind": "penalty", "kappa": KAPPA}]


def interfaces():
    non_matching = [0.0, 0.7, 1.4, 2.0]
    s, c = math.sin(math.radians(SKEW_DEGREES)), math.cos(math.radians(SKEW_DEGREES))
    moves = []
    for x in non_matching[1:3]:
        for y in non_matching[1:3]:
            dx, dy = x - 1.0, y - 1.0
            moves.append({"from": [x, y, 1.0], "to": [1.0 + c * dx - s * dy, 1.0 + s * dx + c * dy, 1.0]})
    return [
        ("matching", FOUNDATION, []),
        ("nested", [0.0, 0.5, 1.0, 1.5, 2.0], []),
        ("non-matching", non_matching, []),
        ("skewed", non_matching, moves),
    ]


PATCH_SUPPORTS = [
    {"body": "foundation", "set": "bottom", "z": 0.0},
    {"body": "foundation", "set": "bottom_front_left", "x": 0.0, "y": 0.0},
    {"body": "foundation", "set": "bottom_front_right", "y": 0.0},
    {"body": "punch", "set": "top_front_left", "x": 0.0, "y": 0.0},
    {"body": "punch", "set": "top_front_right", "y": 0.0},
]
PRESSURE_ON_PUNCH = [{"body": "punch", "set": "top", "pressure": P}]


def tied_load(label):
    """Supports, loads and the exact stress [xx, yy, zz, yz, xz, xy] of a tied load."""
    if label == "normal":
        return PATCH_SUPPORTS, PRESSURE_ON_PUNCH, [0.0, 0.0, -P, 0.0, 0.0, 0.0]
    if label == "parallel":
        supports = [{"body": "foundation", "set": "bottom", "z": 0.0}]
        for body in ["foundation", "punch"]:
            supports += [
                {"body": body, "set": "left", "x": 0.0},
                {"body": body, "set": "right", "x": STRETCH},
                {"body": body, "set": "front", "y": 0.0},
            ]
        return supports, [], [E * STRETCH / 2.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    supports = [
        {"body": "foundation", "set": "bottom", "x": 0.0, "z": 0.0},
        {"body": "punch", "set": "top", "x": SHEAR},
    ]
    for body in ["foundation", "punch"]:
        supports += [
            {"body": body, "set": "left", "z": 0.0},
            {"body": body, "set": "right", "z": 0.0},
            {"body": body, "set": "front", "y": 0.0},
        ]
    g = E / (2.0 * (1.0 + NU))
    return supports, [], [0.0, 0.0, 0.0, 0.0, g * SHEAR / 2.0, 0.0]


def two_blocks(name, description, element, interface, tied, supports, loads, stress, catalogue, mesh_label):
    label, punch, moves = interface
    pair = {
        "name": "interface",
        "slave": {"body": "punch", "set": "bottom"},
        "master": {"body": "foundation", "set": "top"},
        "discretization": {"kind": "mortar", "multiplier": "standard"},
        "enforcement": {"kind": "lagrange"},
    }
    if tied:
        pair["interaction"] = "tied"
    scale = max(abs(v) for v in stress)
    case = {
        "name": name,
        "description": description,
        "materials": {"m": {"E": E, "nu": NU}},
        "bodies": [
            {"name": "foundation", "material": "m", "mesh": {"block3d": {
                "element": element, "x": FOUNDATION, "y": FOUNDATION, "z": [0.0, 0.5, 1.0]}}},
            {"name": "punch", "material": "m", "mesh": {"block3d": {
                "element": element, "x": punch, "y": punch, "z": [1.0, 1.5, 2.0], "moves": moves}}},
        ],
        "supports": supports,
        "loads": loads,
        "contact": [pair],
        "checks": [{"check": "uniform_stress_3d", "stress": stress, "tol": 1e-10}],
        "sweep": {
            "catalogue": catalogue,
            "mesh": mesh_label,
            "discretizations": TIED_DISCRETIZATIONS if tied else DISCRETIZATIONS,
            "enforcements": TIED_ENFORCEMENTS if tied else ENFORCEMENTS,
            "penalty_factor": 1000.0,
            "pressure": scale,
            "tol": 1e-10,
        },
    }
    return case


def write(folder, name, case):
    os.makedirs(os.path.join(HERE, folder), exist_ok=True)
    with open(os.path.join(HERE, folder, name + ".json"), "w") as f:
        json.dump(case, f, indent=2)
        f.write("\n")


def main():
    for element in ELEMENTS:
        for interface in interfaces():
            label = interface[0]
            name = f"patch-3d-{DEGREE[element]}-{element.lower()}-{label}"
            description = (
                f"3D contact patch test, {element}, {label} interface: a punch pressed by p = {P} onto a "
                "foundation of the same footprint; exact: sigma_zz = -p, all else zero. The pair as "
                "written is standard mortar with Lagrange multipliers; `contact-patch table` runs the "
                "sweep (written by cases/3d/make_cases.py)."
            )
            write("patch", name, two_blocks(
                name, description, element, interface, False, PATCH_SUPPORTS, PRESSURE_ON_PUNCH,
                [0.0, 0.0, -P, 0.0, 0.0, 0.0], "patch", f"{element} {label}"))
    for element in ELEMENTS:
        for interface in [i for i in interfaces() if i[0] in ("non-matching", "skewed")]:
            label = interface[0]
            for load in ["normal", "parallel", "shear"]:
                supports, loads, stress = tied_load(load)
                name = f"tied-3d-{DEGREE[element]}-{element.lower()}-{label}-{load}"
                description = (
                    f"3D tied patch test ({load}), {element}, {label} interface: the punch glued to the "
                    "foundation; the exact state is uniform (see cases/3d/make_cases.py). The pair as "
                    "written is standard mortar with Lagrange multipliers; `contact-patch table` runs "
                    "the sweep."
                )
                write("tied", name, two_blocks(
                    name, description, element, interface, True, supports, loads, stress, "tied",
                    f"{load}: {element} {label}"))


if __name__ == "__main__":
    main()
