// The ring of ring.geo in the plane z = 1: not a 2D body.
SetFactory("OpenCASCADE");
Circle(1) = {0, 0, 1, 2};
Circle(2) = {0, 0, 1, 1};
Curve Loop(1) = {1};
Curve Loop(2) = {2};
Plane Surface(1) = {1, 2};
