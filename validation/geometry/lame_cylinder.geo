// Thick-walled cylinder with open ends, 3D: a = 0.05 m <= r <= b = 0.1 m, 0 <= z <= 0.05 m.
// Physical surfaces: "bore" (r = a), "outer" (r = b), "ends" (z = 0 and z = 0.05); volume "wall".
SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 0.05, 0.1};
Cylinder(2) = {0, 0, -0.01, 0, 0, 0.07, 0.05};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Physical Volume("wall") = {3};
bore() = Surface In BoundingBox{-0.05 - 1e-6, -0.05 - 1e-6, -1e-6, 0.05 + 1e-6, 0.05 + 1e-6, 0.05 + 1e-6};
Physical Surface("bore") = {bore()};
ends() = Surface In BoundingBox{-0.1 - 1e-6, -0.1 - 1e-6, -1e-6, 0.1 + 1e-6, 0.1 + 1e-6, 1e-6};
ends() += Surface In BoundingBox{-0.1 - 1e-6, -0.1 - 1e-6, 0.05 - 1e-6, 0.1 + 1e-6, 0.1 + 1e-6, 0.05 + 1e-6};
Physical Surface("ends") = {ends()};
outer() = Boundary{ Volume{3}; };
outer() -= bore();
outer() -= ends();
Physical Surface("outer") = {outer()};
