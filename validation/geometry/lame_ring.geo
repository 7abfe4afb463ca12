// Thick-walled cylinder, plane strain: the ring a = 0.05 m <= r <= b = 0.1 m in z = 0.
// Physical curves: "bore" (r = a), "outer" (r = b); surface "wall".
SetFactory("OpenCASCADE");
Disk(1) = {0, 0, 0, 0.1, 0.1};
Disk(2) = {0, 0, 0, 0.05, 0.05};
BooleanDifference(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };
Physical Surface("wall") = {3};
bore() = Curve In BoundingBox{-0.05 - 1e-6, -0.05 - 1e-6, -1e-6, 0.05 + 1e-6, 0.05 + 1e-6, 1e-6};
Physical Curve("bore") = {bore()};
outer() = Boundary{ Surface{3}; };
outer() -= bore();
Physical Curve("outer") = {outer()};
