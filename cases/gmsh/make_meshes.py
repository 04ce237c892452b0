"""Writes the Gmsh meshes of the cases in this folder with the `gmsh` Python package (PyPI,
`pip install gmsh`; these files were written with gmsh 4.15.2):

  patch-q4.msh     MSH 4.1 ASCII   unstructured 4-node quadrangles on a skew quadrilateral
  patch-q9.msh     MSH 2.2 ASCII   the same domain, 9-node quadrangles
  patch-t6.msh     MSH 4.1 binary  the same domain, 6-node triangles
  hertz-q4.msh     MSH 4.1 binary  a half cylinder (radius 10, flat face up), 4-node
                                   quadrangles graded to 0.02 near the contact point (0, 0)

Physical groups: the patch's sides are the curves "south", "east", "north", "west", its
corners the points "origin" (0, 0) and "south_east" (3, 0), its surface "patch"; the
cylinder's surface is "cylinder", its arc "arc", its flat face "flat" and the point at the
middle of the flat face "flat_centre".

Run from this folder: python3 make_meshes.py
"""

import gmsh

PATCH_CORNERS = [(0.0, 0.0), (3.0, 0.0), (2.5, 2.0), (0.3, 1.7)]


def patch(name, order, quads, version, binary):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    geo = gmsh.model.geo
    points = [geo.addPoint(x, y, 0.0, 0.45) for x, y in PATCH_CORNERS]
    lines = [geo.addLine(points[i], points[(i + 1) % 4]) for i in range(4)]
    loop = geo.addCurveLoop(lines)
    surface = geo.addPlaneSurface([loop])
    geo.synchronize()
    for line, side in zip(lines, ["south", "east", "north", "west"]):
        gmsh.model.addPhysicalGroup(1, [line], name=side)
    gmsh.model.addPhysicalGroup(0, [points[0]], name="origin")
    gmsh.model.addPhysicalGroup(0, [points[1]], name="south_east")
    gmsh.model.addPhysicalGroup(2, [surface], name="patch")
    if quads:
        gmsh.option.setNumber("Mesh.Algorithm", 8)
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.option.setNumber("Mesh.ElementOrder", order)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    gmsh.model.mesh.generate(2)
    save(name, version, binary)


def hertz(name):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    geo = gmsh.model.geo
    radius = 10.0
    centre = geo.addPoint(0.0, radius, 0.0)
    bottom = geo.addPoint(0.0, 0.0, 0.0)
    left = geo.addPoint(-radius, radius, 0.0)
    right = geo.addPoint(radius, radius, 0.0)
    arc_left = geo.addCircleArc(left, centre, bottom)
    arc_right = geo.addCircleArc(bottom, centre, right)
    flat_right = geo.addLine(right, centre)
    flat_left = geo.addLine(centre, left)
    loop = geo.addCurveLoop([arc_left, arc_right, flat_right, flat_left])
    surface = geo.addPlaneSurface([loop])
    geo.synchronize()
    gmsh.model.addPhysicalGroup(1, [arc_left, arc_right], name="arc")
    gmsh.model.addPhysicalGroup(1, [flat_right, flat_left], name="flat")
    gmsh.model.addPhysicalGroup(0, [centre], name="flat_centre")
    gmsh.model.addPhysicalGroup(2, [surface], name="cylinder")
    # element size 0.02 within 0.8 of the contact point, growing to 1.0 at distance 6
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [bottom])
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", 0.02)
    field.setNumber(threshold, "SizeMax", 1.0)
    field.setNumber(threshold, "DistMin", 0.8)
    field.setNumber(threshold, "DistMax", 6.0)
    field.setAsBackgroundMesh(threshold)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 8)
    gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.model.mesh.generate(2)
    save(name, 4.1, True)


def save(name, version, binary):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    # only the elements of physical groups, so every written element belongs to a set
    gmsh.option.setNumber("Mesh.SaveAll", 0)
    gmsh.write(name + ".msh")
    types, tags, _ = gmsh.model.mesh.getElements(2)
    counts = {gmsh.model.mesh.getElementProperties(t)[0]: len(e) for t, e in zip(types, tags)}
    print(f"{name}.msh: MSH {version} {'binary' if binary else 'ASCII'}, 2D elements {counts}")
    gmsh.finalize()


if __name__ == "__main__":
    patch("patch-q4", 1, True, 4.1, False)
    patch("patch-q9", 2, True, 2.2, False)
    patch("patch-t6", 2, False, 4.1, True)
    hertz("hertz-q4")
