#!/usr/bin/env python3
"""Writes the frictional contact patch-test catalogue (meshes A-E x stick/slip) in this folder.

Each case is the contact patch test of cases/patch/patch-<mesh>-nu0.3.json (geometry of
shared/design/benchmarks.md, section 1) with Coulomb friction (section 4): the uniform field
sigma = [0, -p, q] loaded by its own tractions on every free boundary of both bodies, the
pressure p in the first load step, the shear part of the tractions (sxy n_y, sxy n_x) in the
second. `stick`: q = mu p / 2 as a traction on the punch top (every point sticks, the field is
exact; nu = 0.3). `slip`: the punch top dragged by d along x with q = mu p (nu = 0, where a
uniform drag of the top is the exact field's) (every point slips with
|lambda_t| = mu lambda_n; the field is exact again). The punch has no x support: friction holds
it. Rerun after changing it: python3 cases/friction/make_cases.py
"""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
PATCH = os.path.join(HERE, "..", "patch")
P = 10.0
MU = 0.3
KAPPA = 1e4  # as in the patch catalogue; kappa_t defaults to it
DRAG = 0.1  # the punch top's tangential displacement in the slip test (the elastic shear takes 7 mu p / G = 0.042 at nu = 0)
# stick at nu = 0.3; slip at nu = 0: a uniform tangential displacement of the punch top is the
# exact field's only at nu = 0 (at nu > 0 the top widens by eps_xx x, which the drag would hold)
NU = {"stick": "0.3", "slip": "0.0"}


def case(mesh, status):
    nu = NU[status]
    with open(os.path.join(PATCH, f"patch-{mesh}-nu{nu}.json")) as f:
        base = json.load(f)
    q = MU * P / 2 if status == "stick" else MU * P
    normal = [1.0, 1.0]  # the pressure in both steps
    tangential = [0.0, 1.0]  # the tangential load in the second

    def pressure(body, s):
        return {"body": body, "set": s, "pressure": P, "path": normal}

    def shear(body, s, t):
        return {"body": body, "set": s, "traction": [t[0] * q, t[1] * q], "path": tangential}

    supports = [
        {"body": "foundation", "set": "bottom", "y": 0.0},
        {"body": "foundation", "set": "bottom_left", "x": 0.0},
    ]
    loads = [
        pressure("punch", "top"),
        pressure("foundation", "exposed_left"),
        pressure("foundation", "exposed_right"),
        shear("punch", "left", [0.0, -1.0]),
        shear("punch", "right", [0.0, 1.0]),
        shear("foundation", "exposed_left", [1.0, 0.0]),
        shear("foundation", "exposed_right", [1.0, 0.0]),
        shear("foundation", "left", [0.0, -1.0]),
        shear("foundation", "right", [0.0, 1.0]),
        shear("foundation", "bottom", [-1.0, 0.0]),
    ]
    if status == "stick":
        loads.append(shear("punch", "top", [1.0, 0.0]))
        what = f"a tangential traction q = mu p / 2 = {q} on the punch top: every point sticks"
    else:
        supports.append({"body": "punch", "set": "top", "x": DRAG, "path": tangential})
        what = f"the punch top dragged by {DRAG} along x: every point slips with traction mu p = {q}"
    sweep = dict(base["sweep"])
    sweep["catalogue"] = "friction"
    sweep["expect"] = status
    # the augmented Lagrangian again with Laursen & Simo's symmetric form (a column of its own)
    sweep["friction_tangents"] = ["laursen_simo"]
    name = f"friction-{mesh}-{status}"
    c = {
        "name": name,
        "description": f"Frictional contact patch test, mesh {mesh}, nu = {nu}, Coulomb mu = {MU}: step 1 presses the "
        f"punch with p = {P}, step 2 adds {what}. The shear part of the uniform field's traction on every other free "
        f"boundary makes [0, -{P}, {q}] exact. The pair as written is node-to-surface one-pass (punch slave) with the "
        "penalty; `contact-patch table` runs the sweep.",
        "analysis": base["analysis"],
        "materials": base["materials"],
        "bodies": base["bodies"],
        "supports": supports,
        "loads": loads,
        "exact": {"kind": "uniform_stress", "stress": [0.0, -P, q]},
        "contact": [
            {
                "name": "interface",
                "slave": {"body": "punch", "set": "bottom"},
                "master": {"body": "foundation", "set": "contact"},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": {"kind": "penalty", "kappa": KAPPA},
                "interaction": {"coulomb": {"mu": MU}},
            }
        ],
        "solver": {"scheme": "newton", "load_steps": 2},
        "sweep": sweep,
        "checks": [
            {"check": "uniform_stress", "stress": [0.0, -P, q], "tol": 1e-10},
            {"check": "force_balance", "tol": 1e-12},
        ],
    }
    # the same pair as the patch case (node-to-surface one-pass, punch slave): the checks it is
    # known to fail there, with the patch case's reason, where this case declares them
    declared = {check["check"] for check in c["checks"]}
    failures = [e for e in base.get("expected_failures", []) if e["check"] in declared]
    if failures:
        c["expected_failures"] = failures
    return c


for mesh in "ABCDE":
    for status in ["stick", "slip"]:
        c = case(mesh, status)
        with open(os.path.join(HERE, c["name"] + ".json"), "w") as f:
            json.dump(c, f, indent=2)
            f.write("\n")
