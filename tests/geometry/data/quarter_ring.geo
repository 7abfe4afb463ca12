// A quarter of the thick cylinder 1 <= r <= 2, x, y >= 0, 0 <= z <= 1 (OpenCASCADE), in two
// layers meshed conformally: volumes "lower" (z <= 0.5) and "upper" (z >= 0.5).
// Surfaces: "bore" (r = 1), "outer" (r = 2).
SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 0.5, 2, Pi / 2};
Cylinder(2) = {0, 0, 0, 0, 0, 0.5, 1, Pi / 2};
BooleanDifference(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};
Cylinder(4) = {0, 0, 0.5, 0, 0, 0.5, 2, Pi / 2};
Cylinder(5) = {0, 0, 0.5, 0, 0, 0.5, 1, Pi / 2};
BooleanDifference(6) = {Volume{4}; Delete;}{Volume{5}; Delete;};
BooleanFragments{Volume{3, 6}; Delete;}{}
e = 1e-3;
Physical Volume("lower") = Volume In BoundingBox{-e, -e, -e, 2 + e, 2 + e, 0.5 + e};
Physical Volume("upper") = Volume In BoundingBox{-e, -e, 0.5 - e, 2 + e, 2 + e, 1 + e};
Physical Surface("bore") = Surface In BoundingBox{-e, -e, -e, 1 + e, 1 + e, 1 + e};
// The r = 2 faces: reaching x = 2 and y = 2, not flat in z (the annular end faces are).
all() = Surface In BoundingBox{-e, -e, -e, 2 + e, 2 + e, 1 + e};
outer() = {};
For i In {0 : #all() - 1}
  bb() = BoundingBox Surface{all(i)};
  If (bb(3) > 2 - e && bb(4) > 2 - e && bb(5) - bb(2) > e)
    outer() += all(i);
  EndIf
EndFor
Physical Surface("outer") = outer();
