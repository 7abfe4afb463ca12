// A 4 x 4 x 2 box with a cylindrical hole of radius 1 through it along z (OpenCASCADE).
// Surfaces: "bore" (the hole), "bottom" (z = 0), "top" (z = 2); volume "block".
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 4, 4, 2};
Cylinder(2) = {2, 2, 0, 0, 0, 2, 1};
BooleanDifference(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};
e = 1e-3;
Physical Surface("bore") = Surface In BoundingBox{1 - e, 1 - e, -e, 3 + e, 3 + e, 2 + e};
Physical Surface("bottom") = Surface In BoundingBox{-e, -e, -e, 4 + e, 4 + e, e};
Physical Surface("top") = Surface In BoundingBox{-e, -e, 2 - e, 4 + e, 4 + e, 2 + e};
Physical Volume("block") = {3};
