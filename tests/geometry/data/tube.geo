// A tube 1 <= r <= 2, 0 <= z <= 1 along z (OpenCASCADE). Surfaces "bore" (r = 1), "outer"
// (r = 2), "ends" (z = 0 and z = 1); volume "wall".
SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 1, 2};
Cylinder(2) = {0, 0, -0.5, 0, 0, 2, 1};
BooleanDifference(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};
e = 1e-3;
Physical Surface("bore") = Surface In BoundingBox{-1 - e, -1 - e, -e, 1 + e, 1 + e, 1 + e};
ends() = Surface In BoundingBox{-2 - e, -2 - e, -e, 2 + e, 2 + e, e};
ends() += Surface In BoundingBox{-2 - e, -2 - e, 1 - e, 2 + e, 2 + e, 1 + e};
Physical Surface("ends") = {ends()};
outer() = Boundary{Volume{3};};
outer() -= Surface In BoundingBox{-1 - e, -1 - e, -e, 1 + e, 1 + e, 1 + e};
outer() -= ends();
Physical Surface("outer") = {outer()};
Physical Volume("wall") = {3};
