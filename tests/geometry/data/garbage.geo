This is not a gmsh script.
