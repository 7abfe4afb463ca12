// The 2D ring 1 <= r <= 2 in the z = 0 plane (OpenCASCADE): curves "outer", "bore", surface "wall".
SetFactory("OpenCASCADE");
Circle(1) = {0, 0, 0, 2};
Circle(2) = {0, 0, 0, 1};
Curve Loop(1) = {1};
Curve Loop(2) = {2};
Plane Surface(1) = {1, 2};
Physical Curve("outer") = {1};
Physical Curve("bore") = {2};
Physical Surface("wall") = {1};
