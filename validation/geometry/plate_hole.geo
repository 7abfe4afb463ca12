// Plate with a central hole, plane strain: x 0..0.4, y 0..0.1 m, hole radius 0.01 m at
// (0.2, 0.05) (validation/scenes/plate_hole.ini's geometry, fitted to the surface).
// Physical curves: "left" (x = 0), "right" (x = 0.4), "hole"; surface "plate". The points at
// the hole's top and bottom are mesh nodes (the stress probes).
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.4, 0.1};
Disk(2) = {0.2, 0.05, 0, 0.01, 0.01};
BooleanDifference(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };
Physical Surface("plate") = {3};
left() = Curve In BoundingBox{-1e-6, -1e-6, -1e-6, 1e-6, 0.1 + 1e-6, 1e-6};
right() = Curve In BoundingBox{0.4 - 1e-6, -1e-6, -1e-6, 0.4 + 1e-6, 0.1 + 1e-6, 1e-6};
hole() = Curve In BoundingBox{0.19 - 1e-6, 0.04 - 1e-6, -1e-6, 0.21 + 1e-6, 0.06 + 1e-6, 1e-6};
Physical Curve("left") = {left()};
Physical Curve("right") = {right()};
Physical Curve("hole") = {hole()};
