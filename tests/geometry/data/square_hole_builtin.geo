// The square [-2, 2]^2 with the hole r < 1, built-in kernel (circle arcs through centre points).
// Curves "bore", "sides"; surface "plate".
lc = 1;
Point(1) = {0, 0, 0, lc};
Point(2) = {1, 0, 0, lc};
Point(3) = {0, 1, 0, lc};
Point(4) = {-1, 0, 0, lc};
Point(5) = {0, -1, 0, lc};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Point(6) = {-2, -2, 0, lc};
Point(7) = {2, -2, 0, lc};
Point(8) = {2, 2, 0, lc};
Point(9) = {-2, 2, 0, lc};
Line(5) = {6, 7};
Line(6) = {7, 8};
Line(7) = {8, 9};
Line(8) = {9, 6};
Curve Loop(1) = {5, 6, 7, 8};
Curve Loop(2) = {1, 2, 3, 4};
Plane Surface(1) = {1, 2};
Physical Curve("bore") = {1, 2, 3, 4};
Physical Curve("sides") = {5, 6, 7, 8};
Physical Surface("plate") = {1};
