#!/usr/bin/env python3
"""Writes the Cattaneo-Mindlin cases cattaneo-mindlin-L1.json .. -L4.json (run from this folder:
python3 make_cases.py).

Two bodies of one material (E = 200, nu = 0.3, plane strain), so Dundurs' beta = 0 and the normal
and tangential problems of half-spaces uncouple (benchmarks.md section 4; Johnson, Contact
Mechanics, 1985, sections 4.3 and 7.1):
  - `foundation`: the block [-16, 16] x [-16, 0], bottom held in x and y;
  - `indenter`: a block of the same size whose face towards the foundation is Hertz's profile
    y = x^2 / (2 R), R = 100, for |x| <= 2 (continued along its tangent beyond, never in
    contact), top at y = 16; an explicit Q4 mesh whose vertical lines are the foundation's (so
    the interface nodes face each other) and whose rows follow the face, flattening linearly to
    the top.
The blocks mirror each other about the interface but for the indenter's face; what that breaks
(the uncoupling of finite bodies) scales with a / R, here 0.005 (with R = 10 the shear traction
had an odd part of 4 % that did not fall with h).

Load path (displacement control at the indenter's top, which also keeps it from tilting under
the shear; the loads P and Q are measured as the contact forces):
  step 1: top moved down by DOWN (normal load P), x held at 0;
  steps 2..1+SHEAR_STEPS: top moved sideways in equal increments up to SIDE (tangential load Q).
Both meshes: spacing h over |x| <= 1 and over depth 0.4 from the interface, growing by 1.15 per
element outside; h = 0.08, 0.04, 0.02, 0.01 for levels 1-4.
Friction: Coulomb, mu = MU, penalty kappa = kappa_t = KAPPA (force per area per unit gap or
elastic slip: the elastic slip of the stick zone is |q| / KAPPA, below 1e-6 here, against
tangential displacements of order SIDE), node-to-surface, one pass, slave = the indenter's
face. The stick zone is where the status column of interface.contact.csv says `stick`.
(Lagrange multipliers are not used: their semi-smooth Newton cycles on this case, see the
report of branch fricbench.)
"""
import json
import math

E, NU, R, MU = 200.0, 0.3, 100.0, 0.3
HALF_WIDTH, HEIGHT = 16.0, 16.0
FINE_HALF_WIDTH, FINE_DEPTH = 1.0, 0.4
DOWN, SIDE, SHEAR_STEPS = 0.0055, 0.0014, 4
KAPPA = 1.0e6
LEVELS = [0.08, 0.04, 0.02, 0.01]


def graded(fine_to, h, end, growth=1.15):
    """Breaks from 0: spacing h up to fine_to, then growing by `growth` up to end."""
    xs = [0.0]
    while xs[-1] < fine_to - 1e-12:
        xs.append(round(xs[-1] + h, 10))
    step = h
    while xs[-1] < end - 1e-12:
        step *= growth
        nxt = xs[-1] + step
        if end - nxt < 0.5 * growth * step:
            nxt = end
        xs.append(round(min(nxt, end), 10))
    return xs


def face(x):
    """Hertz's gap x^2 / (2 R) for |x| <= 2, then along its tangent."""
    x1 = 2.0
    if abs(x) <= x1:
        return x * x / (2 * R)
    return x1 * x1 / (2 * R) + x1 / R * (abs(x) - x1)


def indenter_mesh(xs, etas):
    """Q4 nodes (i along x fastest) and cells (counter-clockwise from the lower left)."""
    nodes = []
    for eta in etas:
        for x in xs:
            y = face(x) * (1.0 - eta / HEIGHT) + eta
            nodes.append([round(x, 10), round(y, 12)])
    nx = len(xs)
    cells = []
    for j in range(len(etas) - 1):
        for i in range(nx - 1):
            a = j * nx + i
            cells.append([a, a + 1, a + 1 + nx, a + nx])
    return nodes, cells


def case(level, h):
    half = graded(FINE_HALF_WIDTH, h, HALF_WIDTH)
    xs = [-v for v in reversed(half[1:])] + half
    depth = graded(FINE_DEPTH, h, HEIGHT)
    nodes, cells = indenter_mesh(xs, depth)
    steps = 1 + SHEAR_STEPS
    normal_path = [1.0] * steps
    shear_path = [0.0] + [k / SHEAR_STEPS for k in range(1, SHEAR_STEPS + 1)]
    name = f"cattaneo-mindlin-L{level}"
    return {
        "$schema": "../case.schema.json",
        "name": name,
        "description": (
            f"Cattaneo-Mindlin, level {level} (h = {h} at the contact; written by make_cases.py, "
            f"whose notes give the set-up): a cylinder of radius {R:g} (the indenter's face, "
            "Hertz's parabola) pressed onto a block of the same material (E = 200, nu = 0.3, plane "
            f"strain, Dundurs' beta = 0) by moving its top down by {DOWN}, then sheared by "
            f"moving its top sideways by {SIDE} in {SHEAR_STEPS} steps; Coulomb friction "
            f"mu = {MU}, penalty kappa = kappa_t = {KAPPA:g}. Closed forms (Hertz and Cattaneo-Mindlin, "
            "with P and Q the measured contact forces): a = sqrt(4 P R / (pi E*)), "
            "1/E* = 2 (1 - nu^2)/E, stick half-width c = a sqrt(1 - Q/(mu P)). "
            f"`contact-patch cattaneo cases/friction-bench/cattaneo-mindlin-L*.json` writes "
            "reports/cattaneo-mindlin.md/.json/.svg."
        ),
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": E, "nu": NU}},
        "bodies": [
            {
                "name": "foundation",
                "material": "m",
                "mesh": {
                    "block": {
                        "element": "Q4",
                        "x": xs,
                        "y": [-v for v in reversed(depth)],
                    }
                },
            },
            {
                "name": "indenter",
                "material": "m",
                "mesh": {"explicit": {"element": "Q4", "nodes": nodes, "cells": cells}},
                "facet_sets": {
                    "face": {"facets": [[i, 0] for i in range(len(xs) - 1)]}
                },
            },
        ],
        "supports": [
            {"body": "foundation", "set": "bottom", "x": 0.0, "y": 0.0},
            {"body": "indenter", "set": "top", "y": -DOWN, "path": normal_path},
            {"body": "indenter", "set": "top", "x": SIDE, "path": shear_path},
        ],
        "contact": [
            {
                "name": "interface",
                "slave": {"body": "indenter", "set": "face"},
                "master": {"body": "foundation", "set": "top"},
                "discretization": {"kind": "node_to_surface", "passes": 1},
                "enforcement": {"kind": "penalty", "kappa": KAPPA},
                "interaction": {"coulomb": {"mu": MU}},
            }
        ],
        "solver": {"scheme": "newton", "load_steps": steps},
        "checks": [
            {"check": "terminates_with", "reason": "converged"},
        ],
    }


def dump(obj, f):
    """Pretty JSON, but the explicit mesh's node and cell lists and the breaks on one line each
    (the files stay small)."""
    inline = {}

    def hide(d, key):
        marker = f"@@{len(inline)}@@"
        inline[marker] = json.dumps(d[key], separators=(",", ":"))
        d[key] = marker

    for body in obj["bodies"]:
        mesh = body["mesh"]
        for key in ("nodes", "cells"):
            if "explicit" in mesh:
                hide(mesh["explicit"], key)
        for key in ("x", "y"):
            if "block" in mesh:
                hide(mesh["block"], key)
    text = json.dumps(obj, indent=2)
    for marker, value in inline.items():
        text = text.replace(f'"{marker}"', value)
    f.write(text)
    f.write("\n")


if __name__ == "__main__":
    for level, h in enumerate(LEVELS, start=1):
        c = case(level, h)
        with open(f"{c['name']}.json", "w") as f:
            dump(c, f)
